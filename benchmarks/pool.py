"""The local worker pool: jobs in long-lived worker processes, each with a deadline and a memory cap.

:func:`run_local` keeps ``workers`` processes, each running one job at a time (short jobs are sent
in batches, see :func:`next_batch`, each still with its own deadline and row). The parent watches
every job's deadline (``time_limit + grace``): a job past it is SIGKILLed with its worker and
recorded as ``time_limit``; a worker that dies (segfault, the OOM killer, ``os._exit``) is
recorded as ``error``; a fresh worker takes its place and the run goes on. ``memory_mb`` caps
each worker's address space (``resource.setrlimit``), so a memory explosion is a MemoryError (an
``error`` row), not a machine-wide swap storm. Workers die with the parent.

What a worker runs is a parameter (``run(job) -> row``, ``failed(job, status, reason, elapsed)
-> row`` for a job that returned nothing), so the benchmark harness and the gap decomposition
share one pool. A job needs ``time_limit`` and ``grace``; ``group`` (optional) keeps
consecutive jobs of one group in one worker task (they share what the worker caches).
Worker output (stdout and stderr: solver chatter, crash messages, log records) goes to the
``output`` file, or to /dev/null without one.
"""

from __future__ import annotations

import logging
import multiprocessing as mp
import os
import signal
import sys
import time
from collections import deque
from multiprocessing.connection import wait
from pathlib import Path
from typing import Callable

from sarcover.benchmarks.rows import failed_row, run_one

log = logging.getLogger(__name__)

BATCH_TIME_LIMIT = 10.0  # jobs with at most this time limit may share one worker task
MAX_BATCH = 32


def die_with_parent() -> None:
    """Linux: SIGKILL this process when its parent dies (even by SIGKILL)."""
    try:
        import ctypes

        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def redirect_output(output: str | Path | None) -> None:
    """Send this process's stdout and stderr to ``output`` (appended), or stdout to /dev/null:
    a worker's chatter on the terminal would tear the progress line."""
    try:
        if output is None:
            fd = os.open(os.devnull, os.O_WRONLY)
            os.dup2(fd, 1)
        else:
            fd = os.open(output, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
            os.dup2(fd, 1)
            os.dup2(fd, 2)
        os.close(fd)
    except OSError:
        return
    # Python-level streams that do not write to the file descriptors (a test's capture) follow too
    sys.stdout = open(1, "w", buffering=1, closefd=False)
    if output is not None:
        sys.stderr = open(2, "w", buffering=1, closefd=False)


def cap_memory(memory_mb: int) -> None:
    """Cap this process's address space at ``memory_mb`` MB (0: no cap)."""
    if memory_mb:
        import resource

        limit = memory_mb * 1024 * 1024
        try:
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        except (ValueError, OSError):
            pass


def _worker_main(conn, memory_mb: int, parent_pid: int, run, output) -> None:
    die_with_parent()
    if os.getppid() != parent_pid:  # the parent died before the line above took effect
        os._exit(0)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's business
    redirect_output(output)
    cap_memory(memory_mb)
    while True:
        try:
            job = conn.recv()
        except (EOFError, OSError):
            return
        if job is None:
            return
        for one in (job if isinstance(job, list) else [job]):  # a batch: one row back per job
            row = run(one)
            try:
                conn.send(row)
            except (BrokenPipeError, OSError):
                return


class Worker:
    """One worker process, the batch it runs and when its running job started."""

    def __init__(self, ctx, memory_mb: int, run=run_one, output=None):
        self.conn, child = ctx.Pipe()
        self.proc = ctx.Process(target=_worker_main, args=(child, memory_mb, os.getpid(), run, output),
                                daemon=True)
        self.proc.start()
        child.close()
        self.job: dict | None = None  # the job running now (the head of ``queue``)
        self.queue: deque = deque()  # this worker's batch, in order; rows come back one by one
        self.started = 0.0

    def assign(self, jobs: list[dict]) -> None:
        self.queue = deque(jobs)
        self.job, self.started = jobs[0], time.monotonic()
        try:
            self.conn.send(jobs)
        except OSError:  # the worker died idle; the main loop records and replaces it
            pass

    def done_one(self) -> None:
        """The head job's row arrived: the next job of the batch starts its clock now."""
        self.queue.popleft()
        self.job = self.queue[0] if self.queue else None
        self.started = time.monotonic()

    def kill(self) -> None:
        if self.proc.is_alive():
            try:
                os.kill(self.proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        self.proc.join(5)
        self.conn.close()


def exit_reason(code: int | None) -> str:
    """Why a worker process ended, from its exit code (negative: the signal that killed it)."""
    if code is None:
        return "worker process vanished"
    if code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
        hint = " (out of memory?)" if -code == signal.SIGKILL else ""
        return f"worker process died by {name}{hint}"
    return f"worker process exited with code {code}"


def overrun_reason(elapsed: float, job: dict, verb: str = "killed") -> str:
    return (f"{verb} after {elapsed:.1f} s (time limit {job['time_limit']:g} s + grace {job['grace']:g} s)")


def next_batch(pending: deque, workers: int) -> list[dict]:
    """The next task for an idle worker: one job, a group's jobs, or several short ones in a row.

    Jobs with a ``group`` go with the consecutive jobs of the same group (they share the worker's
    caches). Cheap heuristic jobs take milliseconds; sending them one at a time costs a pipe
    round trip and leaves the worker idle while the parent writes the row. Consecutive jobs with
    a time limit of at most ``BATCH_TIME_LIMIT`` go as one batch of at most ``MAX_BATCH`` jobs
    (and at most a quarter of what is left per worker, so the tail stays balanced). Each job
    keeps its own deadline and its own row, sent back as it finishes.
    """
    first = pending.popleft()
    batch = [first]
    group = first.get("group")
    if group is not None:
        while pending and pending[0].get("group") == group:
            batch.append(pending.popleft())
        return batch
    if first["time_limit"] > BATCH_TIME_LIMIT:
        return batch
    size = min(MAX_BATCH, max(1, len(pending) // (4 * workers)))
    while (len(batch) < size and pending and pending[0]["time_limit"] <= BATCH_TIME_LIMIT
           and pending[0].get("group") is None):
        batch.append(pending.popleft())
    return batch


def run_local(jobs: list[dict], emit, *, workers: int, memory_mb: int = 0, run: Callable[[dict], dict] = run_one,
              failed: Callable[..., dict] = failed_row, output: str | Path | None = None) -> None:
    """Run ``jobs`` on ``workers`` processes, calling ``emit(row)`` in the parent as each ends."""
    if not jobs:
        return
    ctx = mp.get_context("fork" if sys.platform.startswith("linux") else "spawn")
    pending = deque(jobs)

    def fresh() -> Worker:
        return Worker(ctx, memory_mb, run, output)

    pool = [fresh() for _ in range(min(workers, len(jobs)))]
    try:
        while pending or any(w.job is not None for w in pool):
            for w in pool:
                if w.job is None and pending:
                    w.assign(next_batch(pending, len(pool)))
            busy = [w for w in pool if w.job is not None]
            now = time.monotonic()
            timeout = min((w.started + w.job["time_limit"] + w.job["grace"] - now for w in busy), default=1.0)
            wait([w.conn for w in busy] + [w.proc.sentinel for w in busy], timeout=max(0.0, min(timeout, 1.0)))
            for i, w in enumerate(pool):
                if w.job is None:
                    continue
                dead = False
                while w.job is not None and w.conn.poll():  # drain every row the batch has sent
                    try:
                        row = w.conn.recv()
                    except (EOFError, OSError):
                        dead = True
                        break
                    w.done_one()
                    emit(row)
                if w.job is None:
                    continue
                elapsed = time.monotonic() - w.started
                if dead or not w.proc.is_alive():
                    w.proc.join(1)
                    if w.proc.exitcode == -signal.SIGINT:
                        # Ctrl-C reached the worker (a solver library re-armed SIGINT there): the
                        # user is stopping the run, so its job is not stored and --resume reruns it
                        raise KeyboardInterrupt
                    reason = exit_reason(w.proc.exitcode)
                    log.debug("%s: %s; a fresh worker takes its place", w.job.get("key"), reason)
                    emit(failed(w.job, "error", reason, elapsed))
                elif elapsed > w.job["time_limit"] + w.job["grace"]:
                    reason = overrun_reason(elapsed, w.job)
                    log.debug("%s: %s; a fresh worker takes its place", w.job.get("key"), reason)
                    emit(failed(w.job, "time_limit", reason, elapsed))
                else:
                    continue
                w.queue.popleft()
                pending.extendleft(reversed(w.queue))  # the rest of its batch goes back in line
                w.kill()
                pool[i] = fresh()
    finally:
        for w in pool:
            if w.job is None:
                try:
                    w.conn.send(None)
                except OSError:
                    pass
        for w in pool:
            if w.job is not None:
                w.kill()
            else:
                w.proc.join(2)
                if w.proc.is_alive():
                    w.kill()
