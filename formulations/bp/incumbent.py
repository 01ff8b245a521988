"""Incumbent search: every plan found anywhere goes through :meth:`IncumbentSearch.offer` (the
verifier decides); plans come from dives, from a MILP over the generated routes, from the
caller's ``primal`` heuristic and from integral LP solutions.

The column-generation routes alone are poor material for the MILP; the dives' routes fit
together (they are priced with earlier routes fixed), and so do the caller's heuristic plan and
the labelling's best routes (:mod:`.elimination`). Proves nothing: the bound is the search's.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np
from sarcover.formulations.bp.constants import TOL
from sarcover.formulations.bp.graph import NodeState, node_graph
from sarcover.formulations.plan import Plan
from sarcover.formulations.verify import verify

if TYPE_CHECKING:
    from sarcover.formulations.bp.elimination import Elimination
    from sarcover.formulations.bp.pricer import Pricer
    from sarcover.formulations.bp.search import Search


class IncumbentSearch:
    """Incumbents of one run. ``primal(seconds) -> routes or None`` (node ids): the caller's
    heuristic, run at most ``options.primal_calls`` times (at the root) with up to
    ``primal_limit`` seconds each; ``dive_limit``: seconds for a dive at the root (later dives
    get less)."""

    def __init__(self, search: "Search", pricer: "Pricer", elimination: "Elimination", primal,
                 *, dive_limit: float, primal_limit: float):
        self.search = search
        self.pricer = pricer
        self.elimination = elimination
        self.primal = primal
        self.dive_limit = dive_limit
        self.primal_limit = primal_limit
        self.dived = False  # the root's first dive has run
        self.dive_starts: set[int] = set()  # first route fixed by each dive so far

    def offer(self, routes):
        """Accept a plan (solver points) as incumbent if the verifier agrees and it is better
        (a better incumbent eliminates more arcs). Returns the verifier's report (None for no
        plan or more than N routes)."""
        s = self.search
        if routes is None or len(routes) > s.problem.N:
            return None
        plan = Plan.of([[p - 1 for p in r] for r in routes])
        rep = verify(s.problem.inst, plan)
        if rep.valid and rep.prize > s.incumbent_value + 1e-9:
            s.incumbent_value = rep.prize
            s.incumbent = list(routes)
            s.log()
            self.elimination.eliminate()
        return rep

    def offer_if_integral(self, x, xa) -> bool:
        """Offer the LP solution's routes if it is integral (no artificials); report whether."""
        if xa.max() <= TOL and np.all(np.abs(x - np.round(x)) <= TOL):
            m = self.search.master
            self.offer([m.routes[r] for r in np.flatnonzero(x > 0.5)])
            return True
        return False

    def run_milp(self, limit: float) -> None:
        """The best plan over the generated routes (HiGHS, started from the incumbent), within
        ``limit`` seconds, over the routes that can be part of a better plan. A call that would
        end in the clock's reserve (the last MILP) runs without HiGHS's presolve, which can
        overrun its limit by seconds, so that the run ends at its time limit."""
        s = self.search
        s.stats.milp_calls += 1
        limit = min(limit, max(0.0, s.clock.hard_deadline - time.perf_counter() - 0.1))
        presolve = time.perf_counter() + limit <= s.clock.deadline
        if limit > 0.05:
            t, before = time.perf_counter(), s.incumbent_value
            allowed = self.elimination.milp_columns()
            if allowed is not None:
                s.stats.milp_columns = int(allowed.sum())
                if not allowed.any():
                    return  # no generated route can be part of a better plan
            self.offer(s.master.milp(limit, allowed, start=s.incumbent, presolve=presolve))
            s.stats.milp_s += time.perf_counter() - t
            s.stats.milp_improved += s.incumbent_value > before

    def call_primal(self) -> bool:
        """Run the caller's heuristic (``primal``), unless there is none, no time is left or it
        has had its ``primal_calls`` calls; returns whether it ran. Its plan becomes columns and,
        if the verifier passes it and it is better, the incumbent. Called when the root's floored
        bound is settled and the first dive has not found a plan that proves it, so instances the
        root or its first dive settle (most TOP instances) never pay for it; and again after the
        root's cut rounds and last dive while the proof is still open, up to ``primal_calls``
        calls in all; the first one earlier if the root's bound is not settled by
        ``primal_late_share`` of the limit (a heuristic may return another plan when called
        again: the registered bp's PyVRP then searches with a new seed until its time is up)."""
        s = self.search
        if self.primal is None or s.clock.time_left() <= 0 or s.stats.primal_calls >= s.options.primal_calls:
            return False
        s.stats.primal_calls += 1
        t = time.perf_counter()
        allowance = min(self.primal_limit, 0.5 * s.clock.time_left())
        try:
            routes = self.primal(allowance)
        except Exception as exc:  # noqa: BLE001 - a failing heuristic must not cost the proof search
            s.stats.primal_error = f"{type(exc).__name__}: {exc}"
            routes = None
        s.stats.primal_s = round((s.stats.primal_s or 0.0) + time.perf_counter() - t, 3)
        if not routes:
            return True
        pts = [tuple(int(v) + 1 for v in r) for r in routes if len(r)]
        before = s.incumbent_value
        rep = self.offer(pts)
        if rep is not None and rep.valid:
            s.stats.primal_prize = max(float(rep.prize), s.stats.primal_prize or -np.inf)
        s.stats.primal_improved = bool(s.stats.primal_improved) or s.incumbent_value > before
        s.master.add_routes([r for r in pts if s.problem.energy(r) <= s.problem.budget])
        return True

    def dive(self, limit: float, start: NodeState | None = None, *, fresh: bool = False) -> None:
        """Diving: fix the route of largest LP value (its nodes and arcs forced), re-solve the
        LP with heuristic pricing only, repeat until the LP solution is integral. A fixing that
        leaves the LP infeasible is undone and the next route tried (at most 3 times). Feeds
        incumbents and columns (routes that fit together) to the MILP. The first route fixed is
        one no earlier dive started from, unless ``fresh`` (the LP has new columns, as after the
        primal heuristic). Leaves the master's bounds at the dive's last node: the caller
        applies its own node again."""
        s = self.search
        m = s.master
        m.hide_repeated = True  # plans are made of elementary routes: ng-routes would only mislead
        before = s.incumbent_value
        try:
            self._dive(limit, start, fresh)
        finally:
            m.hide_repeated = False
        s.stats.dives += 1
        s.stats.dive_improved += s.incumbent_value > before

    def _dive(self, limit: float, start: NodeState | None, fresh: bool) -> None:
        s = self.search
        m = s.master
        stop = min(s.clock.deadline, time.perf_counter() + limit)
        state, parent = (start or NodeState()), None
        used: set[int] = set()  # routes fixed or tried: never picked again
        failures = 0
        while time.perf_counter() < stop:
            m.apply(state)
            cost, ret, allowed = node_graph(s, state)
            for _ in range(200):
                value, x, xa, y = m.solve()
                self.offer_if_integral(x, xa)
                if time.perf_counter() >= stop:
                    break
                res = self.pricer.price(cost, ret, m.point_profit(y), allowed, heuristic=True,
                                        y0=float(y[0]), sig=m.cut_duals(y))
                if not m.add_routes(res.routes):
                    break
            if xa.max() > TOL:  # the fixings cannot be completed (as far as heuristic pricing sees)
                failures += 1
                if parent is None or failures > 3:
                    break
                state, parent = parent, None
                continue
            pos = np.flatnonzero(x > TOL)
            if np.all(np.abs(x[pos] - np.round(x[pos])) <= TOL):
                self.offer([m.routes[r] for r in np.flatnonzero(x > 0.5)])
                break
            cand = [r for r in pos if r not in used]
            if not used and not fresh:  # first fixing: not where a previous dive started
                cand = [r for r in cand if r not in self.dive_starts] or cand
            if not cand:
                break
            r = max(cand, key=lambda k: x[k])
            if not used:
                self.dive_starts.add(r)
            used.add(r)
            full = [0, *m.routes[r], s.problem.V + 1]
            parent = state
            state = state.child(forced_nodes=m.routes[r], forced_arcs=list(zip(full, full[1:])))
