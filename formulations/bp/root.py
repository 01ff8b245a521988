"""The root's policy: what the root node gets beyond column generation.

While its column generation runs (:class:`.colgen.RootSteps`): the caller's heuristic when the
root is slow to settle (past ``primal_late_share`` of the limit with no plan sought since the
start); the certificate of every exact bound (its duals eliminate arcs and MILP columns,
:mod:`.elimination`); once the floored bound is settled, the first dive and, if it leaves the
proof open, the caller's heuristic and a second dive over its columns, before the ng sets grow;
the cut rounds last (:mod:`.cuts`); when an exact pricing hits its label cap, the last cut round
is withdrawn, or with none left the cap grows (:meth:`Root.label_cap`). Once its LP is solved
(:meth:`Root.solve`): the labelling arc bounds (and the root again if they remove arcs), a dive
from the final LP and the caller's heuristic again while the proof stays open. Route
enumeration under the root's certificate (:mod:`.enumeration`) and the MILPs over the generated
routes are run by the tree (:mod:`.tree`).
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING

from sarcover.formulations.bp.graph import NodeState

if TYPE_CHECKING:
    from sarcover.formulations.bp.colgen import ColumnGeneration
    from sarcover.formulations.bp.cuts import CutRounds
    from sarcover.formulations.bp.elimination import Elimination
    from sarcover.formulations.bp.incumbent import IncumbentSearch
    from sarcover.formulations.bp.search import Search


class Root:
    """The root's steps for one run; :meth:`solve` solves the root."""

    def __init__(self, search: "Search", colgen: "ColumnGeneration", elimination: "Elimination",
                 incumbents: "IncumbentSearch", cuts: "CutRounds"):
        self.search = search
        self.colgen = colgen
        self.elimination = elimination
        self.incumbents = incumbents
        self.cuts = cuts

    # -- the steps column generation takes at the root (:class:`.colgen.RootSteps`) -------------
    def slow_to_settle(self) -> bool:
        """The caller's heuristic, once, if the root's bound is not settled by
        ``primal_late_share`` of the limit and no plan has been sought since the start (at scale
        the call before column generation does not count: for the registered bp it is PyVRP's
        short search, the late one searches for its whole allowance); whether it ran."""
        s = self.search
        first = 1 if s.problem.V >= s.options.primal_first_from else 0
        return (s.stats.primal_calls <= first and not self.incumbents.dived
                and time.perf_counter() > s.clock.until(s.options.primal_late_share)
                and self.incumbents.call_primal())

    def certified(self, y, y0: float, best: float, lagrangian: float, bound: float) -> None:
        """Duals that certify the root bound: they eliminate arcs and MILP columns."""
        self.elimination.root_duals(y, y0, best, lagrangian)
        self.search.log(bound)

    def label_cap(self) -> bool:
        """An exact pricing hit the label cap: withdraw the last cut round (its cuts make the
        labels dominate less), or with none left, let the exact calls make twice as many labels
        (:meth:`.pricer.Pricer.raise_exact_cap`): branching on an unconverged root splits off
        children whose pricing is as large, and with an integral LP leaves nothing to branch on
        (the run would end before its limit). Whether column generation goes on."""
        return self.cuts.withdraw() or self.colgen.pricer.raise_exact_cap()

    def settled(self, state: NodeState, bound: float) -> bool:
        """The root's floored bound is settled: find a plan before growing ng sets (which only
        pays when the incumbent is below the floored bound), unless the first dive has run or
        no time is left; whether it ran."""
        if self.incumbents.dived or self.search.clock.time_left() <= 0:
            return False
        self._first_dive(state, bound)
        return True

    def add_cuts(self, state: NodeState, x, y, lp_value: float) -> bool:
        """A cut round on the converged root LP (:meth:`.cuts.CutRounds.add`)."""
        return self.cuts.add(state, x, y, lp_value)

    # -- the root ---------------------------------------------------------------------------
    def solve(self, state: NodeState, bound: float):
        """At scale (``primal_first_from`` points on) the caller's heuristic first; the root's
        column generation, then, once its LP is solved: tighter arc bounds by
        labelling (and the root again on the smaller graph if they remove arcs: its bound may
        now prove the plan) and a dive from the final root LP (the first dive ran before the ng
        sets grew), then the caller's heuristic once more if the proof is still open. Returns
        what :meth:`.colgen.ColumnGeneration.solve` does."""
        s, m, elim = self.search, self.search.master, self.elimination
        if s.problem.V >= s.options.primal_first_from:
            self.incumbents.call_primal()  # at scale: a good plan and its routes first
        bound, x, xa, converged = self.colgen.solve(state, bound)
        if converged and not s.prunable(bound):
            version = elim.version
            elim.eliminate(labels=True)
            if elim.version != version and s.clock.time_left() > 0:
                bound, x, xa, converged = self.colgen.solve(state, bound)
            elif len(x) != m.n_routes:
                # the route pool joined after the LP was solved (and no time is left to
                # re-solve the root): the LP solution over all of the master's columns
                m.apply(state)
                _, x, xa, _ = m.solve()
        s.stats.root_bound = bound if math.isfinite(bound) else None
        s.stats.root_s = time.perf_counter() - s.clock.t0
        if converged and not s.prunable(bound) and s.clock.time_left() > 0:
            inc = self.incumbents
            inc.dived = True
            inc.dive(min(inc.dive_limit, 0.5 * s.clock.time_left()))
            # the heuristic again, now that the cut rounds are done: each call is another draw
            while not s.prunable(bound) and inc.call_primal():
                pass
            m.apply(state)  # back to the root, with the dive's (and heuristic's) columns
            _, x, xa, _ = m.solve()
        return bound, x, xa, converged

    def _first_dive(self, state: NodeState, bound: float) -> None:
        """The root's first dive; if it leaves the proof open, the caller's heuristic, and a
        second dive over its columns. Leaves the master at the root node."""
        s, inc = self.search, self.incumbents
        inc.dived = True
        inc.dive(min(inc.dive_limit, 0.5 * s.clock.time_left()))
        if not s.prunable(bound) and inc.call_primal():
            if not s.prunable(bound):  # dive again, now with the heuristic's columns
                s.master.apply(state)  # (its LP differs: any start route, even the first's)
                inc.dive(min(inc.dive_limit, 0.5 * s.clock.time_left()), fresh=True)
        s.master.apply(state)
