"""Exact methods started from a heuristic plan.

The exact models live in ``formulations`` and may not import heuristics (imports flow one way),
so they accept an optional ``warm_start`` plan; this module is the glue that hands them greedy's
plan. Greedy costs milliseconds. It rarely changes what is proven, but on instances the time
limit stops it keeps the returned incumbent from being much worse than a trivial heuristic (on
p3.2.l HiGHS alone had only the empty plan after 60 s).
"""

from __future__ import annotations

import time

from sarcover.formulations.history import shifted
from sarcover.formulations.milp import solve_milp
from sarcover.formulations.plan import Result, Status
from sarcover.heuristics.greedy import greedy


def milp(instance, *, seed: int = 0, time_limit: float | None = 60.0, threads: int = 1) -> Result:
    """`milp` with greedy's plan (when it finds one) as HiGHS's first incumbent."""
    t0 = time.perf_counter()
    start = greedy(instance, seed=seed)
    plan = start.plan if start.status == Status.FEASIBLE else None
    t1 = time.perf_counter()
    if time_limit is not None:
        time_limit = max(time_limit - (t1 - t0), 0.0)
    result = solve_milp(instance, seed=seed, time_limit=time_limit, threads=threads, warm_start=plan)
    result.runtime_s = time.perf_counter() - t0
    if "history" in result.info:  # times from this call, greedy included
        result.info["history"] = shifted(result.info["history"], t1 - t0)
    result.info["warm_start_prize"] = float(sum(instance.prizes[v] for v in plan.visited)) if plan else None
    return result
