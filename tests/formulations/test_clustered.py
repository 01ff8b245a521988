"""OPT|C, the clustered optimum (formulations/clustered.py), against brute force on tiny instances."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from sarcover.formulations.clustered import (
    inside, oracle_clusters, solve_clustered, solve_clustered_milp, split_groups,
)
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import TOPInstance, to_top
from sarcover.formulations.milp import solve_milp
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Status
from sarcover.formulations.verify import verify

from brute_force import brute_clustered, brute_opt


# ---------------------------------------------------------------- tiny cases


def tiny_instance(seed: int) -> TOPInstance:
    """A SAR instance of 4-6 viewpoints or a TOP one of up to 7 nodes with groups; tight budgets."""
    rng = np.random.default_rng(seed)
    if seed % 2 == 0:
        m, k = [(2, 2), (3, 2), (2, 3)][seed % 3]
        return to_top(generate(m, k, int(rng.integers(2, 4)), seed,
                               e_max=float(rng.choice([2500.0, 3500.0, 4500.0, 6000.0]))))
    v = int(rng.integers(4, 8))
    ids = rng.permutation(v)
    n_groups = int(rng.integers(1, 4))
    groups = tuple(tuple(int(i) for i in part) for part in np.array_split(ids[: 2 * n_groups], n_groups))
    return TOPInstance(coords=rng.uniform(0, 100, (v, 2)), prizes=rng.integers(1, 6, v).astype(float),
                       start=rng.uniform(0, 100, 2), end=rng.uniform(0, 100, 2),
                       budget=float(rng.uniform(80, 250)), n_vehicles=int(rng.integers(2, 4)),
                       e_fly=1.0, e_image=float(rng.choice([0.0, 5.0])), groups=groups)


def random_clusters(inst: TOPInstance, rng) -> list[list[int]]:
    """A random clustering: every node in one of the N clusters or (sometimes) in none."""
    label = rng.integers(-1 if rng.random() < 0.3 else 0, inst.n_vehicles, inst.n_nodes)
    return [[v for v in range(inst.n_nodes) if label[v] == i] for i in range(inst.n_vehicles)]


CASES = [(s, c) for s in range(16) for c in range(2)]


def _check_restricted(inst, clusters, res, expected):
    if expected is None:
        assert res.status == Status.INFEASIBLE, res.reason
        assert res.plan is None
        return
    assert res.status == Status.OPTIMAL, res.reason
    rep = verify(inst, res.plan)
    assert rep.valid, rep.violations
    assert rep.prize == pytest.approx(expected) and res.bound == pytest.approx(expected)
    assert len(res.plan.routes) == inst.n_vehicles and inside(res.plan, clusters)


@pytest.mark.parametrize("seed,c", CASES)
def test_opt_c_equals_brute_force(seed, c):
    """solve_clustered and the joint MILP both give brute force's OPT|C (or prove infeasibility),
    with a verified plan whose route i stays in cluster i."""
    inst = tiny_instance(seed)
    clusters = random_clusters(inst, np.random.default_rng(1000 * seed + c))
    expected = brute_clustered(inst, clusters)
    _check_restricted(inst, clusters, solve_clustered(inst, clusters, time_limit=60), expected)
    _check_restricted(inst, clusters, solve_clustered_milp(inst, clusters, time_limit=60), expected)


def test_branching_on_split_groups():
    """A case where each cluster's own optimum skips a split group: the search must branch.

    Start and end at 0. Group {0, 1}: node 0 at (0, 10) in cluster A, node 1 at (0, -10) in
    cluster B. Each cluster also has a prize-5 node, at (-12, 0) and (12, 0): one route fits that
    node (energy 24) or the group's (20), not both (37.6 > 24.5). Alone each cluster takes its
    prize node, so nobody covers the group; OPT|C gives one prize node up: 5 + 1.
    """
    coords = np.array([[0.0, 10.0], [0.0, -10.0], [-12.0, 0.0], [12.0, 0.0]])
    inst = TOPInstance(coords=coords, prizes=np.array([1.0, 1.0, 5.0, 5.0]), start=np.zeros(2),
                       end=np.zeros(2), budget=24.5, n_vehicles=2, groups=((0, 1),))
    clusters = [[0, 2], [1, 3]]
    assert split_groups(inst, clusters) == 1
    res = solve_clustered(inst, clusters, time_limit=60)
    assert res.status == Status.OPTIMAL and verify(inst, res.plan).prize == 6.0 == brute_clustered(inst, clusters)
    assert res.info["bb_nodes"] > 1 and inside(res.plan, clusters)


@pytest.mark.parametrize("seed", range(10))
def test_opt_c_at_most_opt_and_max_over_clusterings_is_opt(seed):
    """OPT|C <= OPT (milp) for random clusterings, and OPT is the best OPT|C over all clusterings
    (brute force over every labelling of the nodes), the identity the decomposition rests on."""
    inst = tiny_instance(seed)
    opt = solve_milp(inst, time_limit=60)
    expected = brute_opt(inst)
    if expected is None:
        assert opt.status == Status.INFEASIBLE
        return
    assert opt.status == Status.OPTIMAL and verify(inst, opt.plan).prize == pytest.approx(expected)
    rng = np.random.default_rng(seed)
    for _ in range(3):
        clusters = random_clusters(inst, rng)
        res = solve_clustered(inst, clusters, time_limit=60)
        if res.status == Status.OPTIMAL:
            assert verify(inst, res.plan).prize <= expected + 1e-9
    if inst.n_nodes <= 6 and inst.n_vehicles == 2:
        best = max((brute_clustered(inst, [[v for v in range(inst.n_nodes) if lab[v] == i] for i in range(2)])
                    or -1.0) for lab in itertools.product(range(2), repeat=inst.n_nodes))
        assert best == pytest.approx(expected)


def test_oracle_clustering_gives_opt():
    """The clustering an optimal plan induces has OPT|C = OPT, whether the viewpoints it leaves
    unvisited are assigned to a route's cluster (a partition, like a clusterer's) or dropped."""
    for seed in range(3):
        inst = to_top(generate(8, 2, 3, seed=seed))
        opt = solve_milp(inst, time_limit=120)
        assert opt.status == Status.OPTIMAL
        for unvisited in ("assign", "drop"):
            clusters = oracle_clusters(inst, opt.plan, unvisited=unvisited)
            flat = [v for c in clusters for v in c]
            assert len(flat) == len(set(flat))
            if unvisited == "assign":
                assert sorted(flat) == np.flatnonzero(inst.reachable()).tolist()
            else:
                assert sorted(flat) == sorted(opt.plan.visited)
            res = solve_clustered(inst, clusters, time_limit=60)
            assert res.status == Status.OPTIMAL
            assert verify(inst, res.plan).prize == verify(inst, opt.plan).prize


@pytest.mark.slow
def test_paper_size_clusterings_agree_with_the_joint_milp():
    """At M = 20, N = 5, K = 3 (the paper's size) the decomposition and the joint MILP prove the same
    OPT|C for each paper clusterer, below the milp optimum."""
    from sarcover.heuristics.pipeline import cluster_stage

    inst = to_top(generate(20, 3, 5, seed=0))
    for clusterer in ("adpc", "dpc", "kmeans"):
        clusters = cluster_stage(inst, clusterer, seed=0)
        a = solve_clustered(inst, clusters, time_limit=120)
        b = solve_clustered_milp(inst, clusters, time_limit=120)
        assert a.status == b.status == Status.OPTIMAL
        assert verify(inst, a.plan).prize == verify(inst, b.plan).prize
        assert inside(a.plan, clusters) and inside(b.plan, clusters)


def test_bad_clusters_and_warm_start():
    """Overlapping or too many clusters raise; a warm start outside the clusters is never used."""
    inst = tiny_instance(1)
    with pytest.raises(ValueError, match="overlap"):
        solve_clustered(inst, [[0], [0]])
    with pytest.raises(ValueError, match="clusters for"):
        solve_clustered(inst, [[v] for v in range(inst.n_vehicles + 1)])
    clusters = [list(range(inst.n_nodes))] + [[] for _ in range(inst.n_vehicles - 1)]
    outside = Plan.of([[]] + [[0]] + [[] for _ in range(inst.n_vehicles - 2)])
    res = solve_clustered(inst, clusters, warm_start=outside, time_limit=60)
    assert res.status in (Status.OPTIMAL, Status.INFEASIBLE)
    if res.plan is not None:
        assert inside(res.plan, clusters)
