"""Energy repair: make cluster tours fit the budget, keep every group covered, refill.

Rule (documented in the README): for each route over budget, repeatedly remove the viewpoint
with the greatest energy saving per lost prize, saving = c(prev,v) + c(v,next) − c(prev,next)
(flight plus imaging energy), among the viewpoints whose group keeps another visited viewpoint
(a target's last view is kept while possible); only when every remaining viewpoint is its group's
last may one be removed, which uncovers that group. After each removal the route is re-optimised
by 2-opt. Then:

1. every uncovered group gets its cheapest feasible insertion (hardest group first, as greedy);
2. if some group still cannot be inserted, every route is stripped to one viewpoint per group it
   covers (the groups' "last views"), 2-opted, and step 1 is retried; if that fails too, the
   routes are rebuilt from empty by step 1 alone (greedy's group phase, ``info["rebuilt"]``);
3. if ``reinsert``: the removed and stripped viewpoints, and any other reachable unvisited
   viewpoint, are inserted by greatest prize per added energy while any fits, then each route
   is 2-opted and the insertion retried once.

If a group is still uncovered the repair fails: the caller reports Status.NO_PLAN (a heuristic
never proves infeasibility).
"""

from __future__ import annotations

import numpy as np

from formulations.instance import TOPInstance
from heuristics.insertion import RouteSet
from heuristics.tour import route_length, two_opt


class RepairFailed(Exception):
    """No plan covering every group was found; the message names the group."""


def _ratio(prizes: np.ndarray):
    def score(delta: np.ndarray, nodes: np.ndarray) -> np.ndarray:
        p = prizes[nodes - 1][:, None]
        return np.where(delta > 1e-12, p / np.maximum(delta, 1e-12), np.inf * (p > 0))

    return score


class Repairer:
    """Repairs lists of routes (solver indices) for one instance; reuses its matrices."""

    def __init__(self, instance: TOPInstance, D: np.ndarray | None = None, C: np.ndarray | None = None):
        self.instance = instance
        self.D = instance.distance_matrix() if D is None else D
        self.C = instance.cost_matrix() if C is None else C
        self.end = instance.n_nodes + 1
        self.limit = instance.budget * (1.0 + 1e-9)
        # group of each solver index (-1: none, also for start/end)
        self.group = np.concatenate(([-1], instance.group_of, [-1]))
        self.prize = np.concatenate(([0.0], instance.prizes, [0.0]))
        self.stats = {"removed": 0, "reinserted": 0, "stripped": False, "rebuilt": False}

    def energy(self, route) -> float:
        return route_length(self.C, route, 0, self.end)

    def _polish(self, route) -> list[int]:
        return two_opt(self.D, route, 0, self.end).tolist()

    def shrink(self, route: list[int], count: np.ndarray) -> tuple[list[int], list[int]]:
        """Remove viewpoints from one route until it fits; returns (route, removed)."""
        removed = []
        route = list(route)
        while route and self.energy(route) > self.limit:
            seq = np.array([0, *route, self.end])
            prev, node, nxt = seq[:-2], seq[1:-1], seq[2:]
            saving = self.C[prev, node] + self.C[node, nxt] - self.C[prev, nxt]
            p = self.prize[node]
            score = np.where(p > 0, saving / np.maximum(p, 1e-300), np.inf)
            g = self.group[node]
            last = (g >= 0) & (count[np.maximum(g, 0)] <= 1)
            if not last.all():
                score = np.where(last, -np.inf, score)
            k = int(np.argmax(score))
            v = route.pop(k)
            removed.append(v)
            if self.group[v] >= 0:
                count[self.group[v]] -= 1
            route = self._polish(route)
        return route, removed

    def _routeset(self, routes: list[list[int]]) -> RouteSet:
        rs = RouteSet(self.instance, self.C)
        for r, route in enumerate(routes):
            rs.routes[r] = list(route)
            rs.energy[r] = self.energy(route)
            rs.visited[route] = True
        return rs

    def _cover(self, rs: RouteSet, reach: np.ndarray) -> int | None:
        """Insert a view of each uncovered group; return a group that cannot be, or None."""
        inst = self.instance
        covered = np.zeros(len(inst.groups), dtype=bool)
        g = self.group[rs.visited]
        covered[g[g >= 0]] = True
        uncovered = [gi for gi in range(len(inst.groups)) if not covered[gi]]
        while uncovered:
            choice = None
            for gi in uncovered:
                nodes = np.array([v + 1 for v in inst.groups[gi]], dtype=int)
                nodes = nodes[reach[nodes]]
                best = rs.best_insertion(nodes)
                if best is None:
                    return gi
                if choice is None or best[0] < choice[1][0]:  # hardest group first
                    choice = (gi, best)
            gi, (_, node, r, p, delta) = choice
            rs.insert(node, r, p, delta)
            uncovered.remove(gi)
        return None

    def _fill(self, rs: RouteSet, reach: np.ndarray) -> int:
        score = _ratio(self.instance.prizes)
        added = 0
        while True:
            free = np.flatnonzero(reach & ~rs.visited)
            free = free[self.prize[free] > 0]
            best = rs.best_insertion(free, score)
            if best is None:
                return added
            _, node, r, p, delta = best
            rs.insert(node, r, p, delta)
            added += 1

    def repair(self, routes: list[list[int]], reinsert: bool = True) -> list[list[int]]:
        """Feasible routes (solver indices) covering every group; raises RepairFailed."""
        inst = self.instance
        n_groups = len(inst.groups)
        count = np.zeros(max(n_groups, 1), dtype=int)
        for route in routes:
            g = self.group[np.asarray(route, dtype=int)]
            np.add.at(count, g[g >= 0], 1)
        fixed = []
        for route in routes:
            route, removed = self.shrink(route, count)
            self.stats["removed"] += len(removed)
            fixed.append(route)
        reach = np.zeros(inst.n_nodes + 2, dtype=bool)
        reach[1:-1] = inst.reachable()
        rs = self._routeset(fixed)
        missing = self._cover(rs, reach)
        if missing is not None:
            self.stats["stripped"] = True
            stripped = []
            for route in rs.routes:
                seen, keep = set(), []
                for v in route:
                    g = self.group[v]
                    if g >= 0 and g not in seen:
                        seen.add(g)
                        keep.append(v)
                stripped.append(self._polish(keep))
            rs = self._routeset(stripped)
            missing = self._cover(rs, reach)
        if missing is not None:
            self.stats["rebuilt"] = True
            rs = self._routeset([])
            missing = self._cover(rs, reach)
            if missing is not None:
                what = "target" if inst.kind == "sar" else "group"
                raise RepairFailed(f"repair could not fit a viewpoint of {what} {missing} into any route")
        if reinsert:
            self.stats["reinserted"] += self._fill(rs, reach)
            for r in range(len(rs.routes)):
                if len(rs.routes[r]) > 2:
                    rs.routes[r] = self._polish(rs.routes[r])
                    rs.energy[r] = self.energy(rs.routes[r])
            self.stats["reinserted"] += self._fill(rs, reach)
        return [list(r) for r in rs.routes]
