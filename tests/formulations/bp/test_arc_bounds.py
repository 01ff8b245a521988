"""The arc bounds cover every path through each arc (above the threshold, for the labelling ones)."""

from __future__ import annotations

import numpy as np
import pytest

from bp_cases import branch_like, brute_paths, tiny_pricing


@pytest.mark.parametrize("seed", range(4))
def test_arc_bounds_cover_every_path_through_an_arc(seed):
    """The arc bound (best prefix + arc + best suffix) is never below the prize of an elementary
    path through that arc (enumerated), also with forbidden arcs and no triangle inequality; and
    it is not vacuous: on these graphs it is finite and below the largest bound somewhere."""
    from sarcover.formulations.bp.arc_bounds import arc_bounds

    cost, ret, profit, budget = tiny_pricing(seed)
    n = cost.shape[0]
    if seed >= 2:
        branch_like(cost, 200 + seed)
    best = arc_bounds(cost, profit, np.ones(n, dtype=bool), budget, units=64)
    exact = np.full((n, n), -np.inf)
    for prize, path in brute_paths(cost, profit, budget):
        full = (0, *path, n - 1)
        for a, b in zip(full, full[1:]):
            exact[a, b] = max(exact[a, b], prize)
            assert best[a, b] >= prize - 1e-9, (a, b, path)
    used = np.isfinite(exact)
    assert used.any() and np.all(np.isfinite(best[used]))
    assert np.any(best[used] < best[used].max() - 1e-6)


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("ng_size", [3, 8])
def test_label_arc_bounds_cover_every_path_above_the_threshold(seed, ng_size):
    """The labelling arc bound (ng-labels forward and backward, fixed threshold) is never below
    the prize of an elementary path through the arc whose prize beats the threshold; with
    elementary labels it is tighter than the DP arc bound on some arc."""
    from sarcover.formulations.bp.arc_bounds import arc_bounds, label_arc_bounds
    from sarcover.formulations.bp.ng_sets import nearest_ng

    cost, ret, profit, budget = tiny_pricing(seed)
    n = cost.shape[0]
    allowed = np.ones(n, dtype=bool)
    paths = brute_paths(cost, profit, budget)
    prizes = sorted(p for p, _ in paths)
    threshold = prizes[len(prizes) * 3 // 4]
    best, routes = label_arc_bounds(cost, profit, allowed, budget, nearest_ng(cost, ng_size),
                                    threshold, units=64, n_routes=5)
    dp = arc_bounds(cost, profit, allowed, budget, units=64)
    above = np.zeros((n, n), dtype=bool)
    for prize, path in paths:
        if prize <= threshold:
            continue
        full = (0, *path, n - 1)
        for a, b in zip(full, full[1:]):
            above[a, b] = True
            assert best[a, b] >= prize - 1e-9, (a, b, path)
    assert above.any() and not above.all()
    if ng_size == 8:
        assert np.any(best < dp - 1e-6)
    # its routes: elementary paths above the threshold (distinct sets, best first, the best one
    # among them; labels the dominance removed take their routes with them)
    above_paths = {p for pr, p in paths if pr > threshold}
    got = [float(profit[list(r)].sum()) for r in routes]
    assert 0 < len(routes) <= 5 and len({frozenset(r) for r in routes}) == len(routes)
    assert all(tuple(r) in above_paths for r in routes)
    assert got == sorted(got, reverse=True)
    assert got[0] == pytest.approx(max(pr for pr, _ in paths))
