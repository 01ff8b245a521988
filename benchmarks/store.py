"""The results store: one folder, one suite, one set of settings, one JSON line per job.

Rows are appended to ``RESULTS_DIR/results.jsonl`` as each job ends (see
:mod:`sarcover.formulations.records` for the format), flushed to the operating system at once
(SIGKILL-safe) and fsynced at most once a second (bounds the loss on a power cut). A resume
skips the jobs whose ``key`` is stored, and refuses (:class:`HarnessError`, one line) a folder
that holds another suite or the same jobs run with other settings: a job's settings are its
method, time limit and resolved parameters (:func:`settings`), and a changed one would leave
the folder's rows made with two settings under one key each.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

from sarcover.benchmarks.errors import HarnessError
from sarcover.formulations.records import RESULTS_FILE, SCHEMA_VERSION, drop_torn_tail, read_rows

__all__ = ["HarnessError", "ResultsStore", "settings", "stored_suites"]


def stored_suites(directory: Path) -> set[str]:
    """Names of the suites whose rows ``directory`` holds (the ``suite`` of its rows; a row
    without one counts by the folder's suite.toml, the copy its first run wrote)."""
    names: set[str] = set()
    unnamed = False
    with (directory / RESULTS_FILE).open("rb") as fh:
        for raw in fh:
            try:
                name = json.loads(raw).get("suite")
            except (ValueError, AttributeError):
                continue  # a torn line; read_rows counts it
            if isinstance(name, str):
                names.add(name)
            else:
                unnamed = True
    if unnamed or not names:
        copy = directory / "suite.toml"
        try:
            import tomllib

            name = tomllib.loads(copy.read_text()).get("name", None)
        except (OSError, ValueError):
            name = None
        if isinstance(name, str):
            names.add(name)
    return names


def settings(job_or_row: dict) -> dict:
    """What a job's result depends on besides its instance and seed: ``method``, ``time_limit``
    and ``params`` (a job without params has none, ``{}``; a row written before rows carried
    them has no ``params`` here and is compared on the rest only)."""
    out = {"method": job_or_row["method"], "time_limit": job_or_row["time_limit"]}
    if "params" in job_or_row or "schema" not in job_or_row:  # a job, or a row that has them
        out["params"] = job_or_row.get("params") or {}
    return out


def _shown(value) -> str:
    return f"{value:g}" if isinstance(value, float) else json.dumps(value, sort_keys=True)


class ResultsStore:
    """Append-only JSON Lines log of one suite's rows; ``keys`` are the jobs stored."""

    def __init__(self, directory: str | Path, *, resume: bool, suite: str | None = None):
        self.directory = Path(directory)
        self.path = self.directory / RESULTS_FILE
        self.keys: set[str] = set()
        self.stored: dict[str, dict] = {}  # key -> settings of the stored row
        self.statuses: dict[str, str] = {}  # key -> status of the stored row
        self.repaired = 0
        if self.directory.exists() and not self.directory.is_dir():
            raise HarnessError(f"{self.directory} exists and is not a directory")
        self.directory.mkdir(parents=True, exist_ok=True)
        if self.path.exists() and self.path.stat().st_size > 0:
            held = stored_suites(self.directory)
            other = sorted(held - {suite}) if suite is not None else []
            if other:  # one folder, one suite: its report is that suite's, and its job keys are
                raise HarnessError(f"{self.directory} holds results of suite {', '.join(map(repr, other))}, "
                                   f"not {suite!r}; choose another -o")
            if not resume:
                raise HarnessError(f"{self.directory} already holds results; pass --resume to continue "
                                   f"that run, or choose another -o")
            self.repaired = int(drop_torn_tail(self.path))  # a job in flight when the run was killed
            rows, skipped = read_rows(self.directory)
            if skipped["old_schema"]:
                raise HarnessError(f"{self.path}: {skipped['old_schema']} rows of another schema version "
                                   f"(this is schema {SCHEMA_VERSION}); resume into a new -o")
            self.stored = {r["key"]: settings(r) for r in rows if "method" in r and "time_limit" in r}
            self.statuses = {r["key"]: r.get("status") for r in rows}
            self.keys = set(self.statuses)
        self._fh = self.path.open("ab")
        self._last_sync = time.monotonic()

    def check_settings(self, jobs: list[dict]) -> None:
        """Raise HarnessError naming the first setting that differs between a job and its stored
        row (and how many stored jobs differ so): a resume runs the same settings or nothing."""
        changed: dict[tuple, int] = {}
        for job in jobs:
            old = self.stored.get(job["key"])
            if old is None:
                continue
            new = settings(job)
            for field in ("method", "time_limit", "params"):
                if field in old and old[field] != new[field]:
                    what = (job["method"], field, _shown(old[field]), _shown(new[field]))
                    changed[what] = changed.get(what, 0) + 1
        if changed:
            (method, field, old, new), count = next(iter(changed.items()))
            more = f" (and {len(changed) - 1} other changed settings)" if len(changed) > 1 else ""
            raise HarnessError(f"{self.directory}: {method} {field} is {new} in this run but {old} in its "
                               f"{count} stored jobs{more}; a resume never mixes settings: restore it, or "
                               f"choose another -o")

    def append(self, row: dict) -> None:
        self._fh.write((json.dumps(row, allow_nan=False) + "\n").encode())
        self._fh.flush()
        self.keys.add(row["key"])
        self.statuses[row["key"]] = row["status"]
        now = time.monotonic()
        if now - self._last_sync > 1.0:
            os.fsync(self._fh.fileno())
            self._last_sync = now

    def close(self) -> None:
        if not self._fh.closed:
            self._fh.flush()
            os.fsync(self._fh.fileno())
            self._fh.close()
