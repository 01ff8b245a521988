"""The labelling (:func:`.labelling.price`) as the search calls it: heuristic or exact, against a
threshold, with the subset-row cuts' duals, timed and counted; and the choice of the exact
pricing's direction."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np

from sarcover.formulations.bp.constants import TOL
from sarcover.formulations.bp.bounds import relaxed_best, suffix_tables
from sarcover.formulations.bp.graph import cheapest_return, sparse_graph
from sarcover.formulations.bp.labelling import price, sub_buckets
from sarcover.formulations.bp.route_search import improving_routes

if TYPE_CHECKING:
    from sarcover.formulations.bp.search import Search


HEURISTIC_LABELS = 200_000  # labels a heuristic call may make at first (see Pricer.heuristic)
ROOT_LABEL_GROWTH = 4  # at the root the exact calls' label cap may grow to this multiple
ROUTE_SEARCH_COLUMNS = 150  # most routes one local search pricing call returns


class Pricer:
    """Pricing calls of one run. ``bidirectional``: the exact pricing direction; None until the
    first exact call has measured both. ``keep``: the exact calls' share of near-best routes
    (:func:`.labelling.price`); ``exact_labels``: their label cap. From ``sparse_from`` points
    on, the heuristic calls run on the ``sparse_arcs`` cheapest arcs out of each point
    (:func:`.graph.sparse_graph`; 0: never) and return up to ``heuristic_columns`` routes.
    ``heuristic_labels``: the heuristic calls' label cap, which grows when a capped call finds
    nothing (:meth:`heuristic`)."""

    def __init__(self, search: "Search", bidirectional: bool | None, ng_columns: bool,
                 keep: float, exact_labels: int, *, sparse_arcs: int = 0, sparse_from: int = 0,
                 heuristic_columns: int = 30):
        self.search = search
        self.sparse_arcs = sparse_arcs
        self.sparse_from = sparse_from
        self.heuristic_columns = heuristic_columns
        self.bidirectional = bidirectional
        self.ng_columns = ng_columns
        self.keep = keep
        self.exact_labels = exact_labels
        self.max_exact_labels = ROOT_LABEL_GROWTH * exact_labels  # see raise_exact_cap
        self.heuristic_labels = HEURISTIC_LABELS
        self.last_exact_labels = None  # sizes the next exact call's dominance layout

    def price(self, cost, ret, prof, allowed, *, heuristic: bool, y0: float, sig,
              deadline: float | None = None):
        """One labelling call on a node's graph (:func:`.graph.node_graph`) with reduced prizes
        ``prof``; ``y0`` is the threshold a path's reduced prize must beat (the vehicle dual, or
        more for a targeted exact call); ``sig``: the subset-row cuts' duals."""
        s = self.search
        t = time.perf_counter()
        # an exact call makes about as many labels as the one before it: its sub-buckets follow
        nsub = None if heuristic else sub_buckets(cost.shape[0], self.last_exact_labels)
        full = cost
        sparse = heuristic and self.sparse_arcs and s.problem.V >= self.sparse_from
        if sparse:
            cost = sparse_graph(cost, allowed, self.sparse_arcs)
            ret = cheapest_return(cost)
        res = price(cost, ret, prof, s.problem.budget, s.ng, allowed, heuristic=heuristic,
                    max_labels=self.heuristic_labels if heuristic else self.exact_labels,
                    n_cols=self.heuristic_columns if heuristic else 60, min_gain=y0 + TOL,
                    deadline=s.clock.deadline if deadline is None else deadline,
                    bidirectional=bool(self.bidirectional) and not heuristic,
                    cut_members=s.master.cut_members, cut_memory=s.master.cut_memory,
                    cut_duals=sig, keep=0.0 if heuristic else self.keep, nsub=nsub)
        if sparse:  # the relaxed bound is over the full graph's routes, not the sparse one's
            res.relaxed = relaxed_best(*suffix_tables(full, prof, allowed, s.problem.budget),
                                       s.problem.budget)
        s.stats.pricing_s += time.perf_counter() - t
        if not heuristic:
            self.last_exact_labels = res.n_labels
        s.stats.labels += res.n_labels
        return res

    def heuristic(self, cost, ret, prof, allowed, *, y0: float, sig):
        """Heuristic pricing (:meth:`price`). A call that stops at its label cap without an
        improving route runs again with four times the cap, while that is below the exact
        calls' cap: labels are extended in order of energy, so a capped call has not reached
        the long routes, and ending the heuristic phase there hands its work to exact calls
        that take tens of times longer (from about 360 points on; docs/bp.md, column
        generation)."""
        while True:
            res = self.price(cost, ret, prof, allowed, heuristic=True, y0=y0, sig=sig)
            if (self.columns(res) or not res.stopped or self.search.clock.time_left() <= 0
                    or self.heuristic_labels >= self.exact_labels):
                return res
            self.heuristic_labels = min(4 * self.heuristic_labels, self.exact_labels)
            self.search.stats.heuristic_labels = self.heuristic_labels

    def route_search(self, x, y, cost, prof, allowed, *, y0: float) -> list:
        """Improving routes by local search (:mod:`.route_search`) from the LP solution's
        routes and the columns of highest reduced prize under duals ``y`` (as many as the
        vehicles), up to ``ROUTE_SEARCH_COLUMNS`` of them. Only without subset-row cuts, whose
        duals it does not pay."""
        s = self.search
        m = s.master
        t = time.perf_counter()
        rc = m.reduced_costs(y)
        picked = [int(r) for r in np.flatnonzero(x > TOL)]
        picked += [int(r) for r in np.argsort(-rc)[: s.problem.N]]
        repeated = set(m.repeated)  # the local search starts from elementary routes only
        starts = [m.routes[r] for r in dict.fromkeys(picked) if r not in repeated]
        routes = improving_routes(starts, cost, prof, allowed, s.problem.budget, y0 + TOL,
                                  ROUTE_SEARCH_COLUMNS)
        dt = time.perf_counter() - t
        s.stats.pricing_s += dt
        s.stats.route_search_s += dt
        return routes

    def raise_exact_cap(self) -> bool:
        """Double the exact calls' label cap, up to ``ROOT_LABEL_GROWTH`` times the option's
        (memory: about 100 bytes a label); whether it grew. The root calls it when an exact
        pricing hit the cap and no cut round is left to withdraw, so that its column generation
        goes on instead of branching on an unconverged LP."""
        if self.exact_labels >= self.max_exact_labels:
            return False
        self.exact_labels = min(2 * self.exact_labels, self.max_exact_labels)
        self.search.stats.exact_label_cap = self.exact_labels
        return True

    def exact(self, cost, ret, prof, allowed, y0: float, sig):
        """Exact pricing. On the first call both searches run, the bidirectional one under the
        one-way search's time; the faster is kept for the rest of the run (neither dominates:
        bidirectional wins on long routes with many labels, loses when the join is large)."""
        if self.bidirectional is not None:
            return self.price(cost, ret, prof, allowed, heuristic=False, y0=y0, sig=sig)
        t = time.perf_counter()
        self.bidirectional = False
        uni = self.price(cost, ret, prof, allowed, heuristic=False, y0=y0, sig=sig)
        t_uni = time.perf_counter() - t
        if not uni.exact:
            return uni
        deadline = min(self.search.clock.deadline, time.perf_counter() + 0.8 * t_uni)
        t = time.perf_counter()
        self.bidirectional = True
        bi = self.price(cost, ret, prof, allowed, heuristic=False, y0=y0, sig=sig,
                        deadline=deadline)
        t_bi = time.perf_counter() - t
        self.search.stats.mode_times = (round(t_uni, 4), round(t_bi, 4))
        self.bidirectional = bool(bi.exact) and t_bi < 0.8 * t_uni
        return uni

    def columns(self, res) -> list:
        """The improving routes of a pricing result that join the master: the elementary ones,
        and the ng-routes that repeat a point unless ``ng_columns`` is off."""
        return list(res.routes) + (list(res.ng_routes) if self.ng_columns else [])
