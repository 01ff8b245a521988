"""The verifier catches every kind of violation on crafted plans and recomputes the objective."""

import numpy as np
import pytest

from sarcover.formulations.instance import SARInstance, TOPInstance, to_top
from sarcover.formulations.plan import Plan
from sarcover.formulations.verify import route_energy, verify


def test_valid_plan_objective_and_energy(line_instance):
    """A plan visiting all three line nodes: energy 6 (out and back), prize 6, coverage 1."""
    rep = verify(line_instance, Plan.of([[0, 1, 2]]))
    assert rep.valid, rep.violations
    assert rep.energy == [pytest.approx(6.0)]
    assert rep.prize == 6.0 and rep.covered == 3 and rep.coverage == 1.0


def test_budget_violation(line_instance):
    """Zig-zag route of length 8 > budget 6 is rejected."""
    rep = verify(line_instance, Plan.of([[2, 0, 1]]))
    assert not rep.valid
    assert any("budget" in v for v in rep.violations)


def test_budget_relative_tolerance():
    """Energy within 1e-9 relative of the budget passes; 1e-7 over fails."""
    inst = TOPInstance(coords=[[1.0, 0.0]], prizes=[1.0], start=[0, 0], end=[0, 0], budget=2.0, n_vehicles=1)
    assert verify(inst, Plan.of([[0]])).valid
    tight = TOPInstance(coords=[[1.0, 0.0]], prizes=[1.0], start=[0, 0], end=[0, 0],
                        budget=2.0 * (1 - 1e-7), n_vehicles=1)
    assert not verify(tight, Plan.of([[0]])).valid


def test_duplicate_unknown_and_too_many_routes(line_instance):
    """A node twice, an unknown id and more routes than vehicles are each reported."""
    rep = verify(line_instance, Plan.of([[0], [0, 7]]))
    text = " | ".join(rep.violations)
    assert "visited twice" in text and "unknown node 7" in text and "2 routes for 1 vehicles" in text


def test_negative_id_is_unknown(line_instance):
    """A negative node id is unknown, not Python's index from the end."""
    rep = verify(line_instance, Plan.of([[-1]]))
    assert not rep.valid and "unknown node -1" in rep.violations[0]


def test_uncovered_target():
    """A SAR plan that leaves a target without a view is rejected, naming the target."""
    sar = SARInstance(np.array([[500.0, 0.0], [0.0, 800.0]]), 2, 2, 100.0, 0.0, 1.0, 10.0, 5000.0)
    top = to_top(sar)
    rep = verify(top, Plan.of([[0, 1], []]))
    assert not rep.valid and rep.violations == ["target 1 has no visited viewpoint"]
    assert verify(top, Plan.of([[0, 1], [2]])).valid


def test_distinct_depots_and_image_energy():
    """Energy counts start→nodes→end flight plus E_I per node; an empty route costs 0."""
    inst = TOPInstance(coords=[[0.0, 3.0]], prizes=[5.0], start=[0, 0], end=[4, 3],
                       budget=100.0, n_vehicles=2, e_fly=2.0, e_image=7.0)
    assert route_energy(inst, (0,)) == pytest.approx(2.0 * (3 + 4) + 7.0)
    rep = verify(inst, Plan.of([[0], []]))
    assert rep.valid and rep.energy == [pytest.approx(21.0), 0.0] and rep.prize == 5.0
