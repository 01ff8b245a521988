"""`greedy` always returns verified plans, covering every target when it reports a plan."""

import numpy as np
import pytest

from sarcover.benchmarks.registry import run_method
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import to_top
from sarcover.formulations.result import Status


def test_greedy_takes_everything_when_budget_allows(line_instance):
    """Budget 6 on the line instance: all three nodes on one route."""
    res = run_method("greedy", line_instance)
    assert res.status == Status.FEASIBLE and res.report.valid and res.objective == 6.0


@pytest.mark.parametrize("seed", range(300))
def test_greedy_plans_always_verified(seed):
    """Random instances, tight to loose budgets: every plan passes the verifier and covers all targets."""
    rng = np.random.default_rng(seed)
    m, k, n = int(rng.integers(2, 15)), int(rng.integers(1, 5)), int(rng.integers(1, 5))
    e_max = float(rng.choice([2000, 3000, 4500, 6000, 9000]))
    inst = to_top(generate(m, k, n, seed, e_max=e_max))
    res = run_method("greedy", inst)
    assert res.status in (Status.FEASIBLE, Status.NO_PLAN, Status.INFEASIBLE), res.reason
    if res.status == Status.FEASIBLE:
        assert res.report.valid and res.report.groups_covered == m
        assert res.objective == res.report.covered
    else:
        assert res.plan is None and res.reason


def test_greedy_rules_by_hand():
    """Hardest group first, then prize per energy: on a line, the far group's view goes in first.

    Nodes at x = 1, 2 (group 0) and x = 5 (group 1, its only view), one vehicle, budget 10:
    group 1 (cheapest insertion 10) before group 0 (2), then node 2 (prize 3) fits, node 1 too."""
    from sarcover.formulations.instance import TOPInstance

    inst = TOPInstance(coords=np.array([[1.0, 0.0], [2.0, 0.0], [5.0, 0.0]]), prizes=np.array([1.0, 3.0, 1.0]),
                       start=np.zeros(2), end=np.zeros(2), budget=10.0, n_vehicles=1, groups=[[0, 1], [2]])
    res = run_method("greedy", inst)
    assert res.status == Status.FEASIBLE and res.report.valid
    assert res.plan.routes == ((0, 1, 2),) and res.objective == 5.0
