"""Benchmark harness: suites end to end through the CLI, failures isolated, kill + resume, Dask."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from sarcover.benchmarks.cli import main
from sarcover.benchmarks.harness import run_suite
from sarcover.benchmarks.suite import load_suite
from sarcover.formulations.records import FIELDS, SCHEMA_VERSION, read_rows

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent


def write_suite(tmp_path, body: str, name: str = "s.toml") -> Path:
    path = tmp_path / name
    path.write_text(body)
    return path


def rows_of(directory) -> list[dict]:
    rows, skipped = read_rows(directory)
    assert not any(skipped.values()), skipped
    return rows


SMALL = """
name = "small"
methods = ["greedy", "cpsat"]
time_limit = 10
[[instances]]
M = 4
K = 2
N = [2, 3]
runs = 2
[[instances]]
files = ["p2.2.b"]
"""


def test_small_suite_end_to_end_cli(tmp_path, capsys):
    """bench stores one verified row per job with provenance; report writes md, html, png, csv."""
    suite = write_suite(tmp_path, SMALL)
    out = tmp_path / "res"
    assert main(["bench", str(suite), "-o", str(out), "--workers", "2", "--quiet"]) == 0
    rows = rows_of(out)
    assert len(rows) == 5 * 2  # (2 settings × 2 runs + 1 file) × 2 methods
    assert len({r["key"] for r in rows}) == len(rows)
    for r in rows:
        assert r["valid"] is True and r["status"] in ("feasible", "optimal")
        if r["kind"] == "sar":
            assert r["objective"] == pytest.approx(r["coverage"] * r["M"] * r["K"])
        assert r["energy_used"] <= r["e_max"] * r["n_vehicles"] * (1 + 1e-9)
        assert r["versions"]["numpy"] and r["host"] and r["schema"] == SCHEMA_VERSION and r["workers"] == 2
        assert list(r) == list(FIELDS)  # the one schema, in its order
        assert (r["termination"], r["solution"]) in (("completed", "feasible"), ("optimal", "optimal"))
        assert 0 < r["cpu_s"] <= r["wall_s"] + 0.05  # the job thread's CPU time, within its wall time
    sar = [r for r in rows if r["kind"] == "sar"]
    assert {(r["N"], r["instance_seed"]) for r in sar} == {(2, 0), (2, 1), (3, 0), (3, 1)}
    assert pd.read_json(out / "results.jsonl", lines=True).shape[0] == len(rows)  # pandas reads it natively
    rep = tmp_path / "rep"
    assert main(["report", str(out), "-o", str(rep)]) == 0
    for name in ("report.md", "report.html", "methods.csv", "instances.csv", "runs.csv", "example_routes.png",
                 "coverage_vs_N_M4_K2.png", "runtime_by_setting.csv"):
        assert (rep / name).stat().st_size > 0, name
    assert (rep / "example_routes.png").read_bytes()[:4] == b"\x89PNG"
    assert "Per method" in (rep / "report.md").read_text()


def _ten_node_file(tmp_path) -> Path:
    """Ten unit-prize nodes at x = 1..10 on a line, one vehicle, budget 100: the optimum is 10."""
    lines = ["n 12", "m 1", "tmax 100", "0 0 0"] + [f"{x} 0 1" for x in range(1, 11)] + ["0 0 0"]
    path = tmp_path / "line10.txt"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_gap_nine_of_ten_is_ten_percent(tmp_path):
    """A method at 9 of a proven optimum 10 has gap 10 %; the prover has gap 0 and share optimal 1."""
    _ten_node_file(tmp_path)
    suite = write_suite(tmp_path, """
methods = ["bench_methods:all_optimal", "bench_methods:all_but_last"]
[[instances]]
files = ["line10.txt"]
""")
    out = tmp_path / "res"
    assert main(["bench", str(suite), "-o", str(out), "--workers", "1", "--quiet"]) == 0
    assert main(["report", str(out)]) == 0
    table = pd.read_csv(out / "report" / "methods.csv", index_col="method")
    most = table.loc["bench_methods:all_but_last"]
    assert most["gap_mean"] == pytest.approx(0.10) and most["gap_max"] == pytest.approx(0.10)
    assert most["share_optimal"] == 0.0
    best = table.loc["bench_methods:all_optimal"]
    assert best["gap_mean"] == 0.0 and best["share_optimal"] == 1.0
    inst = pd.read_csv(out / "report" / "instances.csv", index_col="instance")
    assert inst["opt"].iloc[0] == 10 and inst["conflict"].isna().all()


def test_crashing_dying_hanging_and_hogging_methods_do_not_stop_the_suite(tmp_path):
    """Raise / dead worker / memory hog: error rows; a hang is killed as time_limit; greedy still runs."""
    suite = write_suite(tmp_path, """
methods = ["bench_methods:crash", "bench_methods:die", "bench_methods:hang", "bench_methods:hog", "greedy"]
time_limit = 0.3
grace = 0.3
memory_mb = 1500
[[instances]]
M = 3
K = 2
N = 2
runs = 2
""")
    out = tmp_path / "res"
    t0 = time.monotonic()
    assert main(["bench", str(suite), "-o", str(out), "--workers", "2", "--quiet"]) == 0
    assert time.monotonic() - t0 < 20
    by = {}
    for r in rows_of(out):
        by.setdefault(r["method"], []).append(r)
    assert all(len(v) == 2 for v in by.values()) and len(by) == 5
    assert all(r["status"] == "error" and "boom" in r["reason"] for r in by["bench_methods:crash"])
    assert all(r["status"] == "error" and "exited with code 3" in r["reason"] for r in by["bench_methods:die"])
    assert all(r["status"] == "time_limit" and "killed" in r["reason"] for r in by["bench_methods:hang"])
    assert all(r["status"] == "error" and "MemoryError" in r["reason"] for r in by["bench_methods:hog"])
    assert all(r["status"] == "feasible" and r["valid"] for r in by["greedy"])


def test_sigkill_mid_run_then_resume_gives_one_row_per_job(tmp_path):
    """SIGKILL the bench process mid-way (plus a torn last line); --resume completes, no duplicates."""
    suite = write_suite(tmp_path, """
methods = ["bench_methods:slow_all"]
[[instances]]
M = 2
K = 2
N = 1
runs = 12
e_max = 20000  # one UAV can fly all four viewpoints
""")
    out = tmp_path / "res"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(TESTS), str(ROOT)])}
    proc = subprocess.Popen([sys.executable, "-m", "sarcover.benchmarks.cli", "bench", str(suite), "-o", str(out),
                             "--workers", "2", "--quiet"], env=env, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    results = out / "results.jsonl"
    try:
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            if results.exists() and results.read_text().count("\n") >= 3:
                break
            time.sleep(0.05)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(10)
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)  # the workers die with their parent; be sure
        except ProcessLookupError:
            pass
    before = results.read_text().count("\n")
    assert 3 <= before < 12, "the kill did not land mid-run"
    with results.open("a") as fh:  # a row torn in half by the kill
        fh.write('{"schema": 1, "key": "torn')
    assert main(["bench", str(suite), "-o", str(out), "--resume", "--quiet"]) == 0
    rows = rows_of(out)
    assert len(rows) == 12 and len({r["key"] for r in rows}) == 12
    assert all(r["status"] == "optimal" for r in rows)
    assert main(["bench", str(suite), "-o", str(out), "--resume", "--quiet"]) == 0  # nothing left to do
    assert len(rows_of(out)) == 12


def test_dask_path_gives_the_same_results_as_local(tmp_path):
    """Dask on loopback stores the same rows as the local pool; a job past its deadline is time_limit."""
    distributed = pytest.importorskip("dask.distributed")
    suite = load_suite(str(write_suite(tmp_path, SMALL.replace('"greedy", "cpsat"', '"greedy"'))))
    run_suite(suite, tmp_path / "local", workers=2, progress=False)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None, host="127.0.0.1", protocol="tcp") as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        assert main(["bench", str(suite.path), "-o", str(tmp_path / "dask"), "--quiet",
                     "--scheduler", cluster.scheduler_address]) == 0
        napping = write_suite(tmp_path, 'methods = ["bench_methods:nap"]\ntime_limit = 0.2\ngrace = 0.2\n'
                                        '[[instances]]\nM = 2\nK = 2\nN = 1', "nap.toml")
        assert main(["bench", str(napping), "-o", str(tmp_path / "nap"), "--quiet",
                     "--scheduler", cluster.scheduler_address]) == 0
    [nap] = rows_of(tmp_path / "nap")
    assert nap["status"] == "time_limit" and "abandoned" in nap["reason"]

    def essence(rows):
        return sorted((r["key"], r["status"], r["objective"], r["routes"], r["valid"]) for r in rows)

    local, dask = rows_of(tmp_path / "local"), rows_of(tmp_path / "dask")
    assert len(local) == len(suite.jobs) == 5
    assert essence(local) == essence(dask)
    assert all(r["workers"] is None for r in dask)


def test_existing_results_need_resume(tmp_path, capsys):
    """Running into a directory that holds results without --resume is a one-line error, exit 2."""
    suite = write_suite(tmp_path, SMALL.replace('"greedy", "cpsat"', '"greedy"'))
    out = tmp_path / "res"
    assert main(["bench", str(suite), "-o", str(out), "--quiet"]) == 0
    capsys.readouterr()
    assert main(["bench", str(suite), "-o", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert "--resume" in err and len(err.splitlines()) == 1


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
    """Every built-in suite parses, names only registered methods, and paper-n is M=20, K=3, N=2..6."""
    from sarcover.benchmarks.suite import builtin_suites

    assert {"quick", "exact-small", "paper-n", "paper-k", "top-chao"} <= set(builtin_suites())
    for name in builtin_suites():
        suite = load_suite(name, runs=None if name.startswith("top-") else 2)
        assert suite.jobs, name
    paper_n = load_suite("paper-n", runs=2)
    assert {(j.source["M"], j.source["K"], j.source["N"]) for j in paper_n.jobs} == {(20, 3, n) for n in range(2, 7)}
    assert not any(j.source["exact"] for j in paper_n.jobs)
    assert load_suite("top-chao").n_instances == 117
    top47 = load_suite("top-4-7")
    assert top47.n_instances == 192 and top47.methods == ["bp"]
    refs = [(j.source["reference"], j.source["best_known"]) for j in top47.jobs]
    assert all((r is None) != (b is None) for r, b in refs)  # each file: a proven optimum or a best known value
    assert sum(r is not None for r, _ in refs) == 50


def test_progress_bar_counts_and_eta():
    """The progress bar prints count, percentage and an ETA; errors and time limits are tallied."""
    import io

    from sarcover.benchmarks.harness import Progress

    stream = io.StringIO()
    bar = Progress(4, "bench t", stream=stream)
    for status in ("feasible", "error", "time_limit", "optimal"):
        bar.update(status)
    last = stream.getvalue().strip().splitlines()[-1]
    assert "4/4" in last and "100%" in last and "ETA 0:00" in last and "1 error" in last and "1 time_limit" in last


def test_ad_hoc_methods_do_not_join_the_registry(tmp_path):
    """A suite's ``module:function`` method runs, but never shows up in the shared registry."""
    from sarcover.benchmarks.registry import METHODS, get_method, run_method
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top
    from sarcover.formulations.result import Status

    before = set(METHODS)
    inst = to_top(generate(2, 2, 1, 0))
    result = run_method("bench_methods:all_but_last", inst, time_limit=5.0)
    assert result.status == Status.FEASIBLE
    assert get_method("bench_methods:nap").name == "bench_methods:nap"
    assert set(METHODS) == before


def test_methods_subset_then_rest_with_resume(tmp_path, capsys):
    """--methods runs only those of a suite's methods; a later --resume of the whole suite runs the rest."""
    suite = write_suite(tmp_path, SMALL)
    out = tmp_path / "res"
    assert main(["bench", str(suite), "-o", str(out), "--methods", "greedy", "--quiet"]) == 0
    rows = rows_of(out)
    assert len(rows) == 5 and {r["method"] for r in rows} == {"greedy"}
    assert main(["bench", str(suite), "-o", str(out), "--resume", "--quiet"]) == 0
    rows = rows_of(out)
    assert len(rows) == 10 and len({r["key"] for r in rows}) == 10
    capsys.readouterr()
    assert main(["bench", str(suite), "-o", str(tmp_path / "x"), "--methods", "greedy,milp"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "'milp'" in err and "not one of the suite's methods" in err


def test_ctrl_c_in_a_worker_stops_the_run_without_storing_its_job(tmp_path, capsys):
    """A worker killed by SIGINT means the user pressed Ctrl-C: exit 130 and the job is not stored
    as an error (so --resume runs it again)."""
    body = 'methods = ["bench_methods:interrupted"]\ntime_limit = 5\n[[instances]]\nM = 2\nK = 2\nN = 1\nruns = 1\n'
    suite = write_suite(tmp_path, body)
    out = tmp_path / "res"
    assert main(["bench", str(suite), "-o", str(out), "--workers", "1", "--quiet"]) == 130
    text = (out / "results.jsonl").read_text() if (out / "results.jsonl").exists() else ""
    assert "interrupted" not in text


def test_ctrl_c_records_the_part_of_the_run_that_was_stored(tmp_path):
    """A run stopped by Ctrl-C after some jobs still appends its record to runs.jsonl (marked
    interrupted, with the jobs it stored), and the report's "how it was run" shows it as stopped;
    a run stopped before storing anything leaves no record."""
    from sarcover.reports.reference import _walls, write_reference

    body = ('methods = ["greedy", "bench_methods:interrupted"]\ntime_limit = 5\n'
            '[[instances]]\nM = 2\nK = 2\nN = 1\nruns = 1\n')
    suite = write_suite(tmp_path, body)
    out = tmp_path / "res"
    assert main(["bench", str(suite), "-o", str(out), "--workers", "1", "--quiet"]) == 130
    assert [r["method"] for r in rows_of(out)] == ["greedy"]
    records = _walls(tmp_path, "res")
    assert len(records) == 1 and records[0]["interrupted"] is True and records[0]["jobs"] == 1
    readme = write_reference(tmp_path, tmp_path / "report", suites=["res"]).read_text()
    assert "| res | 1 (stopped) |" in readme
    # the resume stops at the same job before storing anything: no second record
    assert main(["bench", str(suite), "-o", str(out), "--workers", "1", "--quiet", "--resume"]) == 130
    assert len(_walls(tmp_path, "res")) == 1


WARM_CHECK = r"""
import json, sys
from numba.core.registry import CPUDispatcher
from sarcover.formulations.bp.compile import KERNEL_MODULES
import sarcover.heuristics.kernels as kernels
from sarcover.benchmarks.registry import METHODS, run_method, warm_up
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import to_top

def compiled():
    out = {}
    for mod in (*KERNEL_MODULES, kernels):
        for name in dir(mod):
            f = getattr(mod, name)
            if isinstance(f, CPUDispatcher):
                out[f"{mod.__name__}.{name}"] = len(f.signatures)
    return out

before = compiled()
hooks = warm_up(list(METHODS))
warmed = compiled()
inst = to_top(generate(6, 3, 2, seed=1))
statuses = {m: str(run_method(m, inst, seed=0, time_limit=10).status)
            for m in ("bp", "adpc-pso", "dpc-pso", "kmeans-pso", "adpc-ga", "adpc-aco")}
print(json.dumps({"before": before, "hooks": hooks, "warmed": warmed, "after": compiled(),
                  "statuses": statuses}))
"""


def test_warm_up_leaves_nothing_for_the_jobs_to_compile():
    """In a fresh process, the registry's warm-up hooks compile (or load from numba's disk cache)
    every numba function that bp and the paper's pipelines then call: running them afterwards
    adds no compiled signature. That is what keeps JIT compilation out of a job's time."""
    out = subprocess.run([sys.executable, "-c", WARM_CHECK], cwd=ROOT, capture_output=True,
                         text=True, timeout=600, check=True)
    data = json.loads(out.stdout.strip().splitlines()[-1])
    assert sorted(data["hooks"]) == ["compile_bp", "compile_routers"]
    assert sum(data["before"].values()) == 0  # a fresh process: nothing compiled yet
    assert data["warmed"]["sarcover.formulations.bp.labelling.label_search"] > 0
    assert data["warmed"]["sarcover.heuristics.kernels.pso_iterations"] > 0
    assert data["after"] == data["warmed"]
    assert set(data["statuses"].values()) <= {"optimal", "feasible"}


def test_warm_up_runs_each_hook_once_and_skips_a_broken_one(monkeypatch):
    """Methods that share a hook compile once per process; a hook that fails is skipped."""
    import dataclasses

    import sarcover.benchmarks.registry as registry

    calls = []

    def hook_a():
        calls.append("a")

    def hook_b():
        calls.append("b")

    def broken():
        raise ImportError("no such module")

    methods = dict(registry.METHODS)
    for name in ("adpc-pso", "dpc-pso", "adpc-ga"):
        methods[name] = dataclasses.replace(methods[name], warm_up=hook_a)
    methods["bp"] = dataclasses.replace(methods["bp"], warm_up=hook_b)
    monkeypatch.setattr(registry, "METHODS", methods)
    monkeypatch.setattr(registry, "_WARMED", set())
    assert registry.warm_up(["adpc-pso", "dpc-pso", "greedy", "bp", "tests.x:y"]) == ["hook_a", "hook_b"]
    assert registry.warm_up(["adpc-ga", "bp"]) == []  # already done in this process
    assert calls == ["a", "b"]

    methods["bp"] = dataclasses.replace(methods["bp"], warm_up=broken)
    monkeypatch.setattr(registry, "_WARMED", set())
    assert registry.warm_up(["bp"]) == []  # the job itself will report the problem


def test_suite_with_jit_methods_compiles_before_the_workers_start(tmp_path):
    """The harness warms up in the parent (the workers fork from it) and says so on its stream;
    a suite without numba methods does not."""
    import io

    jit = write_suite(tmp_path, SMALL.replace('["greedy", "cpsat"]', '["greedy", "adpc-pso"]'), "jit.toml")
    stream = io.StringIO()
    run_suite(load_suite(str(jit)), tmp_path / "jit", workers=2, stream=stream)
    assert "compiling numba code" in stream.getvalue()
    assert all(r["status"] == "feasible" for r in rows_of(tmp_path / "jit"))
    plain = write_suite(tmp_path, SMALL.replace('["greedy", "cpsat"]', '["greedy"]'), "plain.toml")
    stream = io.StringIO()
    run_suite(load_suite(str(plain)), tmp_path / "plain", workers=2, stream=stream)
    assert "compiling" not in stream.getvalue()


def test_own_folder_of_instance_files_gives_share_proven_and_certified_gaps(tmp_path):
    """The README's recipe for instance files of one's own: a suite naming a folder of instance
    files (no published optima next to them). The report counts what bp proves per
    size and bounds the gap of the runs it did not prove by their certified bound."""
    import shutil

    from sarcover.benchmarks.catalog import TOP_DIR
    from sarcover.formulations.generate import generate
    from sarcover.formulations.io import save_json

    folder = tmp_path / "Set_own"
    folder.mkdir()
    shutil.copy(TOP_DIR / "p2.2.b.txt", folder)  # proven in well under a second
    save_json(generate(20, 3, 5, seed=5), folder / "m20k3.json")  # bp needs 10-50 s for this one
    suite = write_suite(tmp_path, 'name = "own"\nmethods = ["bp"]\ntime_limit = 1\n'
                                  '[[instances]]\nfiles = ["Set_own/*"]\n')
    out = tmp_path / "res"
    assert main(["bench", str(suite), "-o", str(out), "--workers", "2", "--quiet"]) == 0
    assert main(["report", str(out)]) == 0
    rows = {r["kind"]: r for r in rows_of(out)}
    assert all(r["reference"] is None for r in rows.values())  # no published value used
    assert rows["top"]["status"] == "optimal"
    sar = rows["sar"]
    assert sar["status"] == "time_limit" and sar["valid"] and sar["bound"] > sar["objective"]
    tto = pd.read_csv(out / "report" / "time_to_optimality.csv", index_col=0)
    assert tto["optimal"].sum() == 1 and tto["runs"].sum() == 2
    methods = pd.read_csv(out / "report" / "methods.csv", index_col=0)
    assert methods.loc["bp", "gap_ub_n"] == 1
    assert methods.loc["bp", "gap_ub_max"] == pytest.approx((sar["bound"] - sar["objective"]) / sar["bound"])
