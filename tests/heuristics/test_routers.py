"""PSO, GA and ACO tour routers and the shared tour helpers."""

from __future__ import annotations

import numpy as np
import pytest

from sarcover.heuristics.routing_aco import ACORouter
from sarcover.heuristics.routing_ga import GARouter, order_crossover
from sarcover.heuristics.routing_pso import PSORouter
from sarcover.heuristics.tour import ClusterBatch, invert, path_lengths, route_length, two_opt

ROUTERS = {"pso": PSORouter, "ga": GARouter, "aco": ACORouter}


def polygon_problem(n: int, seed: int):
    """Base + n nodes on an ellipse at random angles (a convex polygon), nodes shuffled.

    Returns (D in solver order with start = end = the base, the optimal tour length).
    """
    rng = np.random.default_rng(seed)
    angles = np.sort(rng.uniform(0, 2 * np.pi, n + 1))
    pts = np.c_[100 * np.cos(angles), 60 * np.sin(angles)]
    hull = np.sqrt(((pts - np.roll(pts, 1, axis=0)) ** 2).sum(axis=1)).sum()
    nodes = pts[1:][rng.permutation(n)]
    allp = np.vstack([pts[0], nodes, pts[0]])
    D = np.sqrt(((allp[:, None] - allp[None]) ** 2).sum(axis=-1))
    return D, hull


def solve(router, D, clusters, seed=0):
    end = D.shape[0] - 1
    batch = ClusterBatch.of(clusters, 0, end)
    best, f = router.solve(D, batch, np.random.default_rng(seed))
    return batch.routes(clusters, best), f, batch


@pytest.mark.parametrize("name", ROUTERS)
@pytest.mark.parametrize("seed", range(4))
def test_convex_polygon_hull_order(name, seed):
    """On 10 points of a convex polygon each router finds the hull tour (the optimum)."""
    D, hull = polygon_problem(10, seed)
    routes, f, _ = solve(ROUTERS[name](), D, [np.arange(1, 11)], seed)
    assert sorted(routes[0].tolist()) == list(range(1, 11))
    assert f[0] == pytest.approx(hull, rel=1e-9)
    assert route_length(D, routes[0], 0, 11) == pytest.approx(hull, rel=1e-9)


@pytest.mark.parametrize("name", ROUTERS)
def test_batched_clusters_of_different_sizes(name):
    """Clusters padded into one batch are each solved to their hull tour; trivial ones pass through."""
    sizes = [4, 9, 1, 0, 6]
    hulls = []
    coords = [np.zeros(2)]
    rng = np.random.default_rng(7)
    clusters = []
    for s in sizes:
        angles = np.sort(rng.uniform(0.2, 2 * np.pi - 0.2, s))
        ring = np.c_[50 * np.cos(angles) - 50, 50 * np.sin(angles)] if s else np.zeros((0, 2))
        clusters.append(np.arange(len(coords), len(coords) + s))
        coords.extend(ring[rng.permutation(s)])
        hull_pts = np.vstack([[0.0, 0.0], ring, [0.0, 0.0]])
        hulls.append(np.sqrt((np.diff(hull_pts, axis=0) ** 2).sum(axis=1)).sum() if s else 0.0)
    coords.append(np.zeros(2))
    P = np.array(coords)
    D = np.sqrt(((P[:, None] - P[None]) ** 2).sum(axis=-1))
    routes, f, batch = solve(ROUTERS[name](), D, clusters, seed=1)
    assert batch.nodes.shape == (3, 9)
    for c, r, h in zip(clusters, routes, hulls):
        assert sorted(r.tolist()) == sorted(c.tolist())
        assert route_length(D, r, 0, len(P) - 1) == pytest.approx(h, rel=1e-9)


@pytest.mark.parametrize("router", [PSORouter(), PSORouter(local_search=False), GARouter(), ACORouter()],
                         ids=["pso", "pso-plain", "ga", "aco"])
def test_never_worse_than_random_tours(router):
    """On random 15-point clusters a router's tour beats the best of 200 random tours."""
    for seed in range(3):
        rng = np.random.default_rng(seed)
        P = np.vstack([[0.0, 0.0], rng.uniform(0, 100, (15, 2)), [100.0, 100.0]])
        D = np.sqrt(((P[:, None] - P[None]) ** 2).sum(axis=-1))
        routes, f, _ = solve(router, D, [np.arange(1, 16)], seed)
        random_tours = np.array([rng.permutation(np.arange(1, 16)) for _ in range(200)])
        assert f[0] == pytest.approx(route_length(D, routes[0], 0, 16))
        assert f[0] <= path_lengths(D, random_tours, 0, 16).min()


def test_order_crossover_by_hand():
    """OX keeps parent 1's slice in place and fills the rest in parent 2's order."""
    p1 = np.array([[0, 1, 2, 3, 4, 5, 6, 7]])
    p2 = np.array([[7, 6, 5, 4, 3, 2, 1, 0]])
    child = order_crossover(p1, p2, np.array([2]), np.array([4]))
    assert child.tolist() == [[7, 6, 2, 3, 4, 5, 1, 0]]
    rng = np.random.default_rng(0)
    a = np.argsort(rng.random((50, 12)), axis=1)
    b = np.argsort(rng.random((50, 12)), axis=1)
    lo = rng.integers(0, 12, 50)
    hi = np.maximum(lo, rng.integers(0, 12, 50))
    kids = order_crossover(a, b, lo, hi)
    assert (np.sort(kids, axis=1) == np.arange(12)).all()
    for r in range(50):
        assert (kids[r, lo[r] : hi[r] + 1] == a[r, lo[r] : hi[r] + 1]).all()


def test_invert_and_two_opt():
    """invert reverses a slice per row; 2-opt untangles a crossing path with distinct ends."""
    perm = np.arange(6)[None, :].repeat(2, axis=0)
    out = invert(perm, np.array([1, 3]), np.array([3, 2]))
    assert out.tolist() == [[0, 3, 2, 1, 4, 5], [0, 1, 2, 3, 4, 5]]
    P = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 1.0], [2.0, 0.0], [1.0, 1.0], [3.0, 0.5]])
    D = np.sqrt(((P[:, None] - P[None]) ** 2).sum(axis=-1))
    route = two_opt(D, [1, 2, 3, 4], 0, 5)
    assert route_length(D, route, 0, 5) < route_length(D, [1, 2, 3, 4], 0, 5)
    assert sorted(route.tolist()) == [1, 2, 3, 4]


@pytest.mark.parametrize("name", ROUTERS)
@pytest.mark.parametrize("seed", range(5))
def test_compiled_kernels_match_numpy(name, seed):
    """The numba kernels run the numpy algorithm on the same draws: the same tours and lengths.

    Start and end differ, so no tour ties with its reverse (the two paths sum lengths in another
    order, which may break such exact ties differently)."""
    g = np.random.default_rng(100 + seed)
    pts = np.vstack([[0, 0], g.uniform(0, 1000, (40, 2)), [1000, 300]])
    D = np.sqrt(((pts[:, None] - pts[None]) ** 2).sum(axis=-1))
    clusters = np.split(g.permutation(np.arange(1, 41)), np.cumsum([14, 9, 11, 6]))[:4]
    fast, f_fast, _ = solve(ROUTERS[name](use_numba=True), D, clusters, seed)
    slow, f_slow, _ = solve(ROUTERS[name](use_numba=False), D, clusters, seed)
    assert all(np.array_equal(a, b) for a, b in zip(fast, slow))
    np.testing.assert_allclose(f_fast, f_slow, rtol=1e-12)
    lengths = [route_length(D, r, 0, 41) for r in fast]
    np.testing.assert_allclose(f_fast, lengths, rtol=1e-12)
