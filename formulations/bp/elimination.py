"""Reduced-cost elimination under the root's certificate: arcs that no plan better than the
incumbent can use leave the pricing graph and every node's LP, and routes that cannot be part of
such a plan leave the MILP over the generated routes.

Under the duals y that certified the root bound, a plan of elementary routes (at most N)
containing route k is worth at most dual_term(y) + rc_k + (N-1)·rc*, where rc* bounds every
route's reduced prize (the exact pricing's value). So a plan better than the incumbent only uses
routes of reduced prize >= incumbent + step - dual_term - (N-1)·rc*, and only arcs through which
some route reaches that. Node bounds then only cover plans better than the incumbent: enough for
pruning, and the reported bound is never below the incumbent.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from sarcover.formulations.bp.arc_bounds import arc_bounds, label_arc_bounds
from sarcover.formulations.bp.graph import NodeState, node_graph
from sarcover.formulations.bp.master import route_floor

if TYPE_CHECKING:
    from sarcover.formulations.bp.search import Search


class Certificate(NamedTuple):
    """Duals that certified the root bound: the duals, their dual term, the bound on every
    route's reduced prize (rc*, at least 0) and the Lagrangian bound they give."""

    duals: np.ndarray
    dual_term: float
    rc_star: float
    bound: float


class Elimination:
    """The root certificate and what it eliminates. ``version`` is bumped whenever more arcs are
    eliminated (column generation then rebuilds its graph). ``elim_limit``: seconds for the
    labelling arc bounds; ``pool_routes``: routes of that labelling that join the master."""

    def __init__(self, search: "Search", *, elim_limit: float, pool_routes: int):
        self.search = search
        self.elim_limit = elim_limit
        self.pool_routes = pool_routes
        self.cert: Certificate | None = None
        self.version = 0
        self._arc_cert = None  # (the certificate the arc bounds belong to, arc bounds, labelled?)

    def root_duals(self, y: np.ndarray, y0: float, best: float, bound: float) -> None:
        """An exact pricing at the root gave the Lagrangian ``bound`` from duals ``y`` (vehicle
        dual ``y0``, best reduced prize ``best``): keep them if they certify a tighter bound,
        and eliminate under them."""
        if not (self.cert is None or bound < self.cert.bound):
            return
        m = self.search.master
        self.cert = Certificate(y.copy(), m.lagrangian_bound(y, y0), max(0.0, best - y0), bound)
        self.eliminate()

    def forget(self) -> None:
        """The certificate's duals refer to rows that are gone (purged cuts)."""
        self.cert = None

    def rc_floor(self) -> float | None:
        """The reduced prize a route needs, under the certificate's duals, to be part of a plan
        better than the incumbent. None: no certificate or no incumbent yet."""
        s = self.search
        if self.cert is None or s.incumbent is None:
            return None
        return route_floor(s.need(), self.cert.dual_term, self.cert.rc_star, s.problem.N)

    def milp_columns(self):
        """(n_routes,) bool: the routes that can be part of a plan better than the incumbent.
        None: no filter."""
        floor = self.rc_floor()
        if floor is None:
            return None
        return self.search.master.reduced_costs(self.cert.duals) >= floor

    def eliminate(self, labels: bool = False) -> None:
        """Eliminate every arc that each route through it leaves below :meth:`rc_floor`: it
        leaves the pricing graph and the LP of every node (and every later plan search) for
        good. Re-checked when the incumbent improves or the root's certificate gets tighter.

        The arc bounds are computed once per certificate: :func:`.arc_bounds.arc_bounds` (a
        2-cycle-free DP over energy units, milliseconds) always; with ``labels`` (once the root
        is solved) also :func:`.arc_bounds.label_arc_bounds` on the arcs the DP leaves (exact
        ng-labelling both ways, about as costly as two exact pricing calls, much tighter). The
        labelling bound only covers the paths above its threshold, so it stays valid as the
        incumbent, and with it the floor, rises. Its forward search also yields the
        ``pool_routes`` best elementary routes that a better plan may use; they join the master
        as columns, so that the MILP over the generated routes can combine them."""
        floor = self.rc_floor()
        if floor is None:
            return
        s = self.search
        cached = self._arc_cert is not None and self._arc_cert[0] is self.cert
        if not cached or (labels and not self._arc_cert[2]):
            t = time.perf_counter()
            y = self.cert.duals
            cost, _, allowed = node_graph(s, NodeState())
            prof = s.master.point_profit(y)
            through = self._arc_cert[1] if cached else arc_bounds(cost, prof, allowed, s.problem.budget)
            if labels:
                cost[through - y[0] < floor] = np.inf
                exact = label_arc_bounds(cost, prof, allowed, s.problem.budget, s.ng, y[0] + floor,
                                         deadline=min(s.clock.deadline, t + self.elim_limit),
                                         n_routes=self.pool_routes)
                if exact is not None:
                    through = np.minimum(through, exact[0])
                    # the same search's best routes: near-optimal columns for the MILP
                    s.stats.pool_routes = s.master.add_routes(exact[1])
                s.stats.elim_labels = exact is not None
            s.stats.elim_s += time.perf_counter() - t
            self._arc_cert = (self.cert, through, labels)
        m = s.master
        y0 = self.cert.duals[0]
        new = (self._arc_cert[1] - y0 < floor) & ~m.eliminated & np.isfinite(s.problem.cost)
        new[:, 0] = new[-1, :] = False
        np.fill_diagonal(new, False)
        if new.any():
            m.eliminated |= new
            self.version += 1
            s.stats.arcs_eliminated = int(m.eliminated.sum())
