"""Speed of the peer heuristics `routing` (OR-Tools) and `pyvrp` beside `greedy` (pytest-benchmark).

Run: ``.venv/bin/pytest benchmarks/speed/bench_peers.py --benchmark-only -p no:cacheprovider``.
Per-run time at the paper's M=20, K=3, N=5 preset and on a 31-customer TOP instance. Both peers
are single-threaded; `pyvrp` stops after 2000 iterations (reproducible), `routing` after 1000
solutions or its time cap (10 s; 60 % cold search, the rest only if a group stayed uncovered).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from sarcover.benchmarks.registry import run_method
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import to_top
from sarcover.formulations.io import read_top
from sarcover.formulations.result import Status

TOP_DIR = Path(__file__).resolve().parent / "instances" / "top"


@pytest.mark.parametrize("method", ["greedy", "routing", "pyvrp"])
def test_bench_peer_sar_m20_k3_n5(benchmark, method):
    """One run on the paper preset at M=20, K=3, N=5 (seed 0)."""
    inst = to_top(generate(20, 3, 5, 0))
    result = benchmark.pedantic(lambda: run_method(method, inst, seed=0, time_limit=10.0), rounds=3, iterations=1)
    assert result.status == Status.FEASIBLE


@pytest.mark.parametrize("method", ["greedy", "routing", "pyvrp"])
def test_bench_peer_top_p3_4_s(benchmark, method):
    """One run on TOP p3.4.s (31 customers, 4 vehicles)."""
    inst = read_top(TOP_DIR / "p3.4.s.txt")
    result = benchmark.pedantic(lambda: run_method(method, inst, seed=0, time_limit=10.0), rounds=3, iterations=1)
    assert result.status == Status.FEASIBLE
