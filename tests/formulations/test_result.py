"""Results: termination apart from solution, the verified result, and the row schema's upgrade."""

from __future__ import annotations

import json

import pytest

from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan
from sarcover.formulations.records import SCHEMA_VERSION, read_rows, upgrade_row
from sarcover.formulations.result import (Result, SolutionStatus, Status, Termination, split_status,
                                          verified_result)


@pytest.fixture
def inst():
    # two nodes on a line, budget 6 (round trip to x=2 and back costs 4; to x=3 costs 6)
    return TOPInstance(coords=[[1.0, 0.0], [3.0, 0.0]], prizes=[1.0, 2.0], start=(0.0, 0.0), end=(0.0, 0.0),
                       budget=6.0, n_vehicles=1, e_fly=1.0, e_image=0.0, groups=((0,),), name="line")


@pytest.mark.parametrize("termination, plan, status", [
    (Termination.OPTIMAL, True, Status.OPTIMAL),
    (Termination.TIME_LIMIT, True, Status.TIME_LIMIT),
    (Termination.TIME_LIMIT, False, Status.TIME_LIMIT),
    (Termination.COMPLETED, True, Status.FEASIBLE),
    (Termination.COMPLETED, False, Status.NO_PLAN),
    (Termination.INFEASIBLE, False, Status.INFEASIBLE),
])
def test_the_status_word_and_its_split_round_trip(termination, plan, status):
    """A (termination, solution) pair gives one status word, and that word (with whether a plan
    exists) gives the pair back: old rows lose nothing."""
    res = Result("m", termination, plan=Plan.of([[0]]) if plan else None)
    assert res.status is status
    assert split_status(str(status), plan) == (termination, res.solution)


def test_a_time_limited_run_with_a_plan_differs_from_one_without():
    """The two answers Status folds into `time_limit` are told apart by `solution`."""
    with_plan = Result("m", Termination.TIME_LIMIT, plan=Plan.of([[0]]))
    without = Result("m", Termination.TIME_LIMIT)
    assert with_plan.solution is SolutionStatus.FEASIBLE and without.solution is SolutionStatus.NONE


def test_verified_result_takes_the_verifiers_objective_and_leaves_the_result_alone(inst):
    """The verified result counts the verifier's objective and leaves the method's Result untouched."""
    res = Result("m", Termination.OPTIMAL, plan=Plan.of([[0, 1]]), bound=3.0, runtime_s=0.5)
    run = verified_result(inst, res, method="name")
    assert run.objective == 3.0 and run.status is Status.OPTIMAL and run.method == "name"
    assert run.valid and run.report.energy == [6.0]
    assert res.method == "m" and not hasattr(res, "objective")  # the method's own object is untouched


@pytest.mark.parametrize("result, needle", [
    (Result("m", Termination.COMPLETED, plan=Plan.of([[1, 1]])), "verifier rejected the plan"),
    (Result("m", Termination.COMPLETED, plan=Plan.of([[1]])), "group 0 has no visited viewpoint"),
    (Result("m", Termination.TIME_LIMIT, plan=Plan.of([[0, 1]]), bound=2.0), "bound 2 below verified objective 3"),
    (Result("m", Termination.OPTIMAL), "optimal without a plan"),
])
def test_bad_claims_become_errors(inst, result, needle):
    """A rejected plan, a bound below the plan, or a proof without a plan are counted as errors,
    keeping what the method claimed."""
    run = verified_result(inst, result)
    assert run.status is Status.ERROR and run.termination is Termination.ERROR
    assert run.solution is SolutionStatus.NONE and run.objective is None
    assert needle in run.reason and run.info["claimed_status"] == str(result.status)


def test_a_status_word_still_works_as_a_termination():
    """A method of one's own written against the one-word status still runs."""
    assert Result("m", Status.FEASIBLE, plan=Plan.of([[0]])).termination is Termination.COMPLETED
    assert Result("m", Status.NO_PLAN).status is Status.NO_PLAN


def test_schema_1_rows_are_read_as_schema_2(tmp_path):
    """Rows written before termination/solution existed are upgraded on read, not skipped."""
    old = {"schema": 1, "key": "a|bp|0", "instance": "a", "method": "bp", "status": "time_limit",
           "objective": 9.0, "bound": 10.0}
    empty = {**old, "key": "a|milp|0", "method": "milp", "objective": None}
    (tmp_path / "results.jsonl").write_text("\n".join(json.dumps(r) for r in (old, empty)) + "\n")
    rows, skipped = read_rows(tmp_path)
    assert skipped == {"partial": 0, "old_schema": 0, "duplicate": 0}
    assert [(r["schema"], r["termination"], r["solution"]) for r in rows] == [
        (SCHEMA_VERSION, "time_limit", "feasible"), (SCHEMA_VERSION, "time_limit", "none")]
    assert upgrade_row({**old, "status": "no_plan", "objective": None})["solution"] == "none"


def test_resume_appends_schema_2_rows_to_a_schema_1_file(tmp_path):
    """A run stored by the old harness can be resumed: its jobs are skipped, the rest run."""
    from sarcover.benchmarks.harness import run_suite
    from sarcover.benchmarks.suite import load_suite

    suite_file = tmp_path / "s.toml"
    suite_file.write_text('name = "s"\nmethods = ["greedy"]\ntime_limit = 5\n'
                          '[[instances]]\nM = 3\nK = 2\nN = 1\nruns = 2\n')
    suite = load_suite(str(suite_file))
    out = tmp_path / "res"
    run_suite(suite, out, workers=1, progress=False)
    lines = (out / "results.jsonl").read_text().splitlines()
    first = json.loads(lines[0])
    first.update(schema=1)
    del first["termination"], first["solution"]
    (out / "results.jsonl").write_text(json.dumps(first) + "\n")  # as the old harness left it
    summary = run_suite(suite, out, workers=1, resume=True, progress=False)
    assert summary["ran"] == 1
    rows, _ = read_rows(out)
    assert len(rows) == 2 and {r["termination"] for r in rows} == {"completed"}
