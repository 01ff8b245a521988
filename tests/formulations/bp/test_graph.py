"""The pricing graph: the sparse graph the heuristic pricing runs on at scale."""

from __future__ import annotations

import numpy as np
import pytest

from bp_cases import tiny_pricing


@pytest.mark.parametrize("k", [1, 3])
def test_sparse_graph_keeps_each_points_k_cheapest_arcs_and_the_start_and_end(k):
    """Every inner point keeps exactly its k cheapest arcs into allowed inner points (at their
    costs) and its arc into the end; the start keeps all its arcs; nothing else is finite."""
    from sarcover.formulations.bp.graph import sparse_graph

    cost, _, _, _ = tiny_pricing(0, n_nodes=9)
    n = cost.shape[0]
    allowed = np.ones(n, dtype=bool)
    allowed[4] = False
    out = sparse_graph(cost, allowed, k)
    assert np.array_equal(out[0], cost[0]) and np.array_equal(out[:, n - 1], cost[:, n - 1])
    for u in range(1, n - 1):
        cand = [w for w in range(1, n - 1) if w != u and allowed[w]]
        kept = [w for w in range(1, n - 1) if np.isfinite(out[u, w])]
        assert len(kept) == k and 4 not in kept
        assert all(out[u, w] == cost[u, w] for w in kept)
        assert max(cost[u, kept]) <= min(cost[u, w] for w in cand if w not in kept)


def test_sparse_graph_with_k_at_least_the_points_is_the_graph():
    """Asked for as many arcs as there are points, the graph is returned unchanged."""
    from sarcover.formulations.bp.graph import sparse_graph

    cost, _, _, _ = tiny_pricing(1)
    assert sparse_graph(cost, np.ones(cost.shape[0], dtype=bool), cost.shape[0]) is cost
