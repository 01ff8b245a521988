"""Plans: a dive gives a verified plan; a failing heuristic costs nothing but its time."""

from __future__ import annotations

import numpy as np
import pytest

from sarcover.formulations.bp import solve_bp
from sarcover.formulations.result import Status

from bp_cases import OPTIMAL, brute_force, plan_prize, random_tiny, top_instance


@pytest.mark.parametrize("seed", range(6))
def test_dive_gives_a_verified_plan(seed):
    """The diving heuristic (root LP, then fixing routes) only returns plans the verifier accepts,
    never better than enumeration; on these tiny instances it finds the enumerated optimum
    whenever a plan exists."""
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = random_tiny(seed, groups=True)
    best = brute_force(inst)
    bp = BranchAndPrice(inst, time_limit=20)
    bp.colgen.solve(NodeState(), np.inf)
    bp.incumbents.dive(5.0)
    s = bp.search
    if best is None:
        assert s.incumbent is None
    else:
        assert s.incumbent is not None and s.incumbent_value == pytest.approx(best)


@pytest.mark.parametrize("kind", ["raises", "over-budget", "empty"])
def test_a_bad_primal_costs_nothing_but_its_time(kind):
    """A failing heuristic, one returning a plan the verifier rejects, or none at all: the run
    goes on and proves the optimum; the rejected plan is never the incumbent."""
    inst = top_instance("p1.2.p")

    def primal(seconds):
        if kind == "raises":
            raise RuntimeError("boom")
        if kind == "over-budget":
            return [list(range(inst.n_nodes))]  # every node in one route: far over the budget
        return None

    r = solve_bp(inst, time_limit=60, primal=primal)
    assert r.status == Status.OPTIMAL and plan_prize(inst, r) == pytest.approx(OPTIMAL["p1.2.p"])
    assert r.info["primal_s"] is not None and r.info["primal_prize"] is None
    assert (r.info["primal_error"] == "RuntimeError: boom") == (kind == "raises")
