"""Column generation at one branch-and-bound node.

Each round solves the restricted master LP and prices:

1. heuristic pricing until it finds no improving route: at the root, from ``route_search_from``
   points on and without cuts, local search from the LP's routes (:mod:`.route_search`) first,
   then the labelling with dominance without remembered sets;
2. exact pricing over ng-routes (a relaxation of elementary routes): its best reduced prize gives
   the certified Lagrangian bound of the round. Improving routes become columns, elementary or
   not: an ng-route that repeats a point enters the master with visit-count coefficients, so it
   is never part of an integer solution but keeps the LP the ng-route relaxation that the pricing
   bounds exactly;
3. targeted exact pricing (below the root): with integer prizes a bound only matters rounded
   down to the prize lattice, so the exact call's threshold is raised to what N routes may add
   without reaching the next lattice point that matters (:meth:`ColumnGeneration.slack`); when
   nothing beats it the node's floored bound is settled and the node is pruned or branched on
   at once, without converging the LP's tail. The root's LP is converged, because converged
   duals make the arc elimination much stronger;
4. dynamic ng sets: when the LP solution uses a route that repeats a point u, u is remembered at
   the points of its cycle (up to ``ng_cap`` points), the routes that stop being ng-routes leave
   the master, and column generation goes on with the stronger relaxation; only within the first
   ``grow_share`` of the time limit, since larger ng sets make pricing slower.

At the root, column generation takes the root's own steps (:class:`RootSteps`, the policy in
:mod:`.root`): the caller's heuristic when the root is slow to settle, the certificate of every
exact bound, the first dive once the floored bound is settled (before the ng sets grow), the
cut rounds last, and, when an exact pricing hits its label cap, their withdrawal or else a
larger cap.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Protocol

import numpy as np
from sarcover.formulations.bp.constants import TOL
from sarcover.formulations.bp.graph import NodeState, node_graph
from sarcover.formulations.bp.ng_sets import add_to_ng

if TYPE_CHECKING:
    from sarcover.formulations.bp.elimination import Elimination
    from sarcover.formulations.bp.pricer import Pricer
    from sarcover.formulations.bp.search import Search


class RootSteps(Protocol):
    """What column generation asks of the root's policy (:class:`.root.Root`), at the root only."""

    def slow_to_settle(self) -> bool:
        """Before an exact pricing: whether a plan was sought because the root is slow to settle
        (the LP is then re-solved with its routes)."""

    def certified(self, y, y0: float, best: float, lagrangian: float, bound: float) -> None:
        """An exact pricing certified ``lagrangian`` from duals ``y``; the root's ``bound``."""

    def label_cap(self) -> bool:
        """An exact pricing hit its label cap: whether column generation can go on (cuts
        withdrawn, or a larger cap)."""

    def settled(self, state: NodeState, bound: float) -> bool:
        """The floored bound is settled: whether plans were sought (the LP is then re-solved)."""

    def add_cuts(self, state: NodeState, x, y, lp_value: float) -> bool:
        """The LP is converged: whether cuts (or the graph) changed it."""


class ColumnGeneration:
    """Solves nodes' LPs for one run (:meth:`solve`); ng sets grow up to ``ng_cap`` points until
    ``grow_until`` (a :func:`time.perf_counter` moment); from ``route_search_from`` points on
    (0: never) a root round without cuts first seeks improving routes by local search
    (:meth:`.pricer.Pricer.route_search`). ``root``: the root's steps (set once
    the root's policy exists)."""

    def __init__(self, search: "Search", pricer: "Pricer", elimination: "Elimination", *,
                 ng_cap: int, grow_until: float, route_search_from: int = 0):
        self.search = search
        self.pricer = pricer
        self.elimination = elimination
        self.ng_cap = ng_cap
        self.grow_until = grow_until
        self.route_search_from = route_search_from
        self.root: RootSteps | None = None
        # (duals, rc*) of the node's last exact pricing: every route's reduced prize under the
        # duals is at most rc* (route enumeration at nodes lists under them)
        self.priced: tuple[np.ndarray, float] | None = None

    def solve(self, state: NodeState, bound: float, targeted: bool = True):
        """Solve one node's LP by column generation, starting from the parent's ``bound``.
        Returns (bound, x, x_art, converged); not converged: out of time, or an exact pricing
        hit its label cap (at the root only once neither withdrawing the last cut round nor a
        larger cap is left, see :meth:`.root.Root.label_cap`). Below the root the exact
        pricing is targeted (it only proves what decides the node's floored bound) unless
        ``targeted`` is False: then the LP converges fully, as route enumeration at the node
        wants (:meth:`.enumeration.Enumeration.close_node`)."""
        s, m, pricer, elim = self.search, self.search.master, self.pricer, self.elimination
        root = self.root if state.depth == 0 else None
        self.priced = None
        version = None
        arcs_decided = bool(state.forbidden_arcs or state.forced_arcs)
        x = xa = None
        while True:
            if version != elim.version:  # first round, or more arcs eliminated since
                version = elim.version
                m.apply(state)
                cost, ret, allowed_base = node_graph(s, state)
                arcs_decided = arcs_decided or version > 0
            t = time.perf_counter()
            value, x, xa, y = m.solve()
            s.stats.lp_s += time.perf_counter() - t
            s.stats.rounds += 1
            if s.clock.time_left() <= 0:
                return bound, x, xa, False
            prof = m.point_profit(y)
            sig = m.cut_duals(y)
            allowed = allowed_base.copy()
            if not arcs_decided:
                # With the triangle inequality a node of reduced prize <= 0 can be skipped.
                allowed &= prof > 1e-12
            y0 = float(y[0])
            if (root is not None and not m.cuts and s.problem.V >= self.route_search_from > 0):
                added = m.add_routes(pricer.route_search(x, y, cost, prof, allowed, y0=y0))
                if added:
                    s.stats.route_search_columns += added
                    root.slow_to_settle()
                    continue  # the labelling only once the local search finds nothing
            res = pricer.heuristic(cost, ret, prof, allowed, y0=y0, sig=sig)
            bound = self._relaxed_bound(y, res, bound, root is not None)
            if s.prunable(bound):
                return bound, x, xa, True  # the relaxed bound proves (or prunes) already
            added = m.add_routes(pricer.columns(res))
            if root is not None and root.slow_to_settle():
                continue  # a plan now, its routes in the LP (checked here too: at hundreds
                # of points the heuristic pricing alone can take the whole limit)
            if added:
                continue
            if s.clock.time_left() <= 0:
                return bound, x, xa, False
            # below the root the exact pricing is targeted; the root's LP is converged
            gain = y0 + (self.slack(m.lagrangian_bound(y, y0)) if root is None and targeted
                         else 0.0)
            res = pricer.exact(cost, ret, prof, allowed, gain, sig)
            s.stats.exact_pricings += 1
            if not res.exact:
                bound = self._relaxed_bound(y, res, bound, root is not None)
            if not res.exact and s.clock.time_left() > 0:
                # the label cap, not the clock: no bound from this call. At the root, withdraw
                # the last cut round or raise the cap and go on; otherwise the node stays
                # unconverged
                s.stats.label_caps += 1
                m.add_routes(pricer.columns(res))
                if root is not None and root.label_cap():
                    continue
                # the LP solution stays the node's, its new columns at 0 (the caller reads
                # x against every column the master holds now)
                return bound, np.concatenate([x, np.zeros(m.n_routes - len(x))]), xa, False
            if res.exact:
                self.priced = (y, max(0.0, res.best - y0))
                lag = m.lagrangian_bound(y, res.best)
                bound = min(bound, lag)
                if root is not None:
                    root.certified(y, y0, res.best, lag, bound)
                if s.prunable(bound):
                    return bound, x, xa, True  # pruned (at the root: proven) before convergence
            if m.add_routes(pricer.columns(res)):
                continue
            if res.best - gain > TOL and res.cycles:
                for cyc in res.cycles:  # cycle u ... u: remember u at every node of the cycle
                    u = cyc[0]
                    for w in cyc[1:-1]:
                        add_to_ng(s.ng, w, u)
                s.stats.ng_growths += 1
                continue
            if not res.exact:
                return bound, x, xa, False
            if root is not None and root.settled(state, bound):
                if s.prunable(bound):
                    return bound, x, xa, True
                continue  # re-solve with the heuristic's and the dive's columns
            if self._grow_ng_from_lp(x):
                m.apply(state)
                continue
            if root is not None and root.add_cuts(state, x, y, value):
                continue
            return bound, x, xa, True

    def _relaxed_bound(self, y, res, bound: float, at_root: bool) -> float:
        """The node's bound after a pricing call that may not have finished (heuristic, label
        cap, clock): the Lagrangian bound of the duals ``y`` with the call's relaxed best path
        (:attr:`.labelling.PricingResult.relaxed`), when lower. This is what certifies a bound
        when exact pricing cannot finish (hundreds of points at K = 6)."""
        if not np.isfinite(res.relaxed):
            return bound
        lag = self.search.master.lagrangian_bound(y, res.relaxed)
        if lag < bound - TOL:
            self.search.stats.relaxed_bounds += 1
            bound = lag
            if at_root:
                self.search.log(bound)
        return bound

    def slack(self, dual_value: float) -> float:
        """Targeted pricing: how much the best route's reduced prize may exceed the vehicle dual
        while dual_value + N·excess stays below the next value that matters: the next lattice
        point above dual_value, or incumbent + step if higher (integer prizes only)."""
        s = self.search
        if not s.problem.integral:
            return 0.0
        target = s.problem.floor(dual_value) + s.problem.step
        if s.incumbent is not None:
            target = max(target, s.incumbent_value + s.problem.step)
        # reported best >= y0 + slack + TOL, so keep N·TOL and the floor's 1e-6 below target
        return max(0.0, (target - dual_value - 2e-6) / s.problem.N - 2 * TOL)

    def _grow_ng_from_lp(self, x) -> bool:
        """Dynamic ng sets: for every repeated route in the LP solution, remember the repeated
        point along its cycle (ng sets capped at ``ng_cap``), exclude the routes that stop being
        ng-routes, and report whether anything changed (the LP is then re-solved)."""
        s = self.search
        m = s.master
        if time.perf_counter() > self.grow_until:
            return False  # growing makes pricing slower: past this point, branching decides
        grown = False
        for r in m.repeated:
            if x[r] <= TOL or r in m.dead:
                continue
            path = m.routes[r]
            last = {}
            for pos, u in enumerate(path):
                if u in last:
                    for w in path[last[u] + 1 : pos]:
                        if not (s.ng[w, u >> 6] >> np.uint64(u & 63)) & np.uint64(1) and \
                                self._ng_size(w) < self.ng_cap:
                            add_to_ng(s.ng, w, u)
                            grown = True
                last[u] = pos
        if grown:
            s.stats.ng_growths += 1
            m.kill_non_ng(s.ng)
        return grown

    def _ng_size(self, w: int) -> int:
        return int(sum(bin(int(word)).count("1") for word in self.search.ng[w]))
