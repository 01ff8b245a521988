"""What every part of one branch-and-price run shares: the problem (:class:`.problem.Problem`),
the clock (:class:`.clock.Clock`), and the run's mutable state: the route master and ng sets,
the incumbent and the statistics.
"""

from __future__ import annotations

import math
import time

from sarcover.formulations.bp.clock import Clock
from sarcover.formulations.bp.constants import TOL
from sarcover.formulations.bp.master import Master
from sarcover.formulations.bp.ng_sets import full_ng, nearest_ng
from sarcover.formulations.bp.options import BPOptions
from sarcover.formulations.bp.problem import Problem
from sarcover.formulations.bp.stats import Stats
from sarcover.formulations.instance import TOPInstance


class Search:
    """Shared state of one run. The parts (column generation, cuts, arc elimination, incumbent
    search, branching) read and update it; only the incumbent search changes the incumbent.
    ``problem`` and ``clock`` are fixed for the run; the rest changes as it goes."""

    def __init__(self, instance: TOPInstance, time_limit: float | None, options: BPOptions):
        self.clock = Clock(time_limit)
        self.problem = p = Problem(instance)
        self.options = options
        self.master = Master(p.V, instance.prizes, instance.groups, p.N,
                             primal_simplex=0 < options.primal_simplex_from <= p.V)
        size = options.ng_size
        self.ng = full_ng(p.V + 2) if size >= p.V else nearest_ng(p.cost, size)
        self.stats = Stats()
        # the incumbent (solver points); without groups the empty plan is one
        self.incumbent_value = 0.0 if not instance.groups else -math.inf
        self.incumbent: list[tuple[int, ...]] | None = [] if not instance.groups else None
        # no plan is worth more than this: a narrow route listing showed it
        # (:meth:`.enumeration.Enumeration.close`); it caps every node's bound
        self.cap = math.inf

    def prunable(self, bound: float) -> bool:
        """No plan better than the incumbent lies under a node of this bound (or above the
        run's cap)."""
        b = self.problem.floor(min(bound, self.cap))
        if self.incumbent is None:
            return b < -TOL  # no plan (prize >= 0) exists below this node
        return b <= self.incumbent_value + TOL

    def need(self) -> float:
        """The value a plan must reach to beat the incumbent: the next lattice point with
        integer prizes, anything above it otherwise."""
        return self.incumbent_value + (self.problem.step if self.problem.integral else 1e-9)

    def lower_cap(self, value: float) -> None:
        """No plan is worth more than ``value`` (the proof is the caller's)."""
        if value < self.cap:
            self.cap = value
            self.stats.cap = value
            self.log(value)

    def log(self, bound: float | None = None) -> None:
        """One point of the history: (seconds since the start, incumbent, bound)."""
        inc = None if self.incumbent is None else self.incumbent_value
        if bound is not None:
            bound = min(bound, self.cap)
        if bound is not None and inc is not None:
            bound = max(bound, inc)  # after arc elimination a bound only covers better plans
        self.stats.history.append((round(time.perf_counter() - self.clock.t0, 4), inc, bound))
