"""solve_bp end to end: the proven optima, valid bounds when stopped, statuses, the registered bp."""

from __future__ import annotations

import pytest

from sarcover.benchmarks.registry import run_method
from sarcover.formulations.bp import BPOptions, solve_bp
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.io import load_instance
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Status

from bp_cases import FAST_TOP, OPTIMAL, TOP_DIR, brute_force, random_tiny, tiny_sar, top_instance


def test_line_instance_by_hand():
    """Two vehicles on a hand-checked instance: (1,0),(2,0) on one trip, (0,3) on the other: 8."""
    inst = TOPInstance(coords=[[1, 0], [2, 0], [0, 3]], prizes=[1, 2, 5], start=[0, 0], end=[0, 0],
                       budget=6.0, n_vehicles=2)
    res = run_method("bp", inst, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == 8.0 and res.bound == 8.0
    one = TOPInstance(coords=[[1, 0], [2, 0], [0, 3]], prizes=[1, 2, 5], start=[0, 0], end=[0, 0],
                      budget=4.5, n_vehicles=1)
    res = run_method("bp", one, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == 3.0


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("groups", [False, True])
def test_matches_brute_force(seed, groups):
    """The proven optimum equals exhaustive enumeration on tiny random instances, with and without groups."""
    inst = random_tiny(seed, groups=groups)
    best = brute_force(inst)
    res = run_method("bp", inst, time_limit=30)
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
    res = run_method("bp", inst, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == pytest.approx(best)


def test_infeasible_groups_proven():
    """Two groups on opposite sides, each reachable alone but not both with one vehicle: infeasible."""
    inst = TOPInstance(coords=[[5, 0], [-5, 0], [0, 1]], prizes=[1, 1, 3], start=[0, 0], end=[0, 0],
                       budget=10.5, n_vehicles=1, groups=((0,), (1,)))
    res = run_method("bp", inst, time_limit=30)
    assert res.status == Status.INFEASIBLE and res.plan is None


def test_groups_force_lower_prize():
    """A group on a cheap node forces the vehicle away from the big prize (hand-checked: 1)."""
    inst = TOPInstance(coords=[[3, 0], [-3, 0]], prizes=[1, 10], start=[0, 0], end=[0, 0],
                       budget=6.5, n_vehicles=1, groups=((0,),))
    res = run_method("bp", inst, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == 1.0 and res.plan.visited == [0]


def test_initial_routes_are_used():
    """A warm-start plan is accepted as incumbent and the proof still reaches the optimum."""
    inst = load_instance(TOP_DIR / "p2.2.d.txt")
    res = solve_bp(inst, time_limit=30, warm_start=Plan.of([[0], [1]]))
    assert res.status == Status.OPTIMAL and res.bound == OPTIMAL["p2.2.d"]


@pytest.mark.parametrize("name", FAST_TOP)
def test_top_benchmark_optimum(name):
    """On a fast TOP subset, bp proves exactly the published optimum."""
    inst = load_instance(TOP_DIR / f"{name}.txt")
    res = run_method("bp", inst, time_limit=60)
    assert res.status == Status.OPTIMAL, res.reason
    assert res.objective == OPTIMAL[name] and res.bound == OPTIMAL[name]


@pytest.mark.parametrize("name", ["p1.2.r", "p3.2.t", "p3.2.j"])
def test_stopped_run_bound_is_valid(name):
    """Stopped after 2 s on hard instances, the certified bound is never below the published optimum."""
    inst = load_instance(TOP_DIR / f"{name}.txt") if (TOP_DIR / f"{name}.txt").exists() else None
    if inst is None:
        pytest.skip(f"{name} not in the public part")
    res = run_method("bp", inst, time_limit=2)
    assert res.status in (Status.OPTIMAL, Status.TIME_LIMIT)
    assert res.bound is not None and res.bound >= OPTIMAL[name] - 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(n for n in OPTIMAL if n.split(".")[0] in ("p1", "p2", "p3")))
def test_top_sets_1_to_3_all(name):
    """Every TOP instance of sets 1-3: the published optimum, proven within 60 s."""
    inst = load_instance(TOP_DIR / f"{name}.txt")
    res = run_method("bp", inst, time_limit=60)
    assert res.bound is None or res.bound >= OPTIMAL[name] - 1e-6
    assert res.status == Status.OPTIMAL, res.reason
    assert res.objective == OPTIMAL[name]


@pytest.mark.parametrize("e_max", [5000.0, 5500.0, 6000.0])
def test_small_sar_matches_brute_force(e_max):
    """SAR form (unit prizes, one group per target) with a binding budget: optimum equals enumeration."""
    inst = tiny_sar(e_max)
    best = brute_force(inst)
    assert best is not None and best < inst.total_prize  # feasible, and the budget binds
    res = run_method("bp", inst, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == best


def test_sar_infeasible_when_targets_do_not_fit():
    """Every target reachable alone but not all in one flight: proven infeasible (precheck passes)."""
    from sarcover.formulations.instance import precheck

    inst = tiny_sar(4500.0)
    assert precheck(inst) is None and brute_force(inst) is None
    res = run_method("bp", inst, time_limit=30)
    assert res.status == Status.INFEASIBLE


def test_solve_bp_options_override_a_default():
    """Without options a run uses its limit's defaults (at 30 s, no cuts); options=BPOptions(...)
    turns cuts on for the same call, and the published optimum is proven either way."""
    import dataclasses

    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    default = solve_bp(inst, time_limit=30)
    forced = solve_bp(inst, time_limit=30,
                      options=BPOptions(cut_rounds=4, cut_gap=100.0, cut_share=1.0))
    # each run's info holds the settings it used, the limit's defaults filled in
    assert default.info["options"] == dataclasses.asdict(BPOptions.for_time_limit(30))
    assert (default.info["cuts"] > 0) == (default.info["options"]["cut_rounds"] > 0)
    assert forced.info["cuts"] > 0 and forced.info["options"]["cut_rounds"] == 4
    assert forced.info["options"]["cut_share"] == 1.0 and "exact_keep" in default.info["options"]
    for r in (default, forced):
        assert r.status == Status.OPTIMAL and r.bound == pytest.approx(OPTIMAL["p2.2.k"])


def test_registered_bp_starts_from_greedy():
    """The registered `bp` gets greedy's routes as first columns: stopped almost at once on a
    paper-size instance it still returns a verified plan at least as good as greedy's, under its bound."""
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(20, 3, 5, 11))
    g = run_method("greedy", inst)
    r = run_method("bp", inst, time_limit=0.5)
    assert g.status == Status.FEASIBLE and r.plan is not None and r.report.valid
    assert r.objective >= g.objective and r.bound >= r.objective
    assert r.info["warm_start_prize"] == g.objective
    # stopped with a gap, some node is left open; a proven run leaves none
    assert r.status != Status.OPTIMAL and r.bound > r.objective and r.info["open_nodes"] >= 1
    proven = solve_bp(top_instance("p3.3.o"), time_limit=30)
    assert proven.status == Status.OPTIMAL and proven.info["open_nodes"] == 0


def test_registered_bp_runs_pyvrp_as_its_primal():
    """The registered `bp` hands PyVRP to the search: on an instance the root leaves open its
    plan is verified and counted (p1.2.l)."""
    r = run_method("bp", top_instance("p1.2.l"), time_limit=60)
    assert r.report.valid and r.status == Status.OPTIMAL
    assert r.info["primal_prize"] is not None and r.info["primal_prize"] <= r.objective + 1e-9
    assert r.info["primal_error"] is None
