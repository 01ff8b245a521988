"""What a method returns, and the verified result that is counted.

Two questions, two fields (as Pyomo keeps ``TerminationCondition`` apart from ``SolutionStatus``):

- :class:`Termination`: why the run stopped (a proof of optimality, a proof of infeasibility,
  the time limit, the end of a heuristic's own schedule, an error);
- :class:`SolutionStatus`: what it found (a plan proven optimal, a plan, no plan).

A method returns a :class:`Result` (its termination, its plan, its bound, its own notes). Only
:func:`verified_result` turns it into the :class:`VerifiedResult` that benchmarks count: the
independent verifier recomputes the objective, and a plan it rejects, a bound below the verified
objective or a claimed optimum without a plan make the run an error. :class:`Status` is the one
word that combines both fields, as result rows, the CLI and the reports print it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan
from sarcover.formulations.verify import VerificationReport, verify


class Termination(str, Enum):
    """Why a run stopped.

    OPTIMAL: it proved its plan optimal. INFEASIBLE: it proved that no plan covers every group
    (the pre-check or an exact solver). TIME_LIMIT: the time limit stopped it before a proof.
    COMPLETED: it ended its own schedule (a heuristic's iterations, or an exact solver whose proof
    holds only for a scaled model); it proves nothing. ERROR: the method failed, or the verifier
    rejected what it returned.
    """

    OPTIMAL = "optimal"
    INFEASIBLE = "infeasible"
    TIME_LIMIT = "time_limit"
    COMPLETED = "completed"
    ERROR = "error"

    def __str__(self) -> str:
        return self.value


class SolutionStatus(str, Enum):
    """What a run found: a plan proven optimal, a plan without proof, or no plan."""

    OPTIMAL = "optimal"
    FEASIBLE = "feasible"
    NONE = "none"

    def __str__(self) -> str:
        return self.value


class Status(str, Enum):
    """The one-word summary of termination and solution (result rows, CLI, reports).

    OPTIMAL: plan proven optimal. FEASIBLE: a plan, no proof, not stopped by the time limit.
    TIME_LIMIT: stopped by the time limit (the solution field says whether a plan exists).
    INFEASIBLE: proven that no plan covers every group. NO_PLAN: a heuristic found no plan
    covering every group, without proof that none exists. ERROR: never counted.
    """

    OPTIMAL = "optimal"
    FEASIBLE = "feasible"
    TIME_LIMIT = "time_limit"
    INFEASIBLE = "infeasible"
    NO_PLAN = "no_plan"
    ERROR = "error"

    def __str__(self) -> str:
        return self.value


def summary_status(termination: Termination, solution: SolutionStatus) -> Status:
    """The :class:`Status` word of a (termination, solution) pair."""
    if termination in (Termination.ERROR, Termination.INFEASIBLE, Termination.TIME_LIMIT):
        return Status(termination.value)
    if solution is SolutionStatus.OPTIMAL:
        return Status.OPTIMAL
    if solution is SolutionStatus.FEASIBLE:
        return Status.FEASIBLE
    return Status.NO_PLAN


def split_status(status: str, has_plan: bool) -> tuple[Termination, SolutionStatus]:
    """The (termination, solution) pair of a :class:`Status` word, for rows written before the
    two fields existed (their ``time_limit`` rows say whether a plan exists only by having one)."""
    status = Status(status)
    found = SolutionStatus.FEASIBLE if has_plan else SolutionStatus.NONE
    if status is Status.OPTIMAL:
        return Termination.OPTIMAL, SolutionStatus.OPTIMAL if has_plan else SolutionStatus.NONE
    if status is Status.FEASIBLE:
        return Termination.COMPLETED, found
    if status is Status.NO_PLAN:
        return Termination.COMPLETED, SolutionStatus.NONE
    if status is Status.TIME_LIMIT:
        return Termination.TIME_LIMIT, found
    return Termination(status.value), SolutionStatus.NONE  # infeasible, error: nothing counted


_LEGACY = {Status.OPTIMAL: Termination.OPTIMAL, Status.FEASIBLE: Termination.COMPLETED,
           Status.NO_PLAN: Termination.COMPLETED, Status.TIME_LIMIT: Termination.TIME_LIMIT,
           Status.INFEASIBLE: Termination.INFEASIBLE, Status.ERROR: Termination.ERROR}


@dataclass
class Result:
    """What a method returns: why it stopped, its plan (or None) and its proven upper bound (or
    None). The solution status follows from them: no plan, a plan, or a plan proven optimal.

    A method of one's own (named ``module:function`` in a suite) may still pass a :class:`Status`
    word as ``termination``; it is read as the termination it implies.
    """

    method: str
    termination: Termination
    plan: Plan | None = None
    bound: float | None = None
    runtime_s: float = 0.0
    reason: str = ""
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        if isinstance(self.termination, Status):
            self.termination = _LEGACY[self.termination]
        else:
            self.termination = Termination(self.termination)

    @property
    def solution(self) -> SolutionStatus:
        if self.plan is None:
            return SolutionStatus.NONE
        return SolutionStatus.OPTIMAL if self.termination is Termination.OPTIMAL else SolutionStatus.FEASIBLE

    @property
    def status(self) -> Status:
        return summary_status(self.termination, self.solution)


@dataclass(frozen=True)
class VerifiedResult:
    """A run as it is counted: the method's result after the independent verifier.

    ``objective`` is the verifier's (never the method's claim); ``report`` is the verifier's
    report of the returned plan (None without one). When the verifier rejected the plan, or the
    bound lies below the verified objective, ``termination`` is ERROR, ``solution`` NONE and
    ``info["claimed_status"]`` keeps what the method said.
    """

    method: str
    termination: Termination
    solution: SolutionStatus
    plan: Plan | None
    objective: float | None
    bound: float | None
    runtime_s: float
    reason: str = ""
    info: dict = field(default_factory=dict)
    report: VerificationReport | None = None

    @property
    def status(self) -> Status:
        return summary_status(self.termination, self.solution)

    @property
    def valid(self) -> bool:
        """True when a plan came back and the verifier accepted it."""
        return self.report is not None and self.report.valid

    @classmethod
    def failed(cls, method: str, termination: Termination, reason: str, runtime_s: float,
               info: dict | None = None) -> "VerifiedResult":
        """A run without a plan (error, or infeasible by the pre-check)."""
        return cls(method, termination, SolutionStatus.NONE, None, None, None, runtime_s, reason, info or {})


def verified_result(instance: TOPInstance, result: Result, *, method: str | None = None,
                    runtime_s: float | None = None) -> VerifiedResult:
    """Count ``result``: verify its plan, take the verifier's objective, and turn a rejected plan,
    a bound below the verified objective, or a proof claim without a plan into an error.

    ``method`` names the run (the registry's name, not the method's own); ``runtime_s`` is used
    when the method reported none.
    """
    name = method or result.method
    runtime = result.runtime_s if result.runtime_s > 0.0 or runtime_s is None else runtime_s
    info = dict(result.info)

    def error(reason: str, report=None) -> VerifiedResult:
        info["claimed_status"] = str(result.status)
        return VerifiedResult(name, Termination.ERROR, SolutionStatus.NONE, result.plan, None, result.bound,
                              runtime, reason, info, report)

    if result.plan is None:
        if result.termination is Termination.OPTIMAL:
            return error("status optimal without a plan")
        return VerifiedResult(name, result.termination, SolutionStatus.NONE, None, None, result.bound,
                              runtime, result.reason, info)
    report = verify(instance, result.plan)
    if not report.valid:
        return error("verifier rejected the plan: " + "; ".join(report.violations[:5]), report)
    objective = report.prize
    bound = result.bound
    if bound is not None and bound < objective - 1e-6 * max(1.0, abs(objective)):
        return error(f"bound {bound:g} below verified objective {objective:g}", report)
    if result.termination is Termination.OPTIMAL and bound is None:
        bound = objective
    return VerifiedResult(name, result.termination, result.solution, result.plan, objective, bound, runtime,
                          result.reason, info, report)
