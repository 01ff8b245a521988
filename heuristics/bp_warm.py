"""The registered `bp` method: branch-and-price started from greedy's routes.

``formulations`` may not import heuristics, so :func:`formulations.bp.solve_bp` takes optional
``initial_routes``; this glue hands it greedy's plan (milliseconds): its routes are the first
columns of the master and its value the first incumbent, so a run stopped early still returns a
plan covering every target whenever greedy found one.
"""

from __future__ import annotations

import time

from formulations.bp import solve_bp
from formulations.history import shifted
from formulations.plan import Result, Status
from heuristics.greedy import greedy


def bp(instance, *, seed: int = 0, time_limit: float | None = 60.0) -> Result:
    """`bp` with greedy's routes (when it finds a plan) as initial columns and incumbent."""
    t0 = time.perf_counter()
    start = greedy(instance, seed=seed)
    routes = [list(r) for r in start.plan.routes] if start.status == Status.FEASIBLE else None
    t1 = time.perf_counter()
    if time_limit is not None:
        time_limit = max(time_limit - (t1 - t0), 0.0)
    result = solve_bp(instance, seed=seed, time_limit=time_limit, initial_routes=routes)
    result.runtime_s = time.perf_counter() - t0
    if "history" in result.info:  # times from this call, greedy included
        result.info["history"] = shifted(result.info["history"], t1 - t0)
    result.info["warm_start_prize"] = (float(sum(instance.prizes[v] for v in start.plan.visited))
                                       if routes is not None else None)
    return result
