"""A real multi-process Dask cluster: `dask scheduler` and `dask worker` as separate processes,
a suite through `sarcover bench --scheduler`, and one worker process SIGKILLed in the middle of a
job. Dask reruns the job on a live worker (the nanny restarts the dead one), so the suite ends
with exactly one row per job, none lost (README, "On a Dask cluster")."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from sarcover.formulations.records import read_rows

TESTS = Path(__file__).resolve().parent
DASK = Path(sys.executable).with_name("dask")
JOBS = 6


def _start(args, env, log):
    return subprocess.Popen(args, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)


def _stop(proc):
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGTERM)  # its own session: the CLI and the processes it started
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(5)


def _wait_for(predicate, seconds, what):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


@pytest.mark.skipif(not DASK.exists(), reason="the dask command line is not installed")
def test_killing_a_worker_mid_job_loses_no_job_and_stores_one_row_each(tmp_path):
    marks = tmp_path / "marks"
    marks.mkdir()
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(TESTS), os.environ.get("PYTHONPATH", "")]),
           "SARCOVER_TEST_MARKS": str(marks)}
    suite = tmp_path / "dask.toml"
    suite.write_text(f'name = "dask-kill"\nmethods = ["bench_methods:marked"]\ntime_limit = 60\n'
                     f'[[instances]]\nM = 2\nK = 2\nN = 1\nruns = {JOBS}\ne_max = 20000\n')
    address_file = tmp_path / "scheduler.json"
    log = (tmp_path / "cluster.log").open("w")
    procs = []
    try:
        procs.append(_start([str(DASK), "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                             "--scheduler-file", str(address_file)], env, log))
        address = _wait_for(lambda: address_file.exists() and json.loads(address_file.read_text() or "{}")
                            .get("address"), 60, "the scheduler")
        procs.append(_start([str(DASK), "worker", "--scheduler-file", str(address_file), "--nworkers", "2",
                             "--nthreads", "1", "--no-dashboard", "--memory-limit", "0"], env, log))
        out = tmp_path / "res"
        bench = subprocess.Popen([sys.executable, "-m", "sarcover.benchmarks.cli", "bench", str(suite), "-o", str(out),
                                  "--scheduler", address, "--quiet"], env=env, stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True, start_new_session=True)
        procs.append(bench)
        first = _wait_for(lambda: sorted(marks.iterdir(), key=lambda p: p.stat().st_mtime), 90, "a job to start")[0]
        victim_job, victim_pid = first.name.rsplit(".", 1)
        os.kill(int(victim_pid), signal.SIGKILL)  # a worker process dies in the middle of its job
        stdout, stderr = bench.communicate(timeout=120)
        assert bench.returncode == 0, stderr
    finally:
        for proc in reversed(procs):
            _stop(proc)
        log.close()
    rows, skipped = read_rows(out)
    assert not any(skipped.values())
    assert len(rows) == JOBS and len({r["key"] for r in rows}) == JOBS  # one row per job, none lost
    assert all(r["status"] == "optimal" and r["valid"] for r in rows)  # the killed job was rerun
    [victim] = [r for r in rows if f"sar-m2-k2-n1-s{r['instance_seed']}" == victim_job]  # the generator's name
    assert victim["pid"] != int(victim_pid)  # its row comes from the rerun on a live worker
    runs = [p for p in marks.iterdir() if p.name.startswith(victim_job + ".")]
    assert len(runs) >= 2  # started twice: killed once, then rerun
