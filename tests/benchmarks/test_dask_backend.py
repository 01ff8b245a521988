"""The Dask backend (benchmarks/dask_backend.py) on a local cluster started in the test."""

import os

import pytest

from sarcover.benchmarks.cli import main
from sarcover.benchmarks.harness import run_suite
from sarcover.benchmarks.suite import load_suite

from bench_suites import SMALL, rows_of, write_suite


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
    assert nap["status"] == "time_limit" and "killed after" in nap["reason"]

    def essence(rows):
        return sorted((r["key"], r["status"], r["objective"], r["routes"], r["valid"]) for r in rows)

    local, dask = rows_of(tmp_path / "local"), rows_of(tmp_path / "dask")
    assert len(local) == len(suite.jobs) == 5
    assert essence(local) == essence(dask)
    assert all(r["workers"] is None for r in dask)


def test_an_overrunning_job_is_killed_and_the_next_job_runs_alone(tmp_path, monkeypatch):
    """On a one-thread Dask worker, a job that spins past its deadline is killed with its child
    process (a time_limit row; the process is gone), and the job after it has its core alone: no
    other thread of its process used CPU while it ran (a job left running in a thread would)."""
    distributed = pytest.importorskip("dask.distributed")
    marks = tmp_path / "marks"
    marks.mkdir()
    monkeypatch.setenv("SARCOVER_TEST_MARKS", str(marks))
    suite = write_suite(tmp_path, 'methods = ["bench_methods:spin", "bench_methods:measured"]\ntime_limit = 0.3\n'
                                  'grace = 0.3\n[method."bench_methods:measured"]\ntime_limit = 60\n'
                                  '[[instances]]\nM = 2\nK = 2\nN = 1\ne_max = 20000\n')
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None,
                                  host="127.0.0.1", protocol="tcp") as cluster:
        summary = run_suite(load_suite(str(suite)), tmp_path / "res", scheduler=cluster.scheduler_address,
                            progress=False)
    assert summary["counts"] == {"time_limit": 1, "optimal": 1}
    rows = {r["method"]: r for r in rows_of(tmp_path / "res")}
    spin, measured = rows["bench_methods:spin"], rows["bench_methods:measured"]
    assert spin["status"] == "time_limit" and "killed after" in spin["reason"]
    [mark] = marks.iterdir()
    spin_pid = int(mark.name.split(".")[1])
    with pytest.raises(ProcessLookupError):
        os.kill(spin_pid, 0)
    assert measured["valid"] and measured["pid"] not in (spin_pid, os.getpid())
    assert measured["info"]["other_threads_cpu_s"] < 0.1, measured["info"]
