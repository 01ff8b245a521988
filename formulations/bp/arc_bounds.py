"""Upper bounds on the prize of any route through each arc, for reduced-cost arc elimination
(:mod:`.elimination`): from the suffix tables (:func:`arc_bounds`) or, tighter, from exact
ng-labelling both ways (:func:`label_arc_bounds`). A route's prize is then at most its arc's
bound, so an arc whose bound cannot beat what a better plan needs leaves the graph.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from sarcover.formulations.bp.bounds import DP_UNITS, dp_unit, suffix_dp
from sarcover.formulations.bp.graph import reversed_graph
from sarcover.formulations.bp.labelling import label_table


@njit(cache=True)
def _through_arcs(cost, prefix, suffix, profit, delta, nb):
    """``best[i, j]``: max over unit splits of prefix[i, b1] + suffix[j, b2] with
    b1 + units(i, j) + b2 <= nb, plus the prizes of i and j (-inf where nothing fits). The
    start's prefix and the end's suffix are empty (0), whatever their table rows say."""
    n = cost.shape[0]
    end = n - 1
    best = np.full((n, n), -np.inf)
    for i in range(n - 1):
        for j in range(1, n):
            c = cost[i, j]
            if i == j or not c < np.inf:
                continue
            q = int(c / delta)
            if q > nb:
                continue
            r = nb - q
            v = -np.inf
            for b1 in range(r + 1):
                a = prefix[i, b1] if i > 0 else 0.0
                if a == -np.inf:
                    continue
                s = a + (suffix[j, r - b1] if j < end else 0.0)
                if s > v:
                    v = s
            if v > -np.inf:
                best[i, j] = v + profit[i] + profit[j]
    return best


def arc_bounds(cost, profit, allowed, budget, units: int = DP_UNITS):
    """(n, n) upper bound on the prize (sum of ``profit``) of any path start -> ... -> i -> j
    -> ... -> end of energy <= ``budget`` that uses arc (i, j); +inf everywhere when the suffix
    tables are off, -inf for arcs no such path uses.

    Both halves come from :func:`suffix_dp`: the suffix j -> ... -> end on the graph, the
    prefix start -> ... -> i as a suffix of the reversed graph (start and end swapped). They are
    2-cycle-free walks with arcs rounded down to whole units, and the arc (i, j) itself is
    rounded down too, so every elementary path through (i, j) is among the combinations (the
    join may turn back at i or j: that only admits more walks). Used for reduced-cost arc
    elimination."""
    n = cost.shape[0]
    profit = np.ascontiguousarray(profit, dtype=np.float64)
    delta, nb = dp_unit(cost, budget, units)
    if nb == 0:
        return np.full((n, n), np.inf)
    suffix, _, _ = suffix_dp(cost, profit, allowed, delta, nb)
    perm, cost_b, profit_b, allowed_b = reversed_graph(cost, profit, allowed)
    h1, _, _ = suffix_dp(cost_b, profit_b, allowed_b, delta, nb)
    prefix = np.ascontiguousarray(h1[perm])  # start -> ... -> i (i's own prize not counted)
    return _through_arcs(np.ascontiguousarray(cost), prefix, suffix, profit, delta, nb)


def label_arc_bounds(cost, profit, allowed, budget, ng, threshold, *, max_labels=2_000_000,
                     deadline=np.inf, units: int = DP_UNITS, n_routes: int = 0):
    """Like :func:`arc_bounds`, from exact ng-labelling instead of the 2-cycle-free DP: the
    prefix table from one-way labels start -> i, the suffix table from labels of the reversed
    graph, over the whole budget, with completion-bound pruning against the fixed
    ``threshold``. Exact for what it is used for: every elementary path through (i, j) with a
    prize above ``threshold`` is bounded by ``best[i, j]`` (each prefix of such a path is a
    label or dominated by one, which has no less prize and no more energy); arcs of no such path
    get a value <= ``threshold``. Returns (best, routes): ``routes`` are up to ``n_routes``
    elementary routes above the threshold from the forward labels, best first, one per set of
    points (near-optimal columns for a MILP). None when a search hit ``max_labels`` or the
    ``deadline``."""
    n = cost.shape[0]
    profit = np.ascontiguousarray(profit, dtype=np.float64)
    delta, nb = dp_unit(cost, budget, units)
    if nb == 0:
        return None
    fwd = label_table(np.ascontiguousarray(cost), profit, budget, ng, allowed, threshold,
                      max_labels, deadline, delta, nb, n_routes)
    if fwd is None:
        return None
    prefix, routes = fwd
    perm, cost_b, profit_b, allowed_b = reversed_graph(cost, profit, allowed)
    bwd = label_table(cost_b, profit_b, budget, ng, allowed_b, threshold, max_labels,
                      deadline, delta, nb)
    if bwd is None:
        return None
    suffix = np.ascontiguousarray(bwd[0][perm])  # labels count their own point's prize
    best = _through_arcs(np.ascontiguousarray(cost), prefix, suffix, np.zeros(n), delta, nb)
    return best, routes
