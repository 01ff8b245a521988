"""The local worker pool (benchmarks/pool.py): deadlines, dead workers, memory cap, batches."""

import time

from sarcover.benchmarks.cli import main

from bench_suites import rows_of, write_suite


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


def test_a_groups_jobs_go_to_one_worker_task_and_long_jobs_alone():
    """next_batch: a group's jobs form one task, long jobs go alone, short ungrouped jobs share a batch."""
    from collections import deque

    from sarcover.benchmarks.pool import BATCH_TIME_LIMIT, next_batch

    long, short = BATCH_TIME_LIMIT + 1, BATCH_TIME_LIMIT

    def j(tl, group=None):
        return {"time_limit": tl, "group": group}

    pending = deque([j(long, "a"), j(long, "a"), j(short, "a"), j(long, "b"), j(long)] + [j(short)] * 9
                    + [j(short, "c")])
    assert [len(next_batch(pending, 1)) for _ in range(3)] == [3, 1, 1]
    assert next_batch(pending, 1) == [j(short)] * 2  # up to a quarter of what is left: 9 // 4 = 2
    rest = []
    while pending:
        rest.append(next_batch(pending, 1))
    assert rest[-1] == [j(short, "c")] and all(batch[0]["group"] is None for batch in rest[:-1])


def test_a_dead_workers_output_is_kept_in_the_workers_log(tmp_path):
    """What a dying worker prints on stdout and stderr is kept in RESULTS/workers.log."""
    suite = write_suite(tmp_path, 'methods = ["bench_methods:chatter"]\n[[instances]]\nM = 2\nK = 2\nN = 1\n')
    assert main(["bench", str(suite), "-o", str(tmp_path / "res"), "--quiet"]) == 0
    [row] = rows_of(tmp_path / "res")
    assert row["status"] == "error" and "exited with code 5" in row["reason"]
    text = (tmp_path / "res" / "workers.log").read_text()
    assert "chatter on stdout" in text and "last words on stderr" in text
