"""The clock of one branch-and-price run: when it started, and the deadlines its parts work to."""

from __future__ import annotations

import math
import time


class Clock:
    """Started on construction. ``hard_deadline`` is the time limit; ``deadline`` keeps a
    ``reserve`` before it for a last MILP over the generated routes. Moments are
    :func:`time.perf_counter` values."""

    def __init__(self, time_limit: float | None):
        self.t0 = time.perf_counter()
        self.limit = float(time_limit) if time_limit is not None else math.inf
        self.hard_deadline = self.t0 + self.limit
        self.reserve = min(5.0, 0.1 * self.limit)
        self.deadline = self.hard_deadline - self.reserve

    def time_left(self) -> float:
        return self.deadline - time.perf_counter()

    def until(self, share: float) -> float:
        """The moment ``share`` of the time limit is used up (never without a limit)."""
        return self.t0 + (share * self.limit if math.isfinite(self.limit) else math.inf)
