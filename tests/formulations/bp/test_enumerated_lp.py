"""The LP over enumerated routes: its cut coefficients, a bound and a filter that keep the optimum."""

from __future__ import annotations

import numpy as np
import pytest

from sarcover.formulations.bp import solve_bp
from sarcover.formulations.bp.enumerated_lp import EnumeratedLP, cut_coefficients
from sarcover.formulations.bp.enumeration_kernel import enumerate_routes
from sarcover.formulations.bp.graph import NodeState, node_graph
from sarcover.formulations.bp.master import _lm_coefficient
from sarcover.formulations.bp.tree import BranchAndPrice
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import to_top
from sarcover.formulations.result import Status
from sarcover.formulations.verify import verify


@pytest.mark.parametrize("seed", range(4))
def test_cut_coefficients_match_the_masters(seed):
    """The kernel's coefficients equal the master's limited-memory count, and with full memory
    floor(visits to S / 2) for elementary routes."""
    rng = np.random.default_rng(seed)
    n = 14
    paths = np.full((60, 10), -1, np.int32)
    routes = []
    for r in range(60):
        route = rng.permutation(np.arange(1, n - 1))[: rng.integers(0, 11)]
        paths[r, : route.size] = route
        routes.append(tuple(route.tolist()))
    cuts = [(tuple(rng.choice(np.arange(1, n - 1), 3, replace=False).tolist()),
             frozenset(rng.choice(np.arange(1, n - 1), 6, replace=False).tolist())) for _ in range(8)]
    in_s = np.zeros((8, n), np.bool_)
    in_m = np.zeros((8, n), np.bool_)
    for c, (S, M) in enumerate(cuts):
        in_s[c, list(S)] = True
        in_m[c, list(set(M) | set(S))] = True
    got = cut_coefficients(paths, in_s, in_m)
    want = [[_lm_coefficient(r, S, set(M) | set(S)) for S, M in cuts] for r in routes]
    assert got.tolist() == want
    full = cut_coefficients(paths, in_s, np.ones_like(in_m))
    assert full.tolist() == [[len(set(r) & set(S)) // 2 for S, _ in cuts] for r in routes]


def _all_routes(seed):
    """A small SAR instance's branch-and-price parts and every elementary route of it."""
    inst = to_top(generate(4, 3, 2, seed))
    bp = BranchAndPrice(inst, time_limit=30)
    s, m = bp.search, bp.search.master
    cost, _, allowed = node_graph(s, NodeState())
    res = enumerate_routes(cost, m.point_profit(np.zeros(m.n_rows)), allowed, s.problem.budget, -1.0)
    return inst, s, m, res.paths


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_enumerated_lp_bounds_every_plan_and_its_filter_keeps_the_optimum(seed):
    """Over every elementary route, the LP bounds the proven optimum before and after rounds of
    full-memory triples; the reduced-cost filter for a plan worth the optimum keeps the routes
    of an optimal plan; the MILP over what is left finds the optimum and no plan above it."""
    inst, s, m, paths = _all_routes(seed)
    best = solve_bp(inst, time_limit=30)
    assert best.status == Status.OPTIMAL
    opt = verify(inst, best.plan).prize
    optimal_routes = {tuple(int(v) + 1 for v in r) for r in best.plan.routes if r}
    lp = EnumeratedLP(m, paths)
    sets = {frozenset(lp.route(i)): i for i in range(len(lp))}
    assert len(sets) == len(lp)
    bounds, cuts = [], 0
    for _ in range(6):
        out = lp.solve()
        bounds.append(out.bound(s.problem.N))
        assert out.bound(s.problem.N) >= opt - 1e-6
        keep = out.rc >= out.floor(opt, s.problem.N)
        kept = {frozenset(lp.route(i)) for i in np.flatnonzero(keep)}
        assert {frozenset(r) for r in optimal_routes} <= kept
        new = lp.separate(out.x, 20)
        lp.keep(keep)
        if not new:
            break
        cuts += lp.add_cuts([(S, None) for S in new])
    assert all(b2 <= b1 + 1e-6 for b1, b2 in zip(bounds, bounds[1:]))  # cuts and filter only tighten
    for with_cuts in (False, True):
        status, plan = lp.milp(opt, 30.0, cuts=with_cuts)
        assert status == "optimal"
        assert sum(float(m.prizes[np.asarray(r) - 1].sum()) for r in plan) == pytest.approx(opt)
        assert lp.milp(opt + 1, 30.0, cuts=with_cuts)[0] == "infeasible"
