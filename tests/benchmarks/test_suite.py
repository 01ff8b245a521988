"""Suite files (benchmarks/suite.py) as the bench command reads them: bad input, overrides, runs, built-ins."""

import pytest

from sarcover.benchmarks.cli import main
from sarcover.benchmarks.suite import load_suite

from bench_suites import write_suite


@pytest.mark.parametrize("body, needle", [
    ('methods = ["greedy", "no-such-method"]\n[[instances]]\nM = 3\nK = 2\nN = 1', "unknown method 'no-such-method'"),
    ('methods = ["greedy"]\n[[instances]]\nM = 3\nK = 0\nN = 1', "K must be >= 1"),
    ('methods = ["greedy"]\ntime_limit = "long"\n[[instances]]\nM = 3\nK = 2\nN = 1', "time_limit must be a finite number"),
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
