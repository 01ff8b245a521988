"""Plans (one route per vehicle) and the result every method returns."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum


class Status(str, Enum):
    """Outcome of a method run.

    OPTIMAL: plan proven optimal. FEASIBLE: a plan, no proof (heuristics; exact methods that
    stopped for another reason than time). TIME_LIMIT: stopped by the time limit (plan and bound
    may exist). INFEASIBLE: proven that no plan covers every group (pre-check or exact solver).
    NO_PLAN: a heuristic found no plan covering every group, without proof that none exists.
    ERROR: the method failed or returned a plan the verifier rejected; never counted.
    """

    OPTIMAL = "optimal"
    FEASIBLE = "feasible"
    TIME_LIMIT = "time_limit"
    INFEASIBLE = "infeasible"
    NO_PLAN = "no_plan"
    ERROR = "error"

    def __str__(self) -> str:
        return self.value


@dataclass(frozen=True)
class Plan:
    """One route per vehicle: ordered node ids (viewpoint ids on a SAR instance)."""

    routes: tuple[tuple[int, ...], ...]

    @classmethod
    def of(cls, routes) -> "Plan":
        return cls(tuple(tuple(int(v) for v in r) for r in routes))

    @property
    def visited(self) -> list[int]:
        return [v for r in self.routes for v in r]


@dataclass
class Result:
    """What a method returns. ``bound`` is a proven upper bound on the objective, or None.

    ``objective`` and the verdict fields are filled in by :func:`sarcover.benchmarks.registry.run_method`
    from the independent verifier, never trusted from the method itself.
    """

    method: str
    status: Status
    plan: Plan | None = None
    bound: float | None = None
    runtime_s: float = 0.0
    reason: str = ""
    info: dict = field(default_factory=dict)
    objective: float | None = None
