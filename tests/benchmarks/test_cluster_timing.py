"""The cluster timing tool (benchmarks/cluster_timing.py): a tiny suite on 1 and 2 local workers, on a
real `dask scheduler` + `dask worker --nworkers 2` it starts as separate processes, and again with
one Dask worker process SIGKILLed mid-run; its table and timing.json, and no process left behind."""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import psutil
import pytest

from sarcover.benchmarks.cluster_timing import main, stored_rows, summarize, table

TESTS = Path(__file__).resolve().parents[1]  # tests/: bench_methods.py is there
DASK = Path(sys.executable).with_name("dask")

# 4 jobs: greedy and a method that sleeps 0.3 s, on two tiny instances (e_max: one route visits all)
TINY = ('name = "tiny-timing"\nmethods = ["greedy", "bench_methods:slow_all"]\ntime_limit = 10\n'
        '[[instances]]\nM = 2\nK = 2\nN = 1\nruns = 2\ne_max = 20000\n')


def _gone(pid: int) -> bool:
    try:
        return psutil.Process(pid).status() == psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return True


@pytest.mark.skipif(not DASK.exists(), reason="the dask command line is not installed")
def test_the_tool_times_local_dask_and_a_killed_worker_end_to_end(tmp_path):
    """Four runs of a 4-job suite: one row per job each, finite ratios, the kill recorded, no process left."""
    suite = tmp_path / "tiny.toml"
    suite.write_text(TINY)
    out = tmp_path / "timing"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(TESTS), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, "-m", "sarcover.benchmarks.cluster_timing", str(suite), "-o", str(out),
                           "--kill-after", "0.2", "--quiet"], env=env, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    timing = json.loads((out / "timing.json").read_text())
    assert list(timing["runs"]) == ["local-1", "local-2", "dask-2", "dask-2-killed"]
    for name, run in timing["runs"].items():
        assert (run["jobs"], run["rows"], run["jobs_stored"]) == (4, 4, 4), name
        assert run["errors"] == run["lost"] == run["duplicated"] == 0 and run["one_row_each"], name
        assert run["statuses"] == {"optimal": 2, "feasible": 2}, name  # slow_all claims optimal, greedy cannot
        assert run["wall_s"] > 0 and run["cpu_s"] > 0 and run["jobs_cpu_s"] > 0, name
        assert (out / name / "results.jsonl").is_file()
    summary = timing["summary"]
    assert all(math.isfinite(summary[k]) and summary[k] > 0 for k in ("local_2_over_local_1", "dask_2_over_local_2"))
    killed = summary["killed"]
    assert killed["kill"] is not None and (killed["lost"], killed["duplicated"]) == (0, 0)
    assert killed["kill"]["orphaned_cpu_s"] >= 0 and killed["kill"]["tasks"] >= 1
    cluster_pids = timing["runs"]["dask-2"]["pids"] + timing["runs"]["dask-2-killed"]["pids"]
    assert killed["kill"]["pid"] in timing["runs"]["dask-2-killed"]["pids"]  # one of its own worker processes
    assert len(cluster_pids) >= 2 * 4  # each cluster: scheduler, `dask worker`, its 2 worker processes at least
    assert all(_gone(pid) for pid in cluster_pids), [p for p in cluster_pids if not _gone(p)]
    # the printed table says the same
    assert "| dask-2-killed" in done.stdout and f"wall time local-2 / local-1: {summary['local_2_over_local_1']:.2f}" \
        in done.stdout
    assert f"SIGKILLed at {killed['kill']['at_s']:.1f} s" in done.stdout and "0 jobs lost, 0 rows duplicated" \
        in done.stdout


def test_bad_input_is_one_line_and_exit_2(tmp_path, capsys):
    """An unknown suite, an -o that holds a run, a bad flag: one line on stderr and exit 2; nothing runs."""
    assert main(["no-such-suite", "-o", str(tmp_path / "t")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("cluster_timing: error: no suite 'no-such-suite'")
    assert not (tmp_path / "t").exists()
    (tmp_path / "t" / "local-1").mkdir(parents=True)
    assert main(["quick", "-o", str(tmp_path / "t"), "--methods", "greedy", "-q"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "local-1 exists" in err
    assert main(["quick", "-o", str(tmp_path / "t"), "--kill-after", "-1"]) == 2
    assert capsys.readouterr().err.count("\n") == 1
    assert main(["quick", "-o", str(tmp_path / "u"), "--workers", "1", "-q"]) == 2  # local-1 twice
    assert "at least 2" in capsys.readouterr().err and not (tmp_path / "u").exists()


def test_rows_count_lost_and_duplicated_jobs_and_the_table_shows_them(tmp_path):
    """stored_rows counts a job stored twice and a job never stored; the table prints them and the ratios."""
    rows = [{"key": "a", "status": "optimal", "cpu_s": 1.0}, {"key": "a", "status": "optimal", "cpu_s": 1.5},
            {"key": "b", "status": "error", "cpu_s": None}]
    (tmp_path / "results.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows) + '{"key": "c", "sta')
    got = stored_rows(tmp_path, ["a", "b", "c"])
    assert (got["rows"], got["jobs_stored"], got["errors"], got["lost"], got["duplicated"]) == (3, 2, 1, 1, 1)
    assert not got["one_row_each"] and got["jobs_cpu_s"] == 2.5
    run = {"wall_s": 10.0, "cpu_s": 9.0, "jobs": 3, **got}
    timing = {"suite": "s", "jobs": 3, "workers": 2, "warm_up_s": 0.5,
              "runs": {"local-1": run, "local-2": {**run, "wall_s": 5.0}, "dask-2": {**run, "wall_s": 6.0},
                       "dask-2-killed": {**run, "wall_s": 8.5, "kill": {"pid": 7, "at_s": 2.0}}}}
    timing["summary"] = summarize(timing)
    assert timing["summary"]["local_2_over_local_1"] == 0.5 and timing["summary"]["dask_2_over_local_2"] == 1.2
    text = table(timing)
    assert "| local-1 | 10.0 | 9.0 | 2.5 | 3 | 1 | 1 | 1 | NO |" in text
    assert "dask-2 / local-2: 1.20" in text
    assert "worker process 7 SIGKILLed at 2.0 s): +2.5 s wall" in text and "1 jobs lost, 1 rows duplicated" in text
