"""An LP HiGHS cannot solve: retried, and if it still fails the search stops with its plan and a
certified bound (the scale run met HiGHS's status "unknown" on a degenerate route master at 600
points: the run ended in an error row with no plan)."""

from __future__ import annotations

import highspy
import pytest

from sarcover.formulations.bp import solve_bp
from sarcover.formulations.bp.highs import RETRIES, LPFailure, solve_lp
from sarcover.formulations.io import load_instance
from sarcover.formulations.result import Status
from sarcover.formulations.verify import verify

from bp_cases import OPTIMAL, TOP_DIR

OPTIMAL_STATUS, UNKNOWN = highspy.HighsModelStatus.kOptimal, highspy.HighsModelStatus.kUnknown


class Flaky:
    """A stand-in for a Highs LP that ends ``failures`` runs with status unknown, then solves."""

    def __init__(self, failures: int):
        self.failures, self.runs, self.cleared, self.seeds = failures, 0, 0, []
        self.seed = 7

    def run(self):
        self.runs += 1
        self.seeds.append(self.seed)

    def getModelStatus(self):
        return UNKNOWN if self.runs <= self.failures else OPTIMAL_STATUS

    def getOptionValue(self, name):
        assert name == "random_seed"
        return highspy.HighsStatus.kOk, self.seed

    def setOptionValue(self, name, value):
        assert name == "random_seed"
        self.seed = value

    def clearSolver(self):
        self.cleared += 1


@pytest.mark.parametrize("failures", [1, 2, len(RETRIES)])
def test_an_lp_ending_unknown_is_run_again(failures):
    """Again with the same seed, then with other seeds, the last time from no basis; the seed
    is left as it was."""
    h = Flaky(failures)
    solve_lp(h, "master LP")
    assert h.runs == failures + 1
    assert h.seeds[:2] == [7, 7] and len(set(h.seeds)) == min(failures, 2) + (failures == 3)
    assert h.cleared == (failures == len(RETRIES))
    assert h.seed == 7


def test_an_lp_that_never_solves_raises_lp_failure_naming_it():
    h = Flaky(failures=100)
    with pytest.raises(LPFailure, match="master LP: HiGHS status .*Unknown"):
        solve_lp(h, "master LP")
    assert h.runs == 1 + len(RETRIES) and h.seed == 7


def test_bp_stops_on_an_lp_failure_with_its_plan_and_a_valid_bound(monkeypatch):
    """Every master LP after the 40th fails: bp ends `feasible` (completed, not an error) with a verified
    plan, a bound no lower than the optimum, and the reason."""
    from sarcover.formulations.bp import master

    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    calls = [0]
    real = master.Master.solve

    def failing(self):
        calls[0] += 1
        if calls[0] > 40:
            raise LPFailure("master LP: HiGHS status kUnknown (test)")
        return real(self)

    monkeypatch.setattr(master.Master, "solve", failing)
    r = solve_bp(inst, time_limit=20)
    assert calls[0] > 40
    assert r.status == Status.FEASIBLE and "stopped early" in r.reason and "kUnknown" in r.reason
    assert r.plan is not None and verify(inst, r.plan).valid
    assert r.bound is not None and r.bound >= OPTIMAL["p2.2.k"] - 1e-6 >= verify(inst, r.plan).prize - 1e-6


def test_bp_stops_when_memory_runs_out_with_its_plan_and_a_valid_bound(monkeypatch):
    """An allocation that fails in the pricing (the scale run: M = 100, K = 3 under a worker's
    4 GB) ends the search like a failed LP: status feasible with the reason, a verified plan,
    a bound no lower than the optimum; never an error."""
    from sarcover.formulations.bp import pricer

    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    calls = [0]
    real = pricer.Pricer.price

    def failing(self, *args, **kw):
        calls[0] += 1
        if calls[0] > 10:
            raise MemoryError("Allocation failed (probably too large).")
        return real(self, *args, **kw)

    monkeypatch.setattr(pricer.Pricer, "price", failing)
    r = solve_bp(inst, time_limit=20)
    assert calls[0] > 10
    assert r.status == Status.FEASIBLE and "out of memory" in r.reason
    assert r.plan is not None and verify(inst, r.plan).valid
    assert r.bound is not None and r.bound >= OPTIMAL["p2.2.k"] - 1e-6 >= verify(inst, r.plan).prize - 1e-6
