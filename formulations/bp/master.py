"""The route master (set packing with group cover) on HiGHS, and its certified Lagrangian bound.

Rows (solver order, point p = node id + 1)::

    row 0            sum_r x_r                 <= N     (vehicles)
    row p, p=1..V    sum_r a_pr x_r            <= 1     (each node at most once; = 1 when forced)
    row V+1+g        sum_r sum_{p in g} a_pr x_r >= 1   (group g covered)
    row V+1+G+c      sum_r floor(a_Sr / 2) x_r  <= 1   (subset-row cut c on a triple S)

Subset-row cuts (Jepsen, Petersen, Spoorendonk & Pisinger 2008) are valid for every plan of
elementary routes: at most one chosen route visits two points of S, because each point is visited
once. Limited memory (Pecin, Pessoa, Poggi & Uchoa 2017): each cut has a memory M ⊇ S of points;
along a route, an unpaired visit to S is forgotten at a point outside M, and ``a_Sr`` counts the
pairs made (repeated visits of an ng-route included, as the pricing counts them). That is at most
floor(visits to S / 2), so the cut stays valid; M is chosen from the LP routes that violate the
full cut, so that the separated violation is kept. At most :data:`MAX_CUTS` at a time (one
64-bit word in the labels); cuts whose dual is zero can be removed to make room
(:meth:`Master.purge_cuts`).

The group row counts visits (a route through two nodes of one group counts 2). For integer x this
is the same constraint as "some chosen route covers g" because each node is visited at most once
overall; in the LP it keeps the pricing linear (each node carries its group's dual).

Columns: one artificial per node row and per group row (coefficient +1, prize -BIG: Phase I, so
that the LP is always feasible, including under "node forced" branches), then the routes. A route
may be an ng-route that visits a point twice: its node and group coefficients count the visits
(and its prize counts each visit, as the pricing does), so it cannot appear in an integer solution
(node rows are <= 1) and the MILP gives it an upper bound of 0. Such routes leave the LP
(:meth:`Master.kill_non_ng`) once the ng sets grow so that they are no ng-routes any more.

Bound (every round, any duals y with the right signs): for every x feasible in the full master
(all routes allowed at the branch-and-bound node, no artificials),
``prize·x = sum_r rc_r x_r + y·(A x) <= N·max(0, rc*) + sum_k (y_k U_k if y_k > 0 else y_k L_k)``
with rc_r = p_r - A_r·y (HiGHS's convention) and rc* the best reduced prize over all allowed
routes (from exact pricing, or any upper bound on it such as ng-route pricing), since
sum_r x_r <= N and L <= A x <= U. Only plans of elementary routes need to satisfy it (they are
the integer solutions), so the bound stays valid whichever repeated routes the LP holds, and rc*
may come from ng-route pricing, which covers every elementary route. When y is the optimal dual
of the restricted LP the second term is its value (with the artificials' prize included, which
only lowers it), so this is the usual ``z_RMP + N·rc*`` (Farley/Lagrangian) bound. It does not
need the LP to be converged or even feasible without artificials; duals are clipped to their
sign so that the formula holds exactly.
"""

from __future__ import annotations

import highspy
import numpy as np
from sarcover.formulations.bp.highs import INF, packing_milp, quiet_highs, solve_lp

MAX_CUTS = 64


def _lm_coefficient(route, S, memory) -> int:
    """Pairs of visits to S along the route, an unpaired visit forgotten outside ``memory``."""
    odd, pairs = False, 0
    for p in route:
        if p not in memory:
            odd = False
        elif p in S:
            if odd:
                pairs += 1
            odd = not odd
    return pairs


def violated_triples(vis: np.ndarray, xp: np.ndarray, have, min_violation: float) -> list:
    """Triples S of points (columns of ``vis``) whose subset-row cut sum_r floor(a_Sr / 2) x_r
    <= 1 the LP solution violates by more than ``min_violation``, most violated first.
    ``vis``: (routes, points) visits of the routes with x > 0 (points that no cut may hold, such
    as start and end, at 0), ``xp`` their LP values; ``have``: triples to leave out."""
    pts = np.flatnonzero(vis.sum(axis=0) > 0)
    found = []
    for a_i, a in enumerate(pts):
        for b_i in range(a_i + 1, len(pts)):
            b = pts[b_i]
            ab = vis[:, a] + vis[:, b]
            rest = pts[b_i + 1 :]
            if rest.size == 0 or not np.any(ab):
                continue
            lhs = ((ab[:, None] + vis[:, rest]) // 2 * xp[:, None]).sum(axis=0)
            for c in np.flatnonzero(lhs > 1.0 + min_violation):
                S = (int(a), int(b), int(rest[c]))
                if S not in have:
                    found.append((float(lhs[c]), S))
    found.sort(key=lambda t: -t[0])
    return [S for _, S in found]


def dual_term(y: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> float:
    """The duals' part of a Lagrangian bound: each row's dual times the bound it sits at (its
    upper bound where the dual is positive, its lower bound where negative); duals clipped to
    their signs, as :meth:`Master.solve` returns them."""
    return float(np.where(y > 0, y * np.where(np.isinf(hi), 0.0, hi),
                          y * np.where(np.isinf(lo), 0.0, lo)).sum())


def route_floor(need: float, term: float, rc_star: float, n_vehicles: int) -> float:
    """The reduced prize a route needs to be part of a plan worth ``need`` under duals of dual
    term ``term`` that bound every route's reduced prize by ``rc_star``: such a plan is worth at
    most term + its routes' reduced prizes, the others' at most ``rc_star`` each."""
    return need - term - (n_vehicles - 1) * max(rc_star, 0.0) - 1e-6


def spread(triples, room: int, per_point: int = 3) -> list:
    """Up to ``room`` of ``triples`` in order, a point in at most ``per_point`` of them (cuts on
    the same few points overlap and lower the LP less)."""
    chosen, used = [], {}
    for S in triples:
        if any(used.get(p, 0) >= per_point for p in S):
            continue
        chosen.append(S)
        for p in S:
            used[p] = used.get(p, 0) + 1
        if len(chosen) >= room:
            break
    return chosen


class Master:
    def __init__(self, n_nodes: int, prizes: np.ndarray, groups, n_vehicles: int, *,
                 primal_simplex: bool = False):
        self.V = n_nodes
        self.G = len(groups)
        self.N = n_vehicles
        self.prizes = np.asarray(prizes, dtype=float)
        self.groups = [np.asarray(g, dtype=np.int64) + 1 for g in groups]  # solver points
        self.group_of_point = np.full(n_nodes + 2, -1, dtype=np.int64)
        for g, pts in enumerate(self.groups):
            self.group_of_point[pts] = g
        self.big = 10.0 * (float(self.prizes.sum()) + 1.0)
        self.n_rows = 1 + self.V + self.G
        self.row_lo = np.concatenate([[-INF], np.full(self.V, -INF), np.ones(self.G)])
        self.row_hi = np.concatenate([[float(n_vehicles)], np.ones(self.V), np.full(self.G, INF)])
        h = quiet_highs()
        if primal_simplex:
            # new columns leave the last basis primal feasible: at hundreds of points HiGHS's
            # primal simplex re-solves the restricted LP in half the dual simplex's time
            h.setOptionValue("simplex_strategy", 4)
        h.changeObjectiveSense(highspy.ObjSense.kMaximize)
        h.addRows(self.n_rows, self.row_lo, self.row_hi, 0, np.zeros(self.n_rows, np.int32),
                  np.zeros(0, np.int32), np.zeros(0))
        self.h = h
        # artificials for node rows 1..V and group rows
        n_art = self.V + self.G
        idx = np.arange(1, self.n_rows, dtype=np.int32)
        h.addCols(n_art, np.full(n_art, -self.big), np.zeros(n_art), np.full(n_art, INF), n_art,
                  np.arange(n_art, dtype=np.int32), idx, np.ones(n_art))
        self.n_art = n_art
        self.routes: list[tuple[int, ...]] = []  # solver points, without start/end
        self.route_prize: list[float] = []
        self.seen: set[tuple[int, ...]] = set()
        cap = 256
        self._visit = np.zeros((cap, self.V + 2), dtype=np.int16)  # visits of each point
        # every arc of every route (start 0 and end V+1 included): route, tail, head
        self._arcs = np.zeros((3, 16 * cap), dtype=np.int32)
        self.n_arcs = 0
        self.repeated: list[int] = []  # routes (ng-routes) that visit some point twice
        self.dead: set[int] = set()  # repeated routes that are no ng-routes of the grown ng sets
        self.hide_repeated = False  # True while a primal heuristic wants elementary routes only
        # arcs no plan better than the incumbent uses (reduced-cost arc elimination)
        self.eliminated = np.zeros((n_nodes + 2, n_nodes + 2), dtype=bool)
        self.col_ub = np.zeros(0)
        self.cur_lo = self.row_lo.copy()  # row bounds at the node the master is set to
        self.cur_hi = self.row_hi.copy()
        self.cuts: list[tuple[int, ...]] = []  # subset-row triples (solver points)
        self.cut_members = np.zeros(self.V + 2, dtype=np.uint64)  # bitset of cuts per point
        self.cut_memory = np.zeros(self.V + 2, dtype=np.uint64)  # cuts remembering each point
        self.memories: list[frozenset] = []
        self.base_rows = self.n_rows

    # -- columns ---------------------------------------------------------------------------
    @property
    def n_routes(self) -> int:
        return len(self.routes)

    def add_routes(self, routes) -> int:
        """Add new routes (tuples of solver points); return how many were new.

        A route may visit a point more than once (an ng-route): its coefficients count the
        visits, so it can never be part of an integer solution (a node row is <= 1) but it keeps
        the LP a relaxation of the elementary one that the ng-route pricing bounds exactly."""
        new = [tuple(int(p) for p in r) for r in routes if r and tuple(r) not in self.seen]
        new = list(dict.fromkeys(new))
        if not new:
            return 0
        k0 = self.n_routes
        need = k0 + len(new)
        if need > self._visit.shape[0]:
            cap = max(need, 2 * self._visit.shape[0])
            visit = np.zeros((cap, self.V + 2), dtype=self._visit.dtype)
            visit[: self._visit.shape[0]] = self._visit
            self._visit = visit
        arcs_needed = self.n_arcs + sum(len(r) + 1 for r in new)
        if arcs_needed > self._arcs.shape[1]:
            arcs = np.zeros((3, max(arcs_needed, 2 * self._arcs.shape[1])), dtype=np.int32)
            arcs[:, : self.n_arcs] = self._arcs[:, : self.n_arcs]
            self._arcs = arcs
        starts, idx, vals, costs = [], [], [], []
        nnz = 0
        end = self.V + 1
        for k, r in enumerate(new, start=k0):
            self.seen.add(r)
            self.routes.append(r)
            pts = np.asarray(r, dtype=np.int64)
            prize = float(self.prizes[pts - 1].sum())
            self.route_prize.append(prize)
            np.add.at(self._visit[k], pts, 1)
            if len(set(r)) < len(r):
                self.repeated.append(k)
            full = [0, *r, end]
            j = self.n_arcs
            self._arcs[0, j : j + len(r) + 1] = k
            self._arcs[1, j : j + len(r) + 1] = full[:-1]
            self._arcs[2, j : j + len(r) + 1] = full[1:]
            self.n_arcs = j + len(r) + 1
            coef: dict[int, float] = {0: 1.0}
            for p in r:
                coef[p] = coef.get(p, 0.0) + 1.0
                g = self.group_of_point[p]
                if g >= 0:
                    row = 1 + self.V + g
                    coef[row] = coef.get(row, 0.0) + 1.0
            for c, S in enumerate(self.cuts):
                a = _lm_coefficient(r, S, self.memories[c])
                if a:
                    coef[self.base_rows + c] = float(a)
            starts.append(nnz)
            rows = sorted(coef)
            idx.extend(rows)
            vals.extend(coef[i] for i in rows)
            nnz += len(rows)
            costs.append(prize)
        n = len(new)
        self.h.addCols(n, np.asarray(costs), np.zeros(n), np.full(n, INF), nnz,
                       np.asarray(starts, np.int32), np.asarray(idx, np.int32), np.asarray(vals))
        self.col_ub = np.concatenate([self.col_ub, np.full(n, INF)])
        return n

    # -- subset-row cuts -------------------------------------------------------------------
    def cut_coefficients(self, S, memory) -> np.ndarray:
        """(n_routes,) limited-memory coefficient of every route."""
        out = np.zeros(self.n_routes, dtype=np.int64)
        pts = list(S)
        for r in np.flatnonzero(self._visit[: self.n_routes][:, pts].sum(axis=1) >= 2):
            out[r] = _lm_coefficient(self.routes[r], S, memory)
        return out

    def _memory(self, S, x) -> frozenset:
        """S plus the points between visits to S on the LP's routes that visit S twice or more."""
        mem = set(S)
        for r in np.flatnonzero(x[: self.n_routes] > 1e-9):
            route = self.routes[r]
            at = [i for i, p in enumerate(route) if p in S]
            if len(at) >= 2:
                mem.update(route[at[0] : at[-1] + 1])
        return frozenset(mem)

    def separate_cuts(self, x: np.ndarray, max_new: int, min_violation: float = 0.05):
        """Most violated subset-row cuts on triples for the LP solution x (routes); up to
        ``max_new`` and :data:`MAX_CUTS` in all, each violated by at least ``min_violation``."""
        room = min(max_new, MAX_CUTS - len(self.cuts))
        k = self.n_routes
        pos = np.flatnonzero(x[:k] > 1e-9)
        if room <= 0 or pos.size == 0:
            return []
        vis = self._visit[pos].astype(np.int64)  # (routes, points)
        vis[:, 0] = vis[:, self.V + 1] = 0
        found = violated_triples(vis, x[pos], set(self.cuts), min_violation)
        return [(S, self._memory(S, x)) for S in spread(found, room)]

    def add_cuts(self, cuts) -> int:
        """Add subset-row cut rows ((triple, memory) of solver points) over all generated routes."""
        cuts = [(tuple(S), frozenset(M)) for S, M in cuts if tuple(S) not in self.cuts]
        cuts = cuts[: MAX_CUTS - len(self.cuts)]
        if not cuts:
            return 0
        starts, idx, vals = [], [], []
        art = self.n_art
        for S, M in cuts:
            a = self.cut_coefficients(S, M)
            nz = np.flatnonzero(a)
            starts.append(len(idx))
            idx.extend((nz + art).tolist())
            vals.extend(a[nz].astype(float).tolist())
        n = len(cuts)
        self.h.addRows(n, np.full(n, -INF), np.ones(n), len(idx), np.asarray(starts, np.int32),
                       np.asarray(idx, np.int32), np.asarray(vals, dtype=float))
        for S, M in cuts:
            self._mark_cut(len(self.cuts), S, M)
            self.cuts.append(S)
            self.memories.append(M)
        self.n_rows += n
        self.row_lo = np.concatenate([self.row_lo, np.full(n, -INF)])
        self.row_hi = np.concatenate([self.row_hi, np.ones(n)])
        self.cur_lo = np.concatenate([self.cur_lo, np.full(n, -INF)])
        self.cur_hi = np.concatenate([self.cur_hi, np.ones(n)])
        return n

    def purge_cuts(self, y: np.ndarray, tol: float = 1e-9) -> int:
        """Remove the cut rows whose dual in ``y`` is zero (their slots are then free for new
        cuts; the pricing ignores them anyway); return how many. Cuts are valid for every plan,
        so dropping some only weakens the LP, and one of zero dual leaves the LP optimum as is."""
        if not self.cuts:
            return 0
        return self.remove_cuts(np.flatnonzero(self.cut_duals(y) <= tol))

    def remove_cuts(self, drop) -> int:
        """Remove the cut rows at positions ``drop`` (in cut order); return how many. Valid at
        any time: every cut holds for every plan, so the LP only gets weaker."""
        drop = np.unique(np.asarray(drop, dtype=np.int64))
        if drop.size == 0:
            return 0
        rows = (drop + self.base_rows).astype(np.int32)
        self.h.deleteRows(int(rows.size), rows)
        keep_row = np.ones(self.n_rows, dtype=bool)
        keep_row[rows] = False
        self.row_lo, self.row_hi, self.cur_lo, self.cur_hi = (
            a[keep_row] for a in (self.row_lo, self.row_hi, self.cur_lo, self.cur_hi))
        self.n_rows -= int(rows.size)
        gone = set(drop.tolist())
        kept = [c for c in range(len(self.cuts)) if c not in gone]
        self.cuts = [self.cuts[c] for c in kept]
        self.memories = [self.memories[c] for c in kept]
        self.cut_members[:] = 0
        self.cut_memory[:] = 0
        for c, (S, M) in enumerate(zip(self.cuts, self.memories)):
            self._mark_cut(c, S, M)
        return int(drop.size)

    def _mark_cut(self, c: int, S, memory) -> None:
        """Set cut c's bit at the points of its triple and of its memory (the pricing's bitsets)."""
        bit = np.uint64(1) << np.uint64(c)
        for p in S:
            self.cut_members[p] |= bit
        for p in memory:
            self.cut_memory[p] |= bit

    def cut_duals(self, y: np.ndarray) -> np.ndarray:
        """Duals of the cut rows (>= 0, clipped), in cut order."""
        return np.maximum(y[self.base_rows :], 0.0)

    # -- branching state -------------------------------------------------------------------
    def incompatible(self, state) -> np.ndarray:
        """(n_routes,) bool: routes that a branch-and-bound node's decisions or the arc
        elimination exclude (checked on the arc list of all routes at once, so repeated visits
        count like any other)."""
        k = self.n_routes
        bad = np.zeros(k, dtype=bool)
        for p in state.forbidden_nodes:
            bad |= self._visit[:k, p] > 0
        route, tail, head = self._arcs[:, : self.n_arcs]
        if self.eliminated.any():
            bad[route[self.eliminated[tail, head]]] = True
        if state.forbidden_arcs or state.forced_arcs:
            end = self.V + 1
            for a, b in state.forbidden_arcs:
                bad[route[(tail == a) & (head == b)]] = True
            # forced (a, b): nothing else may leave a or enter b. One pass over the arcs for
            # all forced arcs: out_to[a] = b (-1 free, -2 two forced arcs leave a: none may)
            out_to = np.full(self.V + 2, -1, dtype=np.int64)
            in_from = np.full(self.V + 2, -1, dtype=np.int64)
            for a, b in state.forced_arcs:
                if a != 0:
                    out_to[a] = b if out_to[a] in (-1, b) else -2
                if b != end:
                    in_from[b] = a if in_from[b] in (-1, a) else -2
            o, i = out_to[tail], in_from[head]
            bad[route[((o != -1) & (o != head)) | ((i != -1) & (i != tail))]] = True
        if self.hide_repeated:
            bad[self.repeated] = True
        if self.dead:
            bad[list(self.dead)] = True
        return bad

    def kill_non_ng(self, ng: np.ndarray) -> int:
        """Exclude the repeated routes that are not ng-routes for the ng sets ``ng`` (bitsets);
        return how many. Only elementary routes matter for the bound, so this is always valid."""
        n = 0
        for r in self.repeated:
            if r in self.dead:
                continue
            mem: set[int] = set()
            for w in self.routes[r]:
                if w in mem:
                    self.dead.add(r)
                    n += 1
                    break
                mem = {u for u in mem if ng[w, u >> 6] >> np.uint64(u & 63) & np.uint64(1)} | {w}
        return n

    def node_rows(self, state) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) bounds of every row at a node: the root's, with each forced point's row at
        ``= 1`` and each group bound on its group's row."""
        lo, hi = self.row_lo.copy(), self.row_hi.copy()
        for p in state.forced_nodes:
            lo[p] = 1.0
        for g, g_lo, g_hi in state.group_bounds:  # views of target g within [g_lo, g_hi]
            row = 1 + self.V + g
            lo[row], hi[row] = max(lo[row], g_lo), min(hi[row], g_hi)
        return lo, hi

    def apply(self, state) -> None:
        """Set column and row bounds for a branch-and-bound node."""
        k = self.n_routes
        ub = np.where(self.incompatible(state), 0.0, INF)
        changed = np.flatnonzero(ub != self.col_ub)
        if changed.size:
            cols = (changed + self.n_art).astype(np.int32)
            self.h.changeColsBounds(cols.size, cols, np.zeros(cols.size), ub[changed])
            self.col_ub = ub
        self.cur_lo, self.cur_hi = lo, hi = self.node_rows(state)
        rows = np.arange(1, 1 + self.V + self.G, dtype=np.int32)
        self.h.changeRowsBounds(rows.size, rows, lo[rows], hi[rows])
        assert k == self.col_ub.size

    # -- solving ---------------------------------------------------------------------------
    def solve(self):
        """Solve the restricted LP. Returns (value, x_routes, x_art, y) with clipped duals."""
        solve_lp(self.h, "master LP")
        sol = self.h.getSolution()
        x = np.asarray(sol.col_value)
        y = np.asarray(sol.row_dual).copy()
        lo, hi = self.cur_lo, self.cur_hi
        y[np.isinf(lo) & (y < 0)] = 0.0  # "<=" rows: y >= 0
        y[np.isinf(hi) & (y > 0)] = 0.0  # ">=" rows: y <= 0
        value = self.h.getInfo().objective_function_value
        return value, x[self.n_art :], x[: self.n_art], y

    def point_profit(self, y: np.ndarray) -> np.ndarray:
        """Reduced prize per solver point (start and end 0): prize - node dual - group dual."""
        prof = np.zeros(self.V + 2)
        prof[1 : self.V + 1] = self.prizes - y[1 : self.V + 1]
        for g, pts in enumerate(self.groups):
            prof[pts] -= y[1 + self.V + g]
        return prof

    def lagrangian_bound(self, y: np.ndarray, best_path_prize: float) -> float:
        """Certified upper bound from duals y and an upper bound on the best path's reduced prize."""
        rc_star = max(0.0, best_path_prize - y[0])
        return dual_term(y, self.cur_lo, self.cur_hi) + self.N * rc_star

    def reduced_costs(self, y: np.ndarray) -> np.ndarray:
        """(n_routes,) reduced prize p_r - A_r·y of every route for duals ``y``; rows added after
        ``y`` was read (cuts) count with dual 0."""
        k = self.n_routes
        if k == 0:
            return np.zeros(0)
        yy = np.zeros(self.n_rows)
        yy[: min(len(y), self.n_rows)] = y[: self.n_rows]
        starts, index, value = self._route_matrix()
        at = np.repeat(np.arange(k), np.diff(starts))
        used = np.bincount(at, weights=value * yy[index], minlength=k)
        return np.asarray(self.route_prize) - used

    def _route_matrix(self):
        """The route columns of the LP matrix (CSC, artificials left out): column starts
        (n_routes + 1, from 0), row indices, values."""
        a = self.h.getLp().a_matrix_
        k = self.n_routes
        starts = np.asarray(a.start_, dtype=np.int64)[self.n_art : self.n_art + k + 1]
        index = np.asarray(a.index_, dtype=np.int32)[starts[0] : starts[-1]]
        value = np.asarray(a.value_)[starts[0] : starts[-1]]
        return starts - starts[0], index, value

    def node_visits(self, x: np.ndarray) -> np.ndarray:
        """(V+2,) visit value of each point in an LP solution."""
        k = self.n_routes
        return x[:k] @ self._visit[:k]

    def group_visits(self, x: np.ndarray) -> np.ndarray:
        """(G,) visits of each group's points (views of each target) in an LP solution."""
        visits = self.node_visits(x)
        return np.array([visits[pts].sum() for pts in self.groups])

    def arc_flows(self, x: np.ndarray) -> dict[tuple[int, int], float]:
        flows: dict[tuple[int, int], float] = {}
        for r in np.flatnonzero(x > 1e-9):
            full = [0, *self.routes[r], self.V + 1]
            for a, b in zip(full, full[1:]):
                flows[(a, b)] = flows.get((a, b), 0.0) + float(x[r])
        return flows

    def milp(self, time_limit: float, allowed: np.ndarray | None = None, start=None,
             presolve: bool = True):
        """Best integer selection of the generated routes (root rows, no branching); routes or
        None. ``allowed``: the routes it may use; ``start``: a plan (routes, each one of the
        generated ones) handed to HiGHS as its first solution, so that its search only looks
        for better ones (within a short limit it finds better plans than without a start);
        ``presolve``: HiGHS's (see :func:`.highs.packing_milp`)."""
        k = self.n_routes
        if k == 0:
            return None
        first = None
        if start:
            pos = {r: i for i, r in enumerate(self.routes)}
            first = [pos.get(tuple(r)) for r in start]
            if None in first or any(i in self.repeated for i in first):
                first = None  # not a selection of the generated elementary routes
        starts, index, value = self._route_matrix()
        ub = np.ones(k) if allowed is None else np.where(allowed, 1.0, 0.0)
        ub[self.repeated] = 0.0  # never in an integer solution
        x0 = None
        if first is not None:
            ub[first] = 1.0  # the start's routes, even where ``allowed`` leaves them out
            x0 = np.zeros(k)
            x0[first] = 1.0
        h = packing_milp(self.row_lo, self.row_hi, np.asarray(self.route_prize), ub,
                         starts[:-1].astype(np.int32), index, value, time_limit, first=x0,
                         presolve=presolve)
        if h.getInfo().primal_solution_status != 2:  # kSolutionStatusFeasible
            return None
        x = np.asarray(h.getSolution().col_value)
        return [self.routes[r] for r in np.flatnonzero(x > 0.5)]
