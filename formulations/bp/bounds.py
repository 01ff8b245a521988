"""Upper bounds on what a label can still add on its way to the end, which let the labelling
(:mod:`.labelling`), the arc bounds (:mod:`.arc_bounds`) and the route enumeration
(:mod:`.enumeration_kernel`) drop labels that cannot beat their threshold.

* the completion bound (:func:`completion_bound`): a fractional knapsack over the
  positive-prize points the label has not remembered and that still fit: a point u is skipped
  unless ``reach[v, u]`` (cheapest energy v -> ... -> u -> end over allowed points,
  Floyd-Warshall, no triangle inequality assumed) is within the label's remaining energy; each
  kept point costs at least its cheapest incoming arc, and one last arc into the end (the
  cheapest of a fitting point) is set aside first;
* the suffix tables (:func:`suffix_dp`): the best prize of a 2-cycle-free walk from each point
  to the end by energy, in whole units of the budget, looked up by :func:`dp_bound`; from the
  start with the whole budget they bound a pricing call's best path (:func:`relaxed_best`).

Both bound the best *elementary* suffix, which is all the pricing's value needs.
"""

from __future__ import annotations

import numpy as np
from numba import njit

DP_UNITS = 512  # energy units of the suffix tables (budget / DP_UNITS each)
DP_MAX_UNITS = 4096  # finer units needed (an arc cheaper than budget / 4096): tables off


@njit(cache=True)
def completion_bound(mask, v, room, need, order, profit, cin, reach, lastord, cend):
    """Upper bound on the prize an elementary suffix can still add to a label at ``v`` with
    ``room`` energy left (budget minus the label's energy).

    A further node u must fit: ``reach[v, u]`` (cheapest energy v -> ... -> u -> end) <= room.
    Among the fitting nodes not remembered in ``mask``, the suffix ends with one arc u -> end
    (at least the smallest ``cend`` of a fitting node: ``lastord`` lists the allowed nodes by
    cend) and each of its nodes w costs at least ``cin[w]`` (its cheapest incoming arc), so a
    fractional knapsack over ``order`` (positive-prize nodes by prize/cin) bounds the prize.
    The knapsack stops as soon as it exceeds ``need`` (the caller only compares against it)."""
    if room <= 0.0:
        return 0.0
    last = np.inf
    for u in lastord:
        if reach[v, u] <= room and not (mask[u >> 6] & (np.uint64(1) << np.uint64(u & 63))):
            last = cend[u]
            break
    if last == np.inf:
        return 0.0  # no further node fits
    room0 = room
    room -= last
    if room < 0.0:
        room = 0.0
    ub = 0.0
    for w in order:
        if reach[v, w] > room0:
            continue
        if mask[w >> 6] & (np.uint64(1) << np.uint64(w & 63)):
            continue
        c = cin[w]
        if c <= 0.0:
            return np.inf
        if c <= room:
            ub += profit[w]
            if ub > need:
                return ub
            room -= c
        else:
            return ub + profit[w] * room / c
    return ub


@njit(cache=True)
def suffix_dp(cost, profit, allowed, delta, nb):
    """Suffix bounds by dynamic programming over energy units of ``delta`` (2-cycle-free paths).

    ``g1[u, b]``: the most prize a path u -> ... -> end can collect after u (u's own prize not
    counted) when its arc costs, each rounded down to whole units, sum to at most b units;
    ``s1[u, b]`` its first successor; ``g2[u, b]`` the best whose first successor differs from
    ``s1[u, b]``. Paths may repeat points but never turn straight back (u -> w -> u), so every
    elementary suffix is among them; rounding each arc down only admits more paths: a label at
    u, reached from v, with ``room`` energy left can add at most ``g1[u, room // delta]``
    (``g2`` if ``s1`` is v). Unreachable: -inf.
    """
    n = cost.shape[0]
    end = n - 1
    g1 = np.full((n, nb + 1), -np.inf)
    g2 = np.full((n, nb + 1), -np.inf)
    s1 = np.full((n, nb + 1), -1, np.int32)
    units = np.full((n, n), nb + 1, np.int64)
    for u in range(n):
        for w in range(n):
            c = cost[u, w]
            if u != w and c < np.inf:
                # Below one unit: only arcs the caller leaves out of the unit choice (start ->
                # end, into the start, out of the end). None leads on to a node; start -> end
                # rounded up only drops the empty route from g1[0, 0], and the start's one
                # label has the whole budget left.
                q = max(int(c / delta), 1)
                if q <= nb:
                    units[u, w] = q
    for b in range(1, nb + 1):
        for u in range(n - 1):
            if u > 0 and not allowed[u]:
                continue
            best = -np.inf
            bs = -1
            second = -np.inf
            if units[u, end] <= b:
                best = 0.0
                bs = end
            for w in range(1, end):
                if w == u or not allowed[w]:
                    continue
                q = units[u, w]
                if q > b:
                    continue
                r = b - q
                val = g1[w, r] if s1[w, r] != u else g2[w, r]
                if val == -np.inf:
                    continue
                val += profit[w]
                if val > best:
                    second = best
                    best = val
                    bs = w
                elif val > second:
                    second = val
            g1[u, b] = best
            s1[u, b] = bs
            g2[u, b] = second
    return g1, s1, g2


@njit(cache=True)
def dp_bound(g1, s1, g2, u, v, room, delta, nb):
    """What a label at ``u`` reached from ``v`` with ``room`` energy left can still add, at most
    (:func:`suffix_dp`; +inf when the tables are disabled, ``nb`` = 0)."""
    if nb == 0:
        return np.inf
    b = int((room + 1e-9 * (1.0 + abs(room))) / delta)  # never round a fitting suffix away
    if b > nb:
        b = nb
    if b < 0:
        return -np.inf
    return g1[u, b] if s1[u, b] != v else g2[u, b]


def relaxed_best(g1, s1, g2, delta, nb, budget) -> float:
    """Upper bound on the best elementary path's reduced prize from the suffix tables
    (:func:`suffix_dp`): the best 2-cycle-free walk from the start within the budget,
    arcs rounded down to whole units, cut duals left unpaid (they only lower a path's prize).
    It holds whatever the labelling did, so a heuristic or capped call still certifies a
    Lagrangian bound with it, a weaker one. +inf when the tables are off (``nb`` = 0)."""
    if nb == 0:
        return np.inf
    return max(0.0, float(dp_bound(g1, s1, g2, 0, -1, float(budget), delta, nb)))


def completion_data(cost, ret, profit, allowed):
    """Completion-bound data (see :func:`completion_bound`): positive nodes by prize/cin, cin, the
    reach matrix (cheapest energy v -> ... -> u -> end through allowed nodes), the allowed
    nodes by their arc into the end, and those arcs."""
    n = cost.shape[0]
    end = n - 1
    pts = np.arange(n)
    inner = (pts > 0) & (pts < end) & allowed
    src = inner | (pts == 0)
    cin = np.where(src[:, None], cost, np.inf)
    np.fill_diagonal(cin, np.inf)
    cin = cin.min(axis=0).astype(np.float64)
    good = np.flatnonzero(inner & (profit > 0))
    ratio = np.where(cin[good] > 0, profit[good] / np.maximum(cin[good], 1e-300), np.inf)
    order = good[np.argsort(-ratio, kind="stable")].astype(np.int64)
    # shortest paths through allowed nodes only (Floyd-Warshall; no triangle inequality needed)
    sp = np.where(np.isfinite(cost), cost, np.inf).astype(np.float64)
    np.fill_diagonal(sp, 0.0)
    for k in np.flatnonzero(inner):
        sp = np.minimum(sp, sp[:, k : k + 1] + sp[k : k + 1, :])
    reach = sp + sp[:, end][None, :]
    fin = np.isfinite(reach)  # rounding slack below: never prune a node that fits
    reach = np.ascontiguousarray(np.where(fin, reach - 1e-9 * (1.0 + np.abs(np.where(fin, reach, 0.0))), np.inf))
    cend = np.ascontiguousarray(cost[:, end], dtype=np.float64)
    inner_pts = np.flatnonzero(inner)
    lastord = inner_pts[np.argsort(cend[inner_pts], kind="stable")].astype(np.int64)
    return order, cin, reach, lastord, cend


def suffix_tables(cost, profit, allowed, budget, units: int = DP_UNITS):
    """Arguments ``g1, s1, g2, delta, nb`` of :func:`.labelling.label_search` for the suffix bound
    (:func:`suffix_dp`). The unit is budget / ``units``, or the cheapest arc between distinct
    points (start -> end aside) if that is smaller, so that every arc costs at least one unit;
    when that would take more than ``DP_MAX_UNITS`` units the tables are off (``nb`` = 0)."""
    n = cost.shape[0]
    delta, nb = dp_unit(cost, budget, units)
    if nb == 0:
        z = np.full((n, 1), np.inf)
        return z, np.full((n, 1), -1, np.int32), z, 1.0, 0
    g1, s1, g2 = suffix_dp(cost, np.ascontiguousarray(profit, dtype=np.float64), allowed,
                            delta, nb)
    return g1, s1, g2, delta, nb


def dp_unit(cost, budget, units):
    """(delta, nb) of the suffix tables (see :func:`suffix_tables`); nb = 0: tables off."""
    n = cost.shape[0]
    off = np.isfinite(cost) & ~np.eye(n, dtype=bool)
    off[0, n - 1] = off[n - 1, 0] = False
    off[:, 0] = False
    off[n - 1, :] = False
    cheapest = float(cost[off].min()) if off.any() else np.inf
    delta = float(budget) / units
    if cheapest < delta:
        delta = cheapest
    if not (budget > 0 and delta > 0 and budget / delta <= DP_MAX_UNITS):
        return 1.0, 0
    return delta, int(budget / delta) + 1
