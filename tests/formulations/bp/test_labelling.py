"""The labelling finds the best elementary (or ng) path exactly, with or without cuts, in any layout."""

from __future__ import annotations

import numpy as np
import pytest

from bp_cases import branch_like, brute_paths, cut_priced, random_cuts, tiny_pricing


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("bidirectional", [False, True])
def test_exact_pricing_matches_enumeration(seed, bidirectional):
    """Elementary labelling (heap order, buckets, reach-filtered completion bound): its best value
    is the best elementary path's prize, its routes are real improving paths; ng-8 labelling and the
    heuristic bracket it (ng value >= elementary best >= any heuristic route)."""
    from sarcover.formulations.bp.labelling import price
    from sarcover.formulations.bp.ng_sets import full_ng, nearest_ng

    cost, ret, profit, budget = tiny_pricing(seed)
    paths = brute_paths(cost, profit, budget)
    best = max(p for p, _ in paths)
    gain = 0.3 * best
    allowed = np.ones(cost.shape[0], dtype=bool)
    kw = dict(max_labels=1_000_000, n_cols=50, min_gain=gain)
    ex = price(cost, ret, profit, budget, full_ng(cost.shape[0]), allowed, heuristic=False,
               bidirectional=bidirectional, **kw)
    assert ex.exact and ex.best == pytest.approx(max(best, gain))
    value = {path: p for p, path in paths}
    for r in ex.routes:
        assert r in value and value[r] > gain
    assert ex.routes[0] in value and value[ex.routes[0]] == pytest.approx(best)
    ng = price(cost, ret, profit, budget, nearest_ng(cost, 2), allowed, heuristic=False,
               bidirectional=bidirectional, **kw)
    assert ng.exact and ng.best >= best - 1e-9
    heur = price(cost, ret, profit, budget, full_ng(cost.shape[0]), allowed, heuristic=True, **kw)
    assert all(r in value and value[r] <= best + 1e-9 for r in heur.routes)


@pytest.mark.parametrize("seed", range(6))
def test_exact_pricing_keeps_near_best_routes_without_losing_the_best(seed):
    """``keep`` holds the exact pricing's pruning threshold below the best path found: the best
    value stays the best elementary prize, every route returned is a real improving path, the
    best comes first, and more of the near-best routes come back (the point of it: more columns
    per exact call)."""
    from sarcover.formulations.bp.labelling import price
    from sarcover.formulations.bp.ng_sets import full_ng

    cost, ret, profit, budget = tiny_pricing(seed, n_nodes=9)
    paths = brute_paths(cost, profit, budget)
    best = max(p for p, _ in paths)
    value = {path: p for p, path in paths}
    allowed = np.ones(cost.shape[0], dtype=bool)
    routes = {}
    for keep in (0.0, 0.5, 1.0):
        res = price(cost, ret, profit, budget, full_ng(cost.shape[0]), allowed, heuristic=False,
                    max_labels=1_000_000, n_cols=1000, min_gain=0.0, keep=keep)
        assert res.exact and res.best == pytest.approx(best)
        assert all(r in value and value[r] > 0.0 for r in res.routes)
        assert value[res.routes[0]] == pytest.approx(best)
        routes[keep] = len(res.routes)
    assert routes[0.0] < routes[0.5] <= routes[1.0]


@pytest.mark.parametrize("seed", range(8))
def test_exact_pricing_with_cuts_matches_enumeration(seed):
    """With subset-row cut duals, exact elementary labelling finds the best path's prize minus
    the duals of the cuts it pays (limited-memory coefficients, enumerated); every route it
    returns has the value it claims to beat; ng labelling stays an upper bound."""
    from sarcover.formulations.bp.labelling import price
    from sarcover.formulations.bp.ng_sets import full_ng, nearest_ng

    cost, ret, profit, budget, (members, memory, sig), value, paths = cut_priced(seed, 100 + seed)
    n = cost.shape[0]
    best = max(v for v, _ in paths)
    gain = 0.2 * best
    kw = dict(max_labels=1_000_000, n_cols=50, min_gain=gain, cut_members=members,
              cut_memory=memory, cut_duals=sig)
    allowed = np.ones(n, dtype=bool)
    ex = price(cost, ret, profit, budget, full_ng(n), allowed, heuristic=False, **kw)
    assert ex.exact and ex.best == pytest.approx(max(best, gain))
    vals = {p: v for v, p in paths}
    assert ex.routes and vals[ex.routes[0]] == pytest.approx(best)
    assert all(vals[r] > gain - 1e-9 for r in ex.routes)
    ng = price(cost, ret, profit, budget, nearest_ng(cost, 2), allowed, heuristic=False, **kw)
    assert ng.exact and ng.best >= best - 1e-9
    # bidirectional search: its join pays the pairs it makes, so the same best value and routes
    # worth what they claim; its ng relaxation stays an upper bound
    bi = price(cost, ret, profit, budget, full_ng(n), allowed, heuristic=False, bidirectional=True, **kw)
    assert bi.exact and bi.best == pytest.approx(ex.best)
    assert bi.routes and vals[bi.routes[0]] == pytest.approx(best)
    assert all(vals[r] > gain - 1e-9 for r in bi.routes)
    bng = price(cost, ret, profit, budget, nearest_ng(cost, 2), allowed, heuristic=False,
                bidirectional=True, **kw)
    assert bng.exact and bng.best >= best - 1e-9


@pytest.mark.parametrize("seed", range(3))
def test_dominance_layout_changes_speed_not_labels(seed):
    """The labelling keeps each point's labels in energy sub-buckets sorted by prize and scans
    only where a dominator or a dominated label can be. On a paper-size graph (M = 20, K = 3)
    with random duals, ng sets and subset-row cuts, one plain bucket per point (nsub = 1) and
    the sub-buckets (default, and an odd count) create exactly the same labels: the same count,
    best value and routes, one-way and bidirectional, exact and heuristic; the most sub-buckets a
    label count may choose too."""
    from sarcover.formulations.bp.graph import cheapest_return
    from sarcover.formulations.bp.labelling import price, sub_buckets
    from sarcover.formulations.bp.ng_sets import nearest_ng
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(20, 3, 5, seed))
    cost = inst.cost_matrix()
    n = cost.shape[0]
    rng = np.random.default_rng(seed)
    profit = np.zeros(n)
    profit[1:-1] = rng.uniform(-0.2, 0.6, n - 2)
    _, _, members, memory, sig = random_cuts(rng, n, 12)
    ret = cheapest_return(cost)
    allowed = np.ones(n, dtype=bool)
    assert sub_buckets(n) > 1
    for heuristic, bidirectional in ((False, False), (False, True), (True, False)):
        runs = [price(cost, ret, profit, inst.budget, nearest_ng(cost, 8), allowed,
                      heuristic=heuristic, bidirectional=bidirectional, max_labels=2_000_000,
                      n_cols=60, min_gain=1.0, cut_members=members, cut_memory=memory,
                      cut_duals=sig, keep=0.0 if heuristic else 0.5, nsub=nsub)
                for nsub in (1, None, 7, 256)]
        assert runs[0].n_labels > 1000
        assert runs[0].exact == (not heuristic)
        for r in runs[1:]:
            assert r.n_labels == runs[0].n_labels
            assert r.best == runs[0].best
            assert r.routes == runs[0].routes and r.ng_routes == runs[0].ng_routes


def test_sub_buckets_follow_the_expected_labels_per_point():
    """Without a label count the layout has NSUB sub-buckets per point; with one, a power of two
    within NSUB_RANGE that grows with the labels per point, and never more than SUB_CELLS in
    all."""
    from sarcover.formulations.bp.labelling import NSUB, NSUB_RANGE, SUB_CELLS, sub_buckets

    assert sub_buckets(62) == NSUB and sub_buckets(62, 0) == NSUB
    counts = [sub_buckets(62, labels) for labels in (100, 20_000, 100_000, 300_000, 10**8)]
    assert counts == sorted(counts) and len(set(counts)) > 2
    assert all(c & (c - 1) == 0 for c in counts)
    assert counts[0] == NSUB_RANGE[0] and counts[-1] == NSUB_RANGE[1]
    assert sub_buckets(102, 10**8) * 102 <= SUB_CELLS
    assert sub_buckets(5000, 10**8) == SUB_CELLS // 5000


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("heuristic,max_labels", [(True, 200_000), (False, 3), (False, 10**6)])
def test_relaxed_best_bounds_every_elementary_path_however_the_call_ended(seed, heuristic, max_labels):
    """A pricing call's ``relaxed`` value is never below the best elementary path's reduced prize
    (enumerated), whether the call was heuristic, stopped at its label cap or finished, also on
    a graph with forbidden arcs and no triangle inequality."""
    from sarcover.formulations.bp.labelling import price
    from sarcover.formulations.bp.ng_sets import nearest_ng

    cost, ret, profit, budget = tiny_pricing(seed)
    if seed >= 2:
        branch_like(cost, 200 + seed)
    n = cost.shape[0]
    best = max([p for p, _ in brute_paths(cost, profit, budget)] or [0.0])
    res = price(cost, ret, profit, budget, nearest_ng(cost, 3), np.ones(n, dtype=bool),
                heuristic=heuristic, max_labels=max_labels, n_cols=10, min_gain=0.0)
    assert np.isfinite(res.relaxed)
    assert res.relaxed >= best - 1e-9
