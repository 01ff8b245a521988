"""The completion bound and the suffix tables never undercut what a label can still add."""

from __future__ import annotations

import numpy as np
import pytest

from bp_cases import branch_like, brute_paths, tiny_pricing


@pytest.mark.parametrize("seed", range(4))
def test_completion_bound_covers_every_suffix(seed):
    """_completion never undercuts the best elementary suffix of a path prefix (enumerated)."""
    from sarcover.formulations.bp.bounds import completion_bound as _completion
    from sarcover.formulations.bp.bounds import completion_data as _prepare
    from sarcover.formulations.bp.ng_sets import n_words

    cost, ret, profit, budget = tiny_pricing(seed)
    n = cost.shape[0]
    order, cin, reach, lastord, cend = _prepare(cost, ret, profit, np.ones(n, dtype=bool))
    paths = brute_paths(cost, profit, budget)
    for _, path in paths[:: max(1, len(paths) // 300)]:
        for cut in range(1, len(path) + 1):
            pre, v = path[:cut], path[cut - 1]
            used = sum(cost[a, b] for a, b in zip((0, *pre), pre))
            mask = np.zeros(n_words(n), dtype=np.uint64)
            for p in pre:
                mask[p >> 6] |= np.uint64(1) << np.uint64(p & 63)
            best_suffix = max(
                [sum(profit[list(q[cut:])]) for _, q in paths if q[:cut] == pre] or [0.0])
            ub = _completion(mask, v, budget - used, np.inf, order, profit, cin, reach, lastord, cend)
            assert ub >= best_suffix - 1e-9


@pytest.mark.parametrize("seed", range(4))
def test_suffix_tables_cover_every_suffix(seed):
    """The DP suffix bound never undercuts the best elementary suffix of a path prefix
    (enumerated), also on a graph with forbidden arcs and no triangle inequality."""
    from sarcover.formulations.bp.bounds import dp_bound as _dp_bound
    from sarcover.formulations.bp.bounds import suffix_tables

    cost, ret, profit, budget = tiny_pricing(seed)
    if seed >= 2:
        branch_like(cost, 100 + seed)
    n = cost.shape[0]
    g1, s1, g2, delta, nb = suffix_tables(cost, profit, np.ones(n, dtype=bool), budget, units=64)
    assert nb > 0
    paths = brute_paths(cost, profit, budget)
    assert paths
    for _, path in paths:
        for cut in range(1, len(path) + 1):
            pre, v = path[:cut], path[cut - 1]
            full = (0, *pre)
            used = sum(cost[a, b] for a, b in zip(full, full[1:]))
            prev = full[-2]
            best_suffix = max(
                [sum(profit[list(q[cut:])]) for _, q in paths if q[:cut] == pre] or [0.0])
            ub = _dp_bound(g1, s1, g2, v, prev, budget - used, delta, nb)
            assert ub >= best_suffix - 1e-9


def test_suffix_tables_are_the_best_walk_without_turning_back():
    """On integer arc costs with a one-unit grid the tables are exact: the best walk (points may
    repeat, no immediate return) within b units, enumerated."""
    from sarcover.formulations.bp.bounds import suffix_dp as _suffix_dp

    rng = np.random.default_rng(7)
    n = 6  # start, 4 nodes, end
    cost = rng.integers(1, 5, size=(n, n)).astype(float)
    cost[:, 0] = np.inf
    cost[n - 1, :] = np.inf
    np.fill_diagonal(cost, 0.0)
    profit = np.concatenate([[0.0], rng.uniform(-1, 3, n - 2), [0.0]])
    nb = 9
    g1, s1, g2 = _suffix_dp(cost, profit, np.ones(n, dtype=bool), 1.0, nb)

    def best_walk(u, prev, b):
        out = 0.0 if cost[u, n - 1] <= b else -np.inf
        for w in range(1, n - 1):
            if w != u and w != prev and cost[u, w] <= b:
                out = max(out, profit[w] + best_walk(w, u, b - cost[u, w]))
        return out

    for u in range(n - 1):
        for b in range(nb + 1):
            assert g1[u, b] == pytest.approx(best_walk(u, -1, b))
            for v in range(1, n - 1):
                got = g1[u, b] if s1[u, b] != v else g2[u, b]
                assert got == pytest.approx(best_walk(u, v, b))
