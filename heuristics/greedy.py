"""`greedy`: the floor baseline. Cover every group by cheapest insertion, then insert by prize per energy.

It is the energy repair's insertion phases (:class:`sarcover.heuristics.repair.Repairer`) on empty routes:

1. groups: among the uncovered groups, the one whose cheapest feasible insertion is the most
   expensive goes first (hardest first), inserted at that cheapest place (first route, then
   first position, on ties);
2. prizes: repeatedly the feasible insertion with the largest prize per added energy.

Insertion costs are kept per route and only the route that changed is re-scored each round.
Its anytime history (``info["history"]``) is the one point where its plan is complete; it stops
when the construction ends (``info["stop_reason"] == "completed"``).
"""

from __future__ import annotations

import time

import numpy as np

from sarcover.formulations.history import History, StopReason
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Result, Termination
from sarcover.heuristics.insertion import RouteSet
from sarcover.heuristics.repair import Repairer


def greedy(instance: TOPInstance, *, seed: int = 0, time_limit: float | None = None) -> Result:
    """Deterministic insertion heuristic (``seed`` and ``time_limit`` are accepted and unused)."""
    t0 = time.perf_counter()
    hist = History(t0)
    info = {"stop_reason": StopReason.COMPLETED.value}
    repairer = Repairer(instance)
    rs = RouteSet(instance, repairer.C)
    reach = np.zeros(instance.n_nodes + 2, dtype=bool)
    reach[1:-1] = instance.reachable()
    missing = repairer.cover(rs, reach)
    if missing is not None:
        what = "target" if instance.kind == "sar" else "group"
        hist.record(info, None, None)
        return Result("greedy", Termination.COMPLETED, reason=f"greedy could not fit a viewpoint of {what} {missing}",
                      runtime_s=time.perf_counter() - t0, info=info)
    repairer.fill(rs, reach)
    plan = Plan.of(rs.node_routes())
    hist.record(info, float(sum(instance.prizes[v] for v in plan.visited)), None)
    return Result("greedy", Termination.COMPLETED, plan=plan, runtime_s=time.perf_counter() - t0, info=info)
