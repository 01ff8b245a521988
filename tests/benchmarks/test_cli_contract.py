"""The CLI's contract: exit codes of `solve`, and a clear one-line answer to every input that once
gave a traceback, an OOM or a silent wrong result (one test per row of the hardening issue)."""

import json
import resource
import subprocess
import sys
from pathlib import Path

import pytest

import sarcover
from sarcover.benchmarks.cli import EXIT_BAD_INPUT, EXIT_METHOD_ERROR, EXIT_NO_PLAN, EXIT_OK, main
from sarcover.formulations.generate import generate
from sarcover.formulations.io import sar_to_dict, save_json
from sarcover.formulations.limits import MAX_NODES, MAX_VEHICLES
from sarcover.benchmarks.registry import METHODS

ROOT = Path(__file__).resolve().parents[2]


def cli(*args, cwd=None, memory_mb=None, stdout=subprocess.PIPE):
    """The real console entry point in a subprocess, optionally under an address-space cap."""
    def cap():
        limit = memory_mb * 1024 * 1024
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

    return subprocess.run([sys.executable, "-m", "sarcover.benchmarks.cli", *args], stdout=stdout,
                          stderr=subprocess.PIPE, text=True, cwd=cwd, preexec_fn=cap if memory_mb else None,
                          timeout=120)


def one_error_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith("sarcover: error: ")
    return lines[0]


def instance_file(tmp_path, name="i.json", **changes) -> Path:
    data = {**sar_to_dict(generate(4, 2, 2, seed=3)), **changes}
    path = tmp_path / name
    path.write_text(json.dumps(data))
    return path


def bad(capsys, *argv) -> str:
    """Run main in-process; it must return exit code 2 with one stderr line, which is returned."""
    capsys.readouterr()
    assert main([str(a) for a in argv]) == EXIT_BAD_INPUT
    return one_error_line(capsys.readouterr().err)


# -- rows of the table --------------------------------------------------------------------
def test_ten_million_views_are_refused_up_front_with_the_limit(tmp_path):
    """"views": 10000000 used to be a 51 PiB numpy allocation and a traceback. Now: refused before
    anything of that size exists (it passes under a 1.5 GB address-space cap), naming the limit."""
    path = instance_file(tmp_path, views=10_000_000)
    out = cli("solve", str(path), memory_mb=1536)
    assert out.returncode == EXIT_BAD_INPUT
    line = one_error_line(out.stderr)
    assert "40000000 viewpoints" in line and f"limit {MAX_NODES} nodes" in line


def test_a_billion_uavs_are_refused_up_front_with_the_limit(tmp_path):
    """"uavs": 1000000000 used to reach the OOM killer (or a MemoryError row and exit 0)."""
    path = instance_file(tmp_path, uavs=1_000_000_000)
    out = cli("solve", str(path), memory_mb=1536)
    assert out.returncode == EXIT_BAD_INPUT
    line = one_error_line(out.stderr)
    assert "uavs = 1000000000" in line and f"limit {MAX_VEHICLES} vehicles" in line


def test_a_method_refuses_more_nodes_than_it_holds(tmp_path, capsys):
    """Per-method limits: an instance within sarcover's limit but beyond the MILP's is refused by
    `solve --method milp` before the model is built; greedy solves it."""
    limit = METHODS["milp"].max_nodes
    path = tmp_path / "wide.json"
    save_json(generate(limit // 4 + 1, 4, 2, seed=0), path)
    line = bad(capsys, "solve", path, "--method", "milp")
    assert f"{4 * (limit // 4 + 1)} nodes" in line
    assert f"more than milp can hold in memory (limit {limit} nodes)" in line


def test_negative_seed_is_bad_input(tmp_path, capsys):
    """--seed -1 used to be exit 0 with status error (numpy's ValueError)."""
    path = instance_file(tmp_path)
    line = bad(capsys, "solve", path, "--method", "adpc-pso", "--seed", "-1")
    assert "--seed" in line and "-1" in line
    line = bad(capsys, "generate", "-M", "3", "-K", "2", "-N", "1", "--seed", "-1", "-o", tmp_path / "g.json")
    assert "--seed" in line


def test_generate_into_an_existing_directory(tmp_path, capsys):
    """-o naming a directory used to be an IsADirectoryError traceback."""
    line = bad(capsys, "generate", "-M", "3", "-K", "2", "-N", "1", "-o", tmp_path)
    assert "is a directory" in line and str(tmp_path) in line


@pytest.mark.parametrize("extra", [[], ["--json"]])
def test_closed_pipe_ends_quietly_with_the_solve_exit_code(tmp_path, extra):
    """`solve ... | head -1` / `solve --json | head -c 300` used to end in a BrokenPipeError
    traceback, exit 1. The reader here is gone before solve writes a byte: nothing on stderr, and
    the exit code is the solve's (0: a plan; 3: no plan)."""
    ok = instance_file(tmp_path, "ok.json")
    hopeless = instance_file(tmp_path, "hopeless.json", e_max=50)
    for path, code in ((ok, EXIT_OK), (hopeless, EXIT_NO_PLAN)):
        proc = subprocess.Popen([sys.executable, "-m", "sarcover.benchmarks.cli", "solve", str(path), *extra],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        proc.stdout.close()  # the reader has gone
        err = proc.stderr.read()
        assert proc.wait(60) == code and err == "", err


def test_overflowing_coordinates_are_refused_as_input(tmp_path):
    """Coordinates of 1e300 used to give numpy overflow warnings, then `infeasible` with energy inf."""
    path = instance_file(tmp_path, targets=[[1e300, 1e300], [100.0, 200.0]])
    out = cli("solve", str(path))
    assert out.returncode == EXIT_BAD_INPUT
    line = one_error_line(out.stderr)  # no RuntimeWarning lines either
    assert "targets[0]" in line and "1e+15" in line and "overflow" in line


def test_unknown_key_in_instance_json_is_refused(tmp_path, capsys):
    """An unknown key used to be accepted silently (a misspelt e_max was ignored)."""
    line = bad(capsys, "solve", instance_file(tmp_path, e_maxx=9000))
    assert "unknown field 'e_maxx'" in line and "e_max" in line


def test_resume_into_another_suites_folder_is_refused(tmp_path, capsys):
    """`bench exact-small --resume -o` a folder of `quick` results used to append to it (and the
    report's title became "exact-small, quick"). Now refused, naming the suite that is there;
    nothing is written and resuming the folder's own suite still works."""
    quick = tmp_path / "quick.toml"
    quick.write_text('name = "quick"\nmethods = ["greedy"]\n[[instances]]\nM = 3\nK = 2\nN = 1\n')
    out = tmp_path / "res"
    assert main(["bench", str(quick), "-o", str(out), "--quiet"]) == EXIT_OK
    before = (out / "results.jsonl").read_text()
    line = bad(capsys, "bench", "exact-small", "--resume", "-o", out, "--quiet")
    assert "suite 'quick'" in line and "'exact-small'" in line and str(out) in line
    assert "suite 'quick'" in bad(capsys, "bench", "exact-small", "-o", out, "--quiet")  # without --resume too
    assert (out / "results.jsonl").read_text() == before
    assert main(["bench", str(quick), "--resume", "-o", str(out), "--quiet"]) == EXIT_OK


# -- the exit-code contract of solve --------------------------------------------------------------
def test_solve_exit_codes_follow_solution_and_termination(tmp_path, capsys):
    """0: a verified plan; 3: no plan (proven infeasible, or a heuristic found none); 4: the method
    failed. The JSON says the same as the code."""
    cases = [
        (instance_file(tmp_path, "plan.json"), "greedy", EXIT_OK, "feasible"),
        (instance_file(tmp_path, "infeasible.json", e_max=50), "greedy", EXIT_NO_PLAN, "infeasible"),
        (tmp_path / "crowded.json", "greedy", EXIT_NO_PLAN, "no_plan"),
        (instance_file(tmp_path, "crash.json"), "bench_methods:crash", EXIT_METHOD_ERROR, "error"),
    ]
    save_json(generate(20, 1, 1, seed=0), cases[2][0])  # every target reachable, not all on one UAV
    for path, method, code, status in cases:
        capsys.readouterr()
        assert main(["solve", str(path), "--method", method, "--json"]) == code, (method, status)
        assert json.loads(capsys.readouterr().out)["status"] == status


def test_exit_codes_are_documented_in_help_and_readme(capsys):
    """`solve --help` names the default method, the formats it reads and the exit codes; the README
    documents the same codes."""
    assert main(["solve", "--help"]) == EXIT_OK
    text = " ".join(capsys.readouterr().out.split())
    assert "default method is greedy" in text and "JSON" in text and "TOP" in text and "p2.3.g" in text
    for code in (EXIT_OK, EXIT_BAD_INPUT, EXIT_NO_PLAN, EXIT_METHOD_ERROR):
        assert f" {code} " in text
    readme = (ROOT / "README.md").read_text()
    section = readme[readme.index("### Exit codes"):]
    section = section[:section.index("\n## ")]
    for code, word in ((EXIT_OK, "plan"), (EXIT_BAD_INPUT, "bad input"), (EXIT_NO_PLAN, "no plan"),
                       (EXIT_METHOD_ERROR, "error")):
        assert f"| {code} |" in section and word in section


# -- conveniences ---------------------------------------------------------------------------------
def test_version(capsys):
    """`--version` prints the installed version and exits 0."""
    assert main(["--version"]) == EXIT_OK
    assert capsys.readouterr().out.strip() == f"sarcover {sarcover.__version__}"


def test_solve_takes_a_benchmark_name_and_says_where_it_plotted(tmp_path, capsys):
    """`solve p2.2.k` finds the shipped TOP file as suites do; --plot names the file on stderr."""
    plot = tmp_path / "p.png"
    assert main(["solve", "p2.2.k", "--plot", str(plot)]) == EXIT_OK
    out = capsys.readouterr()
    assert out.out.startswith("instance p2.2.k: 19 nodes, 0 groups, 2 vehicles")
    assert out.err.strip() == f"plot written to {plot}" and plot.read_bytes()[:4] == b"\x89PNG"


def test_one_uav_is_singular(tmp_path, capsys):
    """Counts of one are written in the singular (1 target, 1 view, 1 UAV, 1 viewpoint)."""
    assert main(["generate", "-M", "1", "-K", "1", "-N", "1", "-o", str(tmp_path / "a.json")]) == EXIT_OK
    assert "1 target × 1 view, 1 UAV, E_max" in capsys.readouterr().out
    assert main(["solve", str(tmp_path / "a.json")]) == EXIT_OK
    out = capsys.readouterr().out
    assert "1 viewpoint, 1 group, 1 vehicle," in out and "vehicle 1: 1 viewpoint," in out


def test_suite_beyond_a_methods_limit_is_refused_when_it_loads(tmp_path, capsys):
    """A random set the MILP cannot hold is a suite error naming the limit, before any job runs;
    run_method itself records such an instance as an error without starting the method."""
    from sarcover.benchmarks.registry import run_method
    from sarcover.formulations.instance import to_top

    limit = METHODS["milp"].max_nodes
    suite = tmp_path / "wide.toml"
    suite.write_text(f'methods = ["greedy", "milp"]\n[[instances]]\nM = {limit // 2 + 1}\nK = 2\nN = 2\n')
    line = bad(capsys, "bench", suite, "-o", tmp_path / "res", "--quiet")
    assert "wide.toml" in line and f"more than milp can hold in memory (limit {limit} nodes)" in line
    assert not (tmp_path / "res").exists()
    run = run_method("milp", to_top(generate(limit // 2 + 1, 2, 2, seed=0)), time_limit=5)
    assert str(run.status) == "error" and f"limit {limit} nodes" in run.reason and run.runtime_s < 1


def test_first_eta_leaves_out_the_compilation(tmp_path, monkeypatch):
    """The progress bar starts after the numba warm-up: a warm-up of 2 s does not enter its clock."""
    import io
    import time

    import sarcover.benchmarks.harness as harness
    from sarcover.benchmarks.suite import load_suite

    monkeypatch.setattr(harness, "warm_up_methods", lambda methods, stream: time.sleep(2.0))
    suite = tmp_path / "one.toml"
    suite.write_text('methods = ["greedy"]\n[[instances]]\nM = 3\nK = 2\nN = 1\n')
    stream = io.StringIO()
    harness.run_suite(load_suite(str(suite)), tmp_path / "res", workers=1, stream=stream)
    last = stream.getvalue().strip().splitlines()[-1]
    assert "1/1" in last and "elapsed 0:00" in last, last


@pytest.mark.parametrize("method", ["cpsat", "routing", "pyvrp"])
@pytest.mark.parametrize("tmax, far, optimum", [(1, 1e13, 1.0), (5e-324, 1.0, 2.0)])
def test_integer_scaled_methods_take_extreme_accepted_numbers(tmp_path, method, tmax, far, optimum):
    """Numbers within the input limits but far apart (arcs 1e13 times the budget, a budget of the
    smallest float) used to overflow the integer arc energies of CP-SAT, OR-Tools and PyVRP: an
    invalid-cast warning, and a TypeError from CP-SAT. Now: no warning, the optimum."""
    import warnings

    from sarcover.benchmarks.registry import run_method
    from sarcover.formulations.io import read_top

    path = tmp_path / "t.txt"
    path.write_text(f"n 5\nm 1\ntmax {tmax!r}\n0 0 0\n{far!r} 0 5\n0 {far!r} 3\n0 0 {optimum!r}\n0 0 0\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        run = run_method(method, read_top(path), time_limit=5)
    assert str(run.status) in ("optimal", "feasible") and run.objective == optimum, run.reason
