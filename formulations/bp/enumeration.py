"""Route enumeration once the root gap is small, and the set-packing MILP over the enumerated
routes that closes it (Baldacci, Christofides & Mingozzi 2008; Pecin et al. 2017).

Under the duals y that certified the root bound (:class:`.elimination.Certificate`), a plan
better than the incumbent only uses elementary routes of reduced prize >= the certificate's floor
(:meth:`.elimination.Elimination.rc_floor`). When few routes reach it, all of them can be listed
(:func:`.enumeration_kernel.enumerate_routes`, on the graph the arc elimination leaves). Each
visited set is one column of the master (its rows only see the set), so one route per set is
enough.

The LP over them (:mod:`.enumerated_lp`: full-memory cuts, reduced-cost filter), then the MILP
over the routes it leaves (vehicles <= N, each point at most once, each group covered) with the
row "prize >= incumbent + step" decide the run: a solution is an optimal plan (every better plan
is among its columns), an LP below that value or an infeasible MILP proves the incumbent
optimal. Both only hold when the listing and the MILP finished; a cap or a time limit leaves the
run as it was.

The same holds below the root under a node's own duals, on the node's graph
(:meth:`Enumeration.close_node`): the LP falls by a few tenths per branching, so a node's window
gets narrow enough to list long before its floored bound reaches the incumbent, and the listing
closes the node (its plans are among the listed routes, and they meet the node's rows: a forced
point's row is ``= 1`` in the LP and the MILP over them).
"""

from __future__ import annotations

import logging
import math
import time
from typing import TYPE_CHECKING

import numpy as np
from sarcover.formulations.bp.audit import audit_listing
from sarcover.formulations.bp.enumerated_lp import EnumeratedLP
from sarcover.formulations.bp.enumeration_kernel import Enumerated, enumerate_routes
from sarcover.formulations.bp.graph import NodeState, node_graph
from sarcover.formulations.bp.master import route_floor

if TYPE_CHECKING:
    from sarcover.formulations.bp.elimination import Elimination
    from sarcover.formulations.bp.incumbent import IncumbentSearch
    from sarcover.formulations.bp.search import Search

log = logging.getLogger(__name__)


class Enumeration:
    """Closing the root gap by enumeration: :meth:`close` lists the routes that a plan better
    than the incumbent may use under the root certificate, tightens the LP over them
    (:class:`.enumerated_lp.EnumeratedLP`: full-memory cuts, reduced-cost filter) and solves the
    MILP over the routes left. It is tried once the root LP is solved, and again whenever the
    certificate or the incumbent has changed since the last try.

    The window (certificate bound - incumbent - one step) decides how: up to ``gap`` steps the
    listing is complete and its outcome a proof (no better plan, or the MILP's plan is
    optimal); above it, only the routes within ``primal_window`` steps of the best are listed
    (the threshold raised by the difference), and the MILP over them can find a better plan
    and cap the bound (:meth:`_cap`), a proof only where that cap meets the incumbent. The
    plan one step above the incumbent has a total slack of the window over its routes, so most
    of its routes sit well inside a narrow window. A narrow try that finds no plan is followed
    at once by a wider one (with the same certificate and incumbent) if its labels and
    routes, times their growth at the narrow listing's rim (over its last ``WIDEN`` steps, or
    all of it if narrower, extrapolated geometrically: :meth:`Enumerated.growth`), stay within
    the caps; a try as wide as the window is complete. The first widening adds ``WIDEN`` steps
    and each next one twice the last, or less (halved down to ``WIDEN``) where the caps call
    for it: at a window of ten steps (TOP's 100-point files) the listings grow slowly, and
    widening by ``WIDEN`` alone took one try per tree node and never reached the window.
    ``primal_window`` 0 turns the narrow tries off. ``limit``: seconds per call of
    :meth:`close` (its tries together);
    ``max_labels``, ``max_routes``: the caps beyond which a listing gives up;
    ``milp_routes``: cut rounds stop once this few routes are left; ``cuts_per_round``:
    triples per round; ``audit``: check a proof by a complete listing apart from the kernels
    (:mod:`.audit`)."""

    WIDEN = 0.1  # the first widening of a narrow window that listed no better plan (steps)
    STALL = 0.002  # cut rounds stop when a round lowers the LP by less than this many steps
    # the MILP is only tried over at most this many routes: over 60 827 (M = 20, K = 4 seed
    # 111) HiGHS ran 150 s past a 100 s time limit, and every proof so far came from < 12 000
    MILP_MAX = 20_000
    NODE_SHARE = 0.1  # a try at a node below the root: this share of ``limit`` ...
    NODE_LABELS = 0.25  # ... and this share of ``max_labels``

    def __init__(self, search: "Search", elimination: "Elimination",
                 incumbents: "IncumbentSearch", *, limit: float, gap: float, max_labels: int,
                 max_routes: int, primal_window: float = 0.0, milp_routes: int = 5000,
                 cuts_per_round: int = 50, audit: bool = False):
        self.search = search
        self.elimination = elimination
        self.incumbents = incumbents
        self.limit = limit
        self.gap = gap
        self.primal_window = primal_window
        self.max_labels = max_labels
        self.max_routes = max_routes
        self.milp_routes = milp_routes
        self.cuts_per_round = cuts_per_round
        self.audit = audit
        self._tried = None  # (certificate, incumbent value) of the last try
        self._wider = None  # the next narrow window to try with them (None: nothing left)
        self._step = self.WIDEN  # steps the narrow window widens by after its next try
        self._node_window = np.inf  # node tries only below this window (one at it was capped)

    def window(self) -> float | None:
        """Certificate bound - incumbent - one step, in prize steps: the slack a plan one step
        better than the incumbent leaves its routes. None when there is nothing to try: no
        certificate or incumbent, no time, no better plan possible, or every try with this
        certificate and incumbent done."""
        s, elim = self.search, self.elimination
        if elim.rc_floor() is None or s.clock.time_left() <= 0:
            return None
        if self._tried == (elim.cert, s.incumbent_value) and self._wider is None:
            return None
        window = (elim.cert.bound - s.incumbent_value - s.problem.step) / s.problem.step
        if window < 0 or (window > self.gap and self.primal_window <= 0):
            return None
        return window

    def close(self) -> bool:
        """Tries under the current certificate and incumbent, a narrow one that listed no
        better plan widened at once (all within ``limit`` seconds); True when one proved the
        incumbent (possibly a new one, the MILP's) optimal. The tries are cheap next to a tree
        node on TOP's two-vehicle files (seconds against a minute), where one try per node
        reached the window's width only after the run's limit."""
        until = min(time.perf_counter() + self.limit, self.search.clock.deadline)
        while True:
            proved = self._try(until)
            if proved or self._wider is None or time.perf_counter() >= until:
                return proved

    def _try(self, until: float) -> bool:
        """One try (deadline ``until`` at the latest); whether it proved the incumbent optimal."""
        s, elim = self.search, self.elimination
        window = self.window()
        if window is None:
            return False
        cert = elim.cert
        if self._tried != (cert, s.incumbent_value):
            width, self._step = self.primal_window, self.WIDEN
        else:
            width = self._wider
        complete = window <= max(self.gap, width)
        self._tried, self._wider = (cert, s.incumbent_value), None
        floor = elim.rc_floor()
        # the least a plan may be worth to have all its routes listed
        reach = s.need() + (0.0 if complete else (window - width) * s.problem.step)
        if not complete:  # only the routes within ``width`` steps of the best
            floor += (window - width) * s.problem.step
        outcome, res = self._decide(cert.duals, floor, NodeState(), until, self.max_labels,
                                    self._counted(width) * s.problem.step)
        s.stats.enum_complete += complete
        log.debug("root listing: window %.3f, width %s, %d labels, %s routes: %s", window,
                  "all" if complete else f"{width:.2f}", res.n_labels,
                  None if res.paths is None else len(res.paths), outcome)
        growth = self._growth(width, res, self.WIDEN)[0] if res.paths is not None else np.inf
        s.stats.enum_growth = round(growth, 3) if np.isfinite(growth) else None
        if outcome is None:
            return False
        if not complete:
            self._cap(reach)
            if outcome == "infeasible":  # no better plan among the listed routes
                self._widen(width, res)
            return s.incumbent_value >= s.cap - 1e-6
        if outcome == "infeasible" and self.audit:
            self._audit(res, cert, floor)
        return outcome in ("infeasible", "optimal")

    def _cap(self, reach: float) -> None:
        """After a narrow try that decided (no plan better than the incumbent among its
        routes, or the best such plan, now the incumbent): the listing held every route of the
        plans worth at least ``reach`` (its floor is that of such a plan), so none of them beats
        the incumbent, and no plan is worth more than the incumbent or the lattice point below
        ``reach``, whichever is higher (:meth:`.search.Search.lower_cap`). A cap at the
        incumbent proves it; above, it lowers the reported bound. At windows of several steps
        (TOP's two-vehicle files) a narrow try that listed no better plan showed the bound one
        or more steps too high, and nothing used that."""
        s, step = self.search, self.search.problem.step
        if s.problem.integral:  # the lowest lattice point at or above reach (1e-6 to spare)
            below = step * math.ceil((reach - 1e-7) / step) - step
        else:
            below = reach
        s.lower_cap(max(s.incumbent_value, below))

    def _audit(self, res: "Enumerated", cert, floor: float) -> None:
        """Check the proof just made by a complete root listing apart from the kernels that made
        it (:func:`.audit.audit_listing`) and report the outcome in the run's stats."""
        s, m = self.search, self.search.master
        y = cert.duals
        sig = self._cut_duals(y)
        prizes = np.zeros(s.problem.V + 2)
        prizes[1 : s.problem.V + 1] = m.prizes
        need = s.need()
        # the listing's graph: an arc eliminated under an earlier certificate is no arc of a
        # plan better than the incumbent, even where a route through it clears this threshold
        cost, _, _ = node_graph(s, NodeState())
        found = audit_listing(res.paths, cost, s.problem.budget, m.point_profit(y),
                              y[0] + floor, (m.cut_members, m.cut_memory, sig), prizes=prizes,
                              vehicles=s.problem.N, need=need,
                              floor=need - cert.dual_term + s.problem.N * y[0],
                              reduced=res.values)
        s.stats.audit = found.summary()
        log.info("audit of the root listing's proof: %s", s.stats.audit)

    def node_window(self, dual_term: float) -> float | None:
        """The window of a node below the root whose LP value is ``dual_term`` (steps above
        incumbent + step), if a listing there may be tried: at most ``gap``, and after a
        listing hit its cap, narrower than that one."""
        s = self.search
        if s.incumbent is None or s.clock.time_left() <= 0:
            return None
        window = (dual_term - s.need()) / s.problem.step
        return window if window <= min(self.gap, self._node_window) else None

    def close_node(self, state: NodeState, y: np.ndarray, dual_term: float,
                   rc_star: float) -> bool:
        """A node below the root whose exact pricing under duals ``y`` (dual term
        ``dual_term``) bounded every route's reduced prize by ``rc_star``: True when the
        complete listing on the node's graph of the routes a plan better than the incumbent
        may use (reduced prize >= incumbent + step - dual_term - (N - 1)·rc_star) holds no
        such plan (its MILP may have raised the incumbent on the way)."""
        s = self.search
        window = self.node_window(dual_term)
        if window is None:
            return False
        floor = route_floor(s.need(), dual_term, rc_star, s.problem.N)
        deadline = min(s.clock.deadline, time.perf_counter() + self.limit * self.NODE_SHARE)
        s.stats.node_enum_tries += 1
        labels = int(self.max_labels * self.NODE_LABELS)
        outcome, res = self._decide(y, floor, state, deadline, labels, 0.0)
        if res.paths is None:  # capped: only narrower windows from now on
            self._node_window = window - 1e-9
        closed = outcome in ("infeasible", "optimal")
        s.stats.node_enum_closed += closed
        log.debug("node listing: window %.3f, rc* %.4f, %d labels, %s routes: %s", window, rc_star,
                  res.n_labels, None if res.paths is None else len(res.paths), outcome)
        return closed

    def _decide(self, y: np.ndarray, floor: float, state: NodeState, deadline: float,
                max_labels: int, margin: float):
        """List the routes of reduced prize >= ``floor`` under duals ``y`` on ``state``'s graph,
        tighten the LP over them and solve the MILP over the routes left for a plan worth
        incumbent + step. Returns (outcome, listing): outcome "infeasible" (no such plan among
        the listed routes), "optimal" (the best such plan, now the incumbent), or None
        (capped, out of time, too many routes for the MILP)."""
        s, m, st = self.search, self.search.master, self.search.stats
        t = time.perf_counter()
        cost, _, allowed = node_graph(s, state)
        sig = self._cut_duals(y)
        st.enum_tries += 1
        try:
            res = enumerate_routes(cost, m.point_profit(y), allowed, s.problem.budget, y[0] + floor,
                                   ng=s.ng, cut_members=m.cut_members, cut_memory=m.cut_memory,
                                   cut_duals=sig, max_labels=max_labels,
                                   max_routes=self.max_routes, deadline=deadline, margin=margin)
        except MemoryError:  # a process memory limit below what the label cap allows
            st.enum_memory += 1
            return None, Enumerated(None, 0)
        finally:
            st.enum_s += time.perf_counter() - t
        st.enum_labels = res.n_labels
        st.enum_routes = None if res.paths is None else len(res.paths)
        if res.paths is None:
            return None, res
        if len(res.paths) == 0:  # no route a better plan could use
            st.enum_status = "infeasible"
            return "infeasible", res
        need = s.need()
        t = time.perf_counter()
        try:
            lp = EnumeratedLP(m, res.paths, cuts=zip(m.cuts, m.memories),
                              rows=m.node_rows(state))
            none_listed = self._tighten(lp, need, y, deadline)
        except MemoryError:
            st.enum_memory += 1
            return None, res
        finally:
            st.enum_lp_s += time.perf_counter() - t
        st.enum_left = len(lp)
        if none_listed:  # no plan worth need among the listed routes
            st.enum_status = "infeasible"
            return "infeasible", res
        if time.perf_counter() >= deadline or len(lp) > self.MILP_MAX:
            return None, res
        t = time.perf_counter()
        status, plan = lp.milp(need, deadline - t)
        st.enum_milp_s += time.perf_counter() - t
        st.enum_status = status
        if plan is not None:
            before = s.incumbent_value
            m.add_routes(plan)  # columns for the tree's LPs and dives too
            self.incumbents.offer(plan)
            st.enum_improved += s.incumbent_value > before
        if status == "optimal":
            value = (np.inf if plan is None
                     else float(np.sum([m.prizes[np.asarray(r) - 1].sum() for r in plan])))
            if s.incumbent_value < value - 1e-6:
                return None, res
        return (status if status in ("infeasible", "optimal") else None), res

    def _cut_duals(self, y: np.ndarray) -> np.ndarray:
        """The master's current cuts' duals in ``y`` (:meth:`.master.Master.cut_duals`),
        0 for a cut added after ``y`` was solved (a certificate from before it)."""
        m = self.search.master
        sig = np.zeros(len(m.cuts))
        cut = m.cut_duals(y)[: len(m.cuts)]
        sig[: cut.size] = cut
        return sig

    def _widen(self, width: float, res: "Enumerated") -> None:
        """After a narrow try that listed no better plan: the next, ``_step`` steps wider (and
        the step after it twice that), or half, a quarter, ... of it down to ``WIDEN``: the
        widest whose labels and routes would stay within the caps, were they to grow as at the
        narrow listing's rim (:meth:`_growth`)."""
        step = self._step
        while step >= self.WIDEN - 1e-9:
            labels, routes = self._growth(width, res, step)
            if (res.n_labels * labels <= self.max_labels
                    and len(res.paths) * routes <= self.max_routes):
                self._wider, self._step = width + step, 2 * step
                return
            step /= 2

    def _counted(self, width: float) -> float:
        """The steps at the rim of a ``width``-wide listing over which it counts its growth."""
        return min(self.WIDEN, width) if width > 0 else self.WIDEN

    def _growth(self, width: float, res: "Enumerated", step: float) -> tuple[float, float]:
        """Labels and routes: how many times more a listing ``step`` steps wider than ``res``
        (``width`` steps wide) would make, growing geometrically as over its rim."""
        power = step / self._counted(width)
        return tuple(g ** power if g > 1 else 1.0 for g in res.growth())

    def _tighten(self, lp: EnumeratedLP, need: float, y: np.ndarray, deadline: float) -> bool:
        """Rounds of full-memory triples on the LP over the listed routes, each followed by the
        reduced-cost filter, until the LP shows that no plan of listed routes is worth ``need``
        (True), few enough routes are left for the MILP (``milp_routes``), no cut is violated,
        a round lowers the LP by less than ``STALL`` steps, or the deadline. ``y``: the root
        certificate's duals, whose best routes start the LP."""
        s, st = self.search, self.search.stats
        last = np.inf
        while True:
            out = lp.solve(y, deadline)
            if out is None:
                return False
            st.enum_lp_bound = bound = out.bound(s.problem.N)
            if bound < need - 1e-6:
                return True
            new = lp.separate(out.x, self.cuts_per_round)  # before the filter renumbers routes
            lp.keep(out.rc >= out.floor(need, s.problem.N))
            if (len(lp) <= self.milp_routes or not new or time.perf_counter() >= deadline
                    or last - bound < self.STALL * s.problem.step):
                return False
            last = bound
            st.enum_cuts += lp.add_cuts([(S, None) for S in new])
