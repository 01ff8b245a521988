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


def _cheapest_per_group(rs: RouteSet, groups: list[np.ndarray]) -> list:
    """Per group, what ``rs.best_insertion(nodes)`` returns, for all groups in one pass per route.

    Same choice and tie-breaking as calling ``best_insertion`` once per group (first route, then
    first candidate, then first position among equal values), with one ``insertion_deltas`` call
    per route instead of one per route and group.
    """
    best: list = [None] * len(groups)
    sizes = np.array([g.size for g in groups])
    nonempty = np.flatnonzero(sizes)
    if nonempty.size == 0:
        return best
    cand = np.concatenate([groups[j] for j in nonempty])
    gid = np.repeat(nonempty, sizes[nonempty])
    for r in range(len(rs.routes)):
        delta = rs.insertion_deltas(r, cand)
        value = np.where(rs.energy[r] + delta <= rs.limit, -delta, -np.inf)
        pos = np.argmax(value, axis=1)
        rowmax = value[np.arange(cand.size), pos]
        for i in np.flatnonzero(rowmax > -np.inf):
            j = gid[i]
            if best[j] is None or rowmax[i] > best[j][0]:
                best[j] = (float(rowmax[i]), int(cand[i]), r, int(pos[i]), float(delta[i, pos[i]]))
    return best


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
    group_nodes = [np.array([v + 1 for v in g if v + 1 in reach_set], dtype=int) for g in instance.groups]
    uncovered = list(range(len(instance.groups)))
    while uncovered:
        best = _cheapest_per_group(rs, [group_nodes[gi] for gi in uncovered])
        missing = [gi for gi, b in zip(uncovered, best) if b is None]
        if missing:
            gi = missing[0]
            return Result(
                "greedy",
                Status.NO_PLAN,
                reason=f"greedy could not fit a viewpoint of {'target' if instance.kind == 'sar' else 'group'} {gi}",
                runtime_s=time.perf_counter() - t0,
            )
        # most expensive cheapest insertion first (the first such group on ties)
        j = min(range(len(uncovered)), key=lambda j: (best[j][0], j))
        _, node, r, p, delta = best[j]
        rs.insert(node, r, p, delta)
        uncovered.pop(j)
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
