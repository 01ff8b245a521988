"""The local search pricing heuristic: improving, elementary routes within the budget, and an
exact bp that stays exact with it."""

from __future__ import annotations

import numpy as np
import pytest

from sarcover.formulations.bp import BPOptions, solve_bp
from sarcover.formulations.bp.route_search import improving_routes
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import TOPInstance, to_top
from sarcover.formulations.result import Status

from bp_cases import brute_force, plan_prize


def _route_energy(cost, route):
    full = [0, *route, cost.shape[0] - 1]
    return sum(cost[a, b] for a, b in zip(full, full[1:]))


def _line(prizes, budget):
    """Points 1..n on a line at x = 1, 2, ...; start and end at the origin."""
    n = len(prizes)
    inst = TOPInstance(coords=[[i + 1.0, 0.0] for i in range(n)], prizes=prizes, start=[0, 0],
                       end=[0, 0], budget=budget, n_vehicles=1)
    return inst.cost_matrix()


def test_inserts_the_best_point_that_fits():
    cost = _line([1, 1, 1], budget=4.0)  # (1) costs 2, (1, 2) costs 4, (3) costs 6
    prof = np.array([0.0, 0.0, 5.0, 9.0, 0.0])  # point 3 is worth most but out of reach
    allowed = np.ones(5, dtype=bool)
    routes = improving_routes([(1,)], cost, prof, allowed, budget=4.0, min_gain=0.0, n_cols=10)
    assert routes and set(routes[0]) == {1, 2}
    assert all(3 not in r for r in routes)


def test_drops_a_point_of_negative_reduced_prize_and_respects_allowed():
    cost = _line([1, 1, 1], budget=10.0)
    prof = np.array([0.0, 1.0, -2.0, 3.0, 0.0])
    allowed = np.array([True, True, True, False, True])
    routes = improving_routes([(1, 2)], cost, prof, allowed, budget=10.0, min_gain=0.5,
                              n_cols=10)
    assert routes == [(1,)]  # 3 is not allowed; (1, 2) is worth -1, 1 alone 1 > 0.5


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_routes_are_elementary_improving_and_within_budget(seed):
    rng = np.random.default_rng(seed)
    inst = to_top(generate(12, 3, 3, seed))
    cost = inst.cost_matrix()
    V = inst.n_nodes
    prof = np.zeros(V + 2)
    prof[1 : V + 1] = rng.uniform(-0.5, 1.5, V)
    allowed = np.ones(V + 2, dtype=bool)
    allowed[rng.choice(np.arange(1, V + 1), 4, replace=False)] = False
    starts = [tuple(int(p) for p in rng.choice(np.arange(1, V + 1), 3, replace=False))
              for _ in range(5)]
    starts = [r for r in starts if _route_energy(cost, r) <= inst.budget]
    gain = 0.7
    routes = improving_routes(starts, cost, prof, allowed, inst.budget, gain, n_cols=50)
    assert routes
    values = [prof[list(r)].sum() for r in routes]
    assert values == sorted(values, reverse=True)  # best first
    started = {p for r in starts for p in r}
    for r, v in zip(routes, values):
        assert len(set(r)) == len(r) and v > gain
        assert _route_energy(cost, r) <= inst.budget * (1 + 1e-9)
        assert all(allowed[p] or p in started for p in r)  # only the starts' own points are kept
    assert len(set(routes)) == len(routes)


@pytest.mark.parametrize("seed", [3, 4])
def test_bp_with_route_search_stays_exact(seed):
    """From the first point on (every root round without cuts starts with the local search)
    the tiny instances' optima are the brute force's."""
    inst = to_top(generate(4, 2, 2, seed))
    best = brute_force(inst)
    r = solve_bp(inst, time_limit=30, options=BPOptions(route_search_from=1))
    assert r.status == Status.OPTIMAL
    assert plan_prize(inst, r) == pytest.approx(best)
    assert r.info["route_search_columns"] > 0  # the local search did add columns


def test_bp_proves_the_same_optimum_with_and_without_route_search():
    inst = to_top(generate(10, 3, 3, 6))
    on = solve_bp(inst, time_limit=60, options=BPOptions(route_search_from=1))
    off = solve_bp(inst, time_limit=60, options=BPOptions(route_search_from=0))
    assert on.status == off.status == Status.OPTIMAL
    assert on.info["route_search_columns"] > 0 and off.info["route_search_columns"] == 0
    assert plan_prize(inst, on) == plan_prize(inst, off) == pytest.approx(on.bound)
