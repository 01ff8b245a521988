"""Exact cross-check: `milp` and `cpsat` agree on random small SAR instances; no heuristic beats them.

Both exact methods run through the registry (verifier + bound check). Where both prove
optimality (or infeasibility) they must agree; where a time limit stops one of them, its
incumbent must stay below the other's proof and its bound above it. Every non-exact method
registered at run time must never exceed a proven optimum or bound, and must return no plan on
an instance proven infeasible.
"""

import pytest

from sarcover.benchmarks.regression import load_spec, random_cases
from sarcover.benchmarks.registry import METHODS, run_method
from sarcover.formulations.result import Status

EXACT = ("milp", "cpsat")
TOL = 1e-9
# Default run: 30 instances with M <= 4, K <= 3 (at most 12 viewpoints); slow run: 200 with the
# full ranges M 3-8, K 2-4. Both cycle through infeasible, tight, medium and loose budgets.
FAST = random_cases(30, start=0, max_targets=4, max_views=3)
FULL = random_cases(200, start=0)


def _heuristics() -> list[str]:
    return [name for name, spec in METHODS.items() if not spec.exact]


def crosscheck(spec: str, time_limit: float, heuristics: list[str], heuristic_limit: float) -> dict:
    """Run both exact methods and the heuristics on ``spec``; assert they are consistent."""
    for name in EXACT:
        if name not in METHODS:
            pytest.skip(f"method {name!r} is not registered")
    inst = load_spec(spec)
    res = {}
    for name in EXACT:
        r = run_method(name, inst, time_limit=time_limit)
        assert r.status != Status.ERROR, f"{spec} {name}: {r.reason}"
        res[name] = r
    a, b = res["milp"], res["cpsat"]
    infeasible = [n for n, r in res.items() if r.status == Status.INFEASIBLE]
    optimal = {n: r.objective for n, r in res.items() if r.status == Status.OPTIMAL}
    if infeasible:  # a proof of infeasibility: nobody may have a plan
        for n, r in res.items():
            assert r.plan is None, f"{spec}: {infeasible} proved infeasible but {n} has a plan"
    if len(optimal) == 2:
        assert abs(optimal["milp"] - optimal["cpsat"]) <= TOL, f"{spec}: optima differ {optimal}"
    for x, y in ((a, b), (b, a)):  # incumbents below the other's bound
        if x.objective is not None and y.bound is not None:
            assert x.objective <= y.bound + TOL, f"{spec}: {x.method} {x.objective} > {y.method} bound {y.bound}"
    bounds = [r.bound for r in res.values() if r.bound is not None]
    cap = min(bounds) if bounds else float("inf")
    for h in heuristics:
        r = run_method(h, inst, time_limit=heuristic_limit)
        assert r.status != Status.ERROR, f"{spec} {h}: {r.reason}"
        if infeasible:
            assert r.plan is None, f"{spec}: {h} has a plan on a proven infeasible instance"
        if r.objective is not None:
            assert r.objective <= cap + TOL, f"{spec}: {h} {r.objective} beats the exact bound {cap}"
    return res


@pytest.mark.parametrize("spec", FAST)
def test_exact_methods_agree_small(spec):
    """30 small SAR instances: milp and cpsat agree; heuristics (first 4 instances) never beat them."""
    heur = _heuristics() if FAST.index(spec) < 4 else ["greedy"]
    res = crosscheck(spec, 10.0, heur, 1.0)
    decided = [r.status in (Status.OPTIMAL, Status.INFEASIBLE) for r in res.values()]
    assert any(decided), f"{spec}: neither exact method decided it within 10 s"


@pytest.mark.slow
@pytest.mark.parametrize("spec", FULL)
def test_exact_methods_agree_full(spec):
    """200 SAR instances (M 3-8, K 2-4, N 1-3) at 30 s: agreement and no heuristic above the bound."""
    crosscheck(spec, 30.0, _heuristics(), 2.0)
