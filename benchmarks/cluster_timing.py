"""Time one suite on 1 local worker, on N local workers and on an N-process Dask cluster, and what a
Dask worker process killed mid-run costs.

Why: the harness runs a suite on the local pool or on a Dask cluster (README, "On a Dask cluster")
and claims that Dask costs about nothing per job and that a killed worker loses no job. This tool
puts numbers on both for a given suite, on this machine::

    python -m sarcover.benchmarks.cluster_timing SUITE -o OUTDIR [--runs R] [--methods A,B]
                                                 [--workers N] [--kill-after SECONDS]

It runs the suite (``load_suite`` and ``run_suite``, as ``sarcover bench`` does) up to four times,
each into its own subfolder of OUTDIR: ``local-1`` (1 local worker), ``local-N`` (N local
workers), ``dask-N`` (a Dask cluster this tool starts as separate processes, as the README
documents: ``dask scheduler --host 127.0.0.1 --port PORT`` and ``dask worker
tcp://127.0.0.1:PORT --nthreads 1 --nworkers N --memory-limit 0``, both with ``--no-dashboard``)
and, with ``--kill-after``, ``dask-N-killed``: the same on a fresh cluster, with one Dask worker
process SIGKILLed as soon as it runs a job once SECONDS have passed (its nanny starts a fresh one
and Dask reruns the job).

Per run it records the wall time of ``run_suite``, the CPU time of this process and every process
under it (the local pool's workers, the Dask scheduler, workers and their job children; killed and
finished processes count once their parent reaped them, and the killed Dask worker's job child is
added as it was when the kill came), the sum of the rows' ``cpu_s`` (the jobs'
own CPU), the rows stored, the jobs that ended in ``error``, the jobs without a row (lost) and the
extra rows of jobs stored twice (duplicated). It writes ``OUTDIR/timing.json`` (after each run, so
an interrupted measurement keeps what it finished) and prints a Markdown table with the ratios
``local-N / local-1`` and ``dask-N / local-N`` and the killed run's extra wall time.

What is in each wall time and what is not: the numba code of the suite's methods is compiled (or
loaded from its disk cache) in this process before any run, so the local workers, which fork from
it, start warm. A cluster is started fresh for each Dask run, outside the clock, and its worker
processes load the numba code before the clock starts; each job child a Dask worker starts (one
per worker process, reused) imports sarcover and loads the numba code inside the clock, as it
does in any Dask run. In the killed run the replacement worker process and its child start inside
the clock: that is part of what the kill costs.

Every process the tool starts is stopped when it ends, also on Ctrl-C or SIGTERM (exit 130). Bad
input (an unknown suite or method, an OUTDIR that already holds a run) is one line on stderr and
exit 2, as with ``sarcover``.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from collections import Counter
from pathlib import Path

from sarcover.formulations.errors import SarcoverError

log = logging.getLogger("sarcover.benchmarks.cluster_timing")  # not __main__ under -m

EXIT_OK, EXIT_BAD_INPUT, EXIT_INTERRUPTED = 0, 2, 130
PROG = "python -m sarcover.benchmarks.cluster_timing"
TIMING_FILE = "timing.json"
CLUSTER_LOG = "cluster.log"  # the Dask processes' output, in the Dask run's folder
START_TIMEOUT_S = 120.0  # for the scheduler and every worker process to come up (a busy machine is slow)


class TimingError(SarcoverError):
    """Bad input, or a cluster that would not start: one line, exit 2."""


# -- CPU time and rows ---------------------------------------------------------------------------
def tree_cpu_s(pid: int | None = None) -> float:
    """CPU seconds (user + system) of process ``pid`` (default: this one) and every live process
    under it, each with the CPU of the children it reaped (so a finished or killed process counts
    once, in its parent's reaped-children time; one that nobody reaped yet is missing)."""
    import psutil

    try:
        root = psutil.Process(pid)
        procs = [root] + root.children(recursive=True)
    except psutil.NoSuchProcess:
        return 0.0
    return sum(_cpu_s(proc) for proc in procs)


def _cpu_s(proc) -> float:
    """CPU seconds of the psutil process ``proc`` and the children it reaped (0 once it is gone)."""
    import psutil

    try:
        t = proc.cpu_times()
    except (psutil.NoSuchProcess, psutil.AccessDenied):
        return 0.0
    return t.user + t.system + getattr(t, "children_user", 0.0) + getattr(t, "children_system", 0.0)


def _below(pid: int) -> list:
    """The psutil processes under ``pid`` (none if it is gone)."""
    import psutil

    try:
        return psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []


def stored_rows(directory: Path, keys: list[str]) -> dict:
    """What ``directory``'s results.jsonl holds for the jobs ``keys``: rows, distinct jobs, jobs
    whose first row is an error, jobs without a row (``lost``), extra rows of jobs stored more than
    once (``duplicated``), whether every job has exactly one row, and the sum of the rows' cpu_s."""
    from sarcover.formulations.records import RESULTS_FILE

    rows = []
    path = directory / RESULTS_FILE
    if path.is_file():
        for raw in path.read_bytes().splitlines():
            try:
                row = json.loads(raw)
            except ValueError:
                continue  # a torn last line (an interrupted run)
            if isinstance(row, dict) and "key" in row:
                rows.append(row)
    per_key = Counter(r["key"] for r in rows)
    first: dict[str, dict] = {}
    for r in rows:
        first.setdefault(r["key"], r)
    wanted = set(keys)
    lost = len(wanted - set(per_key))
    duplicated = sum(n - 1 for n in per_key.values())
    return {"rows": len(rows), "jobs_stored": len(per_key), "errors": sum(r.get("status") == "error"
                                                                          for r in first.values()),
            "lost": lost, "duplicated": duplicated,
            "one_row_each": lost == 0 and duplicated == 0 and set(per_key) <= wanted,
            "statuses": dict(Counter(r.get("status") for r in first.values())),
            "jobs_cpu_s": sum(r["cpu_s"] for r in rows if isinstance(r.get("cpu_s"), (int, float)))}


def time_run(suite, out: Path, *, workers: int | None = None, scheduler: str | None = None,
             progress: bool = True) -> dict:
    """Run ``suite`` into ``out`` (``run_suite``: on ``workers`` local processes, or on the Dask
    cluster at ``scheduler``) and return its measures (the module doc lists them)."""
    from sarcover.benchmarks.harness import run_suite

    cpu0, t0 = tree_cpu_s(), time.monotonic()
    summary = run_suite(suite, out, workers=workers, scheduler=scheduler, progress=progress)
    wall = time.monotonic() - t0
    cpu = tree_cpu_s() - cpu0
    return {"where": f"Dask at {scheduler}" if scheduler else f"{workers} local workers", "wall_s": wall,
            "cpu_s": cpu, "jobs": summary["jobs"], "ran": summary["ran"], "path": str(out),
            **stored_rows(out, [job.key for job in suite.jobs])}


# -- the Dask cluster ----------------------------------------------------------------------------
def dask_command() -> str:
    """The ``dask`` command of this Python environment (beside its interpreter), else on PATH."""
    beside = Path(sys.executable).with_name("dask")
    found = str(beside) if beside.exists() else shutil.which("dask")
    if found is None:
        raise TimingError("the dask command line is not installed (pip install 'dask[distributed]')")
    return found


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


class Cluster:
    """``dask scheduler`` and ``dask worker --nworkers N`` on 127.0.0.1, each in a session of its
    own (Ctrl-C on the terminal reaches this tool only, which stops them). Use as a context
    manager; :meth:`stop` ends every process it started and every process under them."""

    def __init__(self, workers: int, log_path: Path, methods=()):
        self.workers = workers
        self.port = free_port()
        self.address = f"tcp://127.0.0.1:{self.port}"
        self.log = log_path.open("a")
        # the workers import sarcover (and a suite's module:function methods) as this process does
        self.env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
        self.procs: list[subprocess.Popen] = []
        self.seen: dict[int, object] = {}  # pid -> psutil.Process of every process seen under them
        self.methods = list(methods)
        self.start_s = None

    def __enter__(self) -> Cluster:
        try:
            self.start()
        except BaseException:
            self.stop()
            raise
        return self

    def __exit__(self, *exc) -> None:
        self.stop()

    def _spawn(self, args: list[str]) -> subprocess.Popen:
        proc = subprocess.Popen(args, env=self.env, stdin=subprocess.DEVNULL, stdout=self.log,
                                stderr=subprocess.STDOUT, start_new_session=True)
        self.procs.append(proc)
        return proc

    def start(self) -> None:
        """Start the scheduler and the workers, wait for every worker process, and load the
        methods' numba code in each (:func:`~sarcover.benchmarks.dask_backend.warm_up_dask`)."""
        from dask.distributed import Client

        from sarcover.benchmarks.dask_backend import warm_up_dask

        t0 = time.monotonic()
        dask = dask_command()
        self._spawn([dask, "scheduler", "--host", "127.0.0.1", "--port", str(self.port), "--no-dashboard"])
        self._spawn([dask, "worker", self.address, "--nthreads", "1", "--nworkers", str(self.workers),
                     "--memory-limit", "0", "--no-dashboard"])
        deadline = time.monotonic() + START_TIMEOUT_S
        client = None
        while client is None:
            self._check_alive()
            try:
                client = Client(self.address, timeout="5s", set_as_default=False)
            except (OSError, TimeoutError):
                if time.monotonic() > deadline:
                    raise TimingError(f"the Dask scheduler at {self.address} did not start in "
                                      f"{START_TIMEOUT_S:.0f} s (see {self.log.name})") from None
                time.sleep(0.2)
        with client:
            while len(client.scheduler_info(n_workers=-1)["workers"]) < self.workers:
                self._check_alive()
                if time.monotonic() > deadline:
                    raise TimingError(f"{self.workers} Dask worker processes did not come up in "
                                      f"{START_TIMEOUT_S:.0f} s (see {self.log.name})")
                time.sleep(0.2)
            if self.methods:
                warm_up_dask(client, self.methods)
        self.remember()
        self.start_s = time.monotonic() - t0

    def _check_alive(self) -> None:
        for proc in self.procs:
            if proc.poll() is not None:
                raise TimingError(f"{shlex.join(proc.args[:2])} exited with code {proc.returncode} "
                                  f"(see {self.log.name})")

    def remember(self) -> None:
        """Note every process now under the cluster's processes (to make sure they end)."""
        import psutil

        for proc in self.procs:
            try:
                top = psutil.Process(proc.pid)
                for p in [top] + top.children(recursive=True):
                    self.seen.setdefault(p.pid, p)
            except psutil.NoSuchProcess:
                pass

    def worker_pids(self) -> set[int]:
        """The pids of the processes under ``dask worker`` (its worker processes and their children)."""
        import psutil

        try:
            return {p.pid for p in psutil.Process(self.procs[1].pid).children(recursive=True)}
        except (psutil.NoSuchProcess, IndexError):
            return set()

    def stop(self) -> None:
        """SIGTERM each started process's session, SIGKILL what is left after 10 s, and SIGKILL any
        process ever seen under them that still lives (by its psutil handle: never a reused pid).
        A second Ctrl-C or SIGTERM meanwhile waits until they are stopped."""
        with _deferred_signals():
            self._stop()

    def _stop(self) -> None:
        import psutil

        self.remember()
        for proc in reversed(self.procs):
            if proc.poll() is None:
                try:
                    os.killpg(proc.pid, signal.SIGTERM)
                except ProcessLookupError:
                    pass
        for proc in reversed(self.procs):
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(5)
        alive = [p for p in self.seen.values() if _alive(p)]
        for p in alive:
            try:
                p.kill()
            except psutil.NoSuchProcess:
                pass
        psutil.wait_procs(alive, timeout=5)
        self.log.close()


def _alive(proc) -> bool:
    """Whether the psutil handle ``proc`` is a running process (not a zombie awaiting its parent)."""
    import psutil

    try:
        return proc.is_running() and proc.status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


class _deferred_signals:
    """Hold SIGINT and SIGTERM until the block ends (then raise KeyboardInterrupt if one came):
    cleanup that a second Ctrl-C cut short would leave processes behind. Main thread only."""

    def __enter__(self):
        self.came = False
        self.saved = {}
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self.saved[sig] = signal.signal(sig, self._note)
        return self

    def _note(self, signum, frame):
        self.came = True

    def __exit__(self, exc_type, *exc):
        for sig, handler in self.saved.items():
            signal.signal(sig, handler)
        if self.came and exc_type is None:
            raise KeyboardInterrupt


class Killer(threading.Thread):
    """Once ``after`` seconds have passed, SIGKILL one Dask worker process of ``cluster`` that is
    running a job (waiting for one if none is); ``record`` then says which, when and running what.
    :meth:`finish` ends the wait when the run ends first (``record`` stays None)."""

    def __init__(self, cluster: Cluster, after: float):
        super().__init__(daemon=True, name="cluster-timing-killer")
        from dask.distributed import Client

        self.cluster, self.after = cluster, after
        self.client = Client(cluster.address, timeout="30s", set_as_default=False)
        self.done = threading.Event()
        self.record: dict | None = None
        self.error: str | None = None
        self.t0 = time.monotonic()

    def run(self) -> None:
        try:
            if self.done.wait(self.after):
                return
            while not self.done.is_set():
                if self._kill_one():
                    return
                self.done.wait(0.1)
        except Exception as exc:  # noqa: BLE001 - said in the record; the run goes on
            self.error = f"{type(exc).__name__}: {exc}"

    def _kill_one(self) -> bool:
        busy = {address: tasks for address, tasks in self.client.processing().items() if tasks}
        if not busy:
            return False
        pids = self.client.run(os.getpid, workers=list(busy), on_error="return")
        ours = self.cluster.worker_pids()
        for address, tasks in busy.items():
            pid = pids.get(address)
            if isinstance(pid, int) and pid in ours:  # a process of our `dask worker`, never another one
                below = _below(pid)  # its job child: dies with it, but nobody reaps it into the tree
                os.kill(pid, signal.SIGKILL)
                self.record = {"at_s": time.monotonic() - self.t0, "pid": pid, "worker": address,
                               "tasks": len(tasks), "orphaned_cpu_s": sum(_cpu_s(p) for p in below)}
                log.info("killed Dask worker process %d at %.1f s (it held %d task%s)", pid,
                         self.record["at_s"], len(tasks), "" if len(tasks) == 1 else "s")
                return True
        return False

    def finish(self) -> None:
        self.done.set()
        self.join(30)
        self.client.close()


def time_dask_run(suite, out: Path, *, workers: int, kill_after: float | None = None,
                  progress: bool = True) -> dict:
    """:func:`time_run` on a fresh Dask cluster of ``workers`` processes, stopped afterwards; with
    ``kill_after``, one worker process is SIGKILLed mid-job once that many seconds have passed."""
    out.mkdir(parents=True, exist_ok=True)
    with Cluster(workers, out / CLUSTER_LOG, suite.methods) as cluster:
        killer = Killer(cluster, kill_after) if kill_after is not None else None
        try:
            if killer is not None:
                killer.start()
            result = time_run(suite, out, scheduler=cluster.address, progress=progress)
        finally:
            if killer is not None:
                killer.finish()
        cluster.remember()
    result.update(cluster_start_s=cluster.start_s, scheduler=cluster.address, pids=sorted(cluster.seen))
    if killer is not None:
        result["kill"] = killer.record
        if killer.record:  # the killed worker's job child: the kill reparents it, so the tree lost it
            result["cpu_s"] += killer.record["orphaned_cpu_s"]
        if killer.error:
            result["kill_error"] = killer.error
    return result


# -- the measurement -----------------------------------------------------------------------------
def run_names(workers: int, kill: bool) -> list[str]:
    """The runs, in order: ``local-1``, ``local-N``, ``dask-N`` and (with a kill) ``dask-N-killed``."""
    return ["local-1", f"local-{workers}", f"dask-{workers}"] + ([f"dask-{workers}-killed"] if kill else [])


def ratio(a: float | None, b: float | None) -> float | None:
    return a / b if a is not None and b else None


def summarize(timing: dict) -> dict:
    """The ratios and the killed run's cost from ``timing["runs"]`` (None where a run is missing)."""
    n = timing["workers"]
    runs = timing["runs"]
    wall = {name: run.get("wall_s") for name, run in runs.items()}
    out = {f"local_{n}_over_local_1": ratio(wall.get(f"local-{n}"), wall.get("local-1")),
           f"dask_{n}_over_local_{n}": ratio(wall.get(f"dask-{n}"), wall.get(f"local-{n}"))}
    killed = runs.get(f"dask-{n}-killed")
    if killed is not None and wall.get(f"dask-{n}") is not None:
        out["killed"] = {"extra_wall_s": killed["wall_s"] - wall[f"dask-{n}"],
                         "extra_cpu_s": killed["cpu_s"] - runs[f"dask-{n}"]["cpu_s"],
                         "lost": killed["lost"], "duplicated": killed["duplicated"],
                         "errors": killed["errors"], "kill": killed.get("kill")}
    return out


def _num(x, fmt: str = ".1f") -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


def table(timing: dict) -> str:
    """The Markdown table of the runs, then the ratios and the killed run's cost."""
    lines = [f"suite {timing['suite']}: {timing['jobs']} jobs; numba warm-up {_num(timing.get('warm_up_s'))} s "
             "(before the runs)", "",
             "| run | wall s | CPU s | jobs' CPU s | rows | errors | lost | duplicated | one row each |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---|"]
    for name, r in timing["runs"].items():
        label = name + (f" (cluster start {r['cluster_start_s']:.1f} s)" if r.get("cluster_start_s") else "")
        lines.append(f"| {label} | {_num(r['wall_s'])} | {_num(r['cpu_s'])} | {_num(r['jobs_cpu_s'])} | "
                     f"{r['rows']} | {r['errors']} | {r['lost']} | {r['duplicated']} | "
                     f"{'yes' if r['one_row_each'] else 'NO'} |")
    s, n = timing["summary"], timing["workers"]
    lines += ["", f"- wall time local-{n} / local-1: {_num(s[f'local_{n}_over_local_1'], '.2f')}",
              f"- wall time dask-{n} / local-{n}: {_num(s[f'dask_{n}_over_local_{n}'], '.2f')}"]
    if "killed" in s:
        k = s["killed"]
        what = (f"worker process {k['kill']['pid']} SIGKILLed at {k['kill']['at_s']:.1f} s" if k["kill"]
                else "none killed: the run ended first, or the kill failed")
        lines.append(f"- killed worker ({what}): {k['extra_wall_s']:+.1f} s wall and {k['extra_cpu_s']:+.1f} s "
                     f"CPU against dask-{n}; {k['lost']} jobs lost, {k['duplicated']} rows duplicated, "
                     f"{k['errors']} errors")
    return "\n".join(lines)


def _write(outdir: Path, timing: dict) -> None:
    timing["summary"] = summarize(timing)
    tmp = outdir / (TIMING_FILE + ".tmp")
    tmp.write_text(json.dumps(timing, indent=1) + "\n")
    tmp.replace(outdir / TIMING_FILE)


def measure(suite, outdir: Path, *, workers: int = 2, kill_after: float | None = None,
            progress: bool = True) -> dict:
    """Run ``suite`` as the module doc says into subfolders of ``outdir``; return the timing dict
    (also in ``outdir/timing.json``, rewritten after each run)."""
    from sarcover.benchmarks.harness import warm_up_methods
    from sarcover.benchmarks.provenance import environment
    from sarcover.benchmarks.rows import now

    if workers < 2:
        raise TimingError("--workers must be at least 2 (the runs compare 1 local worker with N)")
    names = run_names(workers, kill_after is not None)
    for name in names:
        if (outdir / name).exists():
            raise TimingError(f"{outdir / name} exists: give another -o (each run starts from an empty folder)")
    outdir.mkdir(parents=True, exist_ok=True)
    t = time.monotonic()
    warm_up_methods(suite.methods, sys.stderr if progress else None)
    timing = {"suite": suite.name, "jobs": len(suite.jobs), "methods": suite.methods, "workers": workers,
              "kill_after_s": kill_after, "warm_up_s": time.monotonic() - t, "started_at": now(),
              "command": shlex.join(sys.argv), "interrupted": False, "runs": {}, **environment()}
    try:
        for name in names:
            log.info("%s ...", name)
            if name.startswith("local-"):
                result = time_run(suite, outdir / name, workers=int(name.split("-")[1]), progress=progress)
            else:
                result = time_dask_run(suite, outdir / name, workers=workers, progress=progress,
                                       kill_after=kill_after if name.endswith("-killed") else None)
            timing["runs"][name] = result
            log.info("%s: %.1f s wall, %d rows", name, result["wall_s"], result["rows"])
            _write(outdir, timing)
    except BaseException:
        timing["interrupted"] = True
        _write(outdir, timing)
        raise
    timing["finished_at"] = now()
    _write(outdir, timing)
    return timing


# -- command line --------------------------------------------------------------------------------
class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2, no usage dump
        raise TimingError(message)


def build_parser() -> argparse.ArgumentParser:
    from sarcover.benchmarks.cli import int_at_least, method_list, positive_float

    p = _Parser(prog=PROG, description="Time a suite on 1 local worker, N local workers and an N-process Dask "
                "cluster started here, optionally with a Dask worker killed mid-run; write OUTDIR/timing.json "
                "and print a Markdown table.")
    p.add_argument("suite", help="built-in suite name or suite TOML file")
    p.add_argument("-o", "--output", required=True, help="folder for the runs' results and timing.json")
    p.add_argument("--runs", type=int_at_least(1), help="random instances per setting (replaces the suite's runs)")
    p.add_argument("--methods", type=method_list, help="run only these of the suite's methods, comma-separated")
    p.add_argument("--workers", type=int_at_least(1), default=2, help="N: local and Dask worker processes "
                   "(default 2)")
    p.add_argument("--kill-after", type=positive_float, metavar="SECONDS", help="also run on Dask with one "
                   "worker process SIGKILLed mid-job once SECONDS have passed")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bars, warnings only")
    return p


def main(argv: list[str] | None = None) -> int:
    from sarcover.benchmarks.cli import setup_logging, sigterm_as_interrupt

    try:
        args = build_parser().parse_args(argv)
        setup_logging(quiet=args.quiet)
        from sarcover.benchmarks.suite import load_suite

        suite = load_suite(args.suite, runs=args.runs, methods=args.methods)
        dask_command()  # no dask: say so before any run
        with sigterm_as_interrupt():  # SIGTERM stops the cluster too
            timing = measure(suite, Path(args.output), workers=args.workers, kill_after=args.kill_after,
                             progress=not args.quiet)
    except SarcoverError as exc:  # HarnessError and SuiteError too
        print(f"cluster_timing: error: {' '.join(str(exc).splitlines())}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("cluster_timing: interrupted (every cluster process it started is stopped)", file=sys.stderr)
        return EXIT_INTERRUPTED
    except SystemExit as exc:  # --help
        return exc.code if isinstance(exc.code, int) else EXIT_OK
    print(table(timing), flush=True)
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
