"""The cluster-then-route methods: verified plans, honest statuses, reproducibility."""

from __future__ import annotations

import numpy as np
import pytest

from sarcover.benchmarks.registry import METHODS, run_method
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import TOPInstance, to_top
from sarcover.formulations.result import Status
from sarcover.formulations.verify import verify

PIPELINES = ["adpc-pso", "dpc-pso", "kmeans-pso", "adpc-ga", "adpc-aco"]
FAST = ["adpc-pso", "dpc-pso", "kmeans-pso", "adpc-ga"]  # adpc-aco is ~3x slower: fewer cases


def random_instance(seed: int) -> TOPInstance:
    """A random SAR or general TOP instance; budgets from hopeless to generous."""
    rng = np.random.default_rng(seed)
    if rng.random() < 0.6:
        m, k, n = int(rng.integers(1, 9)), int(rng.integers(1, 5)), int(rng.integers(1, 5))
        e_max = float(rng.choice([800.0, 2500.0, 3500.0, 5000.0, 6000.0, 20000.0]))
        return to_top(generate(m, k, n, seed, e_max=e_max))
    v = int(rng.integers(1, 16))
    coords = rng.uniform(0, 100, (v, 2))
    if rng.random() < 0.2:
        coords[: v // 2] = coords[0]  # duplicated points
    ids = rng.permutation(v)
    n_groups = int(rng.integers(0, min(v, 4) + 1))
    parts = np.array_split(ids[: 2 * n_groups], n_groups) if n_groups else []
    groups = tuple(tuple(int(i) for i in part) for part in parts if len(part))
    start = rng.uniform(0, 100, 2)
    end = start if rng.random() < 0.5 else rng.uniform(0, 100, 2)
    return TOPInstance(
        coords=coords,
        prizes=rng.integers(0, 10, v).astype(float),
        start=start,
        end=end,
        budget=float(rng.uniform(20, 400)),
        n_vehicles=int(rng.integers(1, 5)),
        e_fly=float(rng.uniform(0.5, 2)),
        e_image=float(rng.choice([0.0, 5.0])),
        groups=groups,
    )


def _check(name: str, seeds) -> dict:
    counts: dict[str, int] = {}
    for seed in seeds:
        inst = random_instance(seed)
        result = run_method(name, inst, seed=seed, time_limit=30.0)
        assert result.status != Status.ERROR, (seed, result.reason)
        assert result.status in (Status.FEASIBLE, Status.NO_PLAN, Status.INFEASIBLE), (seed, result.status)
        if result.status == Status.FEASIBLE:
            assert result.report is not None and result.report.valid
            assert len(result.plan.routes) == inst.n_vehicles
        else:
            assert result.plan is None and result.reason
        counts[str(result.status)] = counts.get(str(result.status), 0) + 1
    return counts


@pytest.mark.parametrize("name", FAST)
def test_verified_plans_on_random_instances(name):
    """Every plan on 150 random instances (tight and infeasible budgets included) passes the verifier."""
    counts = _check(name, range(150))
    assert counts.get("feasible", 0) > 50 and counts.get("infeasible", 0) > 5


def test_verified_plans_aco():
    """adpc-aco returns verified plans on 60 random instances."""
    counts = _check("adpc-aco", range(60))
    assert counts.get("feasible", 0) > 20


@pytest.mark.slow
@pytest.mark.parametrize("name", PIPELINES)
def test_verified_plans_many(name):
    """Every plan on 1000 random instances passes the verifier (slow)."""
    _check(name, range(1000, 2000))


@pytest.mark.parametrize("name", PIPELINES)
def test_same_seed_same_plan(name):
    """Two runs with one seed give the same plan; the registry lists the method as a heuristic."""
    inst = to_top(generate(12, 3, 3, seed=5))
    a = run_method(name, inst, seed=3)
    b = run_method(name, inst, seed=3)
    assert a.status == Status.FEASIBLE and a.plan == b.plan
    assert not METHODS[name].exact and a.bound is None


@pytest.mark.parametrize("name", PIPELINES)
def test_paper_instance_coverage_at_least_greedy_groups(name):
    """On a paper-size instance every target is covered and coverage is between 0 and 1."""
    inst = to_top(generate(20, 3, 5, seed=0))
    result = run_method(name, inst, seed=0)
    assert result.status == Status.FEASIBLE
    assert result.report.groups_covered == 20 and 20 <= result.report.covered < 60


def test_unreachable_group_is_infeasible_and_crowded_budget_is_no_plan():
    """A target out of reach is INFEASIBLE (precheck); too many targets for one tiny route is NO_PLAN."""
    far = to_top(generate(3, 3, 2, seed=1, e_max=200.0))
    result = run_method("adpc-pso", far)
    assert result.status == Status.INFEASIBLE
    # four groups on the corners of a square, each alone within budget, two vehicles: at most
    # two groups fit, so no plan covers all four
    coords = np.array([[10.0, 0.0], [-10.0, 0.0], [0.0, 10.0], [0.0, -10.0]])
    inst = TOPInstance(coords=coords, prizes=np.ones(4), start=np.zeros(2), end=np.zeros(2),
                       budget=21.0, n_vehicles=2, groups=((0,), (1,), (2,), (3,)))
    for name in PIPELINES:
        result = run_method(name, inst)
        assert result.status == Status.NO_PLAN and "could not fit" in result.reason


def test_general_top_with_distinct_end():
    """Routes may end elsewhere than they start; the plan is verified against that end."""
    rng = np.random.default_rng(0)
    inst = TOPInstance(coords=rng.uniform(0, 50, (25, 2)), prizes=rng.integers(1, 5, 25).astype(float),
                       start=np.zeros(2), end=np.array([50.0, 50.0]), budget=110.0, n_vehicles=3)
    for name in PIPELINES:
        result = run_method(name, inst)
        assert result.status == Status.FEASIBLE and result.report.valid and result.report.prize > 0
        assert verify(inst, result.plan).valid


@pytest.mark.parametrize("name", PIPELINES)
def test_expired_time_limit_still_gives_a_verified_plan(name):
    """A time limit that expires at once stops the routers early; the repaired plan still verifies."""
    inst = to_top(generate(20, 3, 5, seed=4))
    result = run_method(name, inst, seed=0, time_limit=1e-9)
    assert result.status == Status.FEASIBLE and result.report.valid
    assert result.info["stopped_by_time"] is True


# ---------------------------------------------------------------- the stages apart (decomposition)

from sarcover.heuristics.pipeline import (  # noqa: E402
    ROUTERS, cluster_stage, cluster_then_route, outside_clusters, route_clusters,
)

STAGE_CASES = [(20, 3, 5, 0), (20, 6, 5, 1), (20, 3, 2, 2), (8, 2, 4, 3)]


@pytest.mark.parametrize("clusterer", ["adpc", "dpc", "kmeans"])
def test_cluster_stage_partitions_the_reachable_viewpoints(clusterer):
    """N disjoint clusters, one per UAV, whose union is exactly the reachable viewpoints."""
    for m, k, n, s in STAGE_CASES + [(3, 1, 5, 4)]:  # the last: fewer viewpoints than UAVs
        inst = to_top(generate(m, k, n, seed=s))
        clusters = cluster_stage(inst, clusterer, seed=s)
        assert len(clusters) == n
        flat = np.concatenate(clusters)
        assert flat.size == np.unique(flat).size
        assert sorted(flat.tolist()) == np.flatnonzero(inst.reachable()).tolist()


@pytest.mark.parametrize("clusterer,router", [("adpc", "pso"), ("dpc", "pso"), ("kmeans", "pso"),
                                              ("adpc", "ga"), ("adpc", "aco")])
def test_stages_apart_give_the_pipelines_plan(clusterer, router):
    """cluster_stage + route_clusters with one seed is the pipeline's plan, route for route, and the
    pipeline's info keeps the clusters and which plan nodes lie outside their route's cluster."""
    for m, k, n, s in STAGE_CASES:
        inst = to_top(generate(m, k, n, seed=s))
        whole = cluster_then_route(inst, clusterer, router, seed=s + 1)
        clusters = cluster_stage(inst, clusterer, seed=s + 1)
        apart = route_clusters(inst, clusters, router, seed=s + 1)
        assert whole.status == apart.status == Status.FEASIBLE
        assert whole.plan == apart.plan
        assert whole.info["clusters"] == [c.tolist() for c in clusters]
        outside = whole.info["outside_cluster"]
        assert outside == outside_clusters(whole.plan.routes, clusters)
        for i, route in enumerate(whole.plan.routes):
            assert set(route) - set(outside[i]) <= set(clusters[i].tolist())
            assert set(outside[i]).isdisjoint(clusters[i].tolist())


def test_route_clusters_keeps_route_i_for_cluster_i():
    """Given clusters in any order, route i serves cluster i (up to what repair moves)."""
    inst = to_top(generate(20, 3, 5, seed=3))
    clusters = cluster_stage(inst, "adpc", seed=0)[::-1]
    result = route_clusters(inst, clusters, "pso", seed=0)
    assert result.status == Status.FEASIBLE and verify(inst, result.plan).valid
    for i, route in enumerate(result.plan.routes):
        inside = [v for v in route if v not in result.info["outside_cluster"][i]]
        assert set(inside) <= set(clusters[i].tolist())
        assert len(inside) > 0  # each route keeps part of its own cluster here
    with pytest.raises(ValueError, match="overlap"):
        route_clusters(inst, [clusters[0], clusters[0]], "pso")
    with pytest.raises(ValueError, match="clusters for"):
        route_clusters(inst, [[0]] * 6, "pso")
    assert set(ROUTERS) == {"pso", "ga", "aco"}
