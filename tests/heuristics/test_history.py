"""Every heuristic records its incumbent history in the format of formulations/history.py."""

import pytest

from sarcover.benchmarks.registry import run_method
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import to_top

HEURISTICS = ["greedy", "adpc-pso", "dpc-pso", "kmeans-pso", "adpc-ga", "adpc-aco", "pyvrp", "routing"]


@pytest.fixture(scope="module")
def instance():
    """The paper preset at M = 20, K = 3, N = 5 (the anytime suite's first instance)."""
    return to_top(generate(20, 3, 5, seed=100))


@pytest.mark.parametrize("method", HEURISTICS)
def test_history_is_well_formed_and_ends_at_the_verified_objective(method, instance):
    """[t, incumbent, None] points: times within the run, incumbents rising, no bound, and the
    last incumbent is the verifier's objective of the returned plan."""
    res = run_method(method, instance, seed=0, time_limit=2.0)
    hist = res.info["history"]
    assert res.valid and hist
    times = [p[0] for p in hist]
    incs = [p[1] for p in hist if p[1] is not None]
    assert all(len(p) == 3 and p[2] is None for p in hist)
    assert times == sorted(times) and 0.0 <= times[0] and times[-1] <= res.runtime_s + 1e-3
    assert incs == sorted(incs)
    assert hist[-1][1] == res.objective
    cpu = res.info["history_cpu"]
    assert len(cpu) == len(hist) and cpu == sorted(cpu) and cpu[0] >= 0.0


def test_greedy_is_one_point(instance):
    """greedy's history is a single point: its plan when the construction ends."""
    res = run_method("greedy", instance)
    assert len(res.info["history"]) == 1 and res.info["history"][0][1] == res.objective


@pytest.mark.parametrize("method", ["pyvrp", "routing"])
def test_search_logs_the_returned_plan_when_it_finds_it(method, instance):
    """The peers log improvements during the search: there is a point before the end, and the
    returned plan's prize was already logged when the search found it (the callbacks repair a
    solution exactly as the method repairs its final one)."""
    res = run_method(method, instance, seed=0, time_limit=2.0)
    hist = res.info["history"]
    assert len(hist) >= 2
    assert hist[-2][1] == res.objective
    assert hist[0][0] < hist[-1][0]


def test_no_plan_has_an_empty_incumbent():
    """A heuristic that finds no plan covering every target ends its history without an incumbent."""
    inst = to_top(generate(20, 3, 1, seed=0))  # one UAV cannot cover 20 targets within E_max
    for method in ("greedy", "adpc-pso", "pyvrp", "routing"):
        res = run_method(method, inst, seed=0, time_limit=1.0)
        assert res.plan is None and res.info["history"][-1][1] is None
