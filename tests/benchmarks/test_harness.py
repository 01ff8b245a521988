"""run_suite end to end (benchmarks/harness.py): rows, reports, warm-up, Ctrl-C, strict exit codes."""

import json
from pathlib import Path

import pandas as pd
import pytest

from sarcover.benchmarks.cli import main
from sarcover.benchmarks.harness import run_suite
from sarcover.benchmarks.suite import load_suite
from sarcover.formulations.records import FIELDS, SCHEMA_VERSION

from bench_suites import SMALL, rows_of, write_suite


def test_small_suite_end_to_end_cli(tmp_path, capsys):
    """bench stores one verified row per job with provenance; report writes md, html, png, csv."""
    from sarcover.benchmarks.provenance import code_version
    from sarcover.benchmarks.registry import get_method

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
        assert r["versions"]["sarcover"] == code_version()
        assert r["params"] == get_method(r["method"]).resolve(None)  # the fully resolved defaults
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


def test_the_start_line_counts_the_methods_the_jobs_run(tmp_path, caplog):
    """The suite's start line counts the methods its jobs run (an instance block may run fewer
    than the suite lists) and says "1 worker"."""
    body = ('methods = ["greedy", "routing"]\ntime_limit = 5\n'
            '[[instances]]\nM = 2\nK = 2\nN = 1\nruns = 2\nmethods = ["greedy"]\n')
    suite = write_suite(tmp_path, body)
    with caplog.at_level("INFO", logger="sarcover"):
        assert main(["bench", str(suite), "-o", str(tmp_path / "res"), "--workers", "1"]) == 0
    line = next(r.getMessage() for r in caplog.records if "already stored" in r.getMessage())
    assert "2 jobs (2 instances, 1 methods)" in line and line.endswith("on 1 worker")


def test_ctrl_c_in_a_worker_stops_the_run_without_storing_its_job(tmp_path, capsys):
    """A worker killed by SIGINT (Ctrl-C) exits 130 without storing its job, so --resume runs it again."""
    body = 'methods = ["bench_methods:interrupted"]\ntime_limit = 5\n[[instances]]\nM = 2\nK = 2\nN = 1\nruns = 1\n'
    suite = write_suite(tmp_path, body)
    out = tmp_path / "res"
    assert main(["bench", str(suite), "-o", str(out), "--workers", "1", "--quiet"]) == 130
    text = (out / "results.jsonl").read_text() if (out / "results.jsonl").exists() else ""
    assert "interrupted" not in text


def test_ctrl_c_records_the_part_of_the_run_that_was_stored(tmp_path):
    """A run stopped by Ctrl-C after storing jobs leaves an interrupted runs.jsonl record; one storing none, none."""
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


def test_suite_with_jit_methods_compiles_before_the_workers_start(tmp_path):
    """A suite with numba methods compiles in the parent before the workers fork and says so; one without does not."""
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
    """A suite over a folder of one's own files: the report gives bp's share proven and certified gaps of the rest."""
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


CRASHING = 'methods = ["greedy", "bench_methods:crash"]\n[[instances]]\nM = 3\nK = 2\nN = 1\n'


def test_strict_exits_1_when_a_job_of_the_suite_ended_in_error(tmp_path, capsys):
    """bench --strict exits 1 when a job of the suite (this run or stored) ended in error, 0 without errors."""
    suite = write_suite(tmp_path, CRASHING)
    assert main(["bench", str(suite), "-o", str(tmp_path / "a"), "--quiet"]) == 0
    assert main(["bench", str(suite), "-o", str(tmp_path / "b"), "--quiet", "--strict"]) == 1
    assert "1 job of the suite ended in error" in capsys.readouterr().err
    assert main(["bench", str(suite), "-o", str(tmp_path / "b"), "--quiet", "--strict", "--resume"]) == 1
    clean = write_suite(tmp_path, CRASHING.replace(', "bench_methods:crash"', ""), "clean.toml")
    assert main(["bench", str(clean), "-o", str(tmp_path / "c"), "--quiet", "--strict"]) == 0


def test_verbosity_flags_set_what_the_sarcover_loggers_print(tmp_path, capsys):
    """The suite header by default, one line per job with -v, nothing with -q, before or after the subcommand."""
    suite = write_suite(tmp_path, CRASHING)
    assert main(["bench", str(suite), "-o", str(tmp_path / "d")]) == 0
    err = capsys.readouterr().err
    assert "suite s: 2 jobs" in err and "greedy|0: feasible" not in err
    assert main(["-v", "bench", str(suite), "-o", str(tmp_path / "v")]) == 0
    err = capsys.readouterr().err
    assert "greedy|0: feasible in" in err and "crash|0: error in" in err and "RuntimeError: boom" in err
    assert main(["bench", str(suite), "-o", str(tmp_path / "v2"), "-v"]) == 0
    assert "greedy|0: feasible in" in capsys.readouterr().err
    assert main(["bench", str(suite), "-o", str(tmp_path / "q"), "-q"]) == 0
    assert capsys.readouterr().err == ""


def test_run_records_carry_the_code_version_and_settings(tmp_path):
    """Each runs.jsonl record names the code version and every method's time limits and parameters."""
    from sarcover.benchmarks.provenance import code_version
    from sarcover.benchmarks.registry import get_method

    suite = write_suite(tmp_path, SMALL.replace("time_limit = 10", "time_limit = 10\n[method.cpsat]\ntime_limit = 3"))
    run_suite(load_suite(str(suite)), tmp_path / "r", workers=2, progress=False)
    [record] = [json.loads(line) for line in (tmp_path / "r" / "runs.jsonl").read_text().splitlines()]
    assert record["versions"]["sarcover"] == code_version()
    assert record["settings"] == {"greedy": {"time_limit": [10], "params": {}},
                                  "cpsat": {"time_limit": [3], "params": get_method("cpsat").resolve(None)}}


def test_a_failed_jobs_row_holds_its_whole_traceback(tmp_path):
    """A method that raises leaves an error row with its whole traceback, registry frame to raising line."""
    suite = write_suite(tmp_path, CRASHING)
    run_suite(load_suite(str(suite)), tmp_path / "r", workers=1, progress=False)
    [row] = [r for r in rows_of(tmp_path / "r") if r["status"] == "error"]
    tb = row["info"]["traceback"]
    assert tb[0].startswith("Traceback") and tb[-1] == "RuntimeError: boom"
    assert any("registry.py" in line and "run_method" in line for line in tb)
    assert any("bench_methods.py" in line and "crash" in line for line in tb)


def test_sigterm_stops_a_run_as_ctrl_c_does(tmp_path):
    """``kill`` (SIGTERM) on a running ``bench``: exit 130, the stored rows and an interrupted
    runs.jsonl record kept."""
    import os
    import signal
    import subprocess
    import sys
    import time

    tests = Path(__file__).resolve().parents[1]
    body = ('methods = ["greedy", "bench_methods:hang"]\ntime_limit = 60\n'
            '[[instances]]\nM = 2\nK = 2\nN = 1\nruns = 1\n')
    suite = write_suite(tmp_path, body)
    out = tmp_path / "res"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tests), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.Popen([sys.executable, "-m", "sarcover.benchmarks.cli", "bench", str(suite), "-o", str(out),
                             "--workers", "1", "--quiet"], env=env, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while not ((out / "results.jsonl").exists() and (out / "results.jsonl").read_text().strip()):
            assert time.monotonic() < deadline and proc.poll() is None
            time.sleep(0.1)
        time.sleep(0.5)  # the hanging job has started
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=30) == 130
    finally:
        proc.kill()
    assert "interrupted" in proc.stderr.read()
    assert [r["method"] for r in rows_of(out)] == ["greedy"]
    records = [json.loads(line) for line in (out / "runs.jsonl").read_text().splitlines()]
    assert len(records) == 1 and records[0]["interrupted"] is True and records[0]["jobs"] == 1
