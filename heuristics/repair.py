"""Energy repair: make cluster tours fit the budget, keep every group covered, refill.

Rule (documented in the README): for each route over budget, repeatedly remove the viewpoint
with the greatest energy saving per lost prize, saving = c(prev,v) + c(v,next) − c(prev,next)
(flight plus imaging energy), among the viewpoints whose group keeps another visited viewpoint
(a target's last view is kept while possible); only when every remaining viewpoint is its group's
last may one be removed, which uncovers that group. After each removal the route is re-optimised
by 2-opt. Then:

1. every uncovered group gets its cheapest feasible insertion (hardest group first, as greedy);
   a group that fits nowhere gets room made in one route: views of groups that stay covered
   are dropped there by the rule above until one of its views fits, choosing the route and view
   that lose the least prize (``info["made_room"]`` counts these);
2. if some group still cannot be inserted, every route is stripped to one viewpoint per group it
   covers (the groups' "last views"), 2-opted, and step 1 is retried; if that fails too, the
   routes are rebuilt from empty by step 1 alone (greedy's group phase, ``info["rebuilt"]``);
3. if ``reinsert``: the removed and stripped viewpoints, and any other reachable unvisited
   viewpoint, are inserted by greatest prize per added energy while any fits, then each route
   is 2-opted and the insertion retried once.

If a group is still uncovered the repair fails: the caller returns no plan (a heuristic
never proves infeasibility).
"""

from __future__ import annotations

import numpy as np

from sarcover.formulations.instance import TOPInstance
from sarcover.heuristics.insertion import RouteSet
from sarcover.heuristics.tour import route_length, two_opt


class RepairFailed(Exception):
    """No plan covering every group was found; the message names the group."""


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

    def cover(self, rs: RouteSet, reach: np.ndarray) -> int | None:
        """Insert a view of each uncovered group; return a group that cannot be, or None.

        Greedy's group phase, hardest group first: the group whose cheapest feasible insertion
        is most expensive goes in first, at that place. Insertion costs are kept per route and
        only the route that changed is re-scored each round.
        """
        inst = self.instance
        covered = np.zeros(len(inst.groups), dtype=bool)
        g = self.group[rs.visited]
        covered[g[g >= 0]] = True
        cand = np.array([v + 1 for gi in np.flatnonzero(~covered) for v in inst.groups[gi]], dtype=int)
        cand = cand[reach[cand]] if cand.size else cand
        gid = self.group[cand]
        missing = np.flatnonzero(~covered)
        lost = np.setdiff1d(missing, gid)
        if lost.size:
            return int(lost[0])
        if missing.size == 0:
            return None
        R = len(rs.routes)
        cost = np.full((R, cand.size), np.inf)
        where = np.zeros((R, cand.size), dtype=int)

        def score(r):
            delta = rs.insertion_deltas(r, cand)
            delta = np.where(rs.energy[r] + delta <= rs.limit, delta, np.inf)
            where[r] = np.argmin(delta, axis=1)
            cost[r] = delta[np.arange(cand.size), where[r]]

        for r in range(R):
            score(r)
        alive = np.ones(cand.size, dtype=bool)
        while alive.any():
            best = np.where(alive, cost.min(axis=0), np.inf)  # per candidate, over routes
            group_best = np.full(len(inst.groups), -np.inf)
            np.maximum.at(group_best, gid[alive], -best[alive])  # -(cheapest) per group
            open_groups = np.unique(gid[alive])
            hardest = open_groups[np.argmin(group_best[open_groups])]
            if not np.isfinite(group_best[hardest]):
                return int(hardest)
            mine = np.flatnonzero(alive & (gid == hardest))
            c = mine[np.argmin(best[mine])]
            r = int(np.argmin(cost[:, c]))
            rs.insert(int(cand[c]), r, int(where[r, c]), float(cost[r, c]))
            alive &= gid != hardest
            score(r)
        return None

    def fill(self, rs: RouteSet, reach: np.ndarray) -> int:
        """Insert free reachable viewpoints by greatest prize per added energy while any fits.

        Same rule as greedy's second phase; scores are kept per route and only the route that
        changed is re-scored each round.
        """
        cand = np.flatnonzero(reach & ~rs.visited)
        cand = cand[self.prize[cand] > 0]
        if cand.size == 0:
            return 0
        p = self.prize[cand][:, None]
        R = len(rs.routes)
        value = np.full((R, cand.size), -np.inf)
        where = np.zeros((R, cand.size), dtype=int)
        delta_at = np.zeros((R, cand.size))

        def score(r):
            delta = rs.insertion_deltas(r, cand)
            v = np.where(delta > 1e-12, p / np.maximum(delta, 1e-12), np.inf)
            v = np.where(rs.energy[r] + delta <= rs.limit, v, -np.inf)
            where[r] = np.argmax(v, axis=1)
            rows = np.arange(cand.size)
            value[r] = v[rows, where[r]]
            delta_at[r] = delta[rows, where[r]]

        for r in range(R):
            score(r)
        alive = np.ones(cand.size, dtype=bool)
        added = 0
        while True:
            masked = np.where(alive[None, :], value, -np.inf)
            r, c = np.unravel_index(int(np.argmax(masked)), masked.shape)
            if masked[r, c] == -np.inf:
                return added
            rs.insert(int(cand[c]), int(r), int(where[r, c]), float(delta_at[r, c]))
            alive[c] = False
            added += 1
            score(int(r))

    def _make_room(self, rs: RouteSet, gi: int, reach: np.ndarray) -> bool:
        """Fit a view of uncovered group ``gi`` into one route by dropping views of covered groups.

        For every route and every reachable view v of the group: drop, by the shrink rule
        (greatest saving per prize), views whose group keeps another visited view, until v's
        cheapest insertion fits. The (route, v) losing the least prize is applied. False if no
        route can make room.
        """
        count = np.bincount(self.group[rs.visited & (self.group >= 0)], minlength=len(self.instance.groups))
        nodes = [v + 1 for v in self.instance.groups[gi] if reach[v + 1]]
        best = None
        for r, route in enumerate(rs.routes):
            for v in nodes:
                trial, lost, left = list(route), 0.0, count.copy()
                while True:
                    seq = np.array([0, *trial, self.end])
                    delta = self.C[seq[:-1], v] + self.C[v, seq[1:]] - self.C[seq[:-1], seq[1:]]
                    pos = int(np.argmin(delta))
                    if self.energy(trial) + delta[pos] <= self.limit:
                        if best is None or lost < best[0]:
                            best = (lost, r, trial[:pos] + [v] + trial[pos:])
                        break
                    if not trial:
                        break
                    prev, node, nxt = seq[:-2], seq[1:-1], seq[2:]
                    g = self.group[node]
                    droppable = (g < 0) | (left[np.maximum(g, 0)] > 1)
                    if not droppable.any():
                        break
                    saving = self.C[prev, node] + self.C[node, nxt] - self.C[prev, nxt]
                    p = self.prize[node]
                    score = np.where(p > 0, saving / np.maximum(p, 1e-300), np.inf)
                    k = int(np.argmax(np.where(droppable, score, -np.inf)))
                    lost += float(p[k])
                    if g[k] >= 0:
                        left[g[k]] -= 1
                    trial.pop(k)
        if best is None:
            return False
        _, r, route = best
        rs.visited[rs.routes[r]] = False
        rs.routes[r] = route
        rs.visited[route] = True
        rs.energy[r] = self.energy(route)
        self.stats["made_room"] = self.stats.get("made_room", 0) + 1
        return True

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
        missing = self.cover(rs, reach)
        while missing is not None and self._make_room(rs, missing, reach):
            missing = self.cover(rs, reach)
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
            missing = self.cover(rs, reach)
        if missing is not None:
            self.stats["rebuilt"] = True
            rs = self._routeset([])
            missing = self.cover(rs, reach)
            if missing is not None:
                what = "target" if inst.kind == "sar" else "group"
                raise RepairFailed(f"repair could not fit a viewpoint of {what} {missing} into any route")
        if reinsert:
            self.stats["reinserted"] += self.fill(rs, reach)
            for r in range(len(rs.routes)):
                if len(rs.routes[r]) > 2:
                    rs.routes[r] = self._polish(rs.routes[r])
                    rs.energy[r] = self.energy(rs.routes[r])
            self.stats["reinserted"] += self.fill(rs, reach)
        return [list(r) for r in rs.routes]
