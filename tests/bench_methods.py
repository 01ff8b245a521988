"""Test-only methods a suite names as "bench_methods:NAME" (module-level, importable by workers)."""

import os
import time

from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Result, Termination


def crash(instance, *, seed=0, time_limit=None):
    """Raises: the harness must record an error row and go on."""
    raise RuntimeError("boom")


def die(instance, *, seed=0, time_limit=None):
    """Kills its own process, as a segfault would."""
    os._exit(3)


def hang(instance, *, seed=0, time_limit=None):
    """Ignores its time limit forever: the harness must kill it."""
    while True:
        time.sleep(0.05)


def slow_all(instance, *, seed=0, time_limit=None):
    """Sleeps 0.3 s, then visits every node in one route (for kill/resume tests)."""
    time.sleep(0.3)
    return all_optimal(instance)


def all_optimal(instance, *, seed=0, time_limit=None):
    """Every node on vehicle 1, claimed optimal with bound = total prize (tiny easy instances)."""
    routes = [list(range(instance.n_nodes))] + [[]] * (instance.n_vehicles - 1)
    return Result("all", Termination.OPTIMAL, Plan.of(routes),
                  bound=float(instance.total_prize))


def all_but_last(instance, *, seed=0, time_limit=None):
    """Every node but the last on vehicle 1 (9 of 10 on a 10-node unit-prize instance)."""
    return Result("most", Termination.COMPLETED,
                  Plan.of([list(range(instance.n_nodes - 1))] + [[]] * (instance.n_vehicles - 1)))


def hog(instance, *, seed=0, time_limit=None):
    """Allocates 3 GB at once: under the suite's memory_mb limit this is a MemoryError."""
    block = bytearray(3 * 1024**3)
    return Result("hog", Termination.COMPLETED, reason=str(len(block)))


def nap(instance, *, seed=0, time_limit=None):
    """Sleeps 2 s whatever its time limit (a finite hang, for the Dask soft deadline)."""
    time.sleep(2.0)
    return all_optimal(instance)


def interrupted(instance, *, seed=0, time_limit=None):
    """Dies by SIGINT, as a worker does when Ctrl-C reaches it inside a solver that re-arms SIGINT."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_DFL)
    os.kill(os.getpid(), signal.SIGINT)
    time.sleep(5.0)


def marked(instance, *, seed=0, time_limit=None):
    """Leaves a mark (a file named instance.pid in $SARCOVER_TEST_MARKS) as it starts, sleeps 1.5 s,
    then visits every node: a test can see which worker process runs which job, and kill it mid-job."""
    from pathlib import Path

    (Path(os.environ["SARCOVER_TEST_MARKS"]) / f"{instance.name}.{os.getpid()}").touch()
    time.sleep(1.5)
    return all_optimal(instance)


def spin(instance, *, seed=0, time_limit=None):
    """Burns CPU in pure Python (holding the GIL) forever, after leaving a mark named by its pid."""
    from pathlib import Path

    marks = os.environ.get("SARCOVER_TEST_MARKS")
    if marks:
        (Path(marks) / f"spin.{os.getpid()}").touch()
    x = 0
    while True:
        x += 1


def measured(instance, *, seed=0, time_limit=None):
    """0.5 s of pure-Python CPU work; its info says how much CPU other threads of its process took
    meanwhile (a job left running beside it shows up there)."""
    wall, cpu, proc = time.perf_counter(), time.thread_time(), time.process_time()
    x = 0
    while time.thread_time() - cpu < 0.5:
        x += 1
    result = all_optimal(instance)
    result.info["other_threads_cpu_s"] = (time.process_time() - proc) - (time.thread_time() - cpu)
    result.info["own_wall_s"] = time.perf_counter() - wall
    return result


def kill_parent(instance, *, seed=0, time_limit=None):
    """SIGKILLs its parent process (on Dask: the worker process the job's child belongs to)."""
    import signal

    os.kill(os.getppid(), signal.SIGKILL)
    time.sleep(5.0)


def chatter(instance, *, seed=0, time_limit=None):
    """Prints on stdout and stderr, then exits its process with code 5."""
    import sys

    print("chatter on stdout", flush=True)
    print("last words on stderr", file=sys.stderr, flush=True)
    os._exit(5)
