"""Stop reasons of the exact methods (formulations/history.py)."""

import pytest

from sarcover.benchmarks.registry import run_method
from sarcover.formulations.history import StopReason, stop_reason_of
from sarcover.formulations.result import Termination


@pytest.mark.parametrize("termination, reason", [
    (Termination.OPTIMAL, StopReason.PROOF), (Termination.INFEASIBLE, StopReason.PROOF),
    (Termination.TIME_LIMIT, StopReason.TIME_LIMIT), (Termination.COMPLETED, StopReason.COMPLETED),
    (Termination.ERROR, StopReason.COMPLETED)])
def test_stop_reason_of_a_termination(termination, reason):
    """A proof (optimal or infeasible) is "proof", the time limit "time_limit", the rest "completed"."""
    assert stop_reason_of(termination) == reason


@pytest.mark.parametrize("method", ["milp", "cpsat"])
def test_compact_models_say_proof_when_they_prove(method, line_instance):
    """milp and cpsat prove the line instance optimal and give "proof" as their stop reason."""
    res = run_method(method, line_instance, time_limit=20.0)
    assert res.status == "optimal" and res.info["stop_reason"] == StopReason.PROOF


def test_record_keeps_one_cpu_time_per_kept_point():
    """History.record writes the thinned history and the CPU time of each kept point, rising."""
    from sarcover.formulations.history import MAX_POINTS, History

    hist = History()
    for z in range(3 * MAX_POINTS):
        hist.update(incumbent=float(z))
    info: dict = {}
    hist.record(info, float(3 * MAX_POINTS), None)
    assert len(info["history"]) == len(info["history_cpu"]) == MAX_POINTS
    assert info["history_cpu"] == sorted(info["history_cpu"]) and info["history"][-1][1] == 3 * MAX_POINTS


def test_cpsat_holds_its_warm_start_from_the_start():
    """cpsat's history starts with greedy's plan (its warm start, returned if nothing better is
    found), and what it returns is never below it."""
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(20, 3, 5, seed=100))
    greedy = run_method("greedy", inst)
    res = run_method("cpsat", inst, time_limit=2.0)
    hist = res.info["history"]
    first = next(p for p in hist if p[1] is not None)
    assert first[1] == greedy.objective and first[0] < 0.5 * hist[-1][0]
    assert res.objective >= greedy.objective and hist[-1][1] == res.objective
