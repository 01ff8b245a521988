"""Run jobs on a Dask cluster, each in a child process of its Dask worker that is killed at its deadline.

Dask runs a task in a thread of a worker process, and a thread cannot be killed: a job that
overran its time limit used to go on in its thread, sharing the core with the next job. Here
the task (:func:`run_in_child`) hands the job to a child process of the Dask worker (kept for
the next job while it behaves) and waits: a job past ``time_limit + grace`` is SIGKILLed with
its child and recorded as ``time_limit``; a child that dies (the OOM killer, a crash) is an
``error`` row; ``memory_mb`` caps each child's address space. A Dask worker process that dies
takes its children along, and Dask reruns its job on a live worker; a job whose workers die
more often than Dask's ``allowed-failures`` is an ``error`` row (``dask: KilledWorker``).

Children start from a fresh interpreter (``python -c``, not fork: a Dask worker is
multi-threaded and daemonic), with the Dask worker's ``sys.path``. A job's numba code is
compiled (or loaded from numba's disk cache) in its child before the job's clock starts.
"""

from __future__ import annotations

import atexit
import logging
import os
import subprocess
import sys
import threading
import time
from multiprocessing.connection import Connection

from sarcover.benchmarks.errors import HarnessError
from sarcover.benchmarks.pool import cap_memory, die_with_parent, exit_reason, overrun_reason
from sarcover.benchmarks.registry import warm_up
from sarcover.benchmarks.rows import failed_row, run_one

log = logging.getLogger(__name__)

WARM_UP_S = 900.0  # how long a child may take to import and compile before its job's clock starts


def child_main() -> None:
    """A child's loop: receive a job, compile its method's numba code, say "started", send its row."""
    jobs, rows, memory_mb = (int(a) for a in sys.argv[1:4])
    die_with_parent()
    os.dup2(2, 1)  # solver chatter goes to the Dask worker's log, never into the protocol
    cap_memory(memory_mb)
    inbox, outbox = Connection(jobs, writable=False), Connection(rows, readable=False)
    while True:
        try:
            job = inbox.recv()
        except (EOFError, OSError):
            return
        warm_up([job["method"]])
        outbox.send(("started", None))
        outbox.send(("row", run_one(job)))


class Child:
    """A child process that runs one job at a time, over a pair of pipes."""

    def __init__(self, memory_mb: int):
        job_r, job_w = os.pipe()
        row_r, row_w = os.pipe()
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
        code = "from sarcover.benchmarks.dask_backend import child_main; child_main()"
        self.proc = subprocess.Popen([sys.executable, "-c", code, str(job_r), str(row_w), str(memory_mb)],
                                     pass_fds=(job_r, row_w), stdin=subprocess.DEVNULL, env=env)
        os.close(job_r)
        os.close(row_w)
        self.outbox, self.inbox = Connection(job_w, readable=False), Connection(row_r, writable=False)
        self.memory_mb = memory_mb

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait(5)
        self.outbox.close()
        self.inbox.close()


_IDLE: list[Child] = []  # this Dask worker's children waiting for a job
_LOCK = threading.Lock()


@atexit.register
def _close_idle() -> None:
    """End the idle children with their Dask worker (they would end at EOF anyway)."""
    with _LOCK:
        while _IDLE:
            _IDLE.pop().kill()


def _take(memory_mb: int) -> Child:
    with _LOCK:
        for i, child in enumerate(_IDLE):
            if child.memory_mb == memory_mb and child.proc.poll() is None:
                return _IDLE.pop(i)
    return Child(memory_mb)


def run_in_child(job: dict) -> dict:
    """The row of ``job``, run in a child process killed at its deadline (see the module doc)."""
    child = _take(int(job.get("memory_mb") or 0))
    t0 = time.monotonic()
    started = None
    try:
        child.outbox.send(job)
        while True:
            deadline = (t0 + WARM_UP_S) if started is None else started + job["time_limit"] + job["grace"]
            if not child.inbox.poll(max(0.0, deadline - time.monotonic())):
                elapsed = time.monotonic() - (started or t0)
                child.kill()
                return failed_row(job, "time_limit", overrun_reason(elapsed, job), elapsed)
            kind, value = child.inbox.recv()
            if kind == "started":
                started = time.monotonic()
                continue
            with _LOCK:
                _IDLE.append(child)
            return value
    except (EOFError, OSError):
        child.kill()
        elapsed = time.monotonic() - (started or t0)
        return failed_row(job, "error", exit_reason(child.proc.returncode).replace("worker", "job"), elapsed)


def connect(address: str, security=None):
    """A Dask Client for ``address``; a one-line HarnessError when the scheduler is unreachable.
    ``security``: a :class:`distributed.security.Security` (TLS) or None."""
    from dask.distributed import Client

    if address.startswith("tls://") and security is None:
        raise HarnessError(f"the Dask scheduler at {address} speaks TLS: give its CA certificate and this "
                           f"client's certificate (--tls-ca-file, --tls-cert, --tls-key)")
    try:
        return Client(address, timeout="15s", security=security)
    except (OSError, TimeoutError, ValueError, TypeError) as exc:  # TypeError: TLS settings Dask cannot use
        raise HarnessError(f"cannot reach the Dask scheduler at {address}: {exc}") from None


def warm_up_dask(client, methods) -> None:
    """Compile the numba code of ``methods`` on every worker of the cluster ``client`` reaches
    (its disk cache then serves the children in seconds); a worker that joins later compiles in
    its first job's child, before the job's clock starts."""
    try:
        client.run(warm_up, list(methods))
    except Exception:  # noqa: BLE001 - a worker that cannot warm up compiles in its child
        pass


def run_dask(jobs: list[dict], emit, *, scheduler, warm=(), security=None) -> None:
    """Run ``jobs`` on a Dask cluster (an address like ``tcp://host:8786`` or a Client). The
    methods in ``warm`` compile their numba code on every worker first (:func:`warm_up_dask`)."""
    if not jobs:
        return
    from dask.distributed import Client, as_completed

    own = not isinstance(scheduler, Client)
    client = connect(scheduler, security) if own else scheduler
    try:
        if warm:
            warm_up_dask(client, warm)
        futures = {}
        for job in jobs:
            futures[client.submit(run_in_child, job, pure=False)] = job
        for fut in as_completed(list(futures)):
            job = futures.pop(fut)
            try:
                row = fut.result()
            except Exception as exc:  # noqa: BLE001 - KilledWorker, pickling, ...
                row = failed_row(job, "error", f"dask: {type(exc).__name__}: {exc}", float("nan"))
                log.info("%s: %s", job.get("key"), row["reason"])
            emit(row)
            fut.release()
    finally:
        if own:
            client.close()
