"""What every part of one branch-and-price run shares: the problem in solver form, the clock,
the route master and ng sets, the incumbent, the statistics, and the prize lattice that the
pruning works on.

Solver points: 0 is the start, node id v is point v + 1, V + 1 is the end.
"""

from __future__ import annotations

import math
import time

import numpy as np

from sarcover.formulations.bp.master import Master
from sarcover.formulations.bp.options import BPOptions
from sarcover.formulations.bp.pricing import full_ng, nearest_ng
from sarcover.formulations.bp.stats import Stats
from sarcover.formulations.instance import TOPInstance

TOL = 1e-6


class Search:
    """Shared state of one run. The parts (column generation, cuts, arc elimination, incumbent
    search, branching) read and update it; only the incumbent search changes the incumbent."""

    def __init__(self, instance: TOPInstance, time_limit: float | None, options: BPOptions):
        self.t0 = time.perf_counter()
        self.inst = instance
        self.options = options
        # the clock: ``deadline`` keeps a reserve for a last MILP over the generated routes
        self.limit = float(time_limit) if time_limit is not None else math.inf
        self.hard_deadline = self.t0 + self.limit
        self.reserve = min(5.0, 0.1 * self.limit)
        self.deadline = self.hard_deadline - self.reserve
        # the problem in solver points
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
        self.master = Master(self.V, instance.prizes, instance.groups, self.N)
        n = self.V + 2
        size = options.ng_size
        self.ng = full_ng(n) if size >= self.V else nearest_ng(self.cost, size)
        self.stats = Stats()
        # the incumbent (solver points); without groups the empty plan is one
        self.incumbent_value = 0.0 if not instance.groups else -math.inf
        self.incumbent: list[tuple[int, ...]] | None = [] if not instance.groups else None

    def time_left(self) -> float:
        return self.deadline - time.perf_counter()

    def until(self, share: float) -> float:
        """The moment ``share`` of the time limit is used up (never without a limit)."""
        return self.t0 + (share * self.limit if math.isfinite(self.limit) else math.inf)

    def energy(self, pts) -> float:
        """Energy of the route start -> ``pts`` -> end."""
        full = [0, *pts, self.V + 1]
        return float(sum(self.cost[a, b] for a, b in zip(full, full[1:])))

    def floor(self, bound: float) -> float:
        """The bound rounded down to the prize lattice (multiples of the prizes' gcd)."""
        if not self.integral:
            return bound
        return self.step * math.floor((bound + 1e-6) / self.step)

    def prunable(self, bound: float) -> bool:
        """No plan better than the incumbent lies under a node of this bound."""
        b = self.floor(bound)
        if self.incumbent is None:
            return b < -TOL  # no plan (prize >= 0) exists below this node
        return b <= self.incumbent_value + TOL

    def log(self, bound: float | None = None) -> None:
        """One point of the history: (seconds since the start, incumbent, bound)."""
        inc = None if self.incumbent is None else self.incumbent_value
        if bound is not None and inc is not None:
            bound = max(bound, inc)  # after arc elimination a bound only covers better plans
        self.stats.history.append((round(time.perf_counter() - self.t0, 4), inc, bound))
