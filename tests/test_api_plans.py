"""The Python side of plans from outside: write_plan, read_plan and verify_plan on sarcover."""

import pytest

import sarcover
from sarcover.formulations.planfile import PlanFileError


def test_write_read_and_verify_a_solved_plan(tmp_path):
    """A solved plan written, read back and verified: same routes, the verifier's objective, and
    the gap to p2.3.g's proven optimum 145."""
    inst = sarcover.read_instance("p2.3.g")
    run = sarcover.solve(inst, "greedy")
    sarcover.write_plan(run.plan, tmp_path / "p.json", inst, method="greedy")
    assert sarcover.read_plan(tmp_path / "p.json", inst) == run.plan
    for plan in (tmp_path / "p.json", run.plan, [list(r) for r in run.plan.routes]):
        check = sarcover.verify_plan("p2.3.g", plan)
        assert isinstance(check, sarcover.PlanCheck) and check.valid and check.objective == run.objective
        assert check.known.value == 145.0 and check.gap == pytest.approx((145 - run.objective) / 145)


def test_verify_plan_reports_violations_and_refuses_bad_ids():
    """An invalid plan comes back with its violations; an id that names no node raises one line."""
    inst = sarcover.generate(targets=3, views=2, uavs=1, seed=3)
    check = sarcover.verify_plan(inst, [[0, 0]])
    assert not check.valid and check.objective is None and check.gap is None
    assert "node 0 visited twice (routes 0 and 0)" in check.violations
    assert "target 2 has no visited viewpoint" in check.violations
    with pytest.raises(PlanFileError, match=r"routes\[0\]\[1\]' is 6, not a node id"):
        sarcover.verify_plan(inst, [[0, 6]])


def test_result_is_public():
    """Result, what a method of one's own returns, is part of the public API."""
    assert "Result" in sarcover.__all__ and sarcover.Result is sarcover.formulations.result.Result
