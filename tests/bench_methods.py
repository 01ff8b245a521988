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
    return Result("all", Termination.OPTIMAL, Plan.of([list(range(instance.n_nodes))] + [[]] * (instance.n_vehicles - 1)),
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
