"""The method registry: every solver and heuristic, one signature, one front door.

A method is a picklable module-level function::

    method(instance: TOPInstance, *, seed: int, time_limit: float) -> Result

Entries name their function as ``"module:function"`` and are imported on first use, so that
listing methods (or running a heuristic) does not pay for importing every solver library.
:func:`run_method` is the only way results are counted: it never raises, and it re-verifies
every plan with the independent verifier.
"""

from __future__ import annotations

import importlib
import time
import traceback
from dataclasses import dataclass
from typing import Callable

from sarcover.formulations.errors import SarcoverError
from sarcover.formulations.instance import TOPInstance, precheck
from sarcover.formulations.plan import Result, Status
from sarcover.formulations.verify import VerificationReport, verify


@dataclass(frozen=True)
class MethodSpec:
    name: str
    target: str  # "package.module:function"
    exact: bool  # True if the method can prove optimality (returns bounds)
    summary: str
    # "module:function" that compiles the method's numba code (or loads it from numba's disk
    # cache), so that a benchmark does not charge the compilation to the method's first job
    warm_up: str | None = None

    def load(self) -> Callable[..., Result]:
        return _resolve(self.target)


def _resolve(target: str) -> Callable:
    module, func = target.split(":")
    return getattr(importlib.import_module(module), func)


_ROUTERS_JIT = "sarcover.heuristics.pipeline:warm_up"  # the PSO, GA and ACO kernels

_SPECS = [
    MethodSpec("greedy", "sarcover.heuristics.greedy:greedy", False,
               "cheapest insertion by prize per energy, groups first (floor baseline)"),
    MethodSpec("adpc-pso", "sarcover.heuristics.pipeline:adpc_pso", False,
               "the paper's: ADPC clusters, random-key PSO tours (+2-opt), energy repair and refill",
               _ROUTERS_JIT),
    MethodSpec("dpc-pso", "sarcover.heuristics.pipeline:dpc_pso", False,
               "DPC clusters, random-key PSO tours (+2-opt), energy repair and refill", _ROUTERS_JIT),
    MethodSpec("kmeans-pso", "sarcover.heuristics.pipeline:kmeans_pso", False,
               "scikit-learn KMeans clusters, random-key PSO tours (+2-opt), energy repair and refill",
               _ROUTERS_JIT),
    MethodSpec("adpc-ga", "sarcover.heuristics.pipeline:adpc_ga", False,
               "ADPC clusters, GA tours (OX, inversion, elitism; +2-opt), energy repair and refill",
               _ROUTERS_JIT),
    MethodSpec("adpc-aco", "sarcover.heuristics.pipeline:adpc_aco", False,
               "ADPC clusters, elitist ant system tours (+2-opt), energy repair and refill",
               _ROUTERS_JIT),
    MethodSpec("cpsat", "sarcover.heuristics.cpsat_warm:cpsat", True,
               "CP-SAT routes constraint + energy flow, greedy hint, 1 thread; optimal only if proven unscaled"),
    MethodSpec("routing", "sarcover.heuristics.routing_method:routing", False,
               "OR-Tools routing, prize disjunctions + energy dimension, guided local search, <=10 s"),
    MethodSpec("pyvrp", "sarcover.heuristics.pyvrp_method:pyvrp", False,
               "PyVRP iterated local search, optional clients with prizes, max distance = energy, 2000 its"),
    MethodSpec("milp", "sarcover.heuristics.milp_warm:milp", True,
               "time-flow TOP MILP on HiGHS via Pyomo: pruned arcs, cliques, path + connectivity cuts, 1 thread, gap 0"),
    MethodSpec("bp", "sarcover.heuristics.bp_warm:bp", True,
               "branch-and-price: route master on HiGHS, ng-route labelling pricing (numba), greedy's routes "
               "as first columns, PyVRP as primal heuristic once the root leaves the proof open, 1 thread",
               "sarcover.formulations.bp.pricing:warm_up"),
]

METHODS: dict[str, MethodSpec] = {spec.name: spec for spec in _SPECS}


class UnknownMethodError(SarcoverError):
    def __init__(self, name: str):
        super().__init__(f"unknown method {name!r}; known: {', '.join(METHODS)}")


def warm_up(names) -> list[str]:
    """Run the warm-up hook of each named method once per process (each hook once, however many
    methods share it); return the hooks run now. A failing hook is skipped: the method's own
    run then reports the problem in its row. Forked benchmark workers inherit the compiled code."""
    ran = []
    for name in names:
        try:
            target = get_method(name).warm_up
        except UnknownMethodError:
            continue
        if target is None or target in _WARMED:
            continue
        _WARMED.add(target)
        try:
            _resolve(target)()
        except Exception:  # noqa: BLE001 - the job itself will say what is wrong
            continue
        ran.append(target)
    return ran


_WARMED: set[str] = set()


def get_method(name: str) -> MethodSpec:
    """The registered method ``name``, or an ad hoc one named ``"module:function"``.

    Ad hoc methods (as a suite may name them) are resolved on each call and never added to
    :data:`METHODS`, so listing the registry always shows the built-in methods only.
    """
    try:
        return METHODS[name]
    except KeyError:
        if ":" in name:
            return MethodSpec(name, name, False, "ad hoc (named by a suite)")
        raise UnknownMethodError(name) from None


def run_method(
    name: str, instance: TOPInstance, *, seed: int = 0, time_limit: float = 60.0
) -> tuple[Result, VerificationReport | None]:
    """Run a registered method, verify its plan, and return (result, verifier report).

    Never raises. A failing method, a plan the verifier rejects, or a bound below the verified
    objective all come back as status ERROR with the reason. The objective is always the
    verifier's, never the method's own claim.
    """
    spec = get_method(name)
    t0 = time.perf_counter()
    reason = precheck(instance)
    if reason is not None:
        return Result(name, Status.INFEASIBLE, reason=reason, runtime_s=time.perf_counter() - t0), None
    try:
        result = spec.load()(instance, seed=seed, time_limit=time_limit)
    except Exception as exc:  # a method bug must not stop a benchmark
        tb = traceback.format_exc(limit=-3).strip().splitlines()
        return Result(
            name, Status.ERROR, reason=f"{type(exc).__name__}: {exc}",
            runtime_s=time.perf_counter() - t0, info={"traceback": tb},
        ), None
    result.method = name
    if result.runtime_s <= 0.0:
        result.runtime_s = time.perf_counter() - t0
    report = None
    if result.plan is not None:
        report = verify(instance, result.plan)
        if not report.valid:
            result.info["claimed_status"] = str(result.status)
            result.status = Status.ERROR
            result.reason = "verifier rejected the plan: " + "; ".join(report.violations[:5])
            result.objective = None
            return result, report
        result.objective = report.prize
    elif result.status in (Status.OPTIMAL, Status.FEASIBLE):
        result.info["claimed_status"] = str(result.status)
        result.status = Status.ERROR
        result.reason = f"status {result.info['claimed_status']} without a plan"
    if result.bound is not None and result.objective is not None:
        if result.bound < result.objective - 1e-6 * max(1.0, abs(result.objective)):
            result.info["claimed_status"] = str(result.status)
            result.status = Status.ERROR
            result.reason = f"bound {result.bound:g} below verified objective {result.objective:g}"
    if result.status == Status.OPTIMAL and result.bound is None:
        result.bound = result.objective
    return result, report


def result_record(result: Result, report: VerificationReport | None, instance: TOPInstance) -> dict:
    """Flat JSON-ready record of a run (the CLI's --json output and the harness row)."""
    routes = [list(r) for r in result.plan.routes] if result.plan is not None else None
    total = instance.total_prize
    return {
        "instance": instance.name,
        "method": result.method,
        "exact": get_method(result.method).exact if result.method in METHODS else None,
        "status": str(result.status),
        "objective": result.objective,
        "bound": result.bound,
        "coverage": (result.objective / total if total > 0 else 0.0) if result.objective is not None else None,
        "covered": report.covered if report is not None and report.valid else None,
        "routes": routes,
        "energy": report.energy if report is not None else None,
        "e_max": instance.budget,
        "runtime_s": result.runtime_s,
        "valid": bool(report is not None and report.valid),
        "reason": result.reason,
        "info": {k: v for k, v in result.info.items() if k != "traceback"},
    }
