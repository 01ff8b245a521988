"""Cheapest insertion on the TOP form, vectorised over nodes and positions with numpy.

Routes are kept in solver indices (0 = start, 1..V = nodes, V+1 = end) inside this module and
converted to node ids (0..V-1) at the edge.
"""

from __future__ import annotations

import numpy as np

from sarcover.formulations.instance import TOPInstance


class RouteSet:
    """Mutable routes with their energies, supporting feasible cheapest insertion."""

    def __init__(self, instance: TOPInstance, cost: np.ndarray | None = None):
        self.instance = instance
        self.cost = instance.cost_matrix() if cost is None else cost
        self.end = instance.n_nodes + 1
        self.routes: list[list[int]] = [[] for _ in range(instance.n_vehicles)]
        self.energy = np.zeros(instance.n_vehicles)
        self.visited = np.zeros(instance.n_nodes + 2, dtype=bool)
        self.visited[[0, self.end]] = True
        self.limit = instance.budget * (1.0 + 1e-9)

    def insertion_deltas(self, r: int, candidates: np.ndarray) -> np.ndarray:
        """(len(candidates), len(route)+1) added energy of inserting each candidate at each position."""
        route = self.routes[r]
        seq = np.array([0, *route, self.end])
        a, b = seq[:-1], seq[1:]
        base = self.cost[a, b] if route else np.zeros(1)
        cand = np.asarray(candidates)
        return self.cost[a[None, :], cand[:, None]] + self.cost[cand[:, None], b[None, :]] - base[None, :]

    def best_insertion(self, candidates: np.ndarray, score=None):
        """Best feasible (score, node, route, position) over candidates; None if none fits.

        ``score(delta, nodes)`` maps added energies to a value to maximise; default -delta
        (cheapest insertion).
        """
        best = None
        candidates = np.asarray(candidates)
        if candidates.size == 0:
            return None
        for r in range(len(self.routes)):
            delta = self.insertion_deltas(r, candidates)
            feasible = self.energy[r] + delta <= self.limit
            if not feasible.any():
                continue
            value = -delta if score is None else score(delta, candidates)
            value = np.where(feasible, value, -np.inf)
            flat = int(np.argmax(value))
            i, p = divmod(flat, value.shape[1])
            if best is None or value[i, p] > best[0]:
                best = (float(value[i, p]), int(candidates[i]), r, p, float(delta[i, p]))
        return best

    def insert(self, node: int, r: int, pos: int, delta: float) -> None:
        self.routes[r].insert(pos, node)
        self.energy[r] += delta
        self.visited[node] = True

    def node_routes(self) -> list[list[int]]:
        """Routes as node ids 0..V-1."""
        return [[v - 1 for v in route] for route in self.routes]
