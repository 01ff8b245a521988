"""Run a suite's jobs in isolated worker processes (or on a Dask cluster) into the results store.

- :func:`run_one` runs one job (build the instance, :func:`sarcover.benchmarks.registry.run_method`, which
  verifies the plan) and returns its results row. It never raises.
- Local execution keeps ``workers`` long-lived processes, each running one job at a time (short
  jobs are sent in batches, see :func:`_next_batch`, each still with its own deadline and row). The
  parent watches every job's deadline (``time_limit + grace``): a job past it is SIGKILLed with its
  worker and recorded as ``time_limit``; a worker that dies (segfault, out of memory, ``os._exit``)
  is recorded as ``error``; a fresh worker takes its place and the suite goes on. ``memory_mb``
  caps each worker's address space (``resource.setrlimit``), so a memory explosion is a
  MemoryError (an ``error`` row), not a machine-wide swap storm. Workers die with the parent.
- ``scheduler="tcp://HOST:PORT"`` submits the same :func:`run_one` calls to a Dask distributed
  cluster instead. There a job cannot be hard-killed (Dask runs tasks in threads): a job past its
  deadline is recorded as ``time_limit`` and its thread is abandoned; a job whose worker dies
  is rerun by Dask on a live worker (one row per job still), and recorded as ``error`` only when
  its workers die more often than Dask's ``allowed-failures`` (a job that kills every worker).
- Rows are appended to ``RESULTS_DIR/results.jsonl`` by the parent as each job finishes (see
  :mod:`sarcover.formulations.records` for the format).
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import multiprocessing as mp
import os
import platform
import shlex
import signal
import sys
import threading
import time
import traceback
from collections import deque
from multiprocessing.connection import wait
from pathlib import Path

from sarcover.formulations.errors import SarcoverError
from sarcover.formulations.records import FIELDS, RESULTS_FILE, SCHEMA_VERSION, drop_torn_tail, outcome, read_rows
from sarcover.benchmarks.registry import get_method, warm_up
from sarcover.benchmarks.suite import Suite

_PACKAGES = ("sarcover", "numpy", "scipy", "pandas", "scikit-learn", "pyomo", "highspy", "ortools",
             "pyvrp", "numba", "dask", "distributed")
_ENV: dict | None = None


class HarnessError(SarcoverError):
    """A benchmark run that cannot start (results directory, scheduler)."""


def environment() -> dict:
    """Machine and package versions of this process (computed once per process)."""
    global _ENV
    if _ENV is None:
        from importlib.metadata import PackageNotFoundError, version

        versions = {"python": platform.python_version()}
        for pkg in _PACKAGES:
            try:
                versions[pkg] = version(pkg)
            except PackageNotFoundError:
                versions[pkg] = None
        _ENV = {"host": platform.node(), "platform": platform.platform(terse=True),
                "cpu_count": os.cpu_count(), "versions": versions}
    return _ENV


_LAST_INSTANCE: tuple[str, object] | None = None


def cached_instance(source: dict):
    """:func:`build_instance`, reusing the previous job's instance when the source is the same
    (a suite lists each instance's methods in a row, and a batch runs them in one process)."""
    global _LAST_INSTANCE
    key = json.dumps({k: v for k, v in source.items() if k not in ("exact",)}, sort_keys=True, default=str)
    if _LAST_INSTANCE is not None and _LAST_INSTANCE[0] == key:
        return _LAST_INSTANCE[1]
    instance = build_instance(source)
    _LAST_INSTANCE = (key, instance)
    return instance


def build_instance(source: dict):
    """The TOPInstance a job's ``source`` describes (generator parameters or a file)."""
    if source["type"] == "generate":
        from sarcover.formulations.generate import generate
        from sarcover.formulations.instance import to_top

        return to_top(generate(source["M"], source["K"], source["N"], source["instance_seed"],
                               source["preset"], **source["overrides"]))
    from sarcover.formulations.io import load_instance

    return load_instance(source["path"])


def _now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def base_row(job: dict) -> dict:
    """A row of the schema's fields (:data:`~sarcover.formulations.records.FIELDS`, in order): the
    job's identity and provenance, and the outcome of a job that has not run (an error)."""
    src = job["source"]
    source = {k: v for k, v in src.items() if k not in ("exact", "reference", "best_known")}
    row = dict.fromkeys(FIELDS)
    row.update({
        "schema": SCHEMA_VERSION, "key": job["key"], "suite": job.get("suite"),
        "instance": job["instance"], "method": job["method"], "exact": src.get("exact"),
        "seed": job["seed"], "run": job["run"], "source": source,
        "kind": "sar" if src["type"] == "generate" else None,
        "M": src.get("M"), "K": src.get("K"), "N": src.get("N"), "instance_seed": src.get("instance_seed"),
        "reference": src.get("reference"), "best_known": src.get("best_known"),
        "termination": "error", "solution": "none", "status": "error", "valid": False, "reason": "", "info": {},
        "time_limit": job["time_limit"], "workers": job.get("workers"), **environment(), "pid": os.getpid(),
    })
    return row


def run_one(job: dict) -> dict:
    """Run one job and return its row. Never raises: any failure is an ``error`` row with a reason."""
    t0, c0 = time.perf_counter(), time.thread_time()
    row = base_row(job)
    try:
        from sarcover.benchmarks.registry import run_method

        instance = cached_instance(job["source"])
        row.update(kind=instance.kind, n_nodes=instance.n_nodes, n_groups=len(instance.groups),
                   n_vehicles=instance.n_vehicles, e_max=instance.budget)
        run = run_method(job["method"], instance, seed=job["seed"], time_limit=job["time_limit"],
                         params=job.get("params"))
        rec = outcome(run, instance)
        rec.pop("instance")
        row.update(rec)
        row["threads"] = run.info.get("threads")
    except BaseException as exc:  # noqa: BLE001 - a job must never take the harness down
        if isinstance(exc, KeyboardInterrupt):
            raise
        row.update(termination="error", solution="none", status="error")
        row["reason"] = f"harness: {type(exc).__name__}: {exc}"
        row["info"] = {"traceback": traceback.format_exc(limit=-3).strip().splitlines()}
    row["wall_s"] = time.perf_counter() - t0
    row["cpu_s"] = time.thread_time() - c0
    if row["runtime_s"] is None:
        row["runtime_s"] = row["wall_s"]
    row["finished_at"] = _now()
    return _clean(row)


def failed_row(job: dict, status: str, reason: str, elapsed: float) -> dict:
    """The row of a job whose worker was killed or died (no result came back)."""
    row = base_row(job)
    row.update(termination=status, solution="none", status=status, reason=reason, runtime_s=elapsed,
               wall_s=elapsed, finished_at=_now())
    row["pid"] = None
    return _clean(row)


def _clean(obj):
    """JSON-safe copy: numpy scalars to Python, tuples to lists, NaN/inf to None."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, bool) or obj is None or isinstance(obj, str):
        return obj
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if hasattr(obj, "item"):  # numpy scalar
        return _clean(obj.item())
    if hasattr(obj, "tolist"):
        return _clean(obj.tolist())
    return str(obj)


# -- results store --------------------------------------------------------------------------------
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


class ResultsStore:
    """Append-only JSON Lines log. Each row is flushed to the OS as written (SIGKILL-safe) and
    fsynced at most once a second (bounds the loss on a power cut)."""

    def __init__(self, directory: str | Path, *, resume: bool, suite: str | None = None):
        self.directory = Path(directory)
        self.path = self.directory / RESULTS_FILE
        self.keys: set[str] = set()
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
            self.keys = {r["key"] for r in rows}
        self._fh = self.path.open("ab")
        self._last_sync = time.monotonic()

    def append(self, row: dict) -> None:
        self._fh.write((json.dumps(row, allow_nan=False) + "\n").encode())
        self._fh.flush()
        self.keys.add(row["key"])
        now = time.monotonic()
        if now - self._last_sync > 1.0:
            os.fsync(self._fh.fileno())
            self._last_sync = now

    def close(self) -> None:
        if not self._fh.closed:
            self._fh.flush()
            os.fsync(self._fh.fileno())
            self._fh.close()


# -- progress -------------------------------------------------------------------------------------
def _hms(seconds: float) -> str:
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
                f"elapsed {_hms(elapsed)} ETA {_hms(eta) if self.done else '?'}")
        bad = {k: v for k, v in self.counts.items() if k in ("error", "time_limit")}
        if bad:
            line += " (" + ", ".join(f"{v} {k}" for k, v in sorted(bad.items())) + ")"
        end = "\n" if not self.tty or self.done == self.total else ""
        self.stream.write(("\r" if self.tty else "") + line + end)
        self.stream.flush()


# -- local worker pool ----------------------------------------------------------------------------
def _die_with_parent() -> None:
    try:  # Linux: SIGKILL this worker when the parent dies (even by SIGKILL)
        import ctypes

        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def _worker_main(conn, memory_mb: int, parent_pid: int) -> None:
    _die_with_parent()
    if os.getppid() != parent_pid:
        os._exit(0)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's business
    try:  # solver chatter on stdout would tear the progress bar; stderr stays for crashes
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.close(devnull)
    except OSError:
        pass
    if memory_mb:
        import resource

        limit = memory_mb * 1024 * 1024
        try:
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        except (ValueError, OSError):
            pass
    while True:
        try:
            job = conn.recv()
        except (EOFError, OSError):
            return
        if job is None:
            return
        for one in (job if isinstance(job, list) else [job]):  # a batch: one row back per job
            row = run_one(one)
            try:
                conn.send(row)
            except (BrokenPipeError, OSError):
                return


class _Worker:
    def __init__(self, ctx, memory_mb: int):
        self.conn, child = ctx.Pipe()
        self.proc = ctx.Process(target=_worker_main, args=(child, memory_mb, os.getpid()), daemon=True)
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


def _exit_reason(code: int | None) -> str:
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


BATCH_TIME_LIMIT = 10.0  # jobs with at most this time limit may share one worker task
MAX_BATCH = 32


def _next_batch(pending: deque, workers: int) -> list[dict]:
    """The next task for an idle worker: one job, or several short ones in a row.

    Cheap heuristic jobs take milliseconds; sending them one at a time costs a pipe round trip and
    leaves the worker idle while the parent writes the row. Consecutive jobs with a time limit of
    at most ``BATCH_TIME_LIMIT`` go as one batch of at most ``MAX_BATCH`` jobs (and at most a
    quarter of what is left per worker, so the tail stays balanced). Each job keeps its own
    deadline and its own row, sent back as it finishes.
    """
    first = pending.popleft()
    batch = [first]
    if first["time_limit"] > BATCH_TIME_LIMIT:
        return batch
    size = min(MAX_BATCH, max(1, len(pending) // (4 * workers)))
    while len(batch) < size and pending and pending[0]["time_limit"] <= BATCH_TIME_LIMIT:
        batch.append(pending.popleft())
    return batch


def run_local(jobs: list[dict], emit, *, workers: int, memory_mb: int = 0) -> None:
    """Run ``jobs`` on ``workers`` processes, calling ``emit(row)`` in the parent as each ends."""
    if not jobs:
        return
    ctx = mp.get_context("fork" if sys.platform.startswith("linux") else "spawn")
    pending = deque(jobs)
    pool = [_Worker(ctx, memory_mb) for _ in range(min(workers, len(jobs)))]
    try:
        while pending or any(w.job is not None for w in pool):
            for w in pool:
                if w.job is None and pending:
                    w.assign(_next_batch(pending, len(pool)))
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
                    emit(failed_row(w.job, "error", _exit_reason(w.proc.exitcode), elapsed))
                elif elapsed > w.job["time_limit"] + w.job["grace"]:
                    emit(failed_row(w.job, "time_limit",
                                    f"killed after {elapsed:.1f} s (time limit {w.job['time_limit']:g} s "
                                    f"+ grace {w.job['grace']:g} s)", elapsed))
                else:
                    continue
                w.queue.popleft()
                pending.extendleft(reversed(w.queue))  # the rest of its batch goes back in line
                w.kill()
                pool[i] = _Worker(ctx, memory_mb)
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


# -- Dask -----------------------------------------------------------------------------------------
def run_one_guarded(job: dict) -> dict:
    """run_one with a soft deadline, for Dask workers (threads cannot be killed; see module doc)."""
    box: list[dict] = []
    t0 = time.monotonic()
    thread = threading.Thread(target=lambda: box.append(run_one(job)), daemon=True)
    thread.start()
    thread.join(job["time_limit"] + job["grace"])
    if box:
        return box[0]
    elapsed = time.monotonic() - t0
    return failed_row(job, "time_limit", f"abandoned after {elapsed:.1f} s (time limit {job['time_limit']:g} s "
                                         f"+ grace {job['grace']:g} s; Dask cannot kill the thread)", elapsed)


def connect(address: str):
    """A Dask Client for ``address``; a one-line HarnessError when the scheduler is unreachable."""
    from dask.distributed import Client

    try:
        return Client(address, timeout="15s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise HarnessError(f"cannot reach the Dask scheduler at {address}: {exc}") from None


def warm_up_dask(client, methods) -> None:
    """Compile the numba code of ``methods`` on every worker of the cluster ``client`` reaches
    (see :func:`warm_up_methods`); a worker that joins later compiles in its first job."""
    try:
        client.run(warm_up, list(methods))
    except Exception:  # noqa: BLE001 - a worker that cannot warm up compiles in its job
        pass


def run_dask(jobs: list[dict], emit, *, scheduler, warm=()) -> None:
    """Run ``jobs`` on a Dask cluster (an address like ``tcp://host:8786`` or a Client). The
    methods in ``warm`` compile their numba code on every worker first (:func:`warm_up_dask`)."""
    if not jobs:
        return
    from dask.distributed import Client, as_completed

    own = not isinstance(scheduler, Client)
    client = connect(scheduler) if own else scheduler
    try:
        if warm:
            warm_up_dask(client, warm)
        futures = {}
        for job in jobs:
            futures[client.submit(run_one_guarded, job, pure=False)] = job
        for fut in as_completed(list(futures)):
            job = futures.pop(fut)
            try:
                row = fut.result()
            except Exception as exc:  # noqa: BLE001 - KilledWorker, pickling, ...
                row = failed_row(job, "error", f"dask: {type(exc).__name__}: {exc}", float("nan"))
            emit(row)
            fut.release()
    finally:
        if own:
            client.close()


# -- the front door -------------------------------------------------------------------------------
def default_workers() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:
        return max(1, os.cpu_count() or 1)


def run_suite(suite: Suite, out_dir: str | Path, *, workers: int | None = None, resume: bool = False,
              scheduler=None, progress: bool = True, stream=None) -> dict:
    """Run every job of ``suite`` not yet stored in ``out_dir``; return a summary dict."""
    workers = workers or default_workers()
    client = connect(scheduler) if isinstance(scheduler, str) else None  # fail before touching out_dir
    try:
        return _run_suite(suite, out_dir, workers, resume, client or scheduler, scheduler, progress, stream)
    finally:
        if client is not None:
            client.close()


def _run_suite(suite, out_dir, workers, resume, scheduler, address, progress, stream) -> dict:
    store = ResultsStore(out_dir, resume=resume, suite=suite.name)
    stream = stream or sys.stderr
    try:
        suite_copy = store.directory / "suite.toml"
        if not suite_copy.exists():
            suite_copy.write_text(suite.text)
        todo = [j for j in suite.jobs if j.key not in store.keys]
        stored = len(suite.jobs) - len(todo)
        if store.repaired and progress:
            stream.write(f"{store.path}: dropped a half-written last row (a job in flight when the run was killed)\n")
        where = f"Dask at {address if isinstance(address, str) else 'client'}" if scheduler else f"{workers} workers"
        if progress:
            stream.write(f"suite {suite.name}: {len(suite.jobs)} jobs ({suite.n_instances} instances × "
                         f"{len(suite.methods)} methods), {stored} already stored, {len(todo)} to run on {where}\n")
        payload = [{**j.as_dict(), "suite": suite.name, "workers": None if scheduler else workers} for j in todo]
        t0 = time.monotonic()
        started = _now()
        methods = sorted({job["method"] for job in payload})
        if payload:  # the numba compilation comes first, so the progress bar's ETA leaves it out
            if scheduler:
                warm_up_dask(scheduler, methods)
            else:
                warm_up_methods(methods, stream if progress else None)
        bar = Progress(len(todo), f"bench {suite.name}", stream=stream, enabled=progress)

        def emit(row: dict) -> None:
            store.append(row)
            bar.update(row["status"])

        def record(jobs: int, interrupted: bool) -> float:
            """Append this run's record to runs.jsonl (the report's "how it was run"); a run
            stopped by Ctrl-C is recorded too, with the jobs it stored, so a long run finished
            in several parts still says how long each part took."""
            wall = time.monotonic() - t0
            with (store.directory / "runs.jsonl").open("a") as fh:
                fh.write(json.dumps({"suite": suite.name, "started_at": started, "finished_at": _now(),
                                     "wall_s": wall, "jobs": jobs, "already_stored": stored,
                                     "interrupted": interrupted, "workers": None if scheduler else workers,
                                     "scheduler": address if isinstance(address, str) else None,
                                     "command": shlex.join(sys.argv), **environment()}) + "\n")
            return wall

        try:
            if scheduler:
                run_dask(payload, emit, scheduler=scheduler)
            else:
                run_local(payload, emit, workers=workers, memory_mb=suite.memory_mb)
        except KeyboardInterrupt:
            if bar.done:
                record(bar.done, True)
            raise
        wall = record(len(todo), False)
        return {"suite": suite.name, "jobs": len(suite.jobs), "ran": len(todo), "stored_before": stored,
                "wall_s": wall, "counts": dict(bar.counts), "path": str(store.path)}
    finally:
        store.close()
