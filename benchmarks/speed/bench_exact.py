"""Speed: time to proven optimality by instance size, `milp` and `cpsat` side by side.

pytest-benchmark file (not collected by the default test run)::

    .venv/bin/pytest benchmarks/speed/bench_exact.py --benchmark-enable -p no:cacheprovider -o addopts=""

Each case is a generated SAR instance with a tight budget (1.15 × the coverage threshold) whose
number of reachable viewpoints is 8, 12, 16, 20 or 24; each solver runs with 1 thread and with
all cores, greedy's plan as warm start, a 30 s limit. ``extra_info`` records status, objective
and bound, so a run that stopped on the limit is visible. ``python benchmarks/speed/bench_exact.py``
prints the same comparison as a table (median over the seeds of each size).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import highspy
import numpy as np

from sarcover.formulations.cpsat import solve_cpsat
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import TOPInstance, to_top
from sarcover.formulations.milp import solve_milp
from sarcover.formulations.verify import verify
from sarcover.heuristics.greedy import greedy

SIZES = (8, 12, 16, 20, 24)
TIME_LIMIT = 30.0
BUDGET_FACTOR = 1.15
ALL_CORES = os.cpu_count() or 1
THREADS = (1, ALL_CORES) if ALL_CORES > 1 else (1,)


def sized_instances(size: int, count: int = 3, n_uavs: int = 2) -> list[TOPInstance]:
    """``count`` SAR instances (K = 3, N = 2) whose budget leaves exactly ``size`` viewpoints reachable.

    E_max is the ``size``-th smallest viewpoint round trip (plus 1e-6 relative), kept only when it
    also covers every target (at least the coverage threshold) and greedy finds a plan, so the
    case is feasible: a tight budget by construction.
    """
    found, seed = [], 0
    while len(found) < count and seed < 600:
        for m in range(-(-size // 3), -(-size // 3) + 3):
            base = to_top(generate(m, 3, n_uavs, seed))
            trip = np.sort(base.round_trip_cost())
            thr = max(base.round_trip_cost()[list(g)].min() for g in base.groups)
            e_max = float(trip[size - 1]) * (1 + 1e-6)
            if e_max >= thr and (size == len(trip) or trip[size] > e_max) and len(found) < count:
                inst = to_top(generate(m, 3, n_uavs, seed, e_max=e_max))
                if int(inst.reachable().sum()) == size and greedy(inst).plan is not None:
                    found.append(inst)  # feasible (greedy covers every target): an optimisation case
        seed += 1
    return found


def solve(method: str, inst: TOPInstance, threads: int, time_limit: float = TIME_LIMIT):
    warm = greedy(inst).plan
    if warm is not None and not verify(inst, warm).valid:
        warm = None
    if method == "cpsat":
        return solve_cpsat(inst, time_limit=time_limit, threads=threads, warm_start=warm)
    # HiGHS keeps one global thread pool per process; a run with another thread count fails
    # ("HiGHS stopped: unknown") unless the pool is reset first.
    highspy.Highs.resetGlobalScheduler(True)
    return solve_milp(inst, time_limit=time_limit, threads=threads, warm_start=warm)


try:  # the pytest-benchmark part; importable without pytest for the table below
    import pytest

    CASES = [(s, i) for s in SIZES for i in range(2)]

    @pytest.mark.parametrize("threads", THREADS)
    @pytest.mark.parametrize("method", ["milp", "cpsat"])
    @pytest.mark.parametrize("size,idx", CASES, ids=[f"v{s}-{i}" for s, i in CASES])
    def test_time_to_optimality(benchmark, method, threads, size, idx):
        """Time to proven optimality (or to the 30 s limit) on a tight SAR instance of ``size`` viewpoints."""
        insts = sized_instances(size, 2)
        if idx >= len(insts):
            pytest.skip("no instance of this size")
        inst = insts[idx]
        res = benchmark.pedantic(solve, args=(method, inst, threads), rounds=1, iterations=1)
        benchmark.extra_info.update(status=str(res.status), bound=res.bound, instance=inst.name,
                                    objective=verify(inst, res.plan).prize if res.plan else None)
except ImportError:  # pragma: no cover
    pass


def table(sizes=SIZES, count: int = 3, threads=THREADS, time_limit: float = TIME_LIMIT) -> list[dict]:
    """Run every size × solver × threads; one row per run (size, method, threads, status, seconds)."""
    rows = []
    for size in sizes:
        for inst in sized_instances(size, count):
            for th in threads:
                for method in ("milp", "cpsat"):
                    t0 = time.perf_counter()
                    res = solve(method, inst, th, time_limit)
                    rows.append(dict(size=size, instance=inst.name, method=method, threads=th,
                                     status=str(res.status), seconds=time.perf_counter() - t0,
                                     objective=verify(inst, res.plan).prize if res.plan else None,
                                     bound=res.bound))
                    print(rows[-1], flush=True)
    return rows


def summarise(rows: list[dict]) -> str:
    """Median seconds and proven share per size, milp and cpsat side by side."""
    keys = sorted({(r["method"], r["threads"]) for r in rows}, key=lambda k: (k[1], k[0]))
    head = "size | " + " | ".join(f"{m} {t}T: median s (proven)" for m, t in keys)
    lines = [head, "-" * len(head)]
    for size in sorted({r["size"] for r in rows}):
        cells = []
        for m, t in keys:
            sel = [r for r in rows if r["size"] == size and r["method"] == m and r["threads"] == t]
            proven = sum(r["status"] in ("optimal", "infeasible") for r in sel)
            cells.append(f"{statistics.median(r['seconds'] for r in sel):.2f} ({proven}/{len(sel)})")
        lines.append(f"{size:4d} | " + " | ".join(cells))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python benchmarks/speed/bench_exact.py", description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=list(SIZES))
    ap.add_argument("--count", type=int, default=3, help="instances per size")
    ap.add_argument("--threads", type=int, nargs="+", default=list(THREADS))
    ap.add_argument("--time-limit", type=float, default=TIME_LIMIT)
    args = ap.parse_args(argv)
    rows = table(args.sizes, args.count, args.threads, args.time_limit)
    print(summarise(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
