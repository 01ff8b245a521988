"""The registered `bp` method: branch-and-price warm-started by heuristics.

``formulations`` may not import heuristics, so :func:`sarcover.formulations.bp.solve_bp` takes an optional
``warm_start`` plan and a ``primal`` callback; this glue hands it

- greedy's plan (milliseconds) as the first columns and incumbent, so a run stopped early still
  returns a plan covering every target whenever greedy found one;
- PyVRP's iterated local search (:mod:`sarcover.heuristics.pyvrp_method`, the strongest heuristic of the
  suite) as ``primal``: bp runs it once, with 10 % of its time limit (at most 10 s), only when
  the root's floored bound and the first dive leave the proof open (most TOP instances never
  pay for it). Its routes become columns and its plan, if better, the incumbent.

Measured (M = 20, K = 3, N = 5, seeds 0..7, 2026-12-01): greedy's plans are worth 42-49;
PyVRP's 52-56 at 2 s, within one of the optimum on every seed; its full run (2000 iterations
per pass, about 4 s, inside the 6 s that a 60 s limit allows) reaches the optimum on seeds 0, 2,
3, 5 and 6, and is one short on seeds 1, 4 and 7.
"""

from __future__ import annotations

import time

from sarcover.formulations.bp import BPOptions, solve_bp
from sarcover.formulations.bp.pricing import warm_up
from sarcover.formulations.history import shifted
from sarcover.formulations.plan import Result, Status
from sarcover.heuristics.greedy import greedy


def _pyvrp_routes(instance, seed: int):
    """``primal`` callback: PyVRP's plan within the given seconds, as routes of node ids."""
    from sarcover.heuristics.pyvrp_method import pyvrp

    def run(seconds: float):
        res = pyvrp(instance, seed=seed, time_limit=max(seconds, 0.05))
        if res.status != Status.FEASIBLE or res.plan is None:
            return None
        return [list(r) for r in res.plan.routes]

    return run


def bp(instance, *, seed: int = 0, time_limit: float | None = 60.0) -> Result:
    """`bp` with greedy's routes (when it finds a plan) as initial columns and incumbent, and
    PyVRP as the heuristic run once the root has not proven the incumbent."""
    warm_up()  # numba compilation (or loading it from the disk cache) is not the method's time
    t0 = time.perf_counter()
    # cuts on the user's limit, not on what greedy leaves of it
    options = BPOptions.for_time_limit(time_limit)
    start = greedy(instance, seed=seed)
    warm_start = start.plan if start.status == Status.FEASIBLE else None
    t1 = time.perf_counter()
    if time_limit is not None:
        time_limit = max(time_limit - (t1 - t0), 0.0)
    result = solve_bp(instance, seed=seed, time_limit=time_limit, warm_start=warm_start,
                      primal=_pyvrp_routes(instance, seed), options=options)
    result.runtime_s = time.perf_counter() - t0
    if "history" in result.info:  # times from this call, greedy included
        result.info["history"] = shifted(result.info["history"], t1 - t0)
    result.info["warm_start_prize"] = (float(sum(instance.prizes[v] for v in start.plan.visited))
                                       if warm_start is not None else None)
    return result
