"""Plan files: the documented shape, node ids as the instance numbers them, and one-line errors."""

import json

import numpy as np
import pytest

from sarcover.formulations.generate import generate
from sarcover.formulations.instance import to_top
from sarcover.formulations.io import read_top
from sarcover.formulations.plan import Plan
from sarcover.formulations.planfile import (FORMAT, FORMAT_VERSION, PlanFileError, load_plan, plan_from_dict,
                                            plan_to_dict, save_plan)
from sarcover.formulations.verify import verify
from conftest import TOP_DIR


@pytest.fixture
def sar():
    """Four targets, three views each, two UAVs (paper preset)."""
    return to_top(generate(4, 3, 2, seed=5))


def test_save_and_load_round_trip(tmp_path, sar):
    """A saved plan reads back as the same routes, instance name and method; empty routes survive."""
    plan = Plan.of([[0, 4, 8], [], [11, 2]])
    save_plan(plan, tmp_path / "p.json", sar.name, method="greedy")
    data = json.loads((tmp_path / "p.json").read_text())
    assert data["format"] == FORMAT and data["version"] == FORMAT_VERSION and data["instance"] == sar.name
    back = load_plan(tmp_path / "p.json", sar)
    assert back.plan == plan and back.instance == sar.name and back.method == "greedy"
    save_plan(Plan.of([]), tmp_path / "none.json", sar.name)
    assert load_plan(tmp_path / "none.json").plan.routes == ()


def test_sar_ids_are_target_times_views_plus_view(sar):
    """On a SAR instance id m*K + k is view k of target m: a plan of one view per target covers
    every target, and leaving target m's ids out leaves exactly target m uncovered."""
    k = 3
    one_each = plan_from_dict(plan_to_dict(Plan.of([[m * k + 1 for m in range(4)]]), sar.name), sar).plan
    assert verify(sar, one_each).groups_covered == 4
    missing = Plan.of([[m * k + v for m in (0, 1, 3) for v in range(k)]])
    report = verify(sar, missing)
    assert report.groups_covered == 3 and "target 2 has no visited viewpoint" in report.violations
    views = generate(4, 3, 2, seed=5).viewpoints()
    assert np.allclose(sar.coords[2 * k + 1], views[7])  # target 2, view 1


def test_top_ids_are_point_rows_after_the_start_depot():
    """On a TOP file id i is the i-th point row after the start depot's row (the first row)."""
    path = TOP_DIR / "p2.3.g.txt"
    rows = [ln.split() for ln in path.read_text().splitlines()[3:] if ln.strip()]
    inst = read_top(path)
    for i in (0, 5, inst.n_nodes - 1):
        assert inst.coords[i].tolist() == [float(rows[i + 1][0]), float(rows[i + 1][1])]
        assert inst.prizes[i] == float(rows[i + 1][2])


def good(**changes):
    data = {"format": FORMAT, "version": 1, "instance": "sar-m4-k3-n2-s5", "routes": [[0, 3], [6]]}
    data.update(changes)
    return {k: v for k, v in data.items() if v is not ...}


@pytest.mark.parametrize("data, message", [
    ([1, 2], "top level must be a JSON object"),
    (good(format="sarcover-instance"), "field 'format' must be 'sarcover-plan'"),
    (good(version=2), "field 'version' is 2; this sarcover reads version 1"),
    (good(version=True), "field 'version' is"),
    (good(routes=...), "missing field 'routes'"),
    (good(instance=...), "missing field 'instance'"),
    (good(colour="red"), "unknown field 'colour'"),
    (good(instance=3), "field 'instance' must be the instance's name"),
    (good(instance="p2.3.g"), "the plan is for instance 'p2.3.g', not 'sar-m4-k3-n2-s5'"),
    (good(method=1), "field 'method' must be a string"),
    (good(routes={"0": [1]}), "field 'routes' must be a list"),
    (good(routes=[[0], 5]), "field 'routes[1]' must be a list of node ids, got 5"),
    (good(routes=[[0, 1.0]]), "field 'routes[0][1]' must be an integer node id, got 1"),
    (good(routes=[[0, "1"]]), "field 'routes[0][1]' must be an integer node id, got '1'"),
    (good(routes=[[True]]), "field 'routes[0][0]' must be an integer node id, got True"),
    (good(routes=[[0], [12]]), ("field 'routes[1][0]' is 12, not a node id (instance 'sar-m4-k3-n2-s5' has "
                                "viewpoints 0..11)")),
    (good(routes=[[-1]]), "field 'routes[0][0]' is -1, not a node id"),
])
def test_bad_plans_are_refused_naming_the_field(sar, data, message):
    """Every malformed plan raises a PlanFileError whose one line names the field."""
    with pytest.raises(PlanFileError) as err:
        plan_from_dict(data, sar, source="p.json")
    assert message in str(err.value) and str(err.value).startswith("p.json: ") and "\n" not in str(err.value)


def test_constraint_breaking_plans_are_read_for_the_verifier(sar):
    """A node twice and more routes than vehicles are not bad input: they reach the verifier."""
    plan = plan_from_dict(good(routes=[[0, 0], [], [1]]), sar).plan
    violations = verify(sar, plan).violations
    assert "3 routes for 2 vehicles" in violations and "node 0 visited twice (routes 0 and 0)" in violations


@pytest.mark.parametrize("text, message", [
    (None, "no such file"),
    ("{", "not valid JSON"),
    ("[" * 100000, "not valid JSON"),
    ("\udcff", "not a text file"),
])
def test_unreadable_files_are_one_line_errors(tmp_path, text, message):
    """A missing, broken, deeply nested or binary file: one line naming the file and the problem."""
    path = tmp_path / "p.json"
    if text == "\udcff":
        path.write_bytes(b"\xff\xfe\x00")
    elif text is not None:
        path.write_text(text)
    with pytest.raises(PlanFileError) as err:
        load_plan(path)
    assert message in str(err.value) and str(path) in str(err.value)
