"""`greedy`: the floor baseline. Cover every group by cheapest insertion, then insert by prize per energy."""

from __future__ import annotations

import time

import numpy as np

from formulations.instance import TOPInstance
from formulations.plan import Plan, Result, Status
from heuristics.insertion import RouteSet


def _ratio(prizes: np.ndarray):
    def score(delta: np.ndarray, nodes: np.ndarray) -> np.ndarray:
        p = prizes[nodes - 1][:, None]
        return np.where(delta > 1e-12, p / np.maximum(delta, 1e-12), np.inf * (p > 0))

    return score


def greedy(instance: TOPInstance, *, seed: int = 0, time_limit: float | None = None) -> Result:
    """Deterministic insertion heuristic (``seed`` and ``time_limit`` are accepted and unused).

    Phase 1 covers the groups: among uncovered groups, the one whose cheapest feasible insertion
    is most expensive goes first (hardest first), inserted at that cheapest place. Phase 2
    repeatedly makes the feasible insertion with the largest prize per added energy.
    """
    t0 = time.perf_counter()
    rs = RouteSet(instance)
    reach = np.flatnonzero(instance.reachable()) + 1  # solver indices
    reach_set = set(reach.tolist())
    uncovered = list(range(len(instance.groups)))
    while uncovered:
        choice = None
        for gi in uncovered:
            nodes = np.array([v + 1 for v in instance.groups[gi] if v + 1 in reach_set])
            best = rs.best_insertion(nodes)
            if best is None:
                return Result(
                    "greedy",
                    Status.NO_PLAN,
                    reason=f"greedy could not fit a viewpoint of {'target' if instance.kind == 'sar' else 'group'} {gi}",
                    runtime_s=time.perf_counter() - t0,
                )
            if choice is None or best[0] < choice[1][0]:  # most expensive cheapest insertion
                choice = (gi, best)
        gi, (_, node, r, p, delta) = choice
        rs.insert(node, r, p, delta)
        uncovered.remove(gi)
    score = _ratio(instance.prizes)
    while True:
        free = reach[~rs.visited[reach]]
        free = free[instance.prizes[free - 1] > 0]
        best = rs.best_insertion(free, score)
        if best is None:
            break
        _, node, r, p, delta = best
        rs.insert(node, r, p, delta)
    return Result(
        "greedy",
        Status.FEASIBLE,
        plan=Plan.of(rs.node_routes()),
        runtime_s=time.perf_counter() - t0,
    )
