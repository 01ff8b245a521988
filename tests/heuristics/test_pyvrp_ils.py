"""`pyvrp` specifics: reproducibility, the group repair, and the integer scaling guarantee."""

import time

import numpy as np
import pytest

from sarcover.benchmarks.registry import run_method
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import TOPInstance, to_top
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Status
from sarcover.formulations.scaling import integer_prizes, scaled_costs
from sarcover.formulations.verify import route_energy, verify
from sarcover.heuristics.pyvrp_ils import cover_groups, primal_routes, pyvrp


@pytest.mark.parametrize("seed", [0, 7])
def test_same_seed_same_plan(seed):
    """Stopped by iterations, PyVRP returns the same plan for the same seed."""
    inst = to_top(generate(8, 2, 2, seed, e_max=6000.0))
    a = run_method("pyvrp", inst, seed=seed, time_limit=30.0)
    b = run_method("pyvrp", inst, seed=seed, time_limit=30.0)
    assert all(a.info[p]["stopped_by"] == "iterations" for p in ("pass1", "pass2"))
    assert a.status == Status.FEASIBLE and a.plan == b.plan


def test_without_an_iteration_limit_the_time_limit_stops_both_passes():
    """iterations=None (bp's primal heuristic): both passes search until their time is up (no
    iteration stop); the plan still covers every target."""
    inst = to_top(generate(8, 2, 2, 0, e_max=6000.0))
    res = pyvrp(inst, seed=0, time_limit=1.0, iterations=None)
    assert all(res.info[p]["stopped_by"] == "time" for p in ("pass1", "pass2"))
    rep = verify(inst, res.plan)
    assert rep.valid and rep.groups_covered == len(inst.groups)


def test_bps_primal_heuristic_is_the_method_first_then_searches_its_time():
    """primal_routes' first call is the registered method (same seed, same iteration stop, same
    plan); a second call searches with another seed until its seconds are up (a tiny instance
    the method finishes in far less time keeps it busy) and returns a valid plan (node ids)."""
    inst = to_top(generate(8, 2, 2, 0, e_max=6000.0))
    method = pyvrp(inst, seed=3, time_limit=30.0)
    assert method.info["pass1"]["stopped_by"] == "iterations"
    run = primal_routes(inst, 3)
    assert Plan.of(run(30.0)) == method.plan
    t = time.perf_counter()
    routes = run(1.0)
    assert time.perf_counter() - t >= 0.9  # both passes ran until their share of the second
    assert verify(inst, Plan.of(routes)).valid


def test_cover_groups_repairs_an_uncovering_plan():
    """A plan missing a group gets the group inserted, evicting the cheapest prize per energy."""
    inst = TOPInstance(coords=np.array([[0, 4.0], [3, 0.0], [0, -4.0]]), prizes=np.array([5.0, 1.0, 0.0]),
                       start=np.zeros(2), end=np.zeros(2), budget=9.0, n_vehicles=1, groups=((2,),))
    repaired = cover_groups(inst, [[0]])
    assert repaired == [[2]]
    assert verify(inst, Plan.of(repaired)).valid
    no_room = TOPInstance(coords=np.array([[0, 4.0], [0, -4.0]]), prizes=np.ones(2), start=np.zeros(2),
                          end=np.zeros(2), budget=10.0, n_vehicles=1, groups=((0,), (1,)))
    assert cover_groups(no_room, [[0]]) is None


def test_scaled_routes_never_exceed_budget():
    """Any route within the integer budget is within the true budget (arcs rounded up)."""
    rng = np.random.default_rng(5)
    for trial in range(200):
        v = int(rng.integers(2, 8))
        inst = TOPInstance(coords=rng.uniform(0, 10, (v, 2)), prizes=np.ones(v), start=rng.uniform(0, 10, 2),
                           end=rng.uniform(0, 10, 2), budget=float(rng.uniform(5, 40)), n_vehicles=1,
                           e_image=float(rng.uniform(0, 2)))
        sc = scaled_costs(inst, resolution=int(rng.choice([10, 1000, 10**6])))
        route = list(rng.permutation(v)[: int(rng.integers(1, v + 1))])
        if sc.route_cost([x + 1 for x in route]) <= sc.budget:
            assert route_energy(inst, route) <= inst.budget * (1 + 1e-12)


def test_integer_prizes_dominate():
    """The smallest positive prize outweighs the given cost bound; zero prizes stay zero."""
    p = integer_prizes(np.array([0.0, 0.5, 2.0]), dominate=1000)
    assert p[0] == 0 and p[1] > 1000 and p[2] == 4 * p[1]


def test_infeasible_cover_is_no_plan():
    """Two groups on opposite sides with one vehicle: both passes fail, status NO_PLAN with a reason."""
    inst = TOPInstance(coords=np.array([[0, 4.0], [0, -4.0]]), prizes=np.ones(2), start=np.zeros(2),
                       end=np.zeros(2), budget=10.0, n_vehicles=1, groups=((0,), (1,)))
    res = run_method("pyvrp", inst, time_limit=2.0)
    assert res.status == Status.NO_PLAN and res.plan is None and res.reason


def test_pass1_share_splits_the_time_between_the_passes():
    """Stopped by time, pass 1 (cover copies) ends at ``pass1_share`` of the limit and pass 2
    searches the rest; the plan still covers every target. A share outside (0, 1] is refused."""
    inst = to_top(generate(8, 2, 2, 0, e_max=6000.0))
    short = pyvrp(inst, seed=0, time_limit=2.0, iterations=None, pass1_share=0.1)
    long = pyvrp(inst, seed=0, time_limit=2.0, iterations=None)
    assert short.info["pass1"]["seconds"] < 0.6 < 1.0 < short.info["pass2"]["seconds"]
    assert long.info["pass1"]["seconds"] > 1.0 > long.info["pass2"]["seconds"]
    for res in (short, long):
        rep = verify(inst, res.plan)
        assert rep.valid and rep.groups_covered == len(inst.groups)
    for bad in (0.0, 1.5):
        with pytest.raises(ValueError, match="pass1_share"):
            pyvrp(inst, seed=0, time_limit=1.0, pass1_share=bad)


def test_bps_later_primal_calls_give_pass_1_the_late_share(monkeypatch):
    """primal_routes' first call keeps the method's split (PASS1_SHARE); the later, time-stopped
    calls give pass 1 only LATE_PASS1_SHARE of their seconds."""
    import sarcover.heuristics.pyvrp_ils as module

    shares = []
    real = module.pyvrp

    def spy(*args, **kwargs):
        res = real(*args, **kwargs)
        shares.append((kwargs["pass1_share"], res.info["pass1"]["seconds"]))
        return res

    monkeypatch.setattr(module, "pyvrp", spy)
    inst = to_top(generate(8, 2, 2, 0, e_max=6000.0))
    run = module.primal_routes(inst, 3)
    run(30.0)
    assert verify(inst, Plan.of(run(2.0))).valid
    assert [s for s, _ in shares] == [module.PASS1_SHARE, module.LATE_PASS1_SHARE]
    assert shares[1][1] < 0.6


def test_the_pyvrp_method_takes_pass1_share():
    """The registered method passes its ``pass1_share`` parameter on (a user's setting)."""
    inst = to_top(generate(8, 2, 2, 0, e_max=6000.0))
    res = run_method("pyvrp", inst, seed=0, time_limit=2.0, params={"iterations": 10**9, "pass1_share": 0.1})
    assert res.info["pass1"]["seconds"] < 0.6 < 1.0 < res.info["pass2"]["seconds"]
