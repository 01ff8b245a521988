"""The registered methods, each composed in one function, with its parameters dataclass.

Every function here has the method signature (docs/methods.md)::

    method(instance: TOPInstance, *, seed: int, time_limit: float | None, **params) -> Result

and names its parameters with :func:`~sarcover.benchmarks.params.takes`. What a user runs as
``bp`` (greedy's plan as warm start, PyVRP as primal heuristic, BPOptions from the user's limit)
is :func:`bp`, read top to bottom; it sits here, above ``formulations`` and ``heuristics``,
because it needs both (the layers import formulations ← heuristics ← benchmarks).

What every method may take for granted, because :func:`~sarcover.benchmarks.registry.run_method`
does it once per call before the method's clock starts: the instance passed the
:func:`~sarcover.formulations.instance.precheck` (no group is out of reach), its size is within
the method's limits, its numba code is compiled, and ``params`` are resolved (every field,
checked). The solver front doors (``solve_milp``, ``solve_cpsat``, ``solve_bp``) do not
precheck again: called directly on an instance with a group out of reach they prove it
infeasible themselves, with the solver's reason instead of the precheck's.

Each function imports its code on first call, so listing the methods or running a heuristic
does not import every solver library.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass
from typing import Callable, Literal

from sarcover.benchmarks.params import param, takes
from sarcover.formulations.history import shifted
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.result import Result, Termination

DEFAULT_TIME_LIMIT = 60.0  # seconds per run when the caller gives none (solve, run_method, CLI, suites)


# -- composition shared by the exact methods -------------------------------------------------------
def warm_started(solve: Callable[..., Result], instance: TOPInstance, *, method: str, seed: int,
                 time_limit: float | None, **options) -> Result:
    """``solve`` started from greedy's plan (when greedy finds one), within the same time limit.

    Greedy costs milliseconds; its plan becomes the solver's ``warm_start`` (MIP start, CP-SAT
    hint, bp's first columns and incumbent), so a run the limit stops still returns a plan that
    covers every group whenever greedy found one. The solver gets what greedy left of the limit;
    the returned runtime and the anytime history count from this call, greedy included.

    A model or search too large for the process's memory (a ``MemoryError``: the harness limits
    each worker's memory, and CP-SAT's and the MILP's searches on 240 points have passed 4 GB)
    ends the run with greedy's plan, no bound and the reason, as a run the limit stops would end,
    instead of an error: ``method`` names the method in that result.
    """
    from sarcover.heuristics.greedy import greedy

    t0 = time.perf_counter()
    plan = greedy(instance, seed=seed).plan
    spent = time.perf_counter() - t0
    left = None if time_limit is None else max(time_limit - spent, 0.01)
    try:
        result = solve(instance, seed=seed, time_limit=left, warm_start=plan, **options)
    except MemoryError as exc:
        why = str(exc) or "MemoryError"
        result = Result(method, Termination.COMPLETED, plan=plan,
                        reason=f"out of memory ({why}); greedy's plan, the warm start")
    result.runtime_s = time.perf_counter() - t0
    if "history" in result.info:
        result.info["history"] = shifted(result.info["history"], spent)
    result.info["warm_start_prize"] = (float(sum(instance.prizes[v] for v in plan.visited))
                                       if plan is not None else None)
    return result


# -- greedy ----------------------------------------------------------------------------------------
def greedy(instance, *, seed=0, time_limit=None) -> Result:
    """Cheapest insertion by prize per energy, groups first; no parameters."""
    from sarcover.heuristics.greedy import greedy

    return greedy(instance, seed=seed, time_limit=time_limit)


# -- the paper's cluster-then-route pipelines ------------------------------------------------------
@dataclass(frozen=True)
class DPCParams:
    dc_percentile: float = param(2.0, "DPC cut-off distance d_c as this percentile of the pairwise distances",
                                 minimum=0.0, maximum=100.0)
    dc: float | None = param(None, "DPC cut-off distance d_c in metres (none: from dc_percentile)", minimum=0.0)


@dataclass(frozen=True)
class ADPCParams(DPCParams):
    xi: float = param(0.25, "ADPC expansion index ξ (cluster-size penalty of the assignment)", minimum=0.0)


@dataclass(frozen=True)
class PSOParams:
    population: int = param(30, "particles per cluster's swarm", minimum=1)
    iterations: int = param(100, "PSO iterations (the reproducible stop)", minimum=1)
    w: float = param(0.7298, "inertia weight", minimum=0.0)
    c1: float = param(1.49618, "cognitive coefficient", minimum=0.0)
    c2: float = param(1.49618, "social coefficient", minimum=0.0)
    v_max: float = param(1.0, "velocity clamp on the random keys", minimum=0.0)
    local_search: bool = param(True, "2-opt on each swarm's best every iteration (memetic PSO)")
    refill: bool = param(True, "after energy repair, put removed viewpoints back where they fit")

    def router(self) -> dict:
        return dict(n_particles=self.population, n_iterations=self.iterations, w=self.w, c1=self.c1,
                    c2=self.c2, v_max=self.v_max, local_search=self.local_search)


@dataclass(frozen=True)
class GAParams:
    population: int = param(30, "tours per cluster's population", minimum=2)
    iterations: int = param(100, "GA generations (the reproducible stop)", minimum=1)
    p_crossover: float = param(0.9, "probability of order crossover", minimum=0.0, maximum=1.0)
    p_mutation: float = param(0.3, "probability of inversion mutation", minimum=0.0, maximum=1.0)
    elite: int = param(2, "best tours kept unchanged each generation", minimum=0)
    refill: bool = param(True, "after energy repair, put removed viewpoints back where they fit")

    def router(self) -> dict:
        return dict(n_population=self.population, n_iterations=self.iterations,
                    p_crossover=self.p_crossover, p_mutation=self.p_mutation, n_elite=self.elite)


@dataclass(frozen=True)
class ACOParams:
    population: int = param(30, "ants per colony", minimum=1)
    iterations: int = param(100, "colonies (the reproducible stop)", minimum=1)
    alpha: float = param(1.0, "pheromone weight", minimum=0.0)
    beta: float = param(3.0, "distance (visibility) weight", minimum=0.0)
    rho: float = param(0.5, "pheromone evaporation rate", minimum=0.0, maximum=1.0)
    elitist: float = param(5.0, "extra pheromone on the best tour so far", minimum=0.0)
    local_search: bool = param(True, "2-opt on each colony's best tour")
    refill: bool = param(True, "after energy repair, put removed viewpoints back where they fit")

    def router(self) -> dict:
        return dict(n_ants=self.population, n_iterations=self.iterations, alpha=self.alpha, beta=self.beta,
                    rho=self.rho, elitist=self.elitist, local_search=self.local_search)


@dataclass(frozen=True)
class AdpcPsoParams(PSOParams, ADPCParams):
    pass


@dataclass(frozen=True)
class DpcPsoParams(PSOParams, DPCParams):
    pass


@dataclass(frozen=True)
class AdpcGaParams(GAParams, ADPCParams):
    pass


@dataclass(frozen=True)
class AdpcAcoParams(ACOParams, ADPCParams):
    pass


def _dpc(p: DPCParams) -> dict:
    return dict(dc=p.dc, dc_percentile=p.dc_percentile)


def _adpc(p: ADPCParams) -> dict:
    return dict(xi=p.xi, **_dpc(p))


def _pipeline(instance, clusterer: str, clusterer_options: dict, router: str, p, *, seed, time_limit) -> Result:
    from sarcover.heuristics.pipeline import cluster_then_route

    return cluster_then_route(instance, clusterer, router, seed=seed, time_limit=time_limit, reinsert=p.refill,
                              clusterer_options=clusterer_options, router_options=p.router())


@takes(AdpcPsoParams)
def adpc_pso(instance, *, seed=0, time_limit=None, **params) -> Result:
    """The paper's method: ADPC clusters, random-key PSO tours each cluster, energy repair."""
    p = AdpcPsoParams(**params)
    return _pipeline(instance, "adpc", _adpc(p), "pso", p, seed=seed, time_limit=time_limit)


@takes(DpcPsoParams)
def dpc_pso(instance, *, seed=0, time_limit=None, **params) -> Result:
    """DPC clusters, random-key PSO tours, energy repair."""
    p = DpcPsoParams(**params)
    return _pipeline(instance, "dpc", _dpc(p), "pso", p, seed=seed, time_limit=time_limit)


@takes(PSOParams)
def kmeans_pso(instance, *, seed=0, time_limit=None, **params) -> Result:
    """scikit-learn KMeans clusters (random_state = seed), random-key PSO tours, energy repair."""
    p = PSOParams(**params)
    return _pipeline(instance, "kmeans", {}, "pso", p, seed=seed, time_limit=time_limit)


@takes(AdpcGaParams)
def adpc_ga(instance, *, seed=0, time_limit=None, **params) -> Result:
    """ADPC clusters, GA tours, energy repair."""
    p = AdpcGaParams(**params)
    return _pipeline(instance, "adpc", _adpc(p), "ga", p, seed=seed, time_limit=time_limit)


@takes(AdpcAcoParams)
def adpc_aco(instance, *, seed=0, time_limit=None, **params) -> Result:
    """ADPC clusters, elitist ant system tours, energy repair."""
    p = AdpcAcoParams(**params)
    return _pipeline(instance, "adpc", _adpc(p), "aco", p, seed=seed, time_limit=time_limit)


# -- library peers ---------------------------------------------------------------------------------
Metaheuristic = Literal["guided_local_search", "tabu_search", "generic_tabu_search", "simulated_annealing",
                        "greedy_descent", "automatic"]
FirstSolution = Literal["local_cheapest_insertion", "path_cheapest_arc", "savings", "parallel_cheapest_insertion",
                        "best_insertion", "automatic"]


@dataclass(frozen=True)
class RoutingParams:
    metaheuristic: Metaheuristic = param("guided_local_search", "OR-Tools local search metaheuristic")
    first_solution: FirstSolution = param("local_cheapest_insertion", "OR-Tools first solution strategy")
    solution_limit: int = param(1000, "local-search solutions per search (the reproducible stop)", minimum=1)
    gls_lambda: float = param(10.0, "guided local search penalty coefficient (OR-Tools' default: 0.1)",
                              minimum=0.0)


@takes(RoutingParams)
def routing(instance, *, seed=0, time_limit=DEFAULT_TIME_LIMIT, **params) -> Result:
    """OR-Tools routing: prize disjunctions, an energy dimension, a local search metaheuristic."""
    from sarcover.heuristics.ortools_routing import routing

    p = RoutingParams(**params)
    return routing(instance, seed=seed, time_limit=time_limit, solution_limit=p.solution_limit,
                   metaheuristic=p.metaheuristic.upper(), first_solution=p.first_solution.upper(),
                   gls_lambda=p.gls_lambda)


@dataclass(frozen=True)
class PyVRPParams:
    iterations: int = param(2000, "ILS iterations per pass (the reproducible stop)", minimum=1)
    no_improvement: int = param(150_000, "iterations without improvement before the search restarts",
                                minimum=1)
    history_length: int = param(300, "late-acceptance history length", minimum=1)
    neighbours: int = param(50, "granular neighbourhood size (nearest clients per client)", minimum=1)
    exhaustive_on_best: bool = param(True, "exhaustive local search on each new best solution")
    pass1_share: float = param(0.6, "share of the time limit the first pass (with cover copies) may take",
                               minimum=0.01, maximum=1.0)


@takes(PyVRPParams)
def pyvrp(instance, *, seed=0, time_limit=DEFAULT_TIME_LIMIT, **params) -> Result:
    """PyVRP's iterated local search: optional clients with prizes, max distance = energy."""
    from pyvrp import IteratedLocalSearchParams, SolveParams
    from pyvrp.search import NeighbourhoodParams
    from sarcover.heuristics.pyvrp_ils import pyvrp

    p = PyVRPParams(**params)
    solve_params = SolveParams(
        ils=IteratedLocalSearchParams(num_iters_no_improvement=p.no_improvement, history_length=p.history_length,
                                      exhaustive_on_best=p.exhaustive_on_best),
        neighbourhood=NeighbourhoodParams(num_neighbours=p.neighbours))
    return pyvrp(instance, seed=seed, time_limit=time_limit, iterations=p.iterations, solve_params=solve_params,
                 pass1_share=p.pass1_share)


# -- exact methods ---------------------------------------------------------------------------------
@dataclass(frozen=True)
class MILPParams:
    threads: int = param(1, "HiGHS threads (1: the fair comparison with single-threaded heuristics)", minimum=1)
    root_rounds: int = param(10, "rounds of LP connectivity cuts before the MIP (0: none)", minimum=0)
    cliques: bool = param(True, "incompatibility cliques: nodes no two of which fit on one route")
    paths: bool = param(True, "infeasible 2-arc path inequalities")
    two_cycle: bool = param(True, "two-cycle elimination rows")


@takes(MILPParams)
def milp(instance, *, seed=0, time_limit=DEFAULT_TIME_LIMIT, **params) -> Result:
    """Time-flow TOP MILP on HiGHS via Pyomo, from greedy's plan."""
    from sarcover.formulations.milp import solve_milp

    return warm_started(solve_milp, instance, method="milp", seed=seed, time_limit=time_limit,
                        **asdict(MILPParams(**params)))


@dataclass(frozen=True)
class CPSATParams:
    threads: int = param(1, "CP-SAT workers (1: the fair comparison with single-threaded heuristics)", minimum=1)
    model: Literal["multi", "vehicle"] = param("multi", "routes constraint: one multiple circuit, or a circuit "
                                                        "per vehicle")
    flow: bool = param(True, "redundant single-commodity energy flow rows (a stronger LP)")
    linearization: int = param(2, "CP-SAT linearization level", minimum=0, maximum=2)


@takes(CPSATParams)
def cpsat(instance, *, seed=0, time_limit=DEFAULT_TIME_LIMIT, **params) -> Result:
    """CP-SAT routes constraint + energy flow, from greedy's plan as hint."""
    from sarcover.formulations.cpsat import solve_cpsat

    return warm_started(solve_cpsat, instance, method="cpsat", seed=seed, time_limit=time_limit,
                        **asdict(CPSATParams(**params)))


@takes("sarcover.formulations.bp.options:BPOptions")  # named, so that listing does not import bp
def bp(instance, *, seed=0, time_limit=DEFAULT_TIME_LIMIT, **params) -> Result:
    """Branch-and-price from greedy's plan, with PyVRP as its primal heuristic.

    Parameters: the fields of :class:`~sarcover.formulations.bp.BPOptions`; those left None are
    decided here on the user's ``time_limit`` (not on what greedy leaves of it), the one place
    the registered bp decides them.
    """
    from sarcover.formulations.bp import BPOptions, solve_bp
    from sarcover.heuristics.pyvrp_ils import primal_routes

    options = BPOptions(**params).with_limit_defaults(time_limit)
    return warm_started(solve_bp, instance, method="bp", seed=seed, time_limit=time_limit, options=options,
                        primal=primal_routes(instance, seed))


# numba code compiled before a method's clock starts (see registry.warm_up)
def compile_routers() -> None:
    from sarcover.heuristics.pipeline import warm_up

    warm_up()


def compile_bp() -> None:
    from sarcover.formulations.bp import warm_up

    warm_up()
