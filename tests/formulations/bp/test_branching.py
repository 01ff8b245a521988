"""Strong and group branching prove the same optima."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sarcover.formulations.bp import BPOptions, solve_bp
from sarcover.formulations.result import Status
from sarcover.formulations.verify import verify

from bp_cases import OPTIMAL, plan_prize, top_instance


def test_strong_branching_proves_the_same_optimum():
    """Strong branching (children estimated on the current columns) changes which candidate is
    branched on, never the result: p3.3.o is proven at its published optimum either way, only
    the strong run pays for estimates, and the master's bounds are the node's again after them."""
    from sarcover.formulations.bp.branching import branch, branch_candidates
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = top_instance("p3.3.o")
    results = {st: solve_bp(inst, time_limit=30, options=BPOptions(strong=st)) for st in (1, 5)}
    for st, r in results.items():
        assert r.status == Status.OPTIMAL and plan_prize(inst, r) == pytest.approx(OPTIMAL["p3.3.o"])
        assert verify(inst, r.plan).valid
        assert (r.info["strong_lps"] > 0) == (st > 1)
    bp = BranchAndPrice(inst, time_limit=30)
    m = bp.search.master
    _, x, _, _ = bp.colgen.solve(NodeState(), np.inf)
    cands = branch_candidates(bp.search, NodeState(), x)
    assert len(cands) > 1
    before = m.col_ub.copy()
    lp = float(np.dot(m.route_prize, x[: m.n_routes]))
    pick = branch(bp.search, NodeState(), x, lp, bp.options.strong)
    assert pick in cands
    assert np.array_equal(m.col_ub, before)


def test_group_branching_proves_the_same_optimum():
    """Branching on a target's number of views changes the tree, never the result: on a SAR
    instance under a weak relaxation (ng sets of 2, no cuts, no route enumeration to close the
    root's gap), so that the tree is searched, bp proves the same optimum with and without it,
    and that optimum is the one the default run proves at its root. Only the run with it splits
    on groups."""
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(8, 4, 2, 2))
    ref = solve_bp(inst, time_limit=60)
    assert ref.status == Status.OPTIMAL
    weak = dict(strong=5, ng_size=2, ng_cap=2, cut_rounds=0, enum_share=0)
    for groups in (True, False):
        r = solve_bp(inst, time_limit=60, options=BPOptions(group_branching=groups, **weak))
        assert r.status == Status.OPTIMAL and verify(inst, r.plan).valid
        assert plan_prize(inst, r) == pytest.approx(plan_prize(inst, ref))
        assert r.info["nodes"] > 1 and (r.info["group_branches"] > 0) == groups


def test_strong_branching_stops_at_the_deadline():
    """Strong branching estimates nothing once the clock's deadline has passed (each estimate is
    an LP solve, and the time limit holds): the most fractional candidate is taken, and the
    master's bounds are the node's again."""
    import time

    from sarcover.formulations.bp.branching import branch, branch_candidates
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.tree import BranchAndPrice

    bp = BranchAndPrice(top_instance("p3.3.o"), time_limit=30)
    m = bp.search.master
    _, x, _, _ = bp.colgen.solve(NodeState(), np.inf)
    cands = branch_candidates(bp.search, NodeState(), x, bp.options.strong)
    assert len(cands) > 1
    before = m.col_ub.copy()
    lp = float(np.dot(m.route_prize, x[: m.n_routes]))
    bp.search.clock.deadline = time.perf_counter()  # the time is up
    assert branch(bp.search, NodeState(), x, lp, bp.options.strong) == cands[0]
    assert bp.search.stats.strong_lps == 0
    assert np.array_equal(m.col_ub, before)


def test_a_node_solved_after_the_deadline_stays_open(monkeypatch):
    """When the time is up as the root is solved, the tree neither dives nor branches: the root
    stays open with its bound, which the run reports, and its plan still passes the verifier."""
    import time

    from sarcover.formulations.bp import tree
    from sarcover.formulations.bp.root import Root
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(8, 4, 2, 2))
    weak = BPOptions(strong=5, ng_size=2, ng_cap=2, cut_rounds=0, enum_share=0)
    assert solve_bp(inst, time_limit=60, options=weak).info["nodes"] > 1  # it needs branching
    solved = Root.solve
    roots = []

    def root_then_time_up(self, state, bound):
        out = solved(self, state, bound)
        roots.append(out[0])
        self.search.clock.deadline = time.perf_counter()  # the limit falls as the root ends
        return out

    def no_branching(*args, **kwargs):
        raise AssertionError("branched after the deadline")

    monkeypatch.setattr(Root, "solve", root_then_time_up)
    monkeypatch.setattr(tree, "branch", no_branching)
    r = solve_bp(inst, time_limit=60, options=weak)
    root_floor = math.floor(roots[0] + 1e-6)  # unit prizes
    assert r.info["nodes"] == 1 and r.bound == pytest.approx(root_floor)
    assert verify(inst, r.plan).valid
    # the last MILP may still find a plan of the root's floored bound, which proves it
    proven = plan_prize(inst, r) == pytest.approx(root_floor)
    assert (r.status == Status.OPTIMAL) == proven
    assert r.info["open_nodes"] == (0 if proven else 1)
