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
