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


def test_the_last_milp_runs_without_presolve(monkeypatch):
    """HiGHS's presolve can run past a short limit, so a MILP over the generated routes that
    would end in the clock's reserve (the last one) runs without it; one that ends before the
    deadline keeps it. Either way its plan passes the verifier."""
    import time

    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.master import Master
    from sarcover.formulations.bp.tree import BranchAndPrice
    from sarcover.formulations.plan import Plan
    from sarcover.formulations.verify import verify

    inst = top_instance("p3.3.o")
    bp = BranchAndPrice(inst, time_limit=60)
    bp.colgen.solve(NodeState(), np.inf)
    calls = []
    milp = Master.milp

    def recorded(self, time_limit, allowed=None, start=None, presolve=True):
        calls.append(presolve)
        return milp(self, time_limit, allowed, start, presolve)

    monkeypatch.setattr(Master, "milp", recorded)
    s = bp.search
    bp.incumbents.run_milp(1.0)  # ends long before the deadline
    s.clock.deadline = time.perf_counter()  # now in the reserve: the run's last MILP
    bp.incumbents.run_milp(1.0)
    assert calls == [True, False]
    assert s.incumbent is not None  # the MILPs' plan (no warm start was given)
    rep = verify(inst, Plan.of([[p - 1 for p in r] for r in s.incumbent]))
    assert rep.valid and rep.prize == pytest.approx(s.incumbent_value)
