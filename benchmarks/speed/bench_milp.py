"""Speed of `milp` (pytest-benchmark; not in the default test run).

Run: ``.venv/bin/pytest benchmarks/speed/bench_milp.py --benchmark-only -p no:cacheprovider``.
Times: building the Pyomo model for a 30-customer TOP instance, and solving small instances to
proven optimality with one HiGHS thread.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from sarcover.formulations.io import read_top
from sarcover.formulations.milp import build_milp, solve_milp
from sarcover.formulations.result import Status
from sarcover.formulations.preprocess import prune_arcs

TOP_DIR = Path(__file__).resolve().parent / "instances" / "top"


@pytest.mark.parametrize("name", ["p1.4.r", "p3.2.t"])
def test_bench_build_milp(benchmark, name):
    """Arc pruning plus Pyomo model construction."""
    inst = read_top(TOP_DIR / f"{name}.txt")
    model = benchmark(lambda: build_milp(inst, prune_arcs(inst)))
    assert len(model.x) > 0


@pytest.mark.parametrize("name", ["p2.2.f", "p1.2.g", "p3.2.d"])
def test_bench_solve_milp(benchmark, name):
    """Time to proven optimality, one thread."""
    inst = read_top(TOP_DIR / f"{name}.txt")
    result = benchmark.pedantic(lambda: solve_milp(inst, time_limit=120.0, threads=1), rounds=3, iterations=1)
    assert result.status == Status.OPTIMAL
