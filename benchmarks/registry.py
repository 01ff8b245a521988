"""The method registry: every method by name, with its entry point and limits, and
:func:`run_method`, the only way results are counted.

A method is a function with one signature (the contract, docs/methods.md)::

    method(instance: TOPInstance, *, seed: int, time_limit: float | None, **params) -> Result

Where a method's code lives follows one rule: ``formulations/`` holds the problem and the exact
methods (a model handed to a solver that proves bounds: the Pyomo MILP on HiGHS, CP-SAT,
branch-and-price on HiGHS); ``heuristics/`` holds every method that proves nothing, ours (greedy,
the paper's cluster-then-route pipelines) and the peers built on a library's heuristic search
(OR-Tools routing, PyVRP). :mod:`sarcover.benchmarks.methods` composes each registered method in
one function, with its parameters dataclass.

Three kinds of name reach a method: a registered one (:data:`METHODS`), one an installed package
registers through the entry-point group ``sarcover.methods`` (:func:`plugins`), and an ad hoc
``"module:function"``. Any of them may carry fixed parameters as a variant,
``adpc-pso[iterations=300]`` (:mod:`sarcover.benchmarks.params`).

:func:`run_method` never raises. Once per call, before the method's clock starts, it resolves
the parameters, checks the instance's size against the method's limits, runs the
:func:`~sarcover.formulations.instance.precheck` and the method's numba warm-up; then it runs
the method and hands its result to :func:`~sarcover.formulations.result.verified_result`,
which re-verifies every plan.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import time
import traceback
from dataclasses import dataclass, field, replace
from typing import Callable

from sarcover.benchmarks import methods as m
from sarcover.benchmarks.params import (
    params_class,
    resolve,
    split_variant,
    variant_name,
)
from sarcover.formulations.errors import SarcoverError
from sarcover.formulations.instance import TOPInstance, precheck
from sarcover.formulations.limits import MAX_NODES, MAX_VEHICLES, too_large
from sarcover.formulations.result import (
    Result,
    Termination,
    VerifiedResult,
    verified_result,
)

DEFAULT_TIME_LIMIT = m.DEFAULT_TIME_LIMIT
ENTRY_POINTS = "sarcover.methods"  # the entry-point group through which packages register methods


# -- the registry ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class Method:
    name: str
    run: Callable[..., Result]
    exact: bool  # True if the method can prove optimality (returns bounds)
    summary: str
    # compiles the method's numba code (or loads it from numba's disk cache), so that neither a
    # benchmark's first job nor a solve charges the compilation to the method's time
    warm_up: Callable[[], None] | None = None
    # the largest instance the method holds within a benchmark worker's default memory
    # (formulations/limits.py; docs/limits.md says how each limit was chosen)
    max_nodes: int = MAX_NODES
    max_vehicles: int = MAX_VEHICLES
    # where it comes from: "sarcover", the distribution that registers it, or "ad hoc"
    source: str = "sarcover"
    # a variant's fixed parameters (``adpc-pso[iterations=300]``) and the method it varies
    fixed: dict = field(default_factory=dict, hash=False, compare=False)
    base: str | None = None

    @property
    def params(self) -> type | None:
        """The method's parameters dataclass (None: it declares none)."""
        return params_class(self.run)

    def resolve(self, params: dict | None = None) -> dict:
        """The fully resolved parameters of a run of this method: the variant's fixed ones, then
        ``params``, the rest at their defaults. Raises :class:`ParamError`, one line."""
        return resolve(self.base or self.name, self.run, {**self.fixed, **(params or {})})


# Node limits of the methods whose models outgrow the instance's dense matrices: the MILP's and
# CP-SAT's arc variables and constraints, PyVRP's cover copy of every node, OR-Tools' routing model,
# and the paper's pipelines (their clustering and energy repair grow faster than V²).
PAPER_MAX_NODES = 2000
MILP_MAX_NODES = 1000
CPSAT_MAX_NODES = 800
PYVRP_MAX_NODES = 2000
ROUTING_MAX_NODES = 3000

METHODS: dict[str, Method] = {spec.name: spec for spec in [
    Method("greedy", m.greedy, False, "cheapest insertion by prize per energy, groups first (floor baseline)"),
    Method("adpc-pso", m.adpc_pso, False,
           "the paper's: ADPC clusters, random-key PSO tours (+2-opt), energy repair and refill",
           m.compile_routers, max_nodes=PAPER_MAX_NODES),
    Method("dpc-pso", m.dpc_pso, False,
           "DPC clusters, random-key PSO tours (+2-opt), energy repair and refill",
           m.compile_routers, max_nodes=PAPER_MAX_NODES),
    Method("kmeans-pso", m.kmeans_pso, False,
           "scikit-learn KMeans clusters, random-key PSO tours (+2-opt), energy repair and refill",
           m.compile_routers, max_nodes=PAPER_MAX_NODES),
    Method("adpc-ga", m.adpc_ga, False,
           "ADPC clusters, GA tours (OX, inversion, elitism; +2-opt), energy repair and refill",
           m.compile_routers, max_nodes=PAPER_MAX_NODES),
    Method("adpc-aco", m.adpc_aco, False,
           "ADPC clusters, elitist ant system tours (+2-opt), energy repair and refill",
           m.compile_routers, max_nodes=PAPER_MAX_NODES),
    Method("cpsat", m.cpsat, True,
           "CP-SAT routes constraint + energy flow, greedy hint, 1 thread; optimal only if proven unscaled",
           max_nodes=CPSAT_MAX_NODES),
    Method("routing", m.routing, False,
           "OR-Tools routing, prize disjunctions + energy dimension, guided local search",
           max_nodes=ROUTING_MAX_NODES),
    Method("pyvrp", m.pyvrp, False,
           "PyVRP iterated local search, optional clients with prizes, max distance = energy, 2000 its",
           max_nodes=PYVRP_MAX_NODES),
    Method("milp", m.milp, True,
           "time-flow TOP MILP on HiGHS via Pyomo: pruned arcs, cliques, path + connectivity cuts, 1 thread, gap 0",
           max_nodes=MILP_MAX_NODES),
    Method("bp", m.bp, True,
           "branch-and-price: route master on HiGHS, ng-route labelling pricing (numba), greedy's routes "
           "as first columns, PyVRP as primal heuristic when the root leaves the proof open, 1 thread",
           m.compile_bp),
]}


# -- plugins ---------------------------------------------------------------------------------------
_PLUGINS: dict[str, Method] | None = None


def plugins() -> dict[str, Method]:
    """The methods installed packages register in the entry-point group ``sarcover.methods``
    (name = the method's name, value = ``module:function``), loaded once per process.

    The function may carry ``params`` (a parameters dataclass, :func:`~.params.takes`), ``exact``
    (True if it proves bounds), ``max_nodes``, ``max_vehicles`` and ``warm_up`` (a function)
    as attributes; its docstring's first line is its summary. A name a built-in method has is
    skipped. One that cannot be imported raises :class:`SarcoverError` naming it.
    """
    global _PLUGINS
    if _PLUGINS is None:
        found = {}
        for ep in importlib.metadata.entry_points(group=ENTRY_POINTS):
            if ep.name in METHODS or ep.name in found:
                continue
            dist = ep.dist.name if ep.dist is not None else "an installed package"
            try:
                fn = ep.load()
            except Exception as exc:  # noqa: BLE001 - a broken plugin is the user's to fix: say which
                raise SarcoverError(f"method {ep.name!r} (entry point {ep.value!r} of {dist}): cannot load it "
                                    f"({type(exc).__name__}: {exc})") from None
            found[ep.name] = _describe(ep.name, fn, f"plugin {dist}")
        _PLUGINS = found
    return _PLUGINS


def _describe(name: str, fn, source: str) -> Method:
    """A :class:`Method` for a function that is not built in, from its attributes and docstring."""
    if not callable(fn):
        raise SarcoverError(f"method {name!r} ({source}) is not callable")
    doc = (fn.__doc__ or "").strip().splitlines()
    return Method(name, fn, bool(getattr(fn, "exact", False)), doc[0] if doc else source,
                  getattr(fn, "warm_up", None), int(getattr(fn, "max_nodes", MAX_NODES)),
                  int(getattr(fn, "max_vehicles", MAX_VEHICLES)), source)


def all_methods() -> list[Method]:
    """The built-in methods, then the installed plugins'."""
    return [*METHODS.values(), *plugins().values()]


# -- names -----------------------------------------------------------------------------------------
class UnknownMethodError(SarcoverError):
    def __init__(self, name: str):
        known = ", ".join(spec.name for spec in all_methods())
        super().__init__(f"unknown method {name!r}; known: {known}")


def get_method(name: str) -> Method:
    """The method ``name``: registered, a plugin's, an ad hoc ``"module:function"``, or a
    variant of one of them (``adpc-pso[iterations=300]``, its parameters checked).

    Ad hoc methods (as a suite may name them) are imported on each call and never added to
    :data:`METHODS`, so listing the registry always shows the built-in methods and plugins only.
    """
    base, fixed = split_variant(name)
    spec = _base_method(base)
    if not fixed:
        return spec
    resolved = spec.resolve(fixed)  # raises ParamError on a bad variant
    return replace(spec, name=variant_name(base, {k: resolved[k] for k in fixed}), fixed=fixed, base=base)


def _base_method(name: str) -> Method:
    if name in METHODS:
        return METHODS[name]
    if name in plugins():
        return plugins()[name]
    if ":" not in name:
        raise UnknownMethodError(name)
    module, func = name.split(":", 1)
    try:
        run = getattr(importlib.import_module(module), func)
    except (ImportError, AttributeError, ValueError) as exc:
        raise SarcoverError(f"method {name!r}: cannot import {func!r} from {module!r} ({exc})") from None
    return _describe(name, run, "ad hoc (named by a suite)")


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
    methods share it); return the names of the hooks run now. A failing hook, or a name that
    does not resolve, is skipped: the method's own run then reports the problem in its row.
    Forked benchmark workers inherit the compiled code."""
    ran = []
    for name in names:
        try:
            hook = get_method(name).warm_up
        except Exception:  # noqa: BLE001 - the job itself will say what is wrong
            continue
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


# -- running ---------------------------------------------------------------------------------------
def run_method(name: str, instance: TOPInstance, *, seed: int = 0,
               time_limit: float | None = DEFAULT_TIME_LIMIT, params: dict | None = None) -> VerifiedResult:
    """Run a method and return its verified result. Never raises.

    ``params`` are the method's parameters (a variant's name fixes some); the fully resolved
    ones are in the result's ``info["params"]``. An unknown method or parameter, an instance
    beyond the method's limits, the pre-check's infeasibility proof, a failing method, a plan
    the verifier rejects, or a bound below the verified objective all come back as a result
    with the reason; the objective is always the verifier's, never the method's own claim.
    """
    t0 = time.perf_counter()
    try:
        spec = get_method(name)
        resolved = spec.resolve(params)
        check_size(spec, instance.n_nodes, instance.n_vehicles)  # before the method allocates it
    except Exception as exc:  # noqa: BLE001 - unknown method or parameter, or beyond the method's limits
        return VerifiedResult.failed(name, Termination.ERROR, f"{type(exc).__name__}: {exc}",
                                     time.perf_counter() - t0)
    info = {"params": resolved}
    reason = precheck(instance)  # the one pre-check of a run: the solvers behind it do not repeat it
    if reason is not None:
        return VerifiedResult.failed(spec.name, Termination.INFEASIBLE, reason, time.perf_counter() - t0, info=info)
    warm_up([spec.name])  # numba compilation (or loading it from the disk cache) is not the method's time
    t0 = time.perf_counter()
    try:
        result = spec.run(instance, seed=seed, time_limit=time_limit, **resolved)
    except Exception as exc:  # noqa: BLE001 - a method bug must not stop a benchmark
        tb = traceback.format_exc().strip().splitlines()
        return VerifiedResult.failed(spec.name, Termination.ERROR, f"{type(exc).__name__}: {exc}",
                                     time.perf_counter() - t0, info={**info, "traceback": tb})
    result.info = {**result.info, **info}
    return verified_result(instance, result, method=spec.name, runtime_s=time.perf_counter() - t0)


