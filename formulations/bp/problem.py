"""The problem one branch-and-price run solves, in solver form: fixed for the run.

Solver points: 0 is the start, node id v is point v + 1, V + 1 is the end.
"""

from __future__ import annotations

import math

import numpy as np

from sarcover.formulations.instance import TOPInstance


class Problem:
    """The instance in solver points: arc costs, the budget (with a hair of slack for rounding),
    the points a route can reach, and the prize lattice that the pruning works on."""

    def __init__(self, instance: TOPInstance):
        self.inst = instance
        self.V = instance.n_nodes
        self.N = instance.n_vehicles
        self.cost = instance.cost_matrix()
        self.budget = instance.budget * (1.0 + 1e-9)
        self.integral = bool(np.all(instance.prizes == np.round(instance.prizes)))
        # every plan's prize is a multiple of the prizes' gcd (1 for SAR, 10 for TOP set 3)
        step = math.gcd(*(int(p) for p in instance.prizes)) if self.integral else 0
        self.step = float(step) if step > 0 else 1.0
        trip = self.cost[0, 1 : self.V + 1] + self.cost[1 : self.V + 1, self.V + 1]
        self.reachable = np.zeros(self.V + 2, dtype=bool)
        self.reachable[1 : self.V + 1] = trip <= self.budget

    def energy(self, pts) -> float:
        """Energy of the route start -> ``pts`` -> end."""
        full = [0, *pts, self.V + 1]
        return float(sum(self.cost[a, b] for a, b in zip(full, full[1:])))

    def floor(self, bound: float) -> float:
        """The bound rounded down to the prize lattice (multiples of the prizes' gcd)."""
        if not self.integral:
            return bound
        return self.step * math.floor((bound + 1e-6) / self.step)
