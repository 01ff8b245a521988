"""Enumeration closes the root gap with a proof, gives up a try out of memory, widens narrow tries."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sarcover.formulations.bp import BPOptions, solve_bp
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import to_top
from sarcover.formulations.io import load_instance
from sarcover.formulations.result import Status
from sarcover.formulations.verify import verify

from bp_cases import OPTIMAL, TOP_DIR


def test_enumeration_keeps_the_published_optimum():
    """With enumeration on (any window), bp still proves the published TOP optima."""
    for name in ("p1.2.j", "p2.2.k", "p3.2.e", "p3.3.k"):
        inst = load_instance(TOP_DIR / f"{name}.txt")
        res = solve_bp(inst, time_limit=60, options=BPOptions(enum_share=0.5, enum_gap=1.0))
        assert res.status == Status.OPTIMAL
        assert verify(inst, res.plan).prize == pytest.approx(OPTIMAL[name])


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

    from sarcover.formulations.bp import enumeration
    from sarcover.formulations.io import load_instance

    def out_of_memory(*args, **kwargs):
        raise MemoryError

    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    tried = solve_bp(inst, time_limit=60, options=BPOptions(enum_share=0.5, enum_gap=1.0))
    assert tried.info["enum_tries"] == 1 and tried.info["enum_status"] == "infeasible"  # the try closes it
    monkeypatch.setattr(enumeration, where, out_of_memory)
    res = solve_bp(inst, time_limit=60, options=BPOptions(enum_share=0.5, enum_gap=1.0))
    # every try gives up: the root's, and the nodes' that follow it
    assert res.info["enum_memory"] == res.info["enum_tries"] >= 1
    assert res.info["enum_status"] is None
    assert res.status == Status.OPTIMAL
    assert verify(inst, res.plan).prize == pytest.approx(verify(inst, tried.plan).prize)


def test_narrow_tries_widen_until_complete(monkeypatch):
    """Above enum_gap a try lists only the routes within enum_primal_window steps of the best;
    when they hold no better plan the next try is wider, and one as wide as the
    window is complete and proves the optimum (WIDEN made large, its growth guard aside: the
    second try is complete)."""

    from sarcover.formulations.bp.enumeration import Enumeration
    from sarcover.formulations.io import load_instance

    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    opts = BPOptions(enum_share=0.5, enum_gap=0.0, enum_primal_window=0.1)
    narrow = solve_bp(inst, time_limit=60, options=opts)
    # 0.1, 0.2, 0.4, 0.8 steps wide, widening by twice the last widening, then as wide as the
    # window: complete, and here a proof
    assert narrow.info["enum_tries"] >= 3 and narrow.info["enum_complete"] == 1
    assert narrow.status == Status.OPTIMAL
    # a wider listing that would pass the label cap, grown as over the narrow one's rim, is not
    # tried (its labels grow here, a little)
    capped = solve_bp(inst, time_limit=60, options=dataclasses.replace(
        opts, enum_labels=narrow.info["enum_labels"] + 1))
    assert capped.info["enum_tries"] == 1 and capped.status == Status.OPTIMAL
    monkeypatch.setattr(Enumeration, "WIDEN", 100.0)
    monkeypatch.setattr(Enumeration, "_growth", lambda self, width, res, step: (1.0, 1.0))  # the guard aside
    res = solve_bp(inst, time_limit=60, options=opts)
    assert (res.info["enum_tries"], res.info["enum_complete"]) == (2, 1)
    assert res.status == Status.OPTIMAL and res.info["enum_status"] == "infeasible"
    assert verify(inst, res.plan).prize == pytest.approx(verify(inst, narrow.plan).prize)


def test_widening_is_guarded_by_the_growth_at_the_rim():
    """A narrow try that listed no better plan is widened (by WIDEN steps, then twice the last
    widening, or half of that ... down to WIDEN) only if its labels and routes, times their
    growth over the listing's rim (extrapolated geometrically to the widening's steps), fit
    the caps."""
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
    # the widenings double: 0.2 -> 0.3 -> 0.5 (the second over 0.2 steps: 16 times the labels)
    e = Enumeration(None, None, None, limit=1.0, gap=0.3, max_labels=16_000, max_routes=400,
                    primal_window=0.2)
    e._widen(0.2, res)
    assert e._wider == pytest.approx(0.3)
    e._widen(0.3, res)
    assert e._wider == pytest.approx(0.5)
    e._wider = None
    e._widen(0.5, res)  # 0.4 steps: 256 times the labels; 0.2 steps fit
    assert e._wider == pytest.approx(0.7)
    e._wider, e.max_labels = None, 3999
    e._widen(0.7, res)  # not even 0.1 steps fit
    assert e._wider is None


@pytest.mark.parametrize("seed", range(7))
def test_a_node_listing_decides_exactly(seed):
    """Under any duals and a bound on every route's reduced prize under them, a node's listing
    holds every route a better plan may use: under duals of 0 (a route's reduced prize is its
    prize, at most the total) it finds the brute-force optimum from the empty plan and then
    proves it; on the graph of a node that forbids a point, the best plan without that point;
    at a node that forces the reachable point that costs most to visit, the best plan that
    visits it (below the optimum on seed 6)."""
    from sarcover.formulations.bp.compile import warm_up
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.tree import BranchAndPrice

    from bp_cases import brute_force, random_tiny

    warm_up()  # compiling is not charged to the listing's deadline
    inst = random_tiny(seed, groups=False)
    total = float(inst.prizes.sum())
    bp = BranchAndPrice(inst, time_limit=30, options=BPOptions(enum_share=0.5))
    s, m = bp.search, bp.search.master
    assert s.incumbent_value == 0.0
    root = NodeState()
    m.apply(root)
    y = np.zeros(m.n_rows)
    assert bp.enumeration.close_node(root, y, 0.0, total)  # finds the optimum
    assert s.incumbent_value == brute_force(inst)
    assert bp.enumeration.close_node(root, y, 0.0, total)  # nothing beats it
    assert (s.stats.node_enum_tries, s.stats.node_enum_closed) == (2, 2)

    point = int(np.argmax(inst.prizes))
    without = dataclasses.replace(inst, prizes=np.where(np.arange(inst.n_nodes) == point, 0.0,
                                                        inst.prizes))
    bp = BranchAndPrice(inst, time_limit=30, options=BPOptions(enum_share=0.5))
    node = root.child(forbidden_nodes=[point + 1])
    bp.search.master.apply(node)
    assert bp.enumeration.close_node(node, y, 0.0, total)
    assert bp.search.incumbent_value == brute_force(without)

    bp = BranchAndPrice(inst, time_limit=30, options=BPOptions(enum_share=0.5))
    reachable = np.flatnonzero(bp.search.problem.reachable[1 : inst.n_nodes + 1])
    costly = min(reachable.tolist(), key=lambda p: brute_force(inst, visit=p))
    node = root.child(forced_nodes=[costly + 1])
    bp.search.master.apply(node)
    assert bp.enumeration.close_node(node, y, 0.0, total)
    assert bp.search.incumbent_value == brute_force(inst, visit=costly)


def test_node_listings_close_nodes_and_keep_the_optimum(monkeypatch):
    """With the root's listing off and no cuts (so that these small instances branch), listings
    at nodes close some of them, and the tree proves the optimum bp proves without enumeration."""
    from sarcover.formulations.bp.enumeration import Enumeration

    plain = {}
    for case in [(12, 3, 3, 0), (12, 4, 3, 0), (12, 4, 3, 4)]:
        plain[case] = solve_bp(to_top(generate(*case)), time_limit=30)
    monkeypatch.setattr(Enumeration, "close", lambda self: False)
    closed = 0
    for case, ref in plain.items():
        inst = to_top(generate(*case))
        res = solve_bp(inst, time_limit=30, options=BPOptions(enum_share=0.5, enum_gap=1.0,
                                                              cut_rounds=0))
        assert ref.status == res.status == Status.OPTIMAL
        assert res.info["nodes"] > 1 and res.info["enum_tries"] == res.info["node_enum_tries"]
        assert verify(inst, res.plan).prize == pytest.approx(verify(inst, ref.plan).prize)
        closed += res.info["node_enum_closed"]
    assert closed >= 1


def test_the_cap_rounds_up_to_the_lattice_below_the_listed_plans():
    """A narrow try that decided lists every route of the plans worth at least ``reach``: the
    cap is the lattice point below ``reach`` (``reach`` itself on it: nothing of that value
    beats the incumbent), never below the incumbent; on TOP set 3's lattice of 10 too."""
    from sarcover.formulations.bp.tree import BranchAndPrice

    from bp_cases import random_tiny

    bp = BranchAndPrice(random_tiny(0, groups=False), time_limit=30,
                        options=BPOptions(enum_share=0.5))
    s = bp.search
    assert s.problem.integral and s.problem.step == 1.0 and s.cap == np.inf
    s.incumbent_value = 1093.0
    for reach, cap in [(1096.2, 1096.0), (1095.0005, 1095.0), (1095.0, 1094.0),
                       (1094.79, 1094.0), (1094.5, 1094.0), (1093.2, 1093.0)]:
        bp.enumeration._cap(reach)
        assert s.cap == cap and s.stats.cap == cap  # lowered, never raised
    s.problem.step, s.cap = 10.0, np.inf
    s.incumbent_value = 500.0
    bp.enumeration._cap(523.0)
    assert s.cap == 520.0
    bp.enumeration._cap(505.0)  # the incumbent is the least it can be
    assert s.cap == 500.0 and s.prunable(10_000.0)


@pytest.mark.parametrize("seed", range(8))
def test_narrow_tries_cap_the_bound_without_passing_the_optimum(seed):
    """Under duals of 0 (a route's reduced prize is its prize, rc* the best route's) narrow tries
    from the empty plan list the routes within the window of the best one. After each, the cap
    is at least the brute-force optimum, and a try that says it proved the incumbent holds it
    (the cap at the incumbent, or a complete listing)."""
    from sarcover.formulations.bp.compile import warm_up
    from sarcover.formulations.bp.elimination import Certificate
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.tree import BranchAndPrice

    from bp_cases import brute_force, feasible_routes, random_tiny

    warm_up()  # compiling is not charged to the listings' deadlines
    inst = random_tiny(seed, groups=False)
    best = brute_force(inst)
    rc_star = max(float(inst.prizes[list(r)].sum()) for r in feasible_routes(inst))
    bp = BranchAndPrice(inst, time_limit=30, options=BPOptions(
        enum_share=0.5, enum_gap=0.0, enum_primal_window=0.5))
    s, m = bp.search, bp.search.master
    m.apply(NodeState())
    N = inst.n_vehicles
    bp.elimination.cert = Certificate(np.zeros(m.n_rows), 0.0, rc_star, N * rc_star)
    proved, caps = False, []
    while not proved and bp.enumeration.window() is not None:
        proved = bp.enumeration.close()
        caps.append(s.cap)
        assert s.cap >= best - 1e-9
    assert proved and s.incumbent_value == best
    assert caps == sorted(caps, reverse=True)
    if s.stats.enum_complete == 0:  # proven by the cap alone
        assert s.cap == best
