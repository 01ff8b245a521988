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
    groups = tuple(tuple(int(i) for i in part) for part in np.array_split(ids[: 2 * n_groups], n_groups) if len(part)) if n_groups else ()
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
