"""The route enumeration lists every route above its threshold and counts the narrower listing."""

from __future__ import annotations

import numpy as np
import pytest

from bp_cases import cut_priced


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("with_ng", [False, True])
def test_enumeration_lists_every_route_above_the_threshold(seed, with_ng):
    """Route enumeration (cut duals paid, with and without the backward ng suffix table) lists
    one route per set of points for exactly the elementary routes whose best ordering's value
    beats the threshold (brute force)."""
    from sarcover.formulations.bp.enumeration_kernel import enumerate_routes
    from sarcover.formulations.bp.ng_sets import nearest_ng

    cost, _, profit, budget, (members, memory, sig), value, paths = cut_priced(seed, 200 + seed)
    n = cost.shape[0]
    thr = 0.4 * max(v for v, _ in paths)
    want = {frozenset(p) for v, p in paths if v > thr + 1e-9}
    res = enumerate_routes(cost, profit, np.ones(n, dtype=bool), budget, thr,
                           ng=nearest_ng(cost, 3) if with_ng else None, cut_members=members,
                           cut_memory=memory, cut_duals=sig)
    got = [frozenset(r) for r in res.routes]
    assert len(got) == len(set(got))
    assert set(got) == want
    assert all(value(r) > thr for r in res.routes)


@pytest.mark.parametrize("seed", range(4))
def test_enumeration_counts_what_a_narrower_listing_would_give(seed):
    """With a margin, a listing counts the routes a listing at threshold + margin gives (exactly:
    the sets whose best ordering clears it) and about its labels; its growth is their ratio."""
    from sarcover.formulations.bp.enumeration_kernel import enumerate_routes
    from sarcover.formulations.bp.ng_sets import nearest_ng

    cost, _, profit, budget, (members, memory, sig), _, paths = cut_priced(seed, 300 + seed)
    n = cost.shape[0]
    thr, margin = 0.3 * max(v for v, _ in paths), 0.2 * max(v for v, _ in paths)
    kw = dict(ng=nearest_ng(cost, 3), cut_members=members, cut_memory=memory, cut_duals=sig)
    wide = enumerate_routes(cost, profit, np.ones(n, dtype=bool), budget, thr, margin=margin, **kw)
    narrow = enumerate_routes(cost, profit, np.ones(n, dtype=bool), budget, thr + margin, **kw)
    assert 0 < narrow.inner_routes == len(narrow.routes) == wide.inner_routes < len(wide.routes)
    assert narrow.inner_labels == narrow.n_labels - 1  # every label but the start
    assert 0.5 * narrow.n_labels <= wide.inner_labels <= 2 * narrow.n_labels
    labels, routes = wide.growth()
    assert labels == pytest.approx(wide.n_labels / wide.inner_labels)
    assert routes == pytest.approx(len(wide.routes) / len(narrow.routes)) and routes > 1
