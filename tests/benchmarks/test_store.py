"""The results store (benchmarks/store.py): one folder, one suite, one set of settings; kill and resume."""

import os
import signal
import subprocess
import sys
import time

from sarcover.benchmarks.cli import main

from bench_suites import ROOT, SMALL, TESTS, rows_of, write_suite


def test_existing_results_need_resume(tmp_path, capsys):
    """Running into a directory that holds results without --resume is a one-line error, exit 2."""
    suite = write_suite(tmp_path, SMALL.replace('"greedy", "cpsat"', '"greedy"'))
    out = tmp_path / "res"
    assert main(["bench", str(suite), "-o", str(out), "--quiet"]) == 0
    capsys.readouterr()
    assert main(["bench", str(suite), "-o", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert "--resume" in err and len(err.splitlines()) == 1


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


GREEDY = SMALL.replace('"greedy", "cpsat"', '"greedy"')


def test_resume_with_a_changed_time_limit_is_refused_naming_the_change(tmp_path, capsys):
    """--resume after a changed time limit: one line naming it, exit 2, nothing run; the old setting resumes."""
    suite = write_suite(tmp_path, GREEDY)
    out = tmp_path / "res"
    assert main(["bench", str(suite), "-o", str(out), "--quiet", "--runs", "1"]) == 0
    before = (out / "results.jsonl").read_text()
    write_suite(tmp_path, GREEDY.replace("time_limit = 10", "time_limit = 20"))
    capsys.readouterr()
    assert main(["bench", str(suite), "-o", str(out), "--quiet", "--resume"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert "greedy time_limit is 20 in this run but 10 in its 3 stored jobs" in err
    assert (out / "results.jsonl").read_text() == before
    write_suite(tmp_path, GREEDY)
    assert main(["bench", str(suite), "-o", str(out), "--quiet", "--resume"]) == 0  # adds the runs = 2 jobs
    assert len(rows_of(out)) == 5


def test_resume_with_changed_parameters_is_refused(tmp_path):
    """Changed params are a changed setting; a row without params is compared on method and time limit only."""
    import json

    import pytest

    from sarcover.benchmarks.errors import HarnessError
    from sarcover.benchmarks.store import ResultsStore

    row = {"schema": 2, "key": "i|m|0", "suite": "s", "method": "m", "time_limit": 5.0, "params": {"a": 1}}
    old = {k: v for k, v in row.items() if k != "params"} | {"key": "j|m|0"}
    (tmp_path / "results.jsonl").write_text(json.dumps(row) + "\n" + json.dumps(old) + "\n")
    store = ResultsStore(tmp_path, resume=True, suite="s")
    store.check_settings([{"key": "i|m|0", "method": "m", "time_limit": 5.0, "params": {"a": 1}}])
    store.check_settings([{"key": "j|m|0", "method": "m", "time_limit": 5.0, "params": {"a": 2}}])
    with pytest.raises(HarnessError, match=r'm params is \{"a": 2\} in this run but \{"a": 1\}'):
        store.check_settings([{"key": "i|m|0", "method": "m", "time_limit": 5.0, "params": {"a": 2}}])
    with pytest.raises(HarnessError, match="m time_limit is 6 in this run but 5"):
        store.check_settings([{"key": "j|m|0", "method": "m", "time_limit": 6.0}])
    store.close()


def test_a_folder_of_another_suite_is_refused(tmp_path, capsys):
    """--resume into a folder that holds another suite's rows names that suite, exit 2."""
    suite = write_suite(tmp_path, GREEDY)
    out = tmp_path / "res"
    assert main(["bench", str(suite), "-o", str(out), "--quiet", "--runs", "1"]) == 0
    other = write_suite(tmp_path, GREEDY.replace('name = "small"', 'name = "other"'), "o.toml")
    capsys.readouterr()
    assert main(["bench", str(other), "-o", str(out), "--quiet", "--resume"]) == 2
    err = capsys.readouterr().err.strip()
    assert "holds results of suite 'small', not 'other'" in err and len(err.splitlines()) == 1
