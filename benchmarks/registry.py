"""The method registry: every method's entry point, one line each in :data:`METHODS`.

A method is a function with one signature::

    method(instance: TOPInstance, *, seed: int, time_limit: float | None) -> Result

Where a method's code lives follows one rule: ``formulations/`` holds the problem and the exact
methods (a model handed to a solver that proves bounds: the Pyomo MILP on HiGHS, CP-SAT,
branch-and-price on HiGHS); ``heuristics/`` holds every method that proves nothing, ours (greedy,
the paper's cluster-then-route pipelines) and the peers built on a library's heuristic search
(OR-Tools routing, PyVRP). This module composes them: the exact methods start from greedy's plan
(:func:`warm_started`, written once for all three), and bp also gets PyVRP as its primal
heuristic, which ``formulations`` may not import.

Each entry point imports its code on first call (the import line names it), so listing the
methods or running a heuristic does not import every solver library. :func:`run_method` is the
only way results are counted: it never raises, and it hands the method's result to
:func:`~sarcover.formulations.result.verified_result`, which re-verifies every plan.
"""

from __future__ import annotations

import importlib
import time
import traceback
from dataclasses import dataclass
from typing import Callable

from sarcover.formulations.errors import SarcoverError
from sarcover.formulations.history import shifted
from sarcover.formulations.instance import TOPInstance, precheck
from sarcover.formulations.limits import MAX_NODES, MAX_VEHICLES, too_large
from sarcover.formulations.result import Result, Termination, VerifiedResult, verified_result


# -- composition shared by the exact methods -------------------------------------------------------
def warm_started(solve: Callable[..., Result], instance: TOPInstance, *, seed: int,
                 time_limit: float | None, **options) -> Result:
    """``solve`` started from greedy's plan (when greedy finds one), within the same time limit.

    Greedy costs milliseconds; its plan becomes the solver's ``warm_start`` (MIP start, CP-SAT
    hint, bp's first columns and incumbent), so a run the limit stops still returns a plan that
    covers every group whenever greedy found one. The solver gets what greedy left of the limit;
    the returned runtime and the anytime history count from this call, greedy included.
    """
    from sarcover.heuristics.greedy import greedy

    t0 = time.perf_counter()
    plan = greedy(instance, seed=seed).plan
    spent = time.perf_counter() - t0
    left = None if time_limit is None else max(time_limit - spent, 0.01)
    result = solve(instance, seed=seed, time_limit=left, warm_start=plan, **options)
    result.runtime_s = time.perf_counter() - t0
    if "history" in result.info:
        result.info["history"] = shifted(result.info["history"], spent)
    result.info["warm_start_prize"] = (float(sum(instance.prizes[v] for v in plan.visited))
                                       if plan is not None else None)
    return result


# -- entry points ----------------------------------------------------------------------------------
def greedy(instance, *, seed=0, time_limit=None) -> Result:
    from sarcover.heuristics.greedy import greedy

    return greedy(instance, seed=seed, time_limit=time_limit)


def paper_pipeline(clusterer: str, router: str) -> Callable[..., Result]:
    """The paper's method family: ``clusterer`` clusters, ``router`` tours, energy repair."""

    def run(instance, *, seed=0, time_limit=None) -> Result:
        from sarcover.heuristics.pipeline import cluster_then_route

        return cluster_then_route(instance, clusterer, router, seed=seed, time_limit=time_limit)

    run.__name__ = run.__qualname__ = f"{clusterer}_{router}"
    return run


def routing(instance, *, seed=0, time_limit=60.0) -> Result:
    from sarcover.heuristics.ortools_routing import routing

    return routing(instance, seed=seed, time_limit=time_limit)


def pyvrp(instance, *, seed=0, time_limit=60.0) -> Result:
    from sarcover.heuristics.pyvrp_ils import pyvrp

    return pyvrp(instance, seed=seed, time_limit=time_limit)


def milp(instance, *, seed=0, time_limit=60.0) -> Result:
    from sarcover.formulations.milp import solve_milp

    return warm_started(solve_milp, instance, seed=seed, time_limit=time_limit, threads=1)


def cpsat(instance, *, seed=0, time_limit=60.0) -> Result:
    from sarcover.formulations.cpsat import solve_cpsat

    return warm_started(solve_cpsat, instance, seed=seed, time_limit=time_limit, threads=1)


def bp(instance, *, seed=0, time_limit=60.0) -> Result:
    from sarcover.formulations.bp import BPOptions, solve_bp
    from sarcover.formulations.bp import warm_up
    from sarcover.heuristics.pyvrp_ils import primal_routes

    warm_up()  # numba compilation (or loading it from the disk cache) is not the method's time
    # options from the user's limit (cuts on from 60 s), not from what greedy leaves of it
    return warm_started(solve_bp, instance, seed=seed, time_limit=time_limit,
                        options=BPOptions.for_time_limit(time_limit), primal=primal_routes(instance, seed))


# numba code compiled before a benchmark's workers start (see :func:`warm_up`)
def compile_routers() -> None:
    from sarcover.heuristics.pipeline import warm_up

    warm_up()


def compile_bp() -> None:
    from sarcover.formulations.bp import warm_up

    warm_up()


# -- the registry ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class Method:
    name: str
    run: Callable[..., Result]
    exact: bool  # True if the method can prove optimality (returns bounds)
    summary: str
    # compiles the method's numba code (or loads it from numba's disk cache), so that a
    # benchmark does not charge the compilation to the method's first job
    warm_up: Callable[[], None] | None = None
    # the largest instance the method holds within a benchmark worker's default memory
    # (formulations/limits.py; docs/limits.md says how each limit was chosen)
    max_nodes: int = MAX_NODES
    max_vehicles: int = MAX_VEHICLES


# Node limits of the methods whose models outgrow the instance's dense matrices: the MILP's and
# CP-SAT's arc variables and constraints, PyVRP's cover copy of every node, OR-Tools' routing model,
# and the paper's pipelines (their clustering and energy repair grow faster than V²).
PAPER_MAX_NODES = 2000
MILP_MAX_NODES = 1000
CPSAT_MAX_NODES = 800
PYVRP_MAX_NODES = 2000
ROUTING_MAX_NODES = 3000

METHODS: dict[str, Method] = {m.name: m for m in [
    Method("greedy", greedy, False, "cheapest insertion by prize per energy, groups first (floor baseline)"),
    Method("adpc-pso", paper_pipeline("adpc", "pso"), False,
           "the paper's: ADPC clusters, random-key PSO tours (+2-opt), energy repair and refill",
           compile_routers, max_nodes=PAPER_MAX_NODES),
    Method("dpc-pso", paper_pipeline("dpc", "pso"), False,
           "DPC clusters, random-key PSO tours (+2-opt), energy repair and refill",
           compile_routers, max_nodes=PAPER_MAX_NODES),
    Method("kmeans-pso", paper_pipeline("kmeans", "pso"), False,
           "scikit-learn KMeans clusters, random-key PSO tours (+2-opt), energy repair and refill",
           compile_routers, max_nodes=PAPER_MAX_NODES),
    Method("adpc-ga", paper_pipeline("adpc", "ga"), False,
           "ADPC clusters, GA tours (OX, inversion, elitism; +2-opt), energy repair and refill",
           compile_routers, max_nodes=PAPER_MAX_NODES),
    Method("adpc-aco", paper_pipeline("adpc", "aco"), False,
           "ADPC clusters, elitist ant system tours (+2-opt), energy repair and refill",
           compile_routers, max_nodes=PAPER_MAX_NODES),
    Method("cpsat", cpsat, True,
           "CP-SAT routes constraint + energy flow, greedy hint, 1 thread; optimal only if proven unscaled",
           max_nodes=CPSAT_MAX_NODES),
    Method("routing", routing, False,
           "OR-Tools routing, prize disjunctions + energy dimension, guided local search, <=10 s",
           max_nodes=ROUTING_MAX_NODES),
    Method("pyvrp", pyvrp, False,
           "PyVRP iterated local search, optional clients with prizes, max distance = energy, 2000 its",
           max_nodes=PYVRP_MAX_NODES),
    Method("milp", milp, True,
           "time-flow TOP MILP on HiGHS via Pyomo: pruned arcs, cliques, path + connectivity cuts, 1 thread, gap 0",
           max_nodes=MILP_MAX_NODES),
    Method("bp", bp, True,
           "branch-and-price: route master on HiGHS, ng-route labelling pricing (numba), greedy's routes "
           "as first columns, PyVRP as primal heuristic when the root leaves the proof open, 1 thread",
           compile_bp),
]}


class UnknownMethodError(SarcoverError):
    def __init__(self, name: str):
        super().__init__(f"unknown method {name!r}; known: {', '.join(METHODS)}")


def get_method(name: str) -> Method:
    """The registered method ``name``, or an ad hoc one named ``"module:function"``.

    Ad hoc methods (as a suite may name them) are imported on each call and never added to
    :data:`METHODS`, so listing the registry always shows the built-in methods only.
    """
    try:
        return METHODS[name]
    except KeyError:
        if ":" not in name:
            raise UnknownMethodError(name) from None
    module, func = name.split(":", 1)
    try:
        run = getattr(importlib.import_module(module), func)
    except (ImportError, AttributeError, ValueError) as exc:
        raise SarcoverError(f"method {name!r}: cannot import {func!r} from {module!r} ({exc})") from None
    return Method(name, run, False, "ad hoc (named by a suite)")


def check_size(method: Method | str, n_nodes: int, n_vehicles: int) -> None:
    """Raise :class:`~sarcover.formulations.limits.TooLargeError` for an instance of more nodes
    or vehicles than ``method`` holds in memory (its ``max_nodes``, ``max_vehicles``)."""
    spec = method if isinstance(method, Method) else get_method(method)
    if n_nodes > spec.max_nodes:
        raise too_large(f"{n_nodes} nodes", spec.max_nodes, "nodes", holder=spec.name)
    if n_vehicles > spec.max_vehicles:
        raise too_large(f"{n_vehicles} vehicles", spec.max_vehicles, "vehicles", holder=spec.name)


def warm_up(names) -> list[str]:
    """Run the warm-up hook of each named method once per process (each hook once, however many
    methods share it); return the names of the hooks run now. A failing hook is skipped: the
    method's own run then reports the problem in its row. Forked benchmark workers inherit the
    compiled code."""
    ran = []
    for name in names:
        hook = METHODS[name].warm_up if name in METHODS else None
        if hook is None or hook in _WARMED:
            continue
        _WARMED.add(hook)
        try:
            hook()
        except Exception:  # noqa: BLE001 - the job itself will say what is wrong
            continue
        ran.append(hook.__name__)
    return ran


_WARMED: set = set()


def run_method(name: str, instance: TOPInstance, *, seed: int = 0, time_limit: float | None = 60.0
               ) -> VerifiedResult:
    """Run a method and return its verified result. Never raises.

    The pre-check's infeasibility proof, a failing method, a plan the verifier rejects, or a bound
    below the verified objective all come back as a result with the reason; the objective is
    always the verifier's, never the method's own claim.
    """
    t0 = time.perf_counter()
    try:
        spec = get_method(name)
        check_size(spec, instance.n_nodes, instance.n_vehicles)  # before the method allocates it
    except Exception as exc:  # noqa: BLE001 - unknown method, or beyond the method's memory limits
        return VerifiedResult.failed(name, Termination.ERROR, f"{type(exc).__name__}: {exc}",
                                     time.perf_counter() - t0)
    reason = precheck(instance)
    if reason is not None:
        return VerifiedResult.failed(name, Termination.INFEASIBLE, reason, time.perf_counter() - t0)
    try:
        result = spec.run(instance, seed=seed, time_limit=time_limit)
    except Exception as exc:  # a method bug must not stop a benchmark
        tb = traceback.format_exc(limit=-3).strip().splitlines()
        return VerifiedResult.failed(name, Termination.ERROR, f"{type(exc).__name__}: {exc}",
                                     time.perf_counter() - t0, info={"traceback": tb})
    return verified_result(instance, result, method=name, runtime_s=time.perf_counter() - t0)
