"""Pricing for the route master: a labelling algorithm for the resource-constrained path.

The pricing problem: over paths start -> nodes -> end whose energy (sum of arc costs c_ij =
e_fly·d_ij + e_image·[j node]) stays within the budget, maximise the sum of node *reduced* prizes
(the master's duals subtracted). Energy is the only resource; the prize lives on nodes.

One compiled routine (numba) serves three uses, chosen by its arguments:

* **exact elementary** (``ng`` = all nodes for every node): a label is (node, energy, prize,
  visited set); L1 dominates L2 at the same node if e1 <= e2, p1 >= p2 and visited1 ⊆ visited2.
* **ng-route relaxation** (``ng[w]`` = a small neighbourhood of w): the remembered set is
  intersected with ng[w] on arrival at w, so some cycles are allowed. Every elementary path is
  still an ng-path, so the best ng-path prize is an upper bound on the best elementary one: the
  master bound stays valid. Improving elementary paths are returned as ``routes``, improving
  non-elementary ones as ``ng_routes`` (the master takes both, with visit counts) and their
  repeated segments as ``cycles`` (for growing the ng sets).
* **heuristic** (``heuristic=True``): dominance ignores the remembered sets, so there are few
  labels per node; fast, finds improving columns, proves nothing.

Pruning: a label whose prize plus a bound on what it can still add (:mod:`.bounds`: the
completion bound, a fractional knapsack over the nodes it has not remembered that still fit, and
the suffix tables) cannot exceed the threshold is dropped.
The threshold starts at ``min_gain`` (the vehicle dual, or more for a targeted call) and, in exact
mode, rises with the best complete path found so far (to it, or a ``keep`` share of its gain below
it, which also returns the near-best routes). The value reported is max(best path found,
starting threshold): an upper bound on the best *elementary* path (an elementary path's suffix
visits distinct nodes that are not in the remembered set of any label dominating its prefix, so the
once-per-node knapsack bounds it), which is all the master's bound needs.

Search order and data layout: labels are extended in order of energy (a binary heap), so a label
is only extended once every label of lower energy exists: it is never dominated after its
extensions were made (far fewer labels than FIFO order). For the dominance tests the alive labels
of each point sit in energy sub-buckets (:func:`sub_buckets`: equal slices of the budget, more
of them the more labels a call makes per point), each held in contiguous arrays (energy, prize,
remembered set, cut parities, id) sorted by prize, best first. A candidate can only be
dominated by a label of no more energy and no less prize: the heads of the sub-buckets up to its
energy, down to its prize; it can only dominate the tails of the sub-buckets from its energy on.
Most labels of a point fail one of the two scalar tests, and this layout never visits them. Paths
are kept in creation order.

Bidirectional mode (exact only): the same routine runs forward from the start and backward from
the end (on the reversed graph), extending labels only up to half the budget, and the halves are
joined through one arc (see :func:`price`), with or without subset-row cuts (the join pays the
cut pairs it makes). The branch-and-price picks the direction by timing.

A label is only created if the end is still reachable within the budget (``ret`` = cheapest
energy to the end in the allowed graph), so every stored label is a complete route candidate:
its route is its path followed by the end. Sets are bitsets of ``W`` 64-bit words.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from sarcover.formulations.bp._label_store import (chain, extend, grow, grow_store, heap_push,
                                                   new_store, next_label, out_of_time,
                                                   write_label)
from sarcover.formulations.bp.bounds import (completion_bound, completion_data, dp_bound,
                                             relaxed_best, suffix_tables)
from sarcover.formulations.bp.constants import EPS
from sarcover.formulations.bp.cut_duals import cut_arrays, sigsum
from sarcover.formulations.bp.graph import cheapest_return, reversed_graph

NSUB = 32  # energy sub-buckets per point when the call's size is unknown
NSUB_RANGE = (16, 256)  # the sub-buckets per point a label count may choose
SUB_CELLS = 16384  # at most this many sub-buckets in all (their arrays are allocated per call)


def sub_buckets(n_points: int, labels: int | None = None) -> int:
    """Energy sub-buckets per point of the labelling's dominance layout on ``n_points``.

    ``labels``: the labels the call is expected to make (the run's previous exact call), or None
    for ``NSUB``. A dominance test visits every sub-bucket on its side of the candidate's energy
    and the labels of the one its energy falls in whose prize passes, so the best count grows
    with the labels per point: about 1.5·sqrt(labels per point), as a power of two within
    ``NSUB_RANGE`` (replayed exact calls: 32 was best up to about 1 000 labels per point, 64
    around 1 500, 128 from about 4 000)."""
    s = NSUB
    if labels:
        s = 2 ** round(math.log2(1.5 * math.sqrt(labels / n_points)))
        s = min(max(s, NSUB_RANGE[0]), NSUB_RANGE[1])
    return max(1, min(s, SUB_CELLS // n_points))


@njit(cache=True)
def _sub(e, budget, S):
    """Energy sub-bucket (of ``S`` equal slices of the budget) of a label of energy ``e``."""
    k = int(e * S / budget) if budget > 0 else 0
    if k < 0:
        return 0
    if k >= S:
        return S - 1
    return k


@njit(cache=True)
def label_search(cost, ret, profit, budget, ng, allowed, heuristic, max_labels, order, cin,
                 reach, lastord, cend, threshold, deadline, half, cmem, mmem, sig, g1, s1, g2,
                 delta, nb, keep, nsub):
    """Labelling from node 0 to node n-1.

    Returns (count, node, pred, energy, prize, mask, alive, hit_cap, threshold, cut parities).
    Labels whose prize plus the completion bound cannot exceed ``threshold`` are not stored. In
    exact mode the threshold rises with the best complete path found, to
    ``best - keep * (best - start)`` (``start``: the threshold given): ``keep`` = 0 prunes against
    the best path itself (the best value, few other routes), ``keep`` > 0 keeps the routes within
    that share of the best's gain over the start (more columns per call, more labels), 1 never
    raises it; only labels with energy <= ``half`` are extended (``half`` = budget for a one-way
    search). Labels are kept in creation order (global arrays, for the paths) and, for the
    dominance tests, in ``nsub`` contiguous sub-buckets per point by energy (energy, prize, mask,
    cut parities, label id), each sorted by prize, best first (see the module docstring).

    Limited-memory subset-row cuts (``cmem[w]``: bitset of the cuts whose triple holds w;
    ``mmem[w]``: of the cuts whose memory holds w, a superset; ``sig``: their duals, >= 0): a
    label carries the parity of its visits to each cut's triple, forgotten on arrival at a point
    outside the cut's memory; a visit that makes a pair pays the cut's dual. L1 dominates L2 only
    if it still wins after paying the duals of the cuts where L1 holds an odd visit and L2 does
    not (Jepsen et al. 2008; limited memory: Pecin et al. 2017).
    """
    n = cost.shape[0]
    end = n - 1
    W = ng.shape[1]
    start = threshold
    # labels are extended in order of energy (a binary heap): when a label is extended, every
    # label of lower energy already exists, so it is never dominated after being extended
    node, pred, en, pr, alive, mask, srb, hkey, hval = new_store(W)
    hn = 1
    count = 1
    hit = False
    # the alive labels of each point w, in its sub-buckets w*S .. w*S+S-1 (by energy), each
    # sorted by prize, best first
    S = nsub
    bcnt = np.zeros(n * S, np.int64)
    ben = [np.empty(0, np.float64) for _ in range(n * S)]
    bpr = [np.empty(0, np.float64) for _ in range(n * S)]
    bid = [np.empty(0, np.int32) for _ in range(n * S)]
    bmask = [np.zeros((0, W), np.uint64) for _ in range(n * S)]
    bsr = [np.zeros(0, np.uint64) for _ in range(n * S)]
    newmask = np.zeros(W, np.uint64)
    while True:
        qi, hn = next_label(hkey, hval, hn, alive)
        if qi < 0:
            break
        v = node[qi]
        if en[qi] > half:
            continue
        # the threshold may have risen since this label was stored. Whatever the label's
        # predecessor, g1 (not g2): the label may stand in for a label it dominates whose best
        # suffix starts with this label's predecessor
        if pr[qi] + dp_bound(g1, s1, g2, v, -1, budget - en[qi], delta, nb) <= threshold:
            continue
        if pr[qi] + completion_bound(mask[qi], v, budget - en[qi], threshold - pr[qi], order,
                                     profit, cin, reach, lastord, cend) <= threshold:
            continue
        for w in range(1, end):
            wd = w >> 6
            fits, e2, p2, paired, s2 = extend(en[qi], pr[qi], srb[qi], mask[qi, wd], w,
                                              allowed[w], cost[v, w], ret[w], budget, profit[w],
                                              mmem[w], cmem[w])
            if not fits:
                continue
            if paired:
                p2 -= sigsum(paired, sig)
            for k in range(W):
                newmask[k] = mask[qi, k] & ng[w, k]  # remembered at w: its ng set, and w
            newmask[wd] |= np.uint64(1) << np.uint64(w & 63)
            if p2 + dp_bound(g1, s1, g2, w, v, budget - e2, delta, nb) <= threshold:
                continue
            if p2 + completion_bound(newmask, w, budget - e2, threshold - p2, order, profit, cin,
                                     reach, lastord, cend) <= threshold:
                continue
            # dominance against the labels at w (sub-buckets by energy, each best prize first):
            # a dominator has energy <= e2 and prize >= p2, so it is in the head of a sub-bucket
            # up to e2's (nearest first); a label the new one dominates has energy >= e2 and
            # prize <= p2: the tail of a sub-bucket from e2's on
            dominated = False
            shi = _sub(e2 + EPS, budget, S)
            slo = _sub(e2 - EPS, budget, S)
            for sx in range(shi, -1, -1):
                bx = w * S + sx
                cw = bcnt[bx]
                if cw == 0:
                    continue
                we = ben[bx]
                wp = bpr[bx]
                wm = bmask[bx]
                ws = bsr[bx]
                j = 0
                while j < cw and wp[j] >= p2 - EPS:
                    if we[j] <= e2 + EPS:
                        sub = True
                        if not heuristic:
                            for k in range(W):
                                if wm[j, k] & ~newmask[k]:
                                    sub = False
                                    break
                        if sub:
                            odd = ws[j] & ~s2
                            if odd and wp[j] - sigsum(odd, sig) < p2 - EPS:
                                sub = False
                        if sub:
                            dominated = True
                            break
                    j += 1
                if dominated:
                    break
            if dominated:
                continue
            for sx in range(slo, S):
                bx = w * S + sx
                cw = bcnt[bx]
                if cw == 0:
                    continue
                we = ben[bx]
                wp = bpr[bx]
                wi = bid[bx]
                wm = bmask[bx]
                ws = bsr[bx]
                j = cw - 1
                while j >= 0 and wp[j] <= p2 + EPS:
                    if e2 <= we[j] + EPS:
                        sub = True
                        if not heuristic:
                            for k in range(W):
                                if newmask[k] & ~wm[j, k]:
                                    sub = False
                                    break
                        if sub:
                            odd = s2 & ~ws[j]
                            if odd and p2 - sigsum(odd, sig) < wp[j] - EPS:
                                sub = False
                        if sub:
                            alive[wi[j]] = False
                            cw -= 1  # close the gap, keeping the order
                            for i in range(j, cw):
                                we[i] = we[i + 1]
                                wp[i] = wp[i + 1]
                                wi[i] = wi[i + 1]
                                ws[i] = ws[i + 1]
                                for k in range(W):
                                    wm[i, k] = wm[i + 1, k]
                    j -= 1
                bcnt[bx] = cw
            if count == max_labels or ((count & 4095) == 0 and out_of_time(deadline)):
                hit = True
                break
            if count == node.shape[0]:
                node, pred, en, pr, alive, mask, srb, hkey, hval = grow_store(
                    node, pred, en, pr, alive, mask, srb, hkey, hval)
            write_label(node, pred, en, pr, alive, mask, srb, count, w, qi, e2, p2, s2, newmask)
            hn = heap_push(hkey, hval, hn, e2, count)
            if not heuristic and p2 > threshold and e2 + cost[w, end] <= budget:
                # exact mode looks for the best path: prune against (nearly) the best found
                t2 = p2 - keep * (p2 - start)
                if t2 > threshold:
                    threshold = t2
            bx = w * S + _sub(e2, budget, S)
            cw = bcnt[bx]
            if cw == ben[bx].shape[0]:
                size = max(2 * cw, 8)
                bsr[bx] = grow(bsr[bx], size)
                ben[bx] = grow(ben[bx], size)
                bpr[bx] = grow(bpr[bx], size)
                bid[bx] = grow(bid[bx], size)
                bmask[bx] = grow(bmask[bx], size)
            we = ben[bx]
            wp = bpr[bx]
            wi = bid[bx]
            wm = bmask[bx]
            ws = bsr[bx]
            j = cw  # keep the sub-bucket sorted by prize, best first
            while j > 0 and wp[j - 1] < p2:
                we[j] = we[j - 1]
                wp[j] = wp[j - 1]
                wi[j] = wi[j - 1]
                ws[j] = ws[j - 1]
                for k in range(W):
                    wm[j, k] = wm[j - 1, k]
                j -= 1
            we[j] = e2
            wp[j] = p2
            wi[j] = count
            ws[j] = s2
            for k in range(W):
                wm[j, k] = newmask[k]
            bcnt[bx] = cw + 1
            count += 1
        if hit:
            break
    return (count, node[:count], pred[:count], en[:count], pr[:count], mask[:count],
            alive[:count], hit, threshold, srb[:count])


@njit(cache=True)
def _join(fnode, fen, fpr, fmask, falive, fsr, bnode, ben, bpr, bmask, bsr, bstart, border,
          cost, budget, half, threshold, max_pairs, sig):
    """Join forward labels (energy <= half) with backward labels through one arc.

    Backward labels of point u are ``border[bstart[u]:bstart[u+1]]`` sorted by prize, best
    first (the end's own root label included). Returns the pairs worth more than the (rising)
    threshold and the final threshold.

    Subset-row cuts: ``fsr``/``bsr`` are the labels' cut parities (:func:`label_search`, the backward
    ones counted from the end). A cut odd on both sides has its last forward visit and first
    backward visit in one stretch of its memory (a parity is forgotten at any point outside
    it, and both ends of the joining arc are then inside), so the joined path makes one more
    pair and pays the cut's dual once more. Each half has paid its own pairs already; a path's
    pairs per stretch of memory do not depend on the direction it is counted in.
    """
    n = cost.shape[0]
    W = fmask.shape[1]
    pf = np.empty(max_pairs, np.int64)
    pb = np.empty(max_pairs, np.int64)
    val = np.empty(max_pairs, np.float64)
    k = 0
    for f in range(fnode.shape[0]):
        if not falive[f] or fen[f] > half:
            continue
        v = fnode[f]
        for u in range(1, n):
            if u == v:
                continue
            room = budget - fen[f] - cost[v, u]
            if not room >= 0.0:
                continue
            for t in range(bstart[u], bstart[u + 1]):
                b = border[t]
                if fpr[f] + bpr[b] <= threshold:
                    break
                if ben[b] > room:
                    continue
                ok = True
                for q in range(W):
                    if fmask[f, q] & bmask[b, q]:
                        ok = False
                        break
                if not ok:
                    continue
                pair = fpr[f] + bpr[b]
                both = fsr[f] & bsr[b]
                if both:
                    pair -= sigsum(both, sig)
                    if pair <= threshold:
                        continue
                if k < max_pairs:
                    pf[k] = f
                    pb[k] = b
                    val[k] = pair
                    k += 1
                threshold = pair
    return pf[:k], pb[:k], val[:k], threshold


class PricingResult:
    """Outcome of one pricing call: the best reduced prize over the searched path set, whether
    that value is proven (exact search over a relaxation of the elementary routes), and the
    improving elementary routes found (solver indices, without start and end). ``relaxed``: an
    upper bound on the best elementary path's reduced prize that holds whether or not the search
    finished (the suffix tables' best walk from the start, :func:`.bounds.suffix_dp`, cut duals
    left unpaid); +inf when the tables are off. ``stopped``: the search stopped before it was
    done (its label cap or its deadline), in either mode."""

    __slots__ = ("best", "exact", "routes", "cycles", "n_labels", "ng_routes", "relaxed", "stopped")

    def __init__(self, best, exact, routes, cycles, n_labels, ng_routes=(), relaxed=np.inf,
                 stopped=False):
        self.best = best
        self.exact = exact
        self.routes = routes
        self.cycles = cycles
        self.n_labels = n_labels
        self.ng_routes = ng_routes
        self.relaxed = relaxed
        self.stopped = stopped


def label_table(cost, profit, budget, ng, allowed, threshold, max_labels, deadline, delta, nb,
                n_routes=0, cuts=None):
    """``t[v, b]``: the best prize of a label at v of energy <= b units, over the labels of a
    one-way exact ng-labelling with the fixed ``threshold``, and up to ``n_routes`` elementary
    routes above the threshold (best first, one per set of points); None if it hit a cap.
    ``cuts``: (cut members, cut memory, byte sums of the duals) as :func:`label_search` takes
    them (:func:`.cut_duals.cut_arrays`); None: no cuts. The tables have units of ``delta``,
    ``nb`` + 1 of them (:func:`.bounds.dp_unit`)."""
    n = cost.shape[0]
    end = n - 1
    ret = cheapest_return(cost)
    order, cin, reach, lastord, cend = completion_data(cost, ret, profit, allowed)
    if cuts is None:
        cuts = cut_arrays(n, None, None, None)
    count, node, pred, en, pr, _, _, hit, _, _ = label_search(
        cost, ret, profit, budget, ng, allowed, False, max_labels, order, cin, reach, lastord,
        cend, float(threshold), float(deadline), float(budget), *cuts,
        *suffix_tables(cost, profit, allowed, budget), 1.0, sub_buckets(n),
    )
    if hit:
        return None
    table = np.full((n, nb + 1), -np.inf)
    units = np.minimum((en / delta + 1e-9).astype(np.int64), nb)
    np.maximum.at(table, (node, units), pr)
    routes, sets = [], set()
    if n_routes <= 0:  # the backward search: only its table is wanted
        return np.maximum.accumulate(table, axis=1), routes
    done = (node > 0) & (en + cost[node, end] <= budget) & (pr > threshold)
    cand = np.flatnonzero(done)
    for li in cand[np.argsort(-pr[cand], kind="stable")]:
        if len(routes) >= n_routes:
            break
        path = tuple(chain(node, pred, int(li)))
        key = frozenset(path)
        if len(key) == len(path) and key not in sets:
            sets.add(key)
            routes.append(path)
    return np.maximum.accumulate(table, axis=1), routes


def price(cost, ret, profit, budget, ng, allowed, *, heuristic, max_labels, n_cols, min_gain,
          deadline=np.inf, bidirectional=False, cut_members=None, cut_memory=None, cut_duals=None,
          keep=0.0, nsub=None):
    """Run the labelling; return a :class:`PricingResult`.

    ``profit`` holds the reduced prize of every point (0 at start and end); the value reported is
    the best path prize (the caller subtracts the vehicle dual). ``routes`` are up to ``n_cols``
    elementary paths with prize > ``min_gain``, best first; ``cycles`` lists, for the best
    non-elementary ng-paths, their repeated segments (to grow the ng sets).

    Bidirectional search: forward labels from the start and backward labels from the end (the
    same labelling on the reversed graph) are extended only while their energy is <= budget/2,
    then joined through one arc. Every path splits at its last arc leaving a forward prefix of
    energy <= budget/2; its suffix then has energy < budget/2, so both halves (or labels that
    dominate them) exist and their join is examined.

    Subset-row cuts: ``cut_members[w]`` is the bitset of the (at most 64) cuts whose triple holds
    point w, ``cut_memory[w]`` of those whose memory holds it (None: every cut remembers every
    point), ``cut_duals`` their duals; a path's prize is then its reduced prize with the cuts'
    duals paid, in either direction (:func:`_join` pays the pairs a join makes).

    ``keep`` (exact mode): how far below the best path found the pruning threshold stays, as a
    share of the best's gain over ``min_gain`` (:func:`label_search`); 0 finds the best value with the
    fewest labels, more returns more of the near-best routes. The best value is exact either way.
    A bidirectional search's backward half starts from the forward half's final threshold, so its
    share is measured from there.

    ``nsub``: energy sub-buckets per point for the dominance tests (None: :func:`sub_buckets`);
    it changes only how fast the labels are found, not which.
    """
    n = cost.shape[0]
    nsub = sub_buckets(n) if nsub is None else max(1, int(nsub))
    cmem, mmem, sig = cut_arrays(n, cut_members, cut_memory, cut_duals)
    end = n - 1
    half = budget / 2.0 if bidirectional else budget
    order, cin, reach, lastord, cend = completion_data(cost, ret, profit, allowed)
    tables = suffix_tables(cost, profit, allowed, budget)
    count, node, pred, en, pr, fmask, falive, hit, thr, fsr = label_search(
        cost, ret, profit, budget, ng, allowed, heuristic, max_labels, order, cin, reach,
        lastord, cend, float(min_gain), float(deadline), half, cmem, mmem, sig,
        *tables, float(keep), nsub,
    )
    total = int(count)
    found = []  # (value, path)
    ok = (node > 0) & (en + cost[node, end] <= budget)
    cand = np.flatnonzero(ok & (pr > min_gain))
    for li in cand[np.argsort(-pr[cand], kind="stable")][: 4 * n_cols]:
        found.append((float(pr[li]), chain(node, pred, int(li))))
    best = float(pr[ok].max()) if ok.any() else 0.0
    if bidirectional and not hit:
        perm, cost_b, profit_b, allowed_b = reversed_graph(cost, profit, allowed)
        ret_b = cheapest_return(cost_b)
        order_b, cin_b, reach_b, lastord_b, cend_b = completion_data(cost_b, ret_b, profit_b, allowed_b)
        bcount, bnode, bpred, ben, bpr, bmask, balive, bhit, thr, bsr = label_search(
            cost_b, ret_b, profit_b, budget, ng, allowed_b, heuristic, max_labels, order_b, cin_b,
            reach_b, lastord_b, cend_b, float(thr), float(deadline), half, cmem[perm], mmem[perm], sig,
            *suffix_tables(cost_b, profit_b, allowed_b, budget), float(keep), nsub,
        )
        total += int(bcount)
        hit = hit or bhit
        bok = (bnode > 0) & (ben + cost_b[bnode, end] <= budget)
        if bok.any():
            best = max(best, float(bpr[bok].max()))
        cand = np.flatnonzero(bok & (bpr > min_gain))
        for li in cand[np.argsort(-bpr[cand], kind="stable")][: 2 * n_cols]:
            found.append((float(bpr[li]), chain(bnode, bpred, int(li))[::-1]))
        # backward labels grouped by original point (the root, point 0 here, is the end)
        point = np.where(bnode == 0, end, bnode)
        keep = np.flatnonzero(balive)
        keep = keep[np.lexsort((-bpr[keep], point[keep]))]
        bstart = np.searchsorted(point[keep], np.arange(n + 1)).astype(np.int64)
        pf, pb, val, thr = _join(node, en, pr, fmask, falive, fsr, bnode, ben, bpr, bmask, bsr,
                                 bstart, keep.astype(np.int64), cost, budget, half, float(thr),
                                 4 * n_cols, sig)
        if val.size:
            best = max(best, float(val.max()))
        for f, b, v in zip(pf, pb, val):
            if v > min_gain:
                found.append((float(v), chain(node, pred, int(f)) + chain(bnode, bpred, int(b))[::-1]))
    # Paths pruned by the completion bound are worth at most min_gain; the empty route is 0.
    best = max(best, 0.0, float(min_gain))
    found.sort(key=lambda t: -t[0])
    routes, cycles, ng_routes, seen = [], [], [], set()
    for _, path in found:
        key = tuple(path)
        if key in seen:
            continue
        seen.add(key)
        if len(set(path)) == len(path):
            routes.append(key)
            if len(routes) >= n_cols:
                break
        else:
            if len(ng_routes) < n_cols:
                ng_routes.append(key)
            if len(cycles) < 20:
                last = {}
                for pos, u in enumerate(path):
                    if u in last:
                        cycles.append(tuple(path[last[u] : pos + 1]))
                    last[u] = pos
    return PricingResult(best, (not hit) and (not heuristic), routes, cycles, total, ng_routes,
                         relaxed_best(*tables, budget), bool(hit))

