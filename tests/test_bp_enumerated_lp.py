"""The LP over enumerated routes (:mod:`sarcover.formulations.bp.enumerated_lp`): its cut
coefficients, its bound and reduced-cost filter against proven optima, and bp closing the root
gap with it."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from sarcover.formulations.bp import BPOptions, solve_bp
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


@pytest.mark.parametrize("seed", [0, 4])
def test_bp_with_enumeration_proves_the_optimum(seed):
    """bp with enumeration on (any window) proves the same optimum as without it."""
    inst = to_top(generate(8, 3, 2, seed))
    plain = solve_bp(inst, time_limit=60)
    enum = solve_bp(inst, time_limit=60, options=BPOptions(enum_share=0.5, enum_gap=5.0))
    assert plain.status == enum.status == Status.OPTIMAL
    assert verify(inst, enum.plan).valid
    assert verify(inst, enum.plan).prize == pytest.approx(verify(inst, plain.plan).prize)


@pytest.mark.parametrize("where", ["enumerate_routes", "EnumeratedLP"])
def test_enumeration_out_of_memory_gives_up_the_try(monkeypatch, where):
    """A MemoryError in the listing or in the LP over it (a process memory limit below what the
    label cap allows) ends that try, counted in info; the tree still proves the optimum."""
    from pathlib import Path

    from sarcover.formulations.bp import enumeration
    from sarcover.formulations.io import load_instance

    def out_of_memory(*args, **kwargs):
        raise MemoryError

    inst = load_instance(Path(__file__).resolve().parents[1] / "benchmarks/instances/top/p2.2.k.txt")
    tried = solve_bp(inst, time_limit=60, options=BPOptions(enum_share=0.5, enum_gap=1.0))
    assert tried.info["enum_tries"] == 1 and tried.info["enum_status"] == "infeasible"  # the try closes it
    monkeypatch.setattr(enumeration, where, out_of_memory)
    res = solve_bp(inst, time_limit=60, options=BPOptions(enum_share=0.5, enum_gap=1.0))
    assert res.info["enum_memory"] == 1 and res.info["enum_status"] is None
    assert res.status == Status.OPTIMAL
    assert verify(inst, res.plan).prize == pytest.approx(verify(inst, tried.plan).prize)


def test_narrow_tries_widen_until_complete(monkeypatch):
    """Above enum_gap a try lists only the routes within enum_primal_window steps of the best;
    when they hold no better plan the next try is WIDEN steps wider, and one as wide as the
    window is complete and proves the optimum (WIDEN made large, its growth guard aside: the
    second try is complete)."""
    from pathlib import Path

    from sarcover.formulations.bp.enumeration import Enumeration
    from sarcover.formulations.io import load_instance

    inst = load_instance(Path(__file__).resolve().parents[1] / "benchmarks/instances/top/p2.2.k.txt")
    opts = BPOptions(enum_share=0.5, enum_gap=0.0, enum_primal_window=0.1)
    narrow = solve_bp(inst, time_limit=60, options=opts)
    assert narrow.info["enum_tries"] >= 2 and narrow.info["enum_complete"] == 0  # 0.1 wider each
    # a wider listing that would pass the label cap, grown as over the narrow one's rim, is not
    # tried (its labels grow here, a little)
    capped = solve_bp(inst, time_limit=60, options=dataclasses.replace(
        opts, enum_labels=narrow.info["enum_labels"] + 1))
    assert capped.info["enum_tries"] == 1 and capped.status == Status.OPTIMAL
    monkeypatch.setattr(Enumeration, "WIDEN", 100.0)
    monkeypatch.setattr(Enumeration, "_growth", lambda self, width, res: (1.0, 1.0))  # the guard aside
    res = solve_bp(inst, time_limit=60, options=opts)
    assert (res.info["enum_tries"], res.info["enum_complete"]) == (2, 1)
    assert res.status == Status.OPTIMAL and res.info["enum_status"] == "infeasible"
    assert verify(inst, res.plan).prize == pytest.approx(verify(inst, narrow.plan).prize)


def test_widening_is_guarded_by_the_growth_at_the_rim():
    """A narrow try that listed no better plan is widened by WIDEN steps only if its labels and
    routes, times their growth over the listing's rim (extrapolated geometrically to WIDEN
    steps when the listing is narrower), fit the caps."""
    from sarcover.formulations.bp.enumeration import Enumeration
    from sarcover.formulations.bp.enumeration_kernel import Enumerated

    res = Enumerated(np.zeros((100, 3), np.int32), n_labels=1000, inner_labels=250, inner_routes=50)
    assert res.growth() == (4.0, 2.0)

    def widened(width, max_labels, max_routes):
        e = Enumeration(None, None, None, limit=1.0, gap=0.3, max_labels=max_labels,
                        max_routes=max_routes, primal_window=0.2)
        e._widen(width, res)
        return e._wider

    assert widened(0.2, 4000, 200) == pytest.approx(0.3)
    assert widened(0.2, 3999, 200) is None and widened(0.2, 4000, 199) is None
    # a rim of 0.05 steps: per 0.1 steps 16 times the labels and 4 times the routes
    assert widened(0.05, 16_000, 400) == pytest.approx(0.15)
    assert widened(0.05, 15_999, 400) is None and widened(0.05, 16_000, 399) is None
    assert Enumerated(None, 7).growth() == (np.inf, np.inf)
