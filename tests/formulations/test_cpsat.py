"""`cpsat`: hand-checked optima, distinct depots, groups, infeasibility, integer scaling, TOP values."""

import csv
import math

import numpy as np
import pytest

from sarcover.benchmarks.registry import run_method
from sarcover.formulations.cpsat import CpsatInputError, prize_scale, solve_cpsat
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.io import read_top
from sarcover.formulations.result import Status
from sarcover.formulations.verify import verify
from sarcover.heuristics.greedy import greedy

from conftest import TOP_DIR


PUBLISHED = {r["instance"]: float(r["value"]) for r in csv.DictReader(open(TOP_DIR / "optimal.csv"))}


def top(coords, prizes, budget, n=1, start=(0.0, 0.0), end=(0.0, 0.0), groups=(), e_image=0.0):
    return TOPInstance(coords=np.array(coords, dtype=float), prizes=np.array(prizes, dtype=float),
                       start=np.array(start), end=np.array(end), budget=budget, n_vehicles=n,
                       e_image=e_image, groups=groups)


def solve(inst, **kw):
    """Run through the registry (verifier, bound check) and return (result, report)."""
    res = run_method("cpsat", inst, time_limit=kw.pop("time_limit", 20.0))
    assert res.status != Status.ERROR, res.reason
    return res, res.report


LINE = [[1.0, 0.0], [2.0, 0.0], [3.0, 0.0]]


@pytest.mark.parametrize(
    "budget, expected",
    [(6.0, 6.0), (5.9, 3.0), (4.0, 3.0), (2.0, 1.0), (1.9, 0.0)],
)
def test_line_optimum_by_hand(budget, expected):
    """Nodes at x=1,2,3 (prizes 1,2,3), one vehicle: the optimum is a prefix of the line."""
    res, rep = solve(top(LINE, [1, 2, 3], budget))
    assert res.status == Status.OPTIMAL
    assert res.objective == expected and res.bound == expected


def test_budget_exactly_tight_is_optimal():
    """A route whose energy equals the budget exactly is accepted and proven optimal."""
    res, rep = solve(top(LINE, [1, 2, 3], 4.0))
    assert res.status == Status.OPTIMAL
    assert max(rep.energy) == pytest.approx(4.0)


def test_rounding_gap_never_claims_optimal():
    """Budget 1e-8 below the only 3-prize route: relaxed rounding accepts it, the answer must not."""
    res, rep = solve(top([[1.0, 0.0], [2.0, 0.0]], [1, 2], 4.0 * (1 - 1e-8)))
    assert res.objective == 1.0  # only node 1 truly fits (0→1→0 costs 2)
    assert res.status != Status.OPTIMAL
    assert res.bound is not None and res.bound >= 1.0
    assert res.info.get("relaxed_plan_valid") is False


def test_distinct_start_and_end():
    """Start (0,0), end (4,0): the straight line collects nodes on it; a 2nd vehicle takes the detour."""
    coords = LINE + [[2.0, 3.0]]
    res, _ = solve(top(coords, [1, 1, 1, 5], 4.0, start=(0, 0), end=(4, 0)))
    assert res.status == Status.OPTIMAL and res.objective == 3.0
    res, _ = solve(top(coords, [1, 1, 1, 5], 2 * math.sqrt(13) + 1e-9, n=2, start=(0, 0), end=(4, 0)))
    assert res.status == Status.OPTIMAL and res.objective == 8.0


def test_empty_route_costs_nothing():
    """Depots farther apart than the budget: staying home is feasible, optimum 0."""
    res, rep = solve(top([[50.0, 0.0]], [1], 10.0, start=(0, 0), end=(100, 0)))
    assert res.status == Status.OPTIMAL and res.objective == 0.0


def test_group_forces_cheap_node():
    """A group on the low-prize node overrides the high-prize alternative."""
    coords, prizes = [[1.0, 0.0], [-1.0, 0.0]], [1, 10]
    assert solve(top(coords, prizes, 2.0))[0].objective == 10.0
    res, rep = solve(top(coords, prizes, 2.0, groups=((0,),)))
    assert res.status == Status.OPTIMAL and res.objective == 1.0 and rep.groups_covered == 1


def test_groups_infeasible_beyond_precheck():
    """Each group is reachable alone but one vehicle cannot cover both: proven infeasible."""
    inst = top([[1.0, 0.0], [-1.0, 0.0]], [1, 1], 2.0, groups=((0,), (1,)))
    res, _ = solve(inst)
    assert res.status == Status.INFEASIBLE and res.plan is None and res.reason
    res2, _ = solve(top([[1.0, 0.0], [-1.0, 0.0]], [1, 1], 2.0, n=2, groups=((0,), (1,))))
    assert res2.status == Status.OPTIMAL and res2.objective == 2.0


def test_precheck_infeasible():
    """A group no vehicle can reach is reported infeasible with the reason."""
    res, _ = solve(top([[10.0, 0.0]], [1], 5.0, groups=((0,),)))
    assert res.status == Status.INFEASIBLE and "cannot be covered" in res.reason


def test_decimal_prizes_scaled_exactly():
    """Prizes with decimals are scaled exactly: 0.25 + 0.5 on the reachable prefix."""
    res, _ = solve(top(LINE, [0.25, 0.5, 0.125], 4.0))
    assert res.status == Status.OPTIMAL and res.objective == pytest.approx(0.75)
    assert prize_scale(np.array([0.25, 0.5, 0.125])) == 1000


def test_irrational_prize_raises_clear_error():
    """A prize with more than 6 decimals cannot be represented exactly: one-line error."""
    with pytest.raises(CpsatInputError, match="decimals"):
        solve_cpsat(top(LINE, [math.pi, 1, 1], 4.0))


def test_image_energy_counts():
    """e_image is charged per visited node: with 1 per image only two of three nodes fit in 6 + 2."""
    res, _ = solve(top(LINE, [1, 1, 1], 7.0, e_image=1.0))
    assert res.status == Status.OPTIMAL and res.objective == 2.0


@pytest.mark.parametrize("model", ["multi", "vehicle"])
def test_models_agree_and_hint_is_used(model):
    """Both CP-SAT models reach the published optimum of p2.3.g, with and without a greedy hint."""
    inst = read_top(TOP_DIR / "p2.3.g.txt")
    hint = greedy(inst).plan
    for h in (None, hint):
        res = solve_cpsat(inst, time_limit=20, model=model, warm_start=h)
        assert res.status == Status.OPTIMAL
        assert verify(inst, res.plan).prize == PUBLISHED["p2.3.g"]


def test_time_limit_returns_incumbent_and_valid_bound():
    """A tiny time limit on a 25-node instance still gives a verified plan and a bound >= optimum."""
    inst = read_top(TOP_DIR / "p3.2.k.txt")
    res, rep = solve(inst, time_limit=0.3)
    assert res.status in (Status.TIME_LIMIT, Status.OPTIMAL)
    if res.plan is not None:
        assert rep.valid
    if res.bound is not None:
        assert res.bound >= PUBLISHED["p3.2.k"] - 1e-9
    if res.status == Status.OPTIMAL:
        assert res.objective == PUBLISHED["p3.2.k"]


def _check_top(name: str, time_limit: float):
    inst = read_top(TOP_DIR / f"{name}.txt")
    res = run_method("cpsat", inst, time_limit=time_limit)
    assert res.status != Status.ERROR, res.reason
    if res.status == Status.OPTIMAL:
        assert res.objective == PUBLISHED[name]
    if res.bound is not None:
        assert res.bound >= PUBLISHED[name] - 1e-9
    if res.objective is not None:
        assert res.objective <= PUBLISHED[name] + 1e-9
    return res


FAST_TOP = ["p2.2.a", "p2.2.f", "p2.3.k", "p2.4.k", "p1.2.b", "p1.2.e", "p1.3.d", "p1.4.e",
            "p3.2.a", "p3.3.d", "p3.4.f"]


@pytest.mark.parametrize("name", FAST_TOP)
def test_top_fast_subset_matches_published(name):
    """Fast TOP subset: proven optimal and equal to the published value."""
    res = _check_top(name, 30.0)
    assert res.status == Status.OPTIMAL


ALL_TOP = sorted(n for n in PUBLISHED if n.split(".")[0] in ("p1", "p2", "p3"))


@pytest.mark.slow
@pytest.mark.parametrize("name", ALL_TOP)
def test_top_sets_1_to_3_never_wrong(name):
    """Sets 1-3 at 60 s: every 'optimal' equals the published value, every bound is above it."""
    _check_top(name, 60.0)


def test_zero_prizes_with_group():
    """All prizes zero but a group to cover: a valid plan of value 0, proven optimal."""
    res, rep = solve(top(LINE, [0, 0, 0], 4.0, groups=((1,),)))
    assert res.status == Status.OPTIMAL and res.objective == 0.0 and rep.groups_covered == 1
