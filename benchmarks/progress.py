"""The progress line of a benchmark run: count, percentage, elapsed time, ETA, failures so far."""

from __future__ import annotations

import sys
import time


def hms(seconds: float) -> str:
    """``m:ss``, or ``h:mm:ss`` from an hour on."""
    seconds = int(round(seconds))
    h, rest = divmod(seconds, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


class Progress:
    """A plain-text progress bar with count and ETA on stderr (one line per 5 s when not a TTY)."""

    def __init__(self, total: int, label: str, stream=None, enabled: bool = True):
        self.total, self.label, self.done = total, label, 0
        self.stream = stream or sys.stderr
        self.enabled = enabled and total > 0
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.t0 = time.monotonic()
        self._last = 0.0
        self.counts: dict[str, int] = {}

    def update(self, status: str) -> None:
        self.done += 1
        self.counts[status] = self.counts.get(status, 0) + 1
        now = time.monotonic()
        if not self.enabled:
            return
        if self.tty or now - self._last >= 5.0 or self.done == self.total:
            self._last = now
            self._draw(now)

    def _draw(self, now: float) -> None:
        elapsed = now - self.t0
        frac = self.done / self.total
        eta = elapsed / self.done * (self.total - self.done) if self.done else float("nan")
        bar = "#" * int(24 * frac) + "-" * (24 - int(24 * frac))
        line = (f"{self.label} [{bar}] {self.done}/{self.total} {100 * frac:3.0f}% "
                f"elapsed {hms(elapsed)} ETA {hms(eta) if self.done else '?'}")
        bad = {k: v for k, v in self.counts.items() if k in ("error", "time_limit")}
        if bad:
            line += " (" + ", ".join(f"{v} {k}" for k, v in sorted(bad.items())) + ")"
        end = "\n" if not self.tty or self.done == self.total else ""
        self.stream.write(("\r" if self.tty else "") + line + end)
        self.stream.flush()
