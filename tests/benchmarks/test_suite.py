"""Suite files (benchmarks/suite.py) as the bench command reads them: parameters and grids expanded into named
variants when the suite loads, bad input, overrides, runs, built-ins."""

import pytest

from sarcover.benchmarks.cli import EXIT_BAD_INPUT, EXIT_OK, main
from sarcover.benchmarks.registry import METHODS
from sarcover.benchmarks.suite import SuiteError, load_suite
from sarcover.formulations.records import read_rows

from bench_suites import write_suite


GRID = """
name = "grid"
methods = ["greedy", "pyvrp"]
time_limit = 10
[method.pyvrp.params]
neighbours = 10
[method.pyvrp.grid]
iterations = [5, 20]
exhaustive_on_best = [true, false]
[[instances]]
M = 4
K = 2
N = 2
"""


def write(tmp_path, body: str, name: str = "s.toml"):
    path = tmp_path / name
    path.write_text(body)
    return path


def test_a_grid_expands_into_named_variants_with_resolved_parameters(tmp_path):
    """Two lists of two values: four variants, named by their values, in the keys' order."""
    suite = load_suite(str(write(tmp_path, GRID)))
    assert suite.methods == ["greedy", "pyvrp[iterations=5,exhaustive_on_best=true]",
                             "pyvrp[iterations=5,exhaustive_on_best=false]",
                             "pyvrp[iterations=20,exhaustive_on_best=true]",
                             "pyvrp[iterations=20,exhaustive_on_best=false]"]
    params = {j.method: j.params for j in suite.jobs}
    assert params["greedy"] == {}
    assert params["pyvrp[iterations=20,exhaustive_on_best=false]"] == {
        **METHODS["pyvrp"].resolve(), "iterations": 20, "exhaustive_on_best": False, "neighbours": 10}
    assert all(j.as_dict()["params"] == j.params for j in suite.jobs)


def test_grid_variants_run_as_methods_of_their_own_and_rows_carry_their_parameters(tmp_path, capsys):
    """`sarcover bench` on a grid: one row per variant, each with its parameters, each run with them."""
    out = tmp_path / "res"
    assert main(["bench", str(write(tmp_path, GRID.replace("exhaustive_on_best = [true, false]\n", ""))),
                 "-o", str(out), "--quiet", "--workers", "1"]) == EXIT_OK
    rows, _ = read_rows(out)
    by_method = {r["method"]: r for r in rows}
    assert set(by_method) == {"greedy", "pyvrp[iterations=5]", "pyvrp[iterations=20]"}
    for its in (5, 20):
        row = by_method[f"pyvrp[iterations={its}]"]
        assert row["valid"] and row["info"]["params"]["iterations"] == its
        assert row["info"]["params"]["neighbours"] == 10
        assert row["info"]["pass1"]["iterations"] == its  # PyVRP ran the variant's iterations


def test_methods_option_keeps_every_variant_of_a_listed_method(tmp_path):
    """--methods pyvrp keeps all of pyvrp's variants; a variant's own name keeps that one."""
    path = str(write(tmp_path, GRID))
    assert len(load_suite(path, methods=["pyvrp"]).methods) == 4
    one = "pyvrp[iterations=5,exhaustive_on_best=true]"
    assert load_suite(path, methods=[one]).methods == [one]


def test_bench_methods_takes_a_variant_name_with_its_own_commas(tmp_path):
    """`bench --methods 'pyvrp[a=..,b=..],greedy'` splits at the commas outside the brackets."""
    out = tmp_path / "res"
    one = "pyvrp[iterations=5,exhaustive_on_best=false]"
    assert main(["bench", str(write(tmp_path, GRID)), "-o", str(out), "--quiet", "--methods", f"{one},greedy"]) == 0
    assert {r["method"] for r in read_rows(out)[0]} == {one, "greedy"}


def test_a_listed_variant_name_and_an_instance_sets_override_apply(tmp_path):
    """methods may name a variant; [instances.method.NAME] sets the time limit of all its variants."""
    suite = load_suite(str(write(tmp_path, """
methods = ["adpc-pso[iterations=3]", "pyvrp"]
[method.pyvrp.grid]
iterations = [5, 6]
[[instances]]
M = 3
K = 2
N = 1
[instances.method.pyvrp]
time_limit = 7
""")))
    limits = {j.method: j.time_limit for j in suite.jobs}
    assert limits == {"adpc-pso[iterations=3]": 60.0, "pyvrp[iterations=5]": 7.0, "pyvrp[iterations=6]": 7.0}
    assert {j.params["iterations"] for j in suite.jobs if j.method.startswith("adpc")} == {3}


@pytest.mark.parametrize("table, needle", [
    ("[method.pyvrp.params]\niteratons = 5", "unknown parameter 'iteratons'; valid: iterations (int, 2000)"),
    ("[method.pyvrp.params]\niterations = \"many\"", "'iterations' must be int, got \"many\""),
    ("[method.pyvrp.grid]\niterations = 5", "must be a table of parameter = [values, ...]"),
    ("[method.pyvrp.grid]\niterations = [5, 0]", "'iterations' must be >= 1, got 0"),
    ("[method.pyvrp.params]\niterations = 5\n[method.pyvrp.grid]\niterations = [5]", "both in params and in grid"),
    ("[method.greedy.params]\nx = 1", "'greedy' takes no parameters"),
])
def test_bad_parameters_in_a_suite_are_one_line_before_anything_runs(tmp_path, capsys, table, needle):
    """A suite's bad parameter or grid: exit 2, one line naming it and the file, no results."""
    body = f'methods = ["greedy", "pyvrp"]\n{table}\n[[instances]]\nM = 3\nK = 2\nN = 1\n'
    with pytest.raises(SuiteError, match="bad.toml"):
        load_suite(str(write(tmp_path, body, "bad.toml")))
    capsys.readouterr()
    assert main(["bench", str(tmp_path / "bad.toml"), "-o", str(tmp_path / "res"), "--quiet"]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and needle in err, err
    assert not (tmp_path / "res").exists()


@pytest.mark.parametrize("body, needle", [
    ('methods = ["greedy", "no-such-method"]\n[[instances]]\nM = 3\nK = 2\nN = 1', "unknown method 'no-such-method'"),
    ('methods = ["greedy"]\n[[instances]]\nM = 3\nK = 0\nN = 1', "K must be >= 1"),
    ('methods = ["greedy"]\ntime_limit = "long"\n[[instances]]\nM = 3\nK = 2\nN = 1',
     "time_limit must be a finite number"),
    ('methods = ["greedy"]\n[[instances]]\nM = 3\nK = 2\nN = 1\nviews = 4', "unknown key 'views'"),
    ('methods = ["greedy"]\n[[instances]]\nfiles = ["p9.9.z"]', "instance file 'p9.9.z' not found"),
    ('methods = ["greedy"]\n[[instances]]\nfiles = ["missing.json"]', "instance file 'missing.json' not found"),
    ('methods = ["greedy"]\n[method.milp]\ntime_limit = 3\n[[instances]]\nM = 3\nK = 2\nN = 1', "[method.milp]"),
    ('methods = ["greedy"\n', "not valid TOML"),
    ('methods = ["greedy"]\n[[instances]]\nM = 3\nK = 2\nN = 1\n[instances.method.bp]\ntime_limit = 3',
     "[instances.method.bp] names a method not in methods"),
    ('methods = ["greedy"]\n[[instances]]\nM = 3\nK = 2\nN = 1\n[instances.method.greedy]\ntimelimit = 3',
     "unknown key 'timelimit'"),
])
def test_bad_suite_files_give_one_line_error(tmp_path, capsys, body, needle):
    """Unknown method, bad parameter, missing file: one line naming the problem, exit 2, nothing run."""
    suite = write_suite(tmp_path, body, "bad.toml")
    assert main(["bench", str(suite), "-o", str(tmp_path / "res"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and needle in err and "bad.toml" in err, err
    assert not (tmp_path / "res").exists()


def test_an_instance_set_overrides_a_methods_time_limit(tmp_path):
    """[instances.method.NAME] sets a method's time limit for that set only, over [method.NAME]."""
    suite = load_suite(str(write_suite(tmp_path, """
methods = ["greedy", "bp"]
time_limit = 10
[method.bp]
time_limit = 60
[[instances]]
M = 3
K = 2
N = 1
[[instances]]
M = 3
K = 4
N = 1
[instances.method.bp]
time_limit = 300
""")))
    limits = {(j.source["K"], j.method): j.time_limit for j in suite.jobs}
    assert limits == {(2, "greedy"): 10, (2, "bp"): 60, (4, "greedy"): 10, (4, "bp"): 300}


def test_unknown_suite_name_lists_builtins(capsys):
    """A suite that is neither built in nor a file is a one-line error listing the built-ins."""
    assert main(["bench", "no-such-suite", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "quick" in err and "paper-n" in err and len(err.strip().splitlines()) == 1


def test_runs_define_instances_and_seeds(tmp_path):
    """runs = new random instances per setting (--runs overrides); seeds = method seeds per instance."""
    suite = write_suite(tmp_path, """
methods = ["greedy"]
seeds = 2
[[instances]]
M = 5
K = 2
N = [2, 3]
runs = 1000
seed = 10
""")
    s = load_suite(str(suite), runs=3)
    assert len(s.jobs) == 2 * 3 * 2
    assert {j.source["instance_seed"] for j in s.jobs} == {10, 11, 12}
    assert {j.seed for j in s.jobs} == {0, 1}
    assert sorted(j.run for j in s.jobs if j.source["N"] == 2) == list(range(6))
    assert len(load_suite(str(suite)).jobs) == 2 * 1000 * 2


def test_builtin_suites_load_with_registered_methods():
    """Built-in suites load with registered methods; paper-n is Fig. 3's grid; TOP suites hold every shipped file."""
    from sarcover.benchmarks.catalog import TOP_DIR
    from sarcover.benchmarks.registry import METHODS
    from sarcover.benchmarks.suite import builtin_suites

    assert {"quick", "exact-small", "paper-n", "paper-k", "top-chao"} <= set(builtin_suites())
    for name in builtin_suites():
        suite = load_suite(name, runs=None if name.startswith("top-") else 2)
        assert suite.jobs and set(suite.methods) <= set(METHODS), name
    paper_n = load_suite("paper-n", runs=2)
    assert {(j.source["M"], j.source["K"], j.source["N"]) for j in paper_n.jobs} == {(20, 3, n) for n in range(2, 7)}
    assert not any(j.source["exact"] for j in paper_n.jobs)
    shipped = {p.stem for p in TOP_DIR.glob("p*.txt")}
    assert {j.instance for j in load_suite("top-chao").jobs} == {n for n in shipped if n[1] in "123"}
    top47 = load_suite("top-4-7")
    assert {j.instance for j in top47.jobs} == {n for n in shipped if n[1] in "4567"}
    refs = [(j.source["reference"], j.source["best_known"]) for j in top47.jobs]
    assert all((r is None) != (b is None) for r, b in refs)  # each file: a proven optimum or a best known value


def test_paper_validation_is_paper_opts_grid_and_bp_limits_on_held_out_seeds():
    """paper-validation: the settings and bp time limits of paper-opt, on instance seeds 200..219
    (none of paper-opt's or scale's), with bp and the greedy floor only."""
    def bp_limits(suite):
        return {(j.source["K"], j.source["N"]): j.time_limit for j in suite.jobs if j.method == "bp"}

    val, opt = load_suite("paper-validation"), load_suite("paper-opt")
    assert bp_limits(val) == bp_limits(opt) and set(bp_limits(val).values()) == {60.0, 300.0, 600.0}
    assert set(val.methods) == {"greedy", "bp"}
    seeds = {j.source["instance_seed"] for j in val.jobs}
    assert seeds == set(range(200, 220))
    assert not seeds & {j.source["instance_seed"] for s in ("paper-opt", "scale") for j in load_suite(s).jobs}
    assert len({j.instance for j in val.jobs}) == 9 * 20
