"""Speed of `bp` (pytest-benchmark; not in the default test run).

Run: ``.venv/bin/pytest benchmarks/speed/bench_bp.py --benchmark-only -p no:cacheprovider``.
Times: one exact pricing call (unidirectional vs bidirectional labelling, elementary and ng-8)
on random duals, solving TOP instances to proven optimality (one HiGHS thread), and one SAR
instance at the paper's scale (M = 20, K = 3, N = 5, seed 4: proven in ~6 s on a shared core).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sarcover.formulations.bp import solve_bp
from sarcover.formulations.bp.graph import cheapest_return
from sarcover.formulations.bp.labelling import price
from sarcover.formulations.bp.ng_sets import full_ng, nearest_ng
from sarcover.formulations.io import read_top
from sarcover.formulations.result import Status

TOP_DIR = Path(__file__).resolve().parent / "instances" / "top"


@pytest.mark.parametrize("bidirectional", [False, True])
@pytest.mark.parametrize("ng", ["elementary", "ng8"])
def test_bench_pricing(benchmark, bidirectional, ng):
    """One exact pricing call on p1.3.n with random duals (half the prize on average)."""
    inst = read_top(TOP_DIR / "p1.3.n.txt")
    cost = inst.cost_matrix()
    n = cost.shape[0]
    prof = np.zeros(n)
    prof[1:-1] = inst.prizes * np.random.default_rng(0).uniform(0.0, 1.0, n - 2)
    sets = full_ng(n) if ng == "elementary" else nearest_ng(cost, 8)
    ret = cheapest_return(cost)
    allowed = np.ones(n, dtype=bool)
    res = benchmark(lambda: price(cost, ret, prof, inst.budget, sets, allowed, heuristic=False,
                                  max_labels=5_000_000, n_cols=30, min_gain=1.0,
                                  bidirectional=bidirectional))
    assert res.exact


@pytest.mark.parametrize("name", ["p1.3.n", "p2.2.k", "p3.2.g"])
def test_bench_solve_bp(benchmark, name):
    """Time to proven optimality, one thread."""
    inst = read_top(TOP_DIR / f"{name}.txt")
    result = benchmark.pedantic(lambda: solve_bp(inst, time_limit=120.0), rounds=3, iterations=1)
    assert result.status == Status.OPTIMAL


def test_bench_solve_bp_sar(benchmark):
    """M = 20 targets, K = 3 views, N = 5 UAVs (paper preset, seed 4): time to proven optimality."""
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(20, 3, 5, 4))
    result = benchmark.pedantic(lambda: solve_bp(inst, time_limit=120.0), rounds=1, iterations=1)
    assert result.status == Status.OPTIMAL
