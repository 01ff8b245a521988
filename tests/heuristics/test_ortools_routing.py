"""The `routing` (OR-Tools) and `pyvrp` peer heuristics: hand-checkable optima, depots, groups,
budgets, verified plans on random instances, and never beating published TOP optima."""

import csv

import numpy as np
import pytest

from sarcover.benchmarks.registry import run_method
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import TOPInstance, to_top
from sarcover.formulations.io import load_instance
from sarcover.formulations.result import Status

from conftest import TOP_DIR

PEERS = ["routing", "pyvrp"]
FAST = 1.0  # seconds per run in the default tests


def top(coords, prizes, budget, n=1, start=(0.0, 0.0), end=None, groups=(), e_image=0.0):
    return TOPInstance(coords=np.asarray(coords, float), prizes=np.asarray(prizes, float),
                       start=np.asarray(start, float), end=np.asarray(start if end is None else end, float),
                       budget=budget, n_vehicles=n, e_image=e_image, groups=groups)


# Two near nodes worth 1 each (round trip 4) or one far node worth 10 (round trip 10); budget
# 10.5 fits one of the two choices, not both (2 + sqrt(29) + 5 = 12.4).
CHOICE = dict(coords=[[1, 0], [2, 0], [0, 5]], prizes=[1, 1, 10], budget=10.5)


@pytest.mark.parametrize("method", PEERS)
@pytest.mark.parametrize("n, expected", [(1, 10.0), (2, 12.0)])
def test_obvious_optimum(method, n, expected):
    """One vehicle takes the far prize 10; two vehicles take everything (12)."""
    res = run_method(method, top(**CHOICE, n=n), time_limit=FAST)
    assert res.status == Status.FEASIBLE and res.bound is None
    assert res.objective == expected


@pytest.mark.parametrize("method", PEERS)
def test_line_takes_all(method, line_instance):
    """Three nodes on a line within budget 6: all are visited in one route."""
    res = run_method(method, line_instance, time_limit=FAST)
    assert res.objective == 6.0 and sorted(res.plan.routes[0]) == [0, 1, 2]


@pytest.mark.parametrize("method", PEERS)
def test_distinct_start_end(method):
    """Start (0,0), end (10,0), budget 10: only the node on the segment fits, not the one off it."""
    inst = top([[5, 0], [5, 3]], [1, 5], 10.0, end=(10.0, 0.0))
    res = run_method(method, inst, time_limit=FAST)
    assert res.objective == 1.0 and res.plan.visited == [0]


@pytest.mark.parametrize("method", PEERS)
def test_empty_route_costs_nothing(method):
    """End depot far beyond the budget: nothing is reachable, the empty plan is valid (prize 0)."""
    inst = top([[1, 1]], [3], 1.0, n=2, end=(100.0, 0.0))
    res = run_method(method, inst, time_limit=FAST)
    assert res.status == Status.FEASIBLE and res.objective == 0.0


@pytest.mark.parametrize("method", PEERS)
def test_group_forces_zero_prize_node(method):
    """A prize-0 group node on the far side must be visited, which leaves room for prize 1 only."""
    # round trips: node 0 (0,4): 8; node 1 (3,0): 6; node 2 (0,-4) group: 8. Budget 9, one vehicle:
    # the group node plus nothing else fits (8 + anything > 9 except none) -> objective 0.
    inst = top([[0, 4], [3, 0], [0, -4]], [5, 1, 0], 9.0, groups=((2,),))
    res = run_method(method, inst, time_limit=FAST)
    assert res.status == Status.FEASIBLE
    assert 2 in res.plan.visited and res.objective == 0.0
    # with a second vehicle the group and the prize-5 node both fit
    res2 = run_method(method, top([[0, 4], [3, 0], [0, -4]], [5, 1, 0], 9.0, n=2, groups=((2,),)), time_limit=FAST)
    assert 2 in res2.plan.visited and res2.objective == 5.0


@pytest.mark.parametrize("method", PEERS)
def test_groups_that_cannot_share_a_route(method):
    """Two groups 8 apart each side of the depot: one vehicle cannot cover both (NO_PLAN), two can."""
    coords, groups = [[0, 4], [0, -4]], ((0,), (1,))
    res = run_method(method, top(coords, [1, 1], 10.0, groups=groups), time_limit=FAST)
    assert res.status == Status.NO_PLAN and res.plan is None and res.reason
    res = run_method(method, top(coords, [1, 1], 10.0, n=2, groups=groups), time_limit=FAST)
    assert res.status == Status.FEASIBLE and res.objective == 2.0


@pytest.mark.parametrize("method", PEERS)
def test_budget_exactly_tight(method):
    """A route whose energy equals the budget up to 1e-7 may be missed (rounding up) but never exceeded."""
    inst = top([[3, 0]], [1], 6.0 - 1e-7)
    res = run_method(method, inst, time_limit=FAST)
    assert res.status == Status.FEASIBLE and res.objective == 0.0  # 6 > budget: must not be taken
    res = run_method(method, top([[3, 0]], [1], 6.0), time_limit=FAST)
    assert res.status == Status.FEASIBLE and res.report.valid


@pytest.mark.parametrize("method", PEERS)
def test_unreachable_group_is_infeasible(method):
    """A group whose only node is beyond the budget is reported infeasible by the precheck."""
    res = run_method(method, top([[0, 10]], [1], 5.0, groups=((0,),)), time_limit=FAST)
    assert res.status == Status.INFEASIBLE


def _random_instances():
    rng = np.random.default_rng(2026)
    for seed in range(50):
        m, k, n = int(rng.integers(2, 7)), int(rng.integers(1, 4)), int(rng.integers(1, 4))
        e_max = float(rng.choice([1500.0, 3000.0, 6000.0]))
        yield to_top(generate(m, k, n, seed, e_max=e_max))


@pytest.mark.parametrize("method", PEERS)
def test_random_instances_verified(method):
    """50 random SAR instances (tight to loose): every plan verifies, never ERROR, and in total
    the peer collects at least as much as greedy."""
    totals = {"peer": 0.0, "greedy": 0.0}
    statuses = set()
    for inst in _random_instances():
        res = run_method(method, inst, time_limit=0.3)
        g = run_method("greedy", inst)
        assert res.status != Status.ERROR, res.reason
        statuses.add(res.status)
        if res.plan is not None:
            assert res.report.valid and res.report.groups_covered == len(inst.groups)
            totals["peer"] += res.objective
            totals["greedy"] += g.objective or 0.0
        elif g.plan is not None:
            assert res.status == Status.NO_PLAN
    assert Status.FEASIBLE in statuses
    assert totals["peer"] >= totals["greedy"]


def _optima():
    with open(TOP_DIR / "optimal.csv") as fh:
        return {r["instance"]: float(r["value"]) for r in csv.DictReader(fh) if r["instance"][:2] in ("p1", "p2", "p3")}


@pytest.mark.parametrize("method", PEERS)
@pytest.mark.parametrize("name", ["p2.2.f", "p2.3.g", "p1.4.p"])
def test_top_never_beats_optimum(method, name):
    """On TOP benchmark files the peers never exceed the published optimum (and reach it here)."""
    inst = load_instance(TOP_DIR / f"{name}.txt")
    res = run_method(method, inst, time_limit=2.0)
    assert res.status == Status.FEASIBLE
    assert res.objective <= _optima()[name] + 1e-9
    assert res.objective >= 0.9 * _optima()[name]


def test_routing_reproducible_when_stopped_by_solution_limit():
    """OR-Tools routing stopped by its solution limit (not time) returns the same plan twice."""
    from sarcover.heuristics.ortools_routing import solve_routing

    inst = load_instance(TOP_DIR / "p2.3.g.txt")
    a = solve_routing(inst, time_limit=30.0, solution_limit=200)
    b = solve_routing(inst, time_limit=30.0, solution_limit=200)
    assert a.info["stopped_by"] == "solution_limit"
    assert a.plan == b.plan


@pytest.mark.slow
@pytest.mark.parametrize("method", PEERS)
def test_top_all_files_never_beat_optimum(method):
    """All 117 TOP files (2 s each): every plan verifies and none exceeds the published optimum."""
    optima = _optima()
    for name, value in optima.items():
        res = run_method(method, load_instance(TOP_DIR / f"{name}.txt"), time_limit=2.0)
        assert res.status == Status.FEASIBLE, f"{name}: {res.reason}"
        assert res.objective <= value + 1e-9, f"{name}: {res.objective} > optimum {value}"


def test_never_below_its_greedy_start():
    """With little time on a large instance (120 viewpoints, 1 s) routing still returns at least
    greedy's plan: a cold search that ends below greedy is followed by a greedy-started one."""
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(20, 6, 5, 3))
    g = run_method("greedy", inst)
    r = run_method("routing", inst, time_limit=1.0)
    assert g.status == Status.FEASIBLE and r.status == Status.FEASIBLE and r.report.valid
    assert r.objective >= g.objective
