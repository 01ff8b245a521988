"""Route enumeration once the root gap is small, and the set-packing MILP over the enumerated
routes that closes it (Baldacci, Christofides & Mingozzi 2008; Pecin et al. 2017).

Under the duals y that certified the root bound (:class:`.elimination.Certificate`), a plan
better than the incumbent only uses elementary routes of reduced prize >= the certificate's floor
(:meth:`.elimination.Elimination.rc_floor`). When few routes reach it, all of them can be listed:
a labelling from the start over elementary paths (full visited sets), where a label is only
dominated by a label at the same point with the *same* visited set (no less prize after the cuts'
duals, no more energy), and pruned by the pricing's completion and suffix bounds against the
fixed floor, on the graph the arc elimination leaves. Each visited set is one column of the
master (its rows only see the set), so one route per set is enough.

The LP over them (:mod:`.enumerated_lp`: full-memory cuts, reduced-cost filter), then the MILP
over the routes it leaves (vehicles <= N, each point at most once, each group covered) with the
row "prize >= incumbent + step" decide the run: a solution is an optimal plan (every better plan
is among its columns), an LP below that value or an infeasible MILP proves the incumbent
optimal. Both only hold when the listing and the MILP finished; a cap or a time limit leaves the
run as it was.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numba import njit, objmode

from sarcover.formulations.bp.enumerated_lp import EnumeratedLP
from sarcover.formulations.bp.node import NodeState, node_graph
from sarcover.formulations.bp.pricing import (
    DP_UNITS, EPS, _byte_sums, _completion, _dp_bound, _dp_unit, _grow, _heap_pop, _heap_push,
    _label_table, _prepare, _reversed, _sigsum, cheapest_return, suffix_tables)

if TYPE_CHECKING:
    from sarcover.formulations.bp.elimination import Elimination
    from sarcover.formulations.bp.incumbent import IncumbentSearch
    from sarcover.formulations.bp.search import Search


@njit(cache=True)
def _key_hash(w, mask):
    """Hash of (point, visited set) for the open-addressing table (splitmix64 steps)."""
    h = np.uint64(w) * np.uint64(0x9E3779B97F4A7C15)
    for k in range(mask.shape[0]):
        h ^= mask[k] + np.uint64(0x9E3779B97F4A7C15) + (h << np.uint64(6)) + (h >> np.uint64(2))
        h ^= h >> np.uint64(30)
        h *= np.uint64(0xBF58476D1CE4E5B9)
        h ^= h >> np.uint64(27)
    return h


@njit(cache=True)
def _enumerate(cost, ret, profit, budget, allowed, order, cin, reach, lastord, cend, threshold,
               max_labels, deadline, cmem, mmem, sig, g1, s1, g2, delta, nb, sfx, sdelta, snb,
               margin):
    """Labels of every elementary path start -> ... whose prize (after the cuts' duals) plus
    the completion and suffix bounds exceeds ``threshold``; a label is dropped only when a label
    at the same point with the same visited set has no more energy and no less prize (after
    paying the duals of the cuts where it holds an odd visit and the new one does not).
    ``sfx[w, b]`` (``snb`` > 0): the most prize of a suffix w -> ... -> end of energy <= b units
    of ``sdelta`` (w's own prize counted, the cuts' duals paid) over every suffix of a path
    above the threshold, a third bound.

    Labels with equal (point, set) form a list (``nxt``) whose head sits in an open-addressing
    table. Returns (count, node, pred, energy, prize, mask, alive, hit_cap, inner), ``inner``
    the labels made whose bounds also exceed ``threshold + margin`` (about the labels a listing
    at that threshold would make)."""
    n = cost.shape[0]
    W = (n + 63) // 64
    cap = 1024
    node = np.empty(cap, np.int32)
    pred = np.empty(cap, np.int32)
    en = np.empty(cap, np.float64)
    pr = np.empty(cap, np.float64)
    alive = np.empty(cap, np.bool_)
    mask = np.zeros((cap, W), np.uint64)
    srb = np.zeros(cap, np.uint64)
    nxt = np.empty(cap, np.int32)
    tsize = 1 << 12
    table = np.full(tsize, -1, np.int32)
    used = 0
    node[0] = 0
    pred[0] = -1
    en[0] = 0.0
    pr[0] = 0.0
    alive[0] = True
    nxt[0] = -1
    count = 1
    hit = False
    inner = 0
    hkey = np.empty(cap, np.float64)
    hval = np.empty(cap, np.int32)
    hkey[0] = 0.0
    hval[0] = 0
    hn = 1
    newmask = np.zeros(W, np.uint64)
    end = n - 1
    while hn > 0:
        qi = hval[0]
        hn = _heap_pop(hkey, hval, hn)
        if not alive[qi]:
            continue
        v = node[qi]
        for w in range(1, end):
            if not allowed[w]:
                continue
            e2 = en[qi] + cost[v, w]
            if not (e2 + ret[w] <= budget):  # also rejects inf (removed arcs)
                continue
            wd = w >> 6
            wb = np.uint64(1) << np.uint64(w & 63)
            if mask[qi, wd] & wb:
                continue
            p2 = pr[qi] + profit[w]
            sq = srb[qi] & mmem[w]
            hitc = sq & cmem[w]
            if hitc:
                p2 -= _sigsum(hitc, sig)
            s2 = sq ^ cmem[w]
            for k in range(W):
                newmask[k] = mask[qi, k]
            newmask[wd] |= wb
            ub = p2 + _dp_bound(g1, s1, g2, w, v, budget - e2, delta, nb)
            if ub <= threshold:
                continue
            if snb > 0:
                # the path splits at the arc v -> w: pairs of a cut across the split only
                # lower the route's prize further
                b = min(int((budget - e2) / sdelta + 2e-9), snb)
                ub = min(ub, pr[qi] + sfx[w, b])
                if ub <= threshold:
                    continue
            # the knapsack stops once above threshold + margin, so ub is exact up to there
            ub = min(ub, p2 + _completion(newmask, w, budget - e2, threshold + margin - p2, order,
                                          profit, cin, reach, lastord, cend))
            if ub <= threshold:
                continue
            # the labels of the same point and set: find the list's slot
            slot = np.int64(_key_hash(w, newmask) & np.uint64(tsize - 1))
            while table[slot] >= 0:
                j = table[slot]
                same = node[j] == w
                if same:
                    for k in range(W):
                        if mask[j, k] != newmask[k]:
                            same = False
                            break
                if same:
                    break
                slot = (slot + 1) & (tsize - 1)
            head = table[slot]
            dominated = False
            j = head
            while j >= 0:
                if alive[j]:
                    if en[j] <= e2 + EPS and pr[j] - _sigsum(srb[j] & ~s2, sig) >= p2 - EPS:
                        dominated = True
                        break
                    if e2 <= en[j] + EPS and p2 - _sigsum(s2 & ~srb[j], sig) >= pr[j] - EPS:
                        alive[j] = False  # never extended: it has more energy than the new one
                j = nxt[j]
            if dominated:
                continue
            if count == max_labels:
                hit = True
                break
            if (count & 4095) == 0:
                with objmode(now="float64"):
                    now = time.perf_counter()
                if now > deadline:
                    hit = True
                    break
            if count == cap:
                cap *= 2
                node = _grow(node, cap)
                pred = _grow(pred, cap)
                en = _grow(en, cap)
                pr = _grow(pr, cap)
                alive = _grow(alive, cap)
                mask = _grow(mask, cap)
                srb = _grow(srb, cap)
                nxt = _grow(nxt, cap)
                hkey = _grow(hkey, cap)
                hval = _grow(hval, cap)
            inner += ub > threshold + margin
            node[count] = w
            pred[count] = qi
            en[count] = e2
            pr[count] = p2
            alive[count] = True
            srb[count] = s2
            for k in range(W):
                mask[count, k] = newmask[k]
            nxt[count] = head
            table[slot] = count
            if head < 0:
                used += 1
                if 2 * used > tsize:  # keep the table at most half full
                    tsize *= 2
                    new = np.full(tsize, -1, np.int32)
                    for s0 in range(tsize // 2):
                        h0 = table[s0]
                        if h0 < 0:
                            continue
                        t0 = np.int64(_key_hash(node[h0], mask[h0]) & np.uint64(tsize - 1))
                        while new[t0] >= 0:
                            t0 = (t0 + 1) & (tsize - 1)
                        new[t0] = h0
                    table = new
            hn = _heap_push(hkey, hval, hn, e2, count)
            count += 1
        if hit:
            break
    return (count, node[:count], pred[:count], en[:count], pr[:count], mask[:count],
            alive[:count], hit, inner)


class Enumerated(NamedTuple):
    """Outcome of :func:`enumerate_routes`: the routes (one per visited set) as rows of solver
    points without start and end, padded with -1 (None when a cap or the deadline stopped the
    search), and the labels made; of those, the labels whose bounds also clear the threshold
    plus the ``margin`` and the routes whose best ordering does (``inner_routes``, exact: the
    routes a listing at that threshold would give)."""

    paths: np.ndarray | None
    n_labels: int
    inner_labels: int = 0
    inner_routes: int = 0

    def growth(self) -> tuple[float, float]:
        """Labels and routes of this listing over those ``margin`` further in: how many times
        more a listing ``margin`` wider would make, if they grow geometrically (inf when nothing
        lies that far in)."""
        routes = 0 if self.paths is None else len(self.paths)
        return (self.n_labels / self.inner_labels if self.inner_labels else np.inf,
                routes / self.inner_routes if self.inner_routes else np.inf)

    @property
    def routes(self) -> list | None:
        """The routes as tuples of solver points (None as ``paths``)."""
        if self.paths is None:
            return None
        return [tuple(row[row >= 0].tolist()) for row in self.paths]


def enumerate_routes(cost, profit, allowed, budget, threshold, *, ng=None, cut_members=None,
                     cut_memory=None, cut_duals=None, max_labels=5_000_000,
                     max_routes=300_000, deadline=np.inf, margin=0.0) -> Enumerated:
    """Every elementary route start -> ... -> end of energy <= ``budget`` whose prize (sum of
    ``profit`` over its points, the cuts' duals paid as in the pricing) exceeds ``threshold``,
    one per set of points. ``cost`` has removed arcs at inf; ``allowed``: the points a route may
    visit. None (in ``routes``) when more than ``max_labels`` labels or ``max_routes`` routes
    would be needed, or at the ``deadline``. ``margin``: also count the labels and routes that
    clear ``threshold + margin`` (:meth:`Enumerated.growth`).

    With ``ng`` (ng sets) a backward exact ng-labelling over the whole budget first tabulates
    the best suffix from each point by energy (:func:`.pricing._label_table`, the cuts' duals
    paid): every suffix of a path above the threshold is dominated by one of its labels, so a
    path whose prefix's prize plus the suffix bound of its next point does not exceed the
    threshold has no route to list (a cut's pairs along a route are at least those of its
    prefix plus those of its suffix, so splitting never undercounts the duals). Much tighter
    than the knapsack and DP bounds alone."""
    n = cost.shape[0]
    cost = np.ascontiguousarray(cost, dtype=np.float64)
    profit = np.ascontiguousarray(profit, dtype=np.float64)
    if cut_members is None or cut_duals is None or not np.any(np.asarray(cut_duals) > 0):
        cmem = np.zeros(n, np.uint64)
        mmem = np.zeros(n, np.uint64)
        sig = np.zeros((8, 256))
    else:
        duals = np.asarray(cut_duals, dtype=np.float64)
        active = np.uint64(0)
        for c in np.flatnonzero(duals > 0):
            active |= np.uint64(1) << np.uint64(c)
        cmem = np.ascontiguousarray(np.asarray(cut_members, dtype=np.uint64) & active)
        mmem = (np.full(n, np.uint64(0xFFFFFFFFFFFFFFFF), dtype=np.uint64) if cut_memory is None
                else np.ascontiguousarray(cut_memory, dtype=np.uint64))
        sig = _byte_sums(np.where(duals > 0, duals, 0.0))
    sfx, sdelta, snb = np.zeros((n, 1)), 1.0, 0
    if ng is not None:
        delta, nb = _dp_unit(cost, budget, DP_UNITS)
        if nb > 0:
            perm, cost_b, profit_b, allowed_b = _reversed(cost, profit, allowed)
            bwd = _label_table(cost_b, profit_b, budget, ng, allowed_b, threshold, max_labels,
                               deadline, delta, nb, cuts=(cmem[perm], mmem[perm], sig))
            if bwd is None:
                return Enumerated(None, max_labels)
            sfx, sdelta, snb = np.ascontiguousarray(bwd[0][perm]), delta, nb
    ret = cheapest_return(cost)
    order, cin, reach, lastord, cend = _prepare(cost, ret, profit, allowed)
    count, node, pred, en, pr, mask, _, hit, inner = _enumerate(
        cost, ret, profit, float(budget), allowed, order, cin, reach, lastord, cend,
        float(threshold), int(max_labels), float(deadline), cmem, mmem, sig,
        *suffix_tables(cost, profit, allowed, budget), sfx, float(sdelta), int(snb), float(margin))
    if hit:
        return Enumerated(None, int(count))
    end = n - 1
    done = np.flatnonzero((node > 0) & (en + cost[node, end] <= budget) & (pr > threshold))
    # one label per visited set (the cheapest; any would do for the master's column)
    done = done[np.argsort(en[done], kind="stable")]
    _, first, which = np.unique(mask[done], axis=0, return_index=True, return_inverse=True)
    best = np.full(first.size, -np.inf)
    np.maximum.at(best, which.ravel(), pr[done])  # the set's best ordering
    done = done[np.sort(first)]
    if done.size > max_routes:
        return Enumerated(None, int(count))
    counts = (int(count), int(inner), int(np.sum(best > threshold + margin)))
    # the paths, all at once: walk the predecessors back level by level (last point first)
    levels = []  # (routes still walking, their point at this level)
    cur = done.copy()
    live = np.arange(done.size)
    while live.size:
        levels.append((live, node[cur]))
        cur = pred[cur]
        keep = cur > 0
        live, cur = live[keep], cur[keep]
    length = np.zeros(done.size, np.int64)
    for live, _ in levels:
        length[live] += 1
    paths = np.full((done.size, len(levels)), -1, np.int32)
    for k, (live, pts) in enumerate(levels):  # the k-th point from the end of each route
        paths[live, length[live] - 1 - k] = pts
    return Enumerated(paths, *counts)


def warm_up() -> None:
    """Compile (or load from numba's cache) the enumeration kernel on a tiny graph."""
    cost = np.array([[0.0, 1.0, 2.0], [1.0, 0.0, 1.0], [2.0, 1.0, 0.0]])
    enumerate_routes(cost, np.array([0.0, 1.0, 0.0]), np.ones(3, dtype=bool), 4.0, -1.0)


class Enumeration:
    """Closing the root gap by enumeration: :meth:`close` lists the routes that a plan better
    than the incumbent may use under the root certificate, tightens the LP over them
    (:class:`.enumerated_lp.EnumeratedLP`: full-memory cuts, reduced-cost filter) and solves the
    MILP over the routes left. It is tried once the root LP is solved, and again whenever the
    certificate or the incumbent has changed since the last try.

    The window (certificate bound - incumbent - one step) decides how: up to ``gap`` steps the
    listing is complete and its outcome a proof (no better plan, or the MILP's plan is
    optimal); above it, only the routes within ``primal_window`` steps of the best are listed
    (the threshold raised by the difference), and the MILP over them can only find a better
    plan. The plan one step above the incumbent has a total slack of the window over its
    routes, so most of its routes sit well inside a narrow window. A narrow try that finds no
    plan is followed by one ``WIDEN`` steps wider (with the same certificate and incumbent) if
    its labels and routes, times their growth at the narrow listing's rim (over its last
    ``WIDEN`` steps, or all of it if narrower, extrapolated geometrically to ``WIDEN`` steps:
    :meth:`Enumerated.growth`), stay within the caps; a try as wide as the window is complete.
    ``primal_window`` 0 turns the narrow tries off. ``limit``: seconds per try;
    ``max_labels``, ``max_routes``: the caps beyond which a listing gives up;
    ``milp_routes``: cut rounds stop once this few routes are left; ``cuts_per_round``:
    triples per round."""

    WIDEN = 0.1  # steps added to a narrow window that listed no better plan
    STALL = 0.002  # cut rounds stop when a round lowers the LP by less than this many steps
    # the MILP is only tried over at most this many routes: over 60 827 (M = 20, K = 4 seed
    # 111) HiGHS ran 150 s past a 100 s time limit, and every proof so far came from < 12 000
    MILP_MAX = 20_000

    def __init__(self, search: "Search", elimination: "Elimination",
                 incumbents: "IncumbentSearch", *, limit: float, gap: float, max_labels: int,
                 max_routes: int, primal_window: float = 0.0, milp_routes: int = 5000,
                 cuts_per_round: int = 50):
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
        self._tried = None  # (certificate, incumbent value) of the last try
        self._wider = None  # the next narrow window to try with them (None: nothing left)

    def window(self) -> float | None:
        """Certificate bound - incumbent - one step, in prize steps: the slack a plan one step
        better than the incumbent leaves its routes. None when there is nothing to try: no
        certificate or incumbent, no time, no better plan possible, or every try with this
        certificate and incumbent done."""
        s, elim = self.search, self.elimination
        if elim.rc_floor() is None or s.time_left() <= 0:
            return None
        if self._tried == (elim.cert, s.incumbent_value) and self._wider is None:
            return None
        window = (elim.cert.bound - s.incumbent_value - s.step) / s.step
        if window < 0 or (window > self.gap and self.primal_window <= 0):
            return None
        return window

    def close(self) -> bool:
        """One try; True when it proved the incumbent (possibly a new one, the MILP's) optimal.
        """
        s, elim, m = self.search, self.elimination, self.search.master
        window = self.window()
        if window is None:
            return False
        cert = elim.cert
        width = self.primal_window if self._tried != (cert, s.incumbent_value) else self._wider
        complete = window <= max(self.gap, width)
        self._tried, self._wider = (cert, s.incumbent_value), None
        floor = elim.rc_floor()
        if not complete:  # only the routes within ``width`` steps of the best
            floor += (window - width) * s.step
        t = time.perf_counter()
        deadline = min(s.deadline, t + self.limit)
        y = cert.duals
        cost, _, allowed = node_graph(s, NodeState())
        sig = np.zeros(len(m.cuts))
        cut = np.maximum(y[m.base_rows :], 0.0)[: len(m.cuts)]
        sig[: cut.size] = cut
        st = s.stats
        st.enum_tries += 1
        try:
            res = enumerate_routes(cost, m.point_profit(y), allowed, s.budget, y[0] + floor,
                                   ng=s.ng, cut_members=m.cut_members, cut_memory=m.cut_memory,
                                   cut_duals=sig, max_labels=self.max_labels,
                                   max_routes=self.max_routes, deadline=deadline,
                                   margin=self._counted(width) * s.step)
        except MemoryError:  # a process memory limit below what the label cap allows
            st.enum_memory += 1
            return False
        finally:
            st.enum_s += time.perf_counter() - t
        st.enum_complete += complete
        st.enum_labels = res.n_labels
        st.enum_routes = None if res.paths is None else len(res.paths)
        growth = self._growth(width, res)[0] if res.paths is not None else np.inf
        st.enum_growth = round(growth, 3) if np.isfinite(growth) else None
        if res.paths is None:
            return False
        need = s.incumbent_value + (s.step if s.integral else 1e-9)
        t = time.perf_counter()
        try:
            lp = EnumeratedLP(m, res.paths, cuts=zip(m.cuts, m.memories))
            none_listed = self._tighten(lp, need, y, deadline)
        except MemoryError:
            st.enum_memory += 1
            return False
        finally:
            st.enum_lp_s += time.perf_counter() - t
        st.enum_left = len(lp)
        if none_listed:  # no plan worth need among the listed routes
            st.enum_status = "infeasible"
            if not complete:
                self._widen(width, res)
            return complete
        if time.perf_counter() >= deadline or len(lp) > self.MILP_MAX:
            return False
        t = time.perf_counter()
        status, plan = lp.milp(need, deadline - t)
        st.enum_milp_s += time.perf_counter() - t
        st.enum_status = status
        if plan is not None:
            before = s.incumbent_value
            m.add_routes(plan)  # columns for the tree's LPs and dives too
            self.incumbents.offer(plan)
            st.enum_improved += s.incumbent_value > before
        if not complete:
            if status == "infeasible":  # no better plan among the listed routes
                self._widen(width, res)
            return False
        if status == "infeasible":
            return True
        if status == "optimal" and plan is not None:
            value = float(np.sum([m.prizes[np.asarray(r) - 1].sum() for r in plan]))
            return s.incumbent_value >= value - 1e-6
        return False

    def _widen(self, width: float, res: "Enumerated") -> None:
        """After a narrow try that listed no better plan: the next, ``WIDEN`` steps wider, if
        its labels and routes would stay within the caps, were they to grow as at the narrow
        listing's rim (:meth:`_growth`)."""
        labels, routes = self._growth(width, res)
        if (res.n_labels * labels <= self.max_labels
                and len(res.paths) * routes <= self.max_routes):
            self._wider = width + self.WIDEN

    def _counted(self, width: float) -> float:
        """The steps at the rim of a ``width``-wide listing over which it counts its growth."""
        return min(self.WIDEN, width) if width > 0 else self.WIDEN

    def _growth(self, width: float, res: "Enumerated") -> tuple[float, float]:
        """Labels and routes: how many times more a listing ``WIDEN`` steps wider than ``res``
        (``width`` steps wide) would make, growing geometrically as over its rim."""
        power = self.WIDEN / self._counted(width)
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
            st.enum_lp_bound = bound = out.bound(s.N)
            if bound < need - 1e-6:
                return True
            new = lp.separate(out.x, self.cuts_per_round)  # before the filter renumbers routes
            lp.keep(out.rc >= out.floor(need, s.N))
            if (len(lp) <= self.milp_routes or not new or time.perf_counter() >= deadline
                    or last - bound < self.STALL * s.step):
                return False
            last = bound
            st.enum_cuts += lp.add_cuts([(S, None) for S in new])
