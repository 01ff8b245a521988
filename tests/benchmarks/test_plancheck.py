"""What a checked plan is measured against: optima, bounds, best known values, and conflicts."""

import json

import numpy as np
import pytest

from sarcover.benchmarks.plancheck import check_plan, known_value, same_instance
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import TOPInstance, to_top
from sarcover.formulations.io import read_top
from sarcover.formulations.plan import Plan
from sarcover.formulations.records import SCHEMA_VERSION
from conftest import TOP_DIR


def write_rows(folder, inst, *runs):
    """A results folder with one row per (method, status, objective, bound) on ``inst``."""
    folder.mkdir()
    rows = [{"schema": SCHEMA_VERSION, "key": f"{inst.name}|{m}|0", "suite": "t", "instance": inst.name,
             "method": m, "exact": b is not None, "seed": 0, "status": status, "objective": obj, "bound": b,
             "valid": obj is not None, "kind": inst.kind, "n_nodes": inst.n_nodes, "n_vehicles": inst.n_vehicles,
             "e_max": inst.budget, "reference": None, "runtime_s": 1.0} for m, status, obj, b in runs]
    (folder / "results.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    return folder


@pytest.fixture
def sar():
    """Five targets, two views, two UAVs at a loose E_max: greedy-sized plans are valid."""
    return to_top(generate(5, 2, 2, 4242, e_max=9000.0))


PLAN = Plan.of([[0, 2, 4], [6, 8]])  # one view of each of the five targets


def test_best_bound_when_no_optimum_is_proven(tmp_path, sar):
    """Without a proof the gap is to the lowest bound, 'at most', naming the methods that proved it."""
    folder = write_rows(tmp_path / "r", sar, ("bp", "time_limit", 5.0, 8.0), ("milp", "time_limit", 4.0, 9.0),
                        ("greedy", "feasible", 5.0, None))
    check = check_plan(sar, PLAN, folder)
    assert check.valid and check.objective == 5.0
    assert (check.known.kind, check.known.value) == ("bound", 8.0) and check.known.source.endswith("proven by bp")
    assert check.gap == pytest.approx(3 / 8)
    assert check.lines()[1].startswith("gap at most 37.50% to the best proven bound 8")


def test_disagreeing_optima_and_a_plan_above_the_optimum_are_conflicts(tmp_path, sar):
    """Two exact methods proving 4 and 6, and a plan of 5: the conflicts are named, the gap negative."""
    folder = write_rows(tmp_path / "r", sar, ("milp", "optimal", 4.0, 4.0), ("cpsat", "optimal", 6.0, 6.0))
    check = check_plan(sar, PLAN, folder)
    assert check.known.kind == "optimum" and check.known.value == 6.0  # instance_table's: the largest proof
    assert any(n.startswith("CONFLICT in results") and "proven optima disagree" in n for n in check.notes)
    folder = write_rows(tmp_path / "r2", sar, ("milp", "optimal", 4.0, 4.0))
    check = check_plan(sar, PLAN, folder)
    assert check.gap == pytest.approx(-0.25)
    assert "CONFLICT: the plan is better than the proven optimum" in check.lines()[1]


def test_published_best_known_value_of_a_shipped_file():
    """p3.3.o's published value is a best known one: the gap is to that plan, not to an optimum."""
    inst = read_top(TOP_DIR / "p3.3.o.txt")
    known = known_value(inst)
    assert known.kind == "best_known" and known.value == 590.0
    check = check_plan(inst, Plan.of([[0]]))
    below = f"{100 * (590 - check.objective) / 590:.2f}% below the best known"
    assert check.valid and check.lines()[1].startswith(below)


def test_regression_infeasible_row_and_content_match():
    """A regression row proven infeasible is found by content; an edited copy of a shipped file is not
    the shipped file, whatever its name."""
    infeasible = to_top(generate(5, 3, 1, 1500, e_max=2972.5))
    assert known_value(infeasible).kind == "infeasible"
    assert known_value(to_top(generate(5, 3, 1, 1500, e_max=2972.6))) is None
    shipped = read_top(TOP_DIR / "p2.3.g.txt")
    assert known_value(shipped).value == 145.0
    edited = TOPInstance(coords=shipped.coords, prizes=shipped.prizes, start=shipped.start, end=shipped.end,
                         budget=shipped.budget + 1, n_vehicles=shipped.n_vehicles, name="p2.3.g", kind="top")
    assert not same_instance(edited, shipped) and known_value(edited) is None


def test_to_dict_is_json_and_matches_the_check(sar):
    """The --json object carries the verifier's objective, energies and the known value."""
    data = json.loads(json.dumps(check_plan(sar, PLAN).to_dict()))
    assert data["valid"] and data["objective"] == 5.0 and data["known"] is None and data["gap"] is None
    assert np.allclose(data["energy"], check_plan(sar, PLAN).report.energy)


def test_to_dict_of_a_plan_with_unknown_nodes_is_strict_json(sar):
    """A Plan built in Python with an id that names no node: invalid, and its object has no NaN."""
    data = check_plan(sar, Plan.of([[0, 99]])).to_dict()
    assert not data["valid"] and "route 0 visits unknown node 99" in data["violations"]
    assert data["energy"] == [None] and json.loads(json.dumps(data, allow_nan=False)) == data
