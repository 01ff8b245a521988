"""Run a suite: the jobs not yet stored, on the local pool or a Dask cluster, into its results store.

The parts, one module each: :mod:`~sarcover.benchmarks.rows` (one job, one row),
:mod:`~sarcover.benchmarks.store` (the results folder, resume), :mod:`~sarcover.benchmarks.pool`
(local worker processes with deadlines and a memory cap), :mod:`~sarcover.benchmarks.dask_backend`
(the same on a Dask cluster), :mod:`~sarcover.benchmarks.progress` (the progress line) and
:mod:`~sarcover.benchmarks.provenance` (code version and machine). This module wires them:
:func:`run_suite`. Messages go to ``logging.getLogger("sarcover.benchmarks.harness")``; the
progress line and the numba compilation notice to ``stream``.
"""

from __future__ import annotations

import json
import logging
import os
import shlex
import sys
import time
from pathlib import Path

from sarcover.benchmarks.dask_backend import connect, run_dask, warm_up_dask
from sarcover.benchmarks.errors import HarnessError
from sarcover.benchmarks.pool import run_local
from sarcover.benchmarks.progress import Progress
from sarcover.benchmarks.provenance import environment
from sarcover.benchmarks.registry import get_method, warm_up
from sarcover.benchmarks.rows import now
from sarcover.benchmarks.store import ResultsStore
from sarcover.benchmarks.suite import Suite

__all__ = ["HarnessError", "run_suite", "warm_up_methods", "default_workers"]

log = logging.getLogger(__name__)
WORKER_LOG = "workers.log"  # the worker processes' stdout and stderr, in the results folder


def warm_up_methods(methods, stream) -> None:
    """Compile the numba code of the suite's methods in the parent, before the workers fork:
    they inherit it, so no job pays for it (the first bp job on a fresh checkout used to spend
    ~26 s of its time limit compiling, enough for the harness to kill a 60 s job). numba keeps
    the compiled code on disk, so later runs load it in a few seconds. ``stream``: where to say
    so (None: silently)."""
    hooks = {get_method(m).warm_up for m in methods} - {None}
    if not hooks:
        return
    if stream is not None:
        stream.write("compiling numba code (cached on disk after the first run) ... ")
        stream.flush()
    t = time.monotonic()
    warm_up(methods)
    if stream is not None:
        stream.write(f"{time.monotonic() - t:.1f} s\n")


def default_workers() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:
        return max(1, os.cpu_count() or 1)


def run_suite(suite: Suite, out_dir: str | Path, *, workers: int | None = None, resume: bool = False,
              scheduler=None, security=None, progress: bool = True, stream=None) -> dict:
    """Run every job of ``suite`` not yet stored in ``out_dir``; return a summary dict.

    ``scheduler``: a Dask address (``tcp://HOST:8786``, ``tls://...`` with ``security``, a
    :class:`distributed.security.Security`) or Client; None runs on ``workers`` local processes.
    A resume whose stored jobs ran with other settings (method, time limit, parameters) is refused
    with a HarnessError naming the change. The summary's ``counts`` are this run's statuses,
    ``errors`` the suite's jobs whose stored row (from this run or an earlier one) is an error.
    """
    workers = workers or default_workers()
    client = connect(scheduler, security) if isinstance(scheduler, str) else None  # fail before touching out_dir
    try:
        return _run_suite(suite, out_dir, workers, resume, client or scheduler, scheduler, progress, stream)
    finally:
        if client is not None:
            client.close()


def _run_suite(suite, out_dir, workers, resume, scheduler, address, progress, stream) -> dict:
    store = ResultsStore(out_dir, resume=resume, suite=suite.name)
    stream = stream or sys.stderr
    try:
        payload = [{**j.as_dict(), "suite": suite.name, "workers": None if scheduler else workers,
                    "memory_mb": suite.memory_mb} for j in suite.jobs]
        store.check_settings(payload)
        suite_copy = store.directory / "suite.toml"
        if not suite_copy.exists():
            suite_copy.write_text(suite.text)
        todo = [job for job in payload if job["key"] not in store.keys]
        stored = len(payload) - len(todo)
        if store.repaired:
            log.warning("%s: dropped a half-written last row (a job in flight when the run was killed)", store.path)
        where = (f"Dask at {address if isinstance(address, str) else 'client'}" if scheduler
                 else f"{workers} worker{'s' if workers != 1 else ''}")
        # instance blocks may run a subset of the suite's methods: count what the jobs run
        n_methods = len({job["method"] for job in payload})
        log.info("suite %s: %d jobs (%d instances, %d methods), %d already stored, %d to run on %s",
                 suite.name, len(payload), suite.n_instances, n_methods, stored, len(todo), where)
        t0 = time.monotonic()
        started = now()
        methods = sorted({job["method"] for job in todo})
        if todo:  # the numba compilation comes first, so the progress bar's ETA leaves it out
            if scheduler:
                warm_up_dask(scheduler, methods)
            else:
                warm_up_methods(methods, stream if progress else None)
        bar = Progress(len(todo), f"bench {suite.name}", stream=stream, enabled=progress)

        def emit(row: dict) -> None:
            store.append(row)
            bar.update(row["status"])
            log.debug("%s: %s in %.2f s%s", row["key"], row["status"], row["wall_s"] or 0.0,
                      f" ({row['reason']})" if row["reason"] else "")

        def record(jobs: int, interrupted: bool) -> float:
            """Append this run's record to runs.jsonl (the report's "how it was run"); a run
            stopped by Ctrl-C is recorded too, with the jobs it stored, so a long run finished
            in several parts still says how long each part took."""
            wall = time.monotonic() - t0
            with (store.directory / "runs.jsonl").open("a") as fh:
                fh.write(json.dumps({"suite": suite.name, "started_at": started, "finished_at": now(),
                                     "wall_s": wall, "jobs": jobs, "already_stored": stored,
                                     "interrupted": interrupted, "workers": None if scheduler else workers,
                                     "scheduler": address if isinstance(address, str) else None,
                                     "settings": _settings_table(todo or payload),
                                     "command": shlex.join(sys.argv), **environment()}) + "\n")
            return wall

        try:
            if scheduler:
                run_dask(todo, emit, scheduler=scheduler)
            else:
                run_local(todo, emit, workers=workers, memory_mb=suite.memory_mb,
                          output=store.directory / WORKER_LOG)
        except KeyboardInterrupt:
            if bar.done:
                record(bar.done, True)
            raise
        wall = record(len(todo), False)
        errors = sum(store.statuses.get(job["key"]) == "error" for job in payload)
        return {"suite": suite.name, "jobs": len(payload), "ran": len(todo), "stored_before": stored,
                "wall_s": wall, "counts": dict(bar.counts), "errors": errors, "path": str(store.path)}
    finally:
        store.close()


def _settings_table(jobs: list[dict]) -> dict:
    """Per method of ``jobs``: its time limits and resolved parameters (the run record's
    ``settings``; a method whose sets use several time limits lists each)."""
    out: dict[str, dict] = {}
    for job in jobs:
        entry = out.setdefault(job["method"], {"time_limit": [], "params": job.get("params") or {}})
        if job["time_limit"] not in entry["time_limit"]:
            entry["time_limit"].append(job["time_limit"])
    return out
