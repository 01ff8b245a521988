"""Cluster-then-route: the paper's method family, one registered method per (clusterer, router)
(``adpc-pso`` is ``cluster_then_route(instance, "adpc", "pso")``; see :mod:`sarcover.benchmarks.registry`).

1. Cluster the reachable viewpoints (a viewpoint is reachable if a UAV can fly start → it → end
   within E_max) into N = n_vehicles groups: ADPC, DPC or scikit-learn KMeans (fewer groups if
   there are fewer viewpoints).
2. Route each group start → group → end with a metaheuristic (PSO, GA or ACO; population 30,
   100 iterations), all groups in one numpy batch; fitness = flight distance. Then 2-opt.
3. Energy repair (:mod:`sarcover.heuristics.repair`): drop viewpoints from over-budget tours, cover every
   target, refill with removed viewpoints that fit.

Runs are seeded (``numpy.random.default_rng(seed)``; KMeans gets ``random_state=seed``) and
stopped by iteration counts, so the same seed gives the same plan. ``time_limit`` is a safety
net only: when it expires the routers stop iterating and ``info["stopped_by_time"]`` is set, and
such a run is no longer reproducible.
"""

from __future__ import annotations

import time
from typing import Callable

import numpy as np

from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Result, Termination
from sarcover.heuristics.clustering import ADPC, DPC
from sarcover.heuristics.repair import RepairFailed, Repairer
from sarcover.heuristics.routing_aco import ACORouter
from sarcover.heuristics.routing_ga import GARouter
from sarcover.heuristics.routing_pso import PSORouter
from sarcover.heuristics.tour import ClusterBatch, two_opt


def make_clusterer(kind: str, n_clusters: int, instance: TOPInstance, seed: int):
    """A fresh scikit-learn-style clusterer: 'adpc', 'dpc' or 'kmeans'."""
    if kind == "adpc":
        return ADPC(n_clusters, base=instance.start)
    if kind == "dpc":
        return DPC(n_clusters)
    if kind == "kmeans":
        from sklearn.cluster import KMeans

        return KMeans(n_clusters=n_clusters, n_init=1, random_state=seed)
    raise ValueError(f"unknown clusterer {kind!r}")


_CONTROLLER = None


def _one_openmp_thread():
    """Context limiting OpenMP (scikit-learn's KMeans) to one thread; the controller is cached
    because building it scans the loaded libraries (about 3 ms a call)."""
    global _CONTROLLER
    if _CONTROLLER is None:
        from threadpoolctl import ThreadpoolController

        _CONTROLLER = ThreadpoolController()
    return _CONTROLLER.limit(limits=1, user_api="openmp")


ROUTERS: dict[str, Callable[[], object]] = {"pso": PSORouter, "ga": GARouter, "aco": ACORouter}


def cluster_then_route(
    instance: TOPInstance,
    clusterer: str,
    router: str,
    *,
    seed: int = 0,
    time_limit: float | None = None,
    reinsert: bool = True,
    name: str | None = None,
) -> Result:
    """Run the pipeline and return a Result (a plan, or none with a reason)."""
    t0, c0 = time.perf_counter(), time.thread_time()
    name = name or f"{clusterer}-{router}"
    deadline = None if time_limit is None else t0 + float(time_limit)
    rng = np.random.default_rng(seed)
    reach = np.flatnonzero(instance.reachable())  # node ids
    info: dict = {"clusterer": clusterer, "router": router}
    if reach.size == 0:
        if instance.groups:
            return Result(name, Termination.COMPLETED, reason="no viewpoint is reachable within E_max",
                          runtime_s=time.perf_counter() - t0, info=info)
        empty = Plan.of([[] for _ in range(instance.n_vehicles)])
        return Result(name, Termination.COMPLETED, plan=empty, runtime_s=time.perf_counter() - t0, info=info)

    k = min(instance.n_vehicles, reach.size)
    if clusterer == "kmeans":  # KMeans cannot make more clusters than distinct points
        k = min(k, np.unique(instance.coords[reach], axis=0).shape[0])
    model = make_clusterer(clusterer, k, instance, seed)
    if clusterer == "kmeans":  # one thread like everything else (OpenMP spinning triples CPU time)
        with _one_openmp_thread():
            labels = model.fit(instance.coords[reach]).labels_
    else:
        labels = model.fit(instance.coords[reach]).labels_
    clusters = [reach[labels == c] + 1 for c in range(k)]  # solver indices
    info["cluster_sizes"] = [int(c.size) for c in clusters]
    t1, c1 = time.perf_counter(), time.thread_time()

    D = instance.distance_matrix()
    end = instance.n_nodes + 1
    batch = ClusterBatch.of(clusters, 0, end)
    if batch.which.size:
        best, _ = ROUTERS[router]().solve(D, batch, rng, deadline)
        tours = batch.routes(clusters, best)
    else:
        tours = clusters
    tours = [two_opt(D, t, 0, end).tolist() for t in tours]
    info["stopped_by_time"] = bool(deadline is not None and time.perf_counter() > deadline)
    t2, c2 = time.perf_counter(), time.thread_time()

    repairer = Repairer(instance, D=D)
    try:
        routes = repairer.repair(tours, reinsert=reinsert)
    except RepairFailed as exc:
        info.update(repairer.stats)
        return Result(name, Termination.COMPLETED, reason=str(exc), runtime_s=time.perf_counter() - t0, info=info)
    t3, c3 = time.perf_counter(), time.thread_time()
    info.update(repairer.stats)
    info["time_cluster_s"], info["time_route_s"], info["time_repair_s"] = t1 - t0, t2 - t1, t3 - t2
    info["cpu_cluster_s"], info["cpu_route_s"], info["cpu_repair_s"] = c1 - c0, c2 - c1, c3 - c2  # thread CPU
    routes = [[v - 1 for v in r] for r in routes]
    routes += [[] for _ in range(instance.n_vehicles - len(routes))]
    return Result(name, Termination.COMPLETED, plan=Plan.of(routes), runtime_s=time.perf_counter() - t0, info=info)


def warm_up() -> None:
    """Compile (or load from numba's disk cache) the routers' kernels: one PSO, GA and ACO run on
    a small instance (about 5 s the first time on a checkout, well under 1 s from the cache).
    The benchmark harness calls it before its workers start (:func:`sarcover.benchmarks.registry.warm_up`),
    so the compilation is not charged to a method's first job."""
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    instance = to_top(generate(4, 3, 2, seed=0))
    for router in ("pso", "ga", "aco"):
        cluster_then_route(instance, "adpc", router, seed=0)
