"""A real multi-process Dask cluster: `dask scheduler` and `dask worker --nworkers 2` as separate
processes, suites through `sarcover bench --scheduler`, worker processes killed mid-job.

Each job runs in a child process of its Dask worker. A job whose Dask worker process dies (and
its child with it) is rerun by Dask on a live worker (the nanny restarts the dead one), so the
suite ends with exactly one row per job, none lost; a job that kills every worker it runs on
becomes an `error` row once Dask gives up on it (README, "On a Dask cluster")."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from sarcover.formulations.records import read_rows

TESTS = Path(__file__).resolve().parents[1]  # tests/: bench_methods.py is there
DASK = Path(sys.executable).with_name("dask")
JOBS = 6

pytestmark = pytest.mark.skipif(not DASK.exists(), reason="the dask command line is not installed")


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


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """(scheduler address, environment for processes that reach it, the folder of job marks)."""
    tmp = tmp_path_factory.mktemp("dask")
    marks = tmp / "marks"
    marks.mkdir()
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(TESTS), os.environ.get("PYTHONPATH", "")]),
           "SARCOVER_TEST_MARKS": str(marks)}
    address_file = tmp / "scheduler.json"
    log = (tmp / "cluster.log").open("w")
    procs = []
    try:
        procs.append(_start([str(DASK), "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                             "--scheduler-file", str(address_file)], env, log))
        address = _wait_for(lambda: address_file.exists() and json.loads(address_file.read_text() or "{}")
                            .get("address"), 60, "the scheduler")
        procs.append(_start([str(DASK), "worker", "--scheduler-file", str(address_file), "--nworkers", "2",
                             "--nthreads", "1", "--no-dashboard", "--memory-limit", "0"], env, log))
        yield address, env, marks
    finally:
        for proc in reversed(procs):
            _stop(proc)
        log.close()


def _both_workers_up(address):
    """Wait until both worker processes are registered: at the start, and after a test whose
    workers were killed (each nanny restarts its worker, which takes seconds on a busy machine)."""
    from dask.distributed import Client

    with Client(address, timeout="30s") as client:
        client.wait_for_workers(2, timeout=120)


def _bench(tmp_path, env, address, body):
    _both_workers_up(address)
    suite = tmp_path / "suite.toml"
    suite.write_text(body)
    return subprocess.Popen([sys.executable, "-m", "sarcover.benchmarks.cli", "bench", str(suite), "-o",
                             str(tmp_path / "res"), "--scheduler", address, "--quiet"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)


def _finish(bench, tmp_path, marks):
    """Wait for the bench run; if it hangs, fail with what it and the cluster said."""
    try:
        _, stderr = bench.communicate(timeout=180)
    except subprocess.TimeoutExpired:
        _stop(bench)
        _, stderr = bench.communicate()
        rows = (tmp_path / "res" / "results.jsonl")
        stored = len(rows.read_text().splitlines()) if rows.exists() else 0
        log = (marks.parent / "cluster.log").read_text().splitlines()
        raise AssertionError(f"the bench run did not end in 180 s ({stored} rows stored); its "
                             f"stderr:\n{stderr}\nthe cluster's log, last 40 lines:\n"
                             + "\n".join(log[-40:])) from None
    finally:
        _stop(bench)
    assert bench.returncode == 0, stderr


def _rows(folder):
    rows, skipped = read_rows(folder)
    assert not any(skipped.values())
    return rows


def _parent(pid: int) -> int:
    """The parent process of ``pid`` (Linux /proc)."""
    stat = Path(f"/proc/{pid}/stat").read_text()
    return int(stat.rsplit(")", 1)[1].split()[1])


def test_killing_a_worker_mid_job_loses_no_job_and_stores_one_row_each(cluster, tmp_path):
    """A Dask worker SIGKILLed mid-job: Dask reruns its job elsewhere, one row per job, the victim's from the rerun."""
    address, env, marks = cluster
    bench = _bench(tmp_path, env, address, f'name = "dask-kill"\nmethods = ["bench_methods:marked"]\n'
                   f'time_limit = 60\n[[instances]]\nM = 2\nK = 2\nN = 1\nruns = {JOBS}\ne_max = 20000\n')
    try:
        first = _wait_for(lambda: sorted(marks.iterdir(), key=lambda p: p.stat().st_mtime), 90, "a job to start")[0]
        victim_job, victim_pid = first.name.rsplit(".", 1)  # the pid of the job's child process
        os.kill(_parent(int(victim_pid)), signal.SIGKILL)  # its Dask worker dies in the middle of the job
    finally:
        _finish(bench, tmp_path, marks)
    rows = _rows(tmp_path / "res")
    assert len(rows) == JOBS and len({r["key"] for r in rows}) == JOBS  # one row per job, none lost
    assert all(r["status"] == "optimal" and r["valid"] for r in rows)  # the killed job was retried
    [victim] = [r for r in rows if f"sar-m2-k2-n1-s{r['instance_seed']}" == victim_job]  # the generator's name
    assert victim["pid"] != int(victim_pid)  # its row comes from the rerun on a live worker
    assert len([p for p in marks.iterdir() if p.name.startswith(victim_job + ".")]) >= 2  # killed, then rerun


def test_a_job_that_kills_every_worker_becomes_an_error_row(cluster, tmp_path):
    """A job that kills every worker it runs on becomes one error row naming KilledWorker once Dask gives up."""
    from dask.distributed import Client

    address, env, marks = cluster

    def set_allowed_failures(n, dask_scheduler=None):
        before, dask_scheduler.allowed_failures = dask_scheduler.allowed_failures, n
        return before

    with Client(address, timeout="30s") as client:
        before = client.run_on_scheduler(set_allowed_failures, 0)
        try:
            _finish(_bench(tmp_path, env, address, 'name = "dask-die"\nmethods = ["bench_methods:kill_parent"]\n'
                           'time_limit = 30\n[[instances]]\nM = 2\nK = 2\nN = 1\nruns = 2\n'),
                    tmp_path, marks)
        finally:
            client.run_on_scheduler(set_allowed_failures, before)
    rows = _rows(tmp_path / "res")
    assert len(rows) == 2 and len({r["key"] for r in rows}) == 2
    assert all(r["status"] == "error" and "KilledWorker" in r["reason"] for r in rows), [r["reason"] for r in rows]
