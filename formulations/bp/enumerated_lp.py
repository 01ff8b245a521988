"""The LP over a fixed set of enumerated routes, tightened by subset-row cuts that cost no
pricing.

Once :mod:`.enumeration` has listed every elementary route that a plan better than the incumbent
may use, pricing is inspection: every route's reduced prize is one sparse product away. A cut
then costs an LP row and nothing in any labelling, so triples are separated with full memory
(coefficient floor(visits to S / 2)) as many as the LP asks for: on M = 20, K = 5 the root needs
hundreds of them to lose its last unit, far beyond the 64 that the labelling carries
(docs/bp-log.md). The master's own (limited-memory) cuts are rows too, so the LP starts at most at
the root certificate's bound.

After every round the routes are filtered by reduced cost: under optimal duals y of the LP over
all listed routes (value z, every route's reduced prize rc <= 0), a plan that uses route r is
worth at most z + rc_r, so only routes with rc_r >= need - z can be part of a plan worth
``need``. An LP value below ``need`` proves there is none; otherwise the MILP over the routes
left decides (:meth:`EnumeratedLP.milp`).
"""

from __future__ import annotations

import time
from typing import NamedTuple

import highspy
import numpy as np
import scipy.sparse as sp
from numba import njit
from sarcover.formulations.bp.highs import INF, packing_milp, quiet_highs, solve_lp
from sarcover.formulations.bp.master import dual_term, route_floor, spread, violated_triples


@njit(cache=True)
def cut_coefficients(paths, in_s, in_m):
    """(routes, cuts) limited-memory subset-row coefficients: along each route (rows of solver
    points padded with -1), pairs of visits to cut c's points ``in_s[c]``, an unpaired visit
    forgotten at a point outside its memory ``in_m[c]`` (all True: full memory)."""
    n_routes, width = paths.shape
    n_cuts = in_s.shape[0]
    out = np.zeros((n_routes, n_cuts), np.int8)
    for c in range(n_cuts):
        for r in range(n_routes):
            odd = False
            pairs = 0
            for k in range(width):
                p = paths[r, k]
                if p < 0:
                    break
                if not in_m[c, p]:
                    odd = False
                elif in_s[c, p]:
                    if odd:
                        pairs += 1
                    odd = not odd
            out[r, c] = pairs
    return out


class Solved(NamedTuple):
    """The LP over all listed routes, solved: for every plan of listed routes,
    prize <= ``dual_term`` + sum of its routes' reduced prizes ``rc`` (duals clipped to their
    signs, so this holds exactly), so the LP bounds every such plan by ``bound``
    (``dual_term`` + N·``rc_star``, ``rc_star`` = max(0, largest rc), about 0 once converged)
    and a plan with route r by ``dual_term`` + rc_r + (N-1)·``rc_star``. ``x``: the LP's positive
    route values (route index -> value)."""

    dual_term: float
    rc_star: float
    x: dict
    rc: np.ndarray

    def bound(self, n_vehicles: int) -> float:
        return self.dual_term + n_vehicles * self.rc_star

    def floor(self, need: float, n_vehicles: int) -> float:
        """The reduced prize a route needs to be part of a plan worth ``need``."""
        return route_floor(need, self.dual_term, self.rc_star, n_vehicles)


class EnumeratedLP:
    """The route master's rows (vehicles, each point at most once, each group covered) over the
    routes ``paths`` (rows of solver points, -1 padded), plus subset-row cut rows. ``cuts``:
    (triple, memory) pairs of the master's limited-memory cuts to start with; ``rows``: (lo, hi)
    of the master's rows at the node whose routes these are (:meth:`.master.Master.node_rows`:
    a forced point's row at ``= 1``, group bounds), None for the root's."""

    BATCH = 2000  # columns added to the LP per round of pricing by inspection

    def __init__(self, master, paths: np.ndarray, cuts=(), rows=None):
        self.master = master
        lo, hi = (master.row_lo, master.row_hi) if rows is None else rows
        self.row_lo, self.row_hi = lo[: master.base_rows], hi[: master.base_rows]
        # artificial columns on the rows with a positive lower bound (group covers, forced
        # points), so that every restricted LP is feasible
        self.art_rows = np.flatnonzero(self.row_lo > 0).astype(np.int32)
        self.n_points = master.V + 2
        self.cuts: list[tuple] = []  # (triple, memory or None for full memory)
        self._set_routes(np.ascontiguousarray(paths, dtype=np.int32))
        self.cut_matrix = sp.csr_matrix((len(self.paths), 0))
        self.add_cuts([(tuple(S), frozenset(M)) for S, M in cuts])

    # -- the routes -------------------------------------------------------------------------
    def _set_routes(self, paths: np.ndarray) -> None:
        m = self.master
        self.paths = paths
        k, width = paths.shape
        r, c = np.nonzero(paths >= 0)
        pts = paths[r, c].astype(np.int64)
        self.visits = sp.csr_matrix((np.ones(pts.size), (r, pts)), shape=(k, self.n_points))
        # the base rows: vehicle row, point rows 1..V, group rows (visits to the group's points)
        groups = m.group_of_point[pts]
        g_ok = groups >= 0
        rows = np.concatenate([np.zeros(k, np.int64), pts, 1 + m.V + groups[g_ok]])
        cols = np.concatenate([np.arange(k), r, r[g_ok]])
        self.base = sp.csr_matrix((np.ones(rows.size), (cols, rows)), shape=(k, m.base_rows))
        self.prize = np.bincount(r, weights=m.prizes[pts - 1], minlength=k)
        self.in_lp = np.zeros(k, dtype=bool)
        self.h = None  # built on the next solve

    def __len__(self) -> int:
        return len(self.paths)

    def route(self, i: int) -> tuple:
        row = self.paths[i]
        return tuple(row[row >= 0].tolist())

    # -- cuts -------------------------------------------------------------------------------
    def add_cuts(self, cuts) -> int:
        """Add cut rows ((triple, memory) pairs; memory None means full memory) over every
        listed route; returns how many."""
        cuts = [(tuple(S), M) for S, M in cuts]
        if not cuts:
            return 0
        in_s = np.zeros((len(cuts), self.n_points), np.bool_)
        in_m = np.ones((len(cuts), self.n_points), np.bool_)
        for c, (S, M) in enumerate(cuts):
            in_s[c, list(S)] = True
            if M is not None:
                in_m[c] = False
                in_m[c, list(M)] = True
        coef = sp.csr_matrix(cut_coefficients(self.paths, in_s, in_m).astype(np.float64))
        self.cut_matrix = sp.hstack([self.cut_matrix, coef], format="csr")
        self.cuts.extend(cuts)
        self.h = None  # rebuilt on the next solve (rows over all columns)
        return len(cuts)

    def separate(self, x: dict, max_new: int, min_violation: float = 0.02) -> list:
        """Most violated full-memory triples for the LP solution ``x`` (route -> value)."""
        pos = np.fromiter(x.keys(), dtype=np.int64)
        vis = self.visits[pos].toarray().astype(np.int64)
        vis[:, 0] = vis[:, -1] = 0
        have = {tuple(S) for S, _ in self.cuts}
        found = violated_triples(vis, np.fromiter(x.values(), dtype=float), have, min_violation)
        return spread(found, max_new)

    # -- the LP -----------------------------------------------------------------------------
    def matrix(self) -> sp.csr_matrix:
        """(routes, rows) coefficients: base rows, then cut rows."""
        return sp.hstack([self.base, self.cut_matrix], format="csr")

    def _build(self) -> None:
        m = self.master
        nc = len(self.cuts)
        lo = np.concatenate([self.row_lo, np.full(nc, -INF)])
        hi = np.concatenate([self.row_hi, np.ones(nc)])
        h = quiet_highs()
        h.changeObjectiveSense(highspy.ObjSense.kMaximize)
        h.addRows(lo.size, lo, hi, 0, np.zeros(lo.size, np.int32), np.zeros(0, np.int32),
                  np.zeros(0))
        na = self.art_rows.size
        h.addCols(na, np.full(na, -m.big), np.zeros(na), np.full(na, INF), na,
                  np.arange(na, dtype=np.int32), self.art_rows, np.ones(na))
        self.h, self.lo, self.hi = h, lo, hi
        self.A = self.matrix()
        self.cols = np.zeros(0, np.int64)  # the LP's route columns, as route indices
        self._add_columns(np.flatnonzero(self.in_lp))

    def _add_columns(self, idx: np.ndarray) -> None:
        if idx.size == 0:
            return
        sub = self.A[idx].tocsr()
        self.h.addCols(idx.size, self.prize[idx], np.zeros(idx.size), np.full(idx.size, INF),
                       sub.nnz, sub.indptr[:-1].astype(np.int32), sub.indices.astype(np.int32),
                       sub.data)
        self.cols = np.concatenate([self.cols, idx])
        self.in_lp[idx] = True

    def reduced_prizes(self, y: np.ndarray) -> np.ndarray:
        """(routes,) reduced prize p_r - A_r·y of every listed route."""
        if self.h is None:
            self.A = self.matrix()
        return self.prize - self.A @ y

    def solve(self, y_start: np.ndarray | None = None, deadline: float = np.inf) -> "Solved | None":
        """Solve the LP over all listed routes by pricing by inspection. ``y_start``: duals
        (base rows, then the first cut rows) whose best routes seed an empty LP. None at the
        deadline."""
        if self.h is None:
            self._build()
        if not self.in_lp.any():
            y0 = np.zeros(self.A.shape[1])
            if y_start is not None:
                y0[: min(y0.size, len(y_start))] = y_start[: y0.size]
            rc = self.reduced_prizes(y0)
            self._add_columns(np.argsort(-rc, kind="stable")[: self.BATCH])
        while True:
            if time.perf_counter() > deadline:
                return None
            solve_lp(self.h, "enumerated LP")
            sol = self.h.getSolution()
            y = np.asarray(sol.row_dual).copy()
            y[np.isinf(self.lo) & (y < 0)] = 0.0  # "<=" rows: y >= 0
            y[np.isinf(self.hi) & (y > 0)] = 0.0  # ">=" rows: y <= 0
            rc = self.reduced_prizes(y)
            new = np.flatnonzero((rc > 1e-7) & ~self.in_lp)
            if new.size == 0:
                break
            self._add_columns(new[np.argsort(-rc[new], kind="stable")[: self.BATCH]])
        xv = np.asarray(sol.col_value)[self.art_rows.size :]
        x = {int(self.cols[j]): float(xv[j]) for j in np.flatnonzero(xv > 1e-9)}
        return Solved(dual_term(y, self.lo, self.hi), max(0.0, float(rc.max(initial=0.0))), x, rc)

    def keep(self, mask: np.ndarray) -> None:
        """Keep only the routes where ``mask`` is True (the LP is rebuilt on the next solve)."""
        in_lp = self.in_lp[mask]
        coef = self.cut_matrix[mask]
        self._set_routes(self.paths[mask])
        self.cut_matrix = coef.tocsr()
        self.in_lp = in_lp

    def milp(self, need: float, time_limit: float, *, cuts: bool = False):
        """The best plan of listed routes among those worth at least ``need`` (set packing over
        its rows and the row "prize >= need"; with ``cuts`` also the cut rows, valid for
        every plan). Returns (status, routes): ("optimal", plan), ("infeasible", None): no such
        plan, or ("open", plan or None) at the time limit. Without the cut rows by default: on
        M = 20, K = 5 seed 100 HiGHS found the plan worth ``need`` among 6 413 routes in 15 s
        without them, and not in 150 s with the 443 rows."""
        m, k = self.master, len(self)
        if k == 0:
            return "infeasible", None
        a = sp.hstack([self.base, sp.csr_matrix(self.prize[:, None])]
                      + ([self.cut_matrix] if cuts else []), format="csr")
        n_cuts = a.shape[1] - m.base_rows - 1
        lo = np.concatenate([self.row_lo, [need], np.full(n_cuts, -INF)])
        hi = np.concatenate([self.row_hi, [INF], np.ones(n_cuts)])
        # the rows of ``a`` are the routes: its CSR arrays are the CSC arrays of the columns
        h = packing_milp(lo, hi, self.prize, np.ones(k), a.indptr[:-1].astype(np.int32),
                         a.indices.astype(np.int32), a.data, time_limit, abs_gap=True)
        st = h.getModelStatus()
        if st == highspy.HighsModelStatus.kInfeasible:
            return "infeasible", None
        plan = None
        if h.getInfo().primal_solution_status == 2:  # kSolutionStatusFeasible
            x = np.asarray(h.getSolution().col_value)
            plan = [self.route(r) for r in np.flatnonzero(x > 0.5)]
        return ("optimal" if st == highspy.HighsModelStatus.kOptimal else "open"), plan
