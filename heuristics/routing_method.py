"""`routing`: OR-Tools routing with guided local search (:mod:`sarcover.formulations.routing`).

The cold search (local cheapest insertion, then guided local search) gets ``COLD_SHARE`` of the
time. If its best plan leaves a group uncovered, or collects less than the `greedy` plan (which
covers every group whenever greedy succeeds), a second search starts from greedy's plan with the
remaining time, and the better of the two plans is returned. On tight SAR budgets the cold search
sometimes never finds a covering plan; with little CPU (a loaded machine, 120 viewpoints) it can
end far below greedy (K=6: 31-58 views where greedy has ~80). When the cold plan is at least
greedy's, the warm search is skipped: it gave worse plans than a cold one (M=20, K=3, N=5: 43 vs
45-47 views).
"""

from __future__ import annotations

import time

from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Result, Status
from sarcover.formulations.routing import DEFAULT_TIME_CAP, solve_routing
from sarcover.heuristics.greedy import greedy

TIME_CAP = 10.0  # seconds: the method runs at most min(time_limit, TIME_CAP)
COLD_SHARE = 0.6


def _prize(instance: TOPInstance, result: Result) -> float:
    """Prize of a result's plan (-1 without one, so any plan beats no plan)."""
    if result.plan is None or result.status not in (Status.FEASIBLE, Status.OPTIMAL):
        return -1.0
    return float(sum(instance.prizes[v] for v in result.plan.visited))


def routing(instance: TOPInstance, *, seed: int = 0, time_limit: float | None = 60.0) -> Result:
    """OR-Tools routing heuristic; status FEASIBLE or NO_PLAN, never a bound (``seed`` unused)."""
    t0 = time.perf_counter()
    cap = min(DEFAULT_TIME_CAP if time_limit is None else float(time_limit), TIME_CAP)
    result = solve_routing(instance, time_limit=COLD_SHARE * cap if instance.groups else cap)
    result.info["phase"] = "cold"
    if instance.groups:
        start = greedy(instance)
        remaining = cap - (time.perf_counter() - t0)
        if start.plan is not None and remaining > 0.05 and _prize(instance, result) < _prize(instance, start):
            warm = solve_routing(instance, time_limit=remaining,
                                 initial_routes=[list(r) for r in start.plan.routes])
            warm.info["phase"] = "greedy warm start"
            if _prize(instance, warm) >= _prize(instance, result):
                result = warm
    result.method = "routing"
    result.runtime_s = time.perf_counter() - t0
    return result
