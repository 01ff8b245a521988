"""Branch-and-price (`bp`): hand-checked optima, groups, infeasibility, bounds on the TOP benchmark."""

from __future__ import annotations

import csv
import itertools
from pathlib import Path

import numpy as np
import pytest

from benchmarks.registry import run_method
from formulations.bp import solve_bp
from formulations.instance import TOPInstance
from formulations.io import load_instance
from formulations.plan import Status
from formulations.verify import route_energy

TOP_DIR = Path(__file__).resolve().parent.parent / "benchmarks" / "instances" / "top"
OPTIMAL = {r["instance"]: float(r["value"]) for r in csv.DictReader(open(TOP_DIR / "optimal.csv"))}


def brute_force(inst: TOPInstance) -> float | None:
    """Best prize over all plans of a tiny instance (None if no plan covers every group)."""
    v = inst.n_nodes
    routes = [()]
    for k in range(1, v + 1):
        for perm in itertools.permutations(range(v), k):
            if route_energy(inst, perm) <= inst.budget * (1 + 1e-9):
                routes.append(perm)
    sets = {frozenset(r) for r in routes}
    best = None
    for combo in itertools.combinations_with_replacement(sorted(sets, key=sorted), inst.n_vehicles):
        nodes = [i for s in combo for i in s]
        if len(nodes) != len(set(nodes)):
            continue
        seen = set(nodes)
        if any(not seen.intersection(g) for g in inst.groups):
            continue
        prize = float(sum(inst.prizes[i] for i in seen))
        best = prize if best is None else max(best, prize)
    return best


def random_tiny(seed: int, *, groups: bool, same_depot: bool = True) -> TOPInstance:
    rng = np.random.default_rng(seed)
    coords = rng.uniform(0, 10, size=(6, 2))
    end = np.zeros(2) if same_depot else np.array([10.0, 10.0])
    return TOPInstance(
        coords=coords, prizes=rng.integers(1, 6, size=6).astype(float), start=np.zeros(2), end=end,
        budget=18.0 if same_depot else 20.0, n_vehicles=2, e_fly=1.0, e_image=0.5,
        groups=((0, 1), (2, 3)) if groups else (),
    )


def test_line_instance_by_hand():
    """Two vehicles on a hand-checked instance: (1,0),(2,0) on one trip, (0,3) on the other: 8."""
    inst = TOPInstance(coords=[[1, 0], [2, 0], [0, 3]], prizes=[1, 2, 5], start=[0, 0], end=[0, 0],
                       budget=6.0, n_vehicles=2)
    res, rep = run_method("bp", inst, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == 8.0 and res.bound == 8.0
    one = TOPInstance(coords=[[1, 0], [2, 0], [0, 3]], prizes=[1, 2, 5], start=[0, 0], end=[0, 0],
                      budget=4.5, n_vehicles=1)
    res, rep = run_method("bp", one, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == 3.0


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("groups", [False, True])
def test_matches_brute_force(seed, groups):
    """The proven optimum equals exhaustive enumeration on tiny random instances, with and without groups."""
    inst = random_tiny(seed, groups=groups)
    best = brute_force(inst)
    res, rep = run_method("bp", inst, time_limit=30)
    if best is None:
        assert res.status == Status.INFEASIBLE
    else:
        assert res.status == Status.OPTIMAL and res.objective == pytest.approx(best)
        assert res.bound == pytest.approx(best)


@pytest.mark.parametrize("seed", range(3))
def test_start_differs_from_end(seed):
    """Open routes from start to a different end: optimum equals enumeration."""
    inst = random_tiny(seed, groups=False, same_depot=False)
    best = brute_force(inst)
    res, rep = run_method("bp", inst, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == pytest.approx(best)


def test_infeasible_groups_proven():
    """Two groups on opposite sides, each reachable alone but not both with one vehicle: infeasible."""
    inst = TOPInstance(coords=[[5, 0], [-5, 0], [0, 1]], prizes=[1, 1, 3], start=[0, 0], end=[0, 0],
                       budget=10.5, n_vehicles=1, groups=((0,), (1,)))
    res, rep = run_method("bp", inst, time_limit=30)
    assert res.status == Status.INFEASIBLE and res.plan is None


def test_groups_force_lower_prize():
    """A group on a cheap node forces the vehicle away from the big prize (hand-checked: 1)."""
    inst = TOPInstance(coords=[[3, 0], [-3, 0]], prizes=[1, 10], start=[0, 0], end=[0, 0],
                       budget=6.5, n_vehicles=1, groups=((0,),))
    res, rep = run_method("bp", inst, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == 1.0 and res.plan.visited == [0]


def test_initial_routes_are_used():
    """A warm-start plan is accepted as incumbent and the proof still reaches the optimum."""
    inst = load_instance(TOP_DIR / "p2.2.d.txt")
    res = solve_bp(inst, time_limit=30, initial_routes=[[0], [1]])
    assert res.status == Status.OPTIMAL and res.bound == OPTIMAL["p2.2.d"]


FAST_TOP = ["p1.2.j", "p1.3.n", "p1.4.r", "p2.2.k", "p2.3.g", "p2.4.k", "p3.2.e", "p3.3.k", "p3.4.p"]


@pytest.mark.parametrize("name", FAST_TOP)
def test_top_benchmark_optimum(name):
    """On a fast TOP subset, bp proves exactly the published optimum."""
    inst = load_instance(TOP_DIR / f"{name}.txt")
    res, rep = run_method("bp", inst, time_limit=60)
    assert res.status == Status.OPTIMAL, res.reason
    assert res.objective == OPTIMAL[name] and res.bound == OPTIMAL[name]


@pytest.mark.parametrize("name", ["p1.2.r", "p3.2.t", "p3.2.j"])
def test_stopped_run_bound_is_valid(name):
    """Stopped after 2 s on hard instances, the certified bound is never below the published optimum."""
    inst = load_instance(TOP_DIR / f"{name}.txt") if (TOP_DIR / f"{name}.txt").exists() else None
    if inst is None:
        pytest.skip(f"{name} not in the public part")
    res, rep = run_method("bp", inst, time_limit=2)
    assert res.status in (Status.OPTIMAL, Status.TIME_LIMIT)
    assert res.bound is not None and res.bound >= OPTIMAL[name] - 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(OPTIMAL))
def test_top_sets_1_to_3_all(name):
    """Every TOP instance of sets 1-3: the published optimum, proven within 60 s."""
    inst = load_instance(TOP_DIR / f"{name}.txt")
    res, rep = run_method("bp", inst, time_limit=60)
    assert res.bound is None or res.bound >= OPTIMAL[name] - 1e-6
    assert res.status == Status.OPTIMAL, res.reason
    assert res.objective == OPTIMAL[name]


def tiny_sar(e_max: float) -> TOPInstance:
    """Three targets, two views each, one UAV (explicit parameters: independent of the presets)."""
    from formulations.instance import SARInstance, to_top

    targets = np.array([[1500.0, 200.0], [200.0, 1500.0], [900.0, 900.0]])
    return to_top(SARInstance(targets=targets, n_views=2, n_uavs=1, altitude=200.0, pitch_deg=45.0,
                              e_fly=1.0, e_image=150.0, e_max=e_max))


@pytest.mark.parametrize("e_max", [5000.0, 5500.0, 6000.0])
def test_small_sar_matches_brute_force(e_max):
    """SAR form (unit prizes, one group per target) with a binding budget: optimum equals enumeration."""
    inst = tiny_sar(e_max)
    best = brute_force(inst)
    assert best is not None and best < inst.total_prize  # feasible, and the budget binds
    res, rep = run_method("bp", inst, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == best


def test_sar_infeasible_when_targets_do_not_fit():
    """Every target reachable alone but not all in one flight: proven infeasible (precheck passes)."""
    from formulations.instance import precheck

    inst = tiny_sar(4500.0)
    assert precheck(inst) is None and brute_force(inst) is None
    res, rep = run_method("bp", inst, time_limit=30)
    assert res.status == Status.INFEASIBLE
