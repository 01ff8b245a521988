"""Anytime history of a method: incumbent and bound against time, and why the run stopped.

``Result.info["history"]`` is a list of ``[t, incumbent, bound]``: ``t`` seconds since the method
was called, ``incumbent`` the best verified objective found so far (None before the first plan)
and ``bound`` the best proven upper bound so far (None before the first one, and always None for
a heuristic), both in the objective's units. A point is appended whenever either improves, and a
last point at the end holds exactly the method's final objective and bound. Plain floats and None
only, so a result row stays JSON; thinned to at most :data:`MAX_POINTS` points (first and last
always kept). Every registered method records one (greedy a single point); a heuristic's
incumbent is the prize its returned plan would count at that moment (after its own repair).

``Result.info["history_cpu"]`` (where :meth:`History.record` wrote the history) gives the CPU
time of each point: seconds of the process's CPU time (all its threads) since the method was
called, one per point of ``history``. On a machine shared with other work it is the clock that
other processes do not inflate (a benchmark worker process runs one job at a time).

``Result.info["stop_reason"]`` says why the run ended, one of :class:`StopReason`.
"""

from __future__ import annotations

import math
import time
from enum import Enum

from sarcover.formulations.result import Termination

MAX_POINTS = 200
_EPS = 1e-9


class StopReason(str, Enum):
    """Why a run ended (``info["stop_reason"]``); a run that ends before its time limit says which.

    PROOF: an exact method proved its plan optimal (or that none exists). TIME_LIMIT: the time limit
    stopped it. ITERATION_LIMIT: its own iteration or solution count, the reproducible stop (the same
    seed gives the same plan). CONVERGED: its own no-improvement criterion. COMPLETED: it ran a fixed
    schedule with nothing left to search (a construction such as greedy, or an exact solver whose
    proof holds only for a scaled model).
    """

    PROOF = "proof"
    TIME_LIMIT = "time_limit"
    ITERATION_LIMIT = "iteration_limit"
    CONVERGED = "converged"
    COMPLETED = "completed"

    def __str__(self) -> str:
        return self.value


def stop_reason_of(termination: Termination) -> str:
    """The stop reason an exact method's termination implies (an error ends it too: "completed")."""
    termination = Termination(termination)
    if termination in (Termination.OPTIMAL, Termination.INFEASIBLE):
        return StopReason.PROOF.value
    if termination is Termination.TIME_LIMIT:
        return StopReason.TIME_LIMIT.value
    return StopReason.COMPLETED.value


def _kept(n: int, max_points: int) -> list[int]:
    """Indices of at most ``max_points`` of ``n`` points, evenly spread; first and last kept."""
    if n <= max_points:
        return list(range(n))
    step = (n - 1) / (max_points - 1)
    return sorted({round(k * step) for k in range(max_points)} | {0, n - 1})


def thin(points: list, max_points: int = MAX_POINTS) -> list:
    """At most ``max_points`` of ``points``, evenly spread by index; first and last kept."""
    return [points[i] for i in _kept(len(points), max_points)]


def shifted(points: list, dt: float) -> list:
    """The history with every time moved by ``dt`` (a wrapper that ran a heuristic first)."""
    return [[round(t + dt, 4), inc, bnd] for t, inc, bnd in points]


class History:
    """Records the running best incumbent (max) and bound (min) with their times."""

    def __init__(self, t0: float | None = None, c0: float | None = None):
        self.t0 = time.perf_counter() if t0 is None else t0
        self.c0 = time.process_time() if c0 is None else c0
        self.points: list[list] = []
        self.cpu: list[float] = []  # process CPU seconds since c0, one per point
        self.incumbent: float | None = None
        self.bound: float | None = None

    def update(self, incumbent: float | None = None, bound: float | None = None) -> bool:
        """Take a new verified objective and/or a new valid bound; log a point if either improves."""
        changed = False
        if incumbent is not None and math.isfinite(incumbent) and (
                self.incumbent is None or incumbent > self.incumbent + _EPS * max(1.0, abs(incumbent))):
            self.incumbent = float(incumbent)
            changed = True
        if bound is not None and math.isfinite(bound) and (
                self.bound is None or bound < self.bound - _EPS * max(1.0, abs(bound))):
            self.bound = float(bound)
            changed = True
        if changed:
            self._point(self.incumbent, self.bound)
        return changed

    def _point(self, incumbent, bound) -> None:
        self.points.append([round(time.perf_counter() - self.t0, 4), incumbent, bound])
        self.cpu.append(round(time.process_time() - self.c0, 4))

    def finish(self, incumbent: float | None, bound: float | None) -> list:
        """Append the final point (the method's own objective and bound) and return the thinned list."""
        inc = None if incumbent is None or not math.isfinite(incumbent) else float(incumbent)
        bnd = None if bound is None or not math.isfinite(bound) else float(bound)
        self._point(inc, bnd)
        return thin(self.points)

    def record(self, info: dict, incumbent: float | None, bound: float | None) -> None:
        """:meth:`finish`, written to ``info["history"]`` with the CPU time of each kept point in
        ``info["history_cpu"]``."""
        info["history"] = self.finish(incumbent, bound)
        info["history_cpu"] = [self.cpu[i] for i in _kept(len(self.cpu), MAX_POINTS)]
