"""Speed of the harness hot paths (pytest-benchmark; not in the default run).

    .venv/bin/pytest benchmarks/speed/bench_harness.py --benchmark-only -p no:cacheprovider \\
        --benchmark-columns median,mean,min,rounds

- ``build_instance``: a worker rebuilding a paper-size instance (M=20, K=3, N=5) from its job.
- ``run_one_greedy``: one whole job (build, greedy, verification, row) at that size.
- ``row_write``: appending one row to the results store (JSON + flush).
- ``run_in_child_greedy``: the same job as a Dask task runs it: in a child process of the worker
  (kept between jobs), over a pipe, with its deadline watched.
- ``report``: ``sarcover report`` on 400 synthetic rows (4 methods, proven and bound-only instances).

The paper suites are 40 000 short jobs; the harness's own cost per job (build + verify + row +
pipe) must stay a few milliseconds so that the methods, not the harness, set the wall time.
"""

from __future__ import annotations

import json
import random

import pytest

from sarcover.benchmarks.rows import build_instance, run_one
from sarcover.benchmarks.store import ResultsStore
from sarcover.reports.report import write_report
from sarcover.reports.results import SCHEMA_VERSION

SOURCE = {"type": "generate", "M": 20, "K": 3, "N": 5, "instance_seed": 7, "preset": "paper", "overrides": {}}
JOB = {"key": "k", "instance": "sar-m20-k3-n5-s7", "method": "greedy", "seed": 0, "run": 0,
       "time_limit": 10.0, "grace": 5.0, "source": {**SOURCE, "exact": False}, "suite": "bench", "workers": 1}


def test_build_instance(benchmark):
    """A worker rebuilds the M=20, K=3, N=5 instance from the job's generator parameters."""
    inst = benchmark(build_instance, SOURCE)
    assert inst.n_nodes == 60


def test_run_one_greedy(benchmark):
    """One whole greedy job: instance, run_method (with verification), row."""
    row = benchmark(run_one, JOB)
    assert row["status"] in ("feasible", "no_plan")


def test_run_in_child_greedy(benchmark):
    """One whole greedy job through a Dask task's child process (started once, then reused)."""
    from sarcover.benchmarks.dask_backend import run_in_child

    run_in_child(JOB)  # starts the child: its interpreter start is not per job
    row = benchmark(run_in_child, JOB)
    assert row["status"] in ("feasible", "no_plan") and row["pid"] is not None


def test_row_write(benchmark, tmp_path):
    """Append one ~1.3 kB row to the results store."""
    row = run_one(JOB)
    store = ResultsStore(tmp_path / "res", resume=False)
    counter = iter(range(10**9))

    def write():
        store.append({**row, "key": f"k{next(counter)}"})

    benchmark(write)
    store.close()


def _synthetic(directory, n_instances=100, methods=("exact", "a", "b", "c")):
    rng = random.Random(0)
    lines = []
    for i in range(n_instances):
        opt = rng.randint(10, 20)
        proven = i % 2 == 0
        for m in methods:
            obj = opt if m == "exact" else opt - rng.randint(0, 3)
            lines.append({
                "schema": SCHEMA_VERSION, "key": f"i{i}|{m}|0", "suite": "bench",
                "instance": f"sar-m5-k2-n{2 + i % 3}-s{i}",
                "method": m, "exact": m == "exact", "seed": 0, "run": i, "kind": "sar", "M": 5, "K": 2, "N": 2 + i % 3,
                "instance_seed": i, "n_nodes": 10, "reference": None,
                "status": ("optimal" if proven else "time_limit") if m == "exact" else "feasible",
                "objective": float(obj), "bound": float(opt if proven else opt + 2) if m == "exact" else None,
                "coverage": obj / 10, "valid": True, "routes": None, "runtime_s": rng.random(),
                "source": {"type": "generate", "M": 5, "K": 2, "N": 2, "instance_seed": i, "preset": "paper",
                           "overrides": {}},
            })
    directory.mkdir()
    (directory / "results.jsonl").write_text("\n".join(json.dumps(r) for r in lines) + "\n")


@pytest.mark.parametrize("rows", [400])
def test_report(benchmark, tmp_path, rows):
    """sarcover report on 400 rows: tables, Markdown, HTML and every plot."""
    _synthetic(tmp_path / "res")
    summary = benchmark.pedantic(write_report, args=(tmp_path / "res", tmp_path / "rep"), rounds=3, iterations=1)
    assert "400 runs" in summary
