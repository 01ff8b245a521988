"""The route enumeration's kernel: every elementary route whose prize (after the cuts' duals)
beats a fixed threshold, one per set of points (:func:`enumerate_routes`).

A labelling from the start over elementary paths (full visited sets), where a label is only
dominated by a label at the same point with the *same* visited set (no less prize after the cuts'
duals, no more energy), and pruned by the pricing's completion and suffix bounds
(:mod:`.bounds`) against the fixed threshold. It shares the label store of the pricing's
labelling (:mod:`._label_store`). When and how the branch-and-price uses it:
:mod:`.enumeration`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit
from sarcover.formulations.bp._label_store import (extend, grow, grow_store, heap_push, new_store,
                                                   next_label, out_of_time, write_label)
from sarcover.formulations.bp.bounds import (DP_UNITS, completion_bound, completion_data, dp_bound,
                                             dp_unit, suffix_tables)
from sarcover.formulations.bp.constants import EPS
from sarcover.formulations.bp.cut_duals import cut_arrays, sigsum
from sarcover.formulations.bp.graph import cheapest_return, reversed_graph
from sarcover.formulations.bp.labelling import label_table


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
    node, pred, en, pr, alive, mask, srb, hkey, hval = new_store(W)
    hn = 1
    nxt = np.empty(node.shape[0], np.int32)
    nxt[0] = -1
    tsize = 1 << 12
    table = np.full(tsize, -1, np.int32)
    used = 0
    count = 1
    hit = False
    inner = 0
    newmask = np.zeros(W, np.uint64)
    end = n - 1
    while True:
        qi, hn = next_label(hkey, hval, hn, alive)
        if qi < 0:
            break
        v = node[qi]
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
                newmask[k] = mask[qi, k]
            newmask[wd] |= np.uint64(1) << np.uint64(w & 63)
            ub = p2 + dp_bound(g1, s1, g2, w, v, budget - e2, delta, nb)
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
            ub = min(ub, p2 + completion_bound(newmask, w, budget - e2, threshold + margin - p2, order,
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
                    if en[j] <= e2 + EPS and pr[j] - sigsum(srb[j] & ~s2, sig) >= p2 - EPS:
                        dominated = True
                        break
                    if e2 <= en[j] + EPS and p2 - sigsum(s2 & ~srb[j], sig) >= pr[j] - EPS:
                        alive[j] = False  # never extended: it has more energy than the new one
                j = nxt[j]
            if dominated:
                continue
            if count == max_labels or ((count & 4095) == 0 and out_of_time(deadline)):
                hit = True
                break
            if count == node.shape[0]:
                node, pred, en, pr, alive, mask, srb, hkey, hval = grow_store(
                    node, pred, en, pr, alive, mask, srb, hkey, hval)
                nxt = grow(nxt, node.shape[0])
            write_label(node, pred, en, pr, alive, mask, srb, count, w, qi, e2, p2, s2, newmask)
            inner += ub > threshold + margin
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
            hn = heap_push(hkey, hval, hn, e2, count)
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
    routes a listing at that threshold would give); ``values``: each listed set's best prize
    (after the cuts' duals) over the orders its labels reached, row for row with ``paths``."""

    paths: np.ndarray | None
    n_labels: int
    inner_labels: int = 0
    inner_routes: int = 0
    values: np.ndarray | None = None

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
    the best suffix from each point by energy (:func:`.labelling.label_table`, the cuts' duals
    paid): every suffix of a path above the threshold is dominated by one of its labels, so a
    path whose prefix's prize plus the suffix bound of its next point does not exceed the
    threshold has no route to list (a cut's pairs along a route are at least those of its
    prefix plus those of its suffix, so splitting never undercounts the duals). Much tighter
    than the knapsack and DP bounds alone."""
    n = cost.shape[0]
    cost = np.ascontiguousarray(cost, dtype=np.float64)
    profit = np.ascontiguousarray(profit, dtype=np.float64)
    cmem, mmem, sig = cut_arrays(n, cut_members, cut_memory, cut_duals)
    sfx, sdelta, snb = np.zeros((n, 1)), 1.0, 0
    if ng is not None:
        delta, nb = dp_unit(cost, budget, DP_UNITS)
        if nb > 0:
            perm, cost_b, profit_b, allowed_b = reversed_graph(cost, profit, allowed)
            bwd = label_table(cost_b, profit_b, budget, ng, allowed_b, threshold, max_labels,
                               deadline, delta, nb, cuts=(cmem[perm], mmem[perm], sig))
            if bwd is None:
                return Enumerated(None, max_labels)
            sfx, sdelta, snb = np.ascontiguousarray(bwd[0][perm]), delta, nb
    ret = cheapest_return(cost)
    order, cin, reach, lastord, cend = completion_data(cost, ret, profit, allowed)
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
    return Enumerated(paths, *counts, values=best[np.argsort(first)])
