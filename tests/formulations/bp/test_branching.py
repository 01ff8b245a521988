"""Strong and group branching prove the same optima."""

from __future__ import annotations

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
