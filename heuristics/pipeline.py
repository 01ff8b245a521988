"""Cluster-then-route: the paper's method family, one registered method per (clusterer, router)
(``adpc-pso`` is ``cluster_then_route(instance, "adpc", "pso")``; see :mod:`sarcover.benchmarks.registry`).

1. Cluster the reachable viewpoints (a viewpoint is reachable if a UAV can fly start → it → end
   within E_max) into N = n_vehicles groups: ADPC, DPC or scikit-learn KMeans (fewer groups if
   there are fewer viewpoints).
2. Route each group start → group → end with a metaheuristic (PSO, GA or ACO; population 30,
   100 iterations), all groups in one numpy batch; fitness = flight distance. Then 2-opt.
3. Energy repair (:mod:`sarcover.heuristics.repair`): drop viewpoints from over-budget tours, cover every
   target, refill with removed viewpoints that fit.

The stages are callable apart (the decomposition of the gap into clustering and routing loss
needs them): :func:`cluster_stage` returns each UAV's cluster, :func:`route_clusters` runs stages
2-3 on any clusters. Cluster i is UAV i's, and route i of the plan flies it; the plan's ``info``
keeps the clusters (``clusters``) and, per route, the nodes repair or refill took from outside
its cluster (``outside_cluster``).

Runs are seeded (``numpy.random.default_rng(seed)``; KMeans gets ``random_state=seed``) and
stopped by iteration counts, so the same seed gives the same plan (``info["stop_reason"]`` is
``"iteration_limit"``). They also stop at ``time_limit``: when it expires the routers stop
iterating, ``info["stopped_by_time"]`` is set and the stop reason is ``"time_limit"``; such a run
is no longer reproducible. The anytime history (``info["history"]``) is one point: the plan
exists only once the energy repair has made the tours feasible, and its prize is the plan's.
"""

from __future__ import annotations

import time
from typing import Callable

import numpy as np

from sarcover.formulations.history import History, StopReason
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Result, Termination
from sarcover.heuristics.clustering import ADPC, DPC
from sarcover.heuristics.repair import RepairFailed, Repairer
from sarcover.heuristics.routing_aco import ACORouter
from sarcover.heuristics.routing_ga import GARouter
from sarcover.heuristics.routing_pso import PSORouter
from sarcover.heuristics.tour import ClusterBatch, two_opt


def make_clusterer(kind: str, n_clusters: int, instance: TOPInstance, seed: int, **options):
    """A fresh scikit-learn-style clusterer: 'adpc', 'dpc' or 'kmeans'; ``options`` are the
    clusterer's keyword arguments (ADPC: ``xi``, ``dc``, ``dc_percentile``; DPC: ``dc``,
    ``dc_percentile``)."""
    if kind == "adpc":
        return ADPC(n_clusters, base=instance.start, **options)
    if kind == "dpc":
        return DPC(n_clusters, **options)
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


def cluster_stage(instance: TOPInstance, clusterer: str, *, seed: int = 0,
                  clusterer_options: dict | None = None) -> list[np.ndarray]:
    """The clustering stage alone: the node ids (0..V-1) of each UAV's cluster.

    Returns ``instance.n_vehicles`` disjoint arrays; entry i is the cluster UAV i flies (route i
    of the pipeline's plan). The reachable viewpoints are split into k = min(N, reachable) groups
    (KMeans: also at most the number of distinct points) labelled 0..k-1 by the clusterer, and
    UAV i takes label i; UAVs k..N-1 get an empty cluster. Unreachable viewpoints are in no
    cluster. Deterministic for a seed (only KMeans uses it, as ``random_state``), and it draws
    nothing from the routers' random stream, so running it apart does not change their plans.
    """
    reach = np.flatnonzero(instance.reachable())
    n = instance.n_vehicles
    if reach.size == 0:
        return [np.zeros(0, dtype=int) for _ in range(n)]
    k = min(n, reach.size)
    if clusterer == "kmeans":  # KMeans cannot make more clusters than distinct points
        k = min(k, np.unique(instance.coords[reach], axis=0).shape[0])
    model = make_clusterer(clusterer, k, instance, seed, **(clusterer_options or {}))
    if clusterer == "kmeans":  # one thread like everything else (OpenMP spinning triples CPU time)
        with _one_openmp_thread():
            labels = model.fit(instance.coords[reach]).labels_
    else:
        labels = model.fit(instance.coords[reach]).labels_
    clusters = [reach[labels == c] for c in range(k)]
    return clusters + [np.zeros(0, dtype=int) for _ in range(n - k)]


def outside_clusters(routes, clusters) -> list[list[int]]:
    """Per route i, the node ids it visits that are not in ``clusters[i]`` (route i is UAV i's;
    a route without a cluster has every node outside). Repair and refill put them there."""
    out = []
    for i, route in enumerate(routes):
        own = set(int(v) for v in clusters[i]) if i < len(clusters) else set()
        out.append([int(v) for v in route if int(v) not in own])
    return out


def _check_clusters(instance: TOPInstance, clusters) -> list[np.ndarray]:
    """The clusters as int arrays; ValueError unless at most N of them are disjoint node ids."""
    clusters = [np.asarray(c, dtype=int).reshape(-1) for c in clusters]
    if len(clusters) > instance.n_vehicles:
        raise ValueError(f"{len(clusters)} clusters for {instance.n_vehicles} UAVs")
    flat = np.concatenate(clusters) if clusters else np.zeros(0, dtype=int)
    if flat.size and (flat.min() < 0 or flat.max() >= instance.n_nodes):
        raise ValueError("a cluster names a node id outside 0..V-1")
    if np.unique(flat).size != flat.size:
        raise ValueError("clusters overlap: a node is in two clusters (or twice in one)")
    return clusters


def _route_stage(instance, clusters, router, rng, deadline, reinsert, name, info, t0, c0, t1, c1, hist,
                 router_options=None) -> Result:
    """Route each cluster (router + 2-opt), then repair; route i is cluster i's UAV.

    ``clusters`` are node ids; the routers and the repair work in solver indices (id + 1).
    Times from t0 (call) and t1 (end of clustering) go into ``info``; ``hist`` (started at the
    call) gets the plan's prize once the repair has made it.
    """
    D = instance.distance_matrix()
    end = instance.n_nodes + 1
    tours = [c + 1 for c in clusters]  # solver indices
    batch = ClusterBatch.of(tours, 0, end)
    if batch.which.size:
        best, _ = ROUTERS[router](**(router_options or {})).solve(D, batch, rng, deadline)
        tours = batch.routes(tours, best)
    tours = [two_opt(D, t, 0, end).tolist() for t in tours]
    info["stopped_by_time"] = bool(deadline is not None and time.perf_counter() > deadline)
    info["stop_reason"] = (StopReason.TIME_LIMIT if info["stopped_by_time"] else StopReason.ITERATION_LIMIT).value
    t2, c2 = time.perf_counter(), time.thread_time()

    repairer = Repairer(instance, D=D)
    try:
        routes = repairer.repair(tours, reinsert=reinsert)
    except RepairFailed as exc:
        info.update(repairer.stats)
        hist.record(info, None, None)
        return Result(name, Termination.COMPLETED, reason=str(exc), runtime_s=time.perf_counter() - t0, info=info)
    t3, c3 = time.perf_counter(), time.thread_time()
    info.update(repairer.stats)
    info["time_cluster_s"], info["time_route_s"], info["time_repair_s"] = t1 - t0, t2 - t1, t3 - t2
    info["cpu_cluster_s"], info["cpu_route_s"], info["cpu_repair_s"] = c1 - c0, c2 - c1, c3 - c2  # thread CPU
    routes = [[v - 1 for v in r] for r in routes]
    routes += [[] for _ in range(instance.n_vehicles - len(routes))]
    outside = outside_clusters(routes, clusters)
    info["outside_cluster"] = outside
    info["n_outside_cluster"] = sum(len(o) for o in outside)
    plan = Plan.of(routes)
    hist.record(info, float(sum(instance.prizes[v] for v in plan.visited)), None)
    return Result(name, Termination.COMPLETED, plan=plan, runtime_s=time.perf_counter() - t0, info=info)


def route_clusters(
    instance: TOPInstance,
    clusters,
    router: str,
    *,
    seed: int = 0,
    time_limit: float | None = None,
    reinsert: bool = True,
    name: str | None = None,
) -> Result:
    """The pipeline's routing stage on given clusters: router (+2-opt) on each, then repair.

    ``clusters``: at most N disjoint lists of node ids; cluster i is UAV i's and becomes route i
    of the plan (missing ones are empty). With the clusters of :func:`cluster_stage` and the same
    seed this is exactly :func:`cluster_then_route`'s plan. ``info["outside_cluster"]`` lists, per
    route, the nodes the repair or refill put there from outside its cluster.
    """
    t0, c0 = time.perf_counter(), time.thread_time()
    hist = History(t0)
    clusters = _check_clusters(instance, clusters)
    clusters += [np.zeros(0, dtype=int) for _ in range(instance.n_vehicles - len(clusters))]
    deadline = None if time_limit is None else t0 + float(time_limit)
    info: dict = {"clusterer": "given", "router": router, "cluster_sizes": [int(c.size) for c in clusters],
                  "clusters": [c.tolist() for c in clusters]}
    return _route_stage(instance, clusters, router, np.random.default_rng(seed), deadline, reinsert,
                        name or f"given-{router}", info, t0, c0, t0, c0, hist)


def cluster_then_route(
    instance: TOPInstance,
    clusterer: str,
    router: str,
    *,
    seed: int = 0,
    time_limit: float | None = None,
    reinsert: bool = True,
    name: str | None = None,
    clusterer_options: dict | None = None,
    router_options: dict | None = None,
) -> Result:
    """Run the pipeline and return a Result (a plan, or none with a reason).

    ``clusterer_options``, ``router_options``: keyword arguments of the clusterer
    (:func:`make_clusterer`) and of the router's class (e.g. ``n_iterations`` of
    :class:`~sarcover.heuristics.routing_pso.PSORouter`); None: their defaults.
    :func:`cluster_stage` then the routing stage of :func:`route_clusters`: route i of the plan
    is UAV i, which flies cluster i (``info["clusters"]``, node ids); ``info["outside_cluster"]``
    lists per route the nodes repair or refill took from outside that cluster.
    """
    t0, c0 = time.perf_counter(), time.thread_time()
    hist = History(t0)
    name = name or f"{clusterer}-{router}"
    deadline = None if time_limit is None else t0 + float(time_limit)
    rng = np.random.default_rng(seed)
    info: dict = {"clusterer": clusterer, "router": router}
    if not instance.reachable().any():
        info["stop_reason"] = StopReason.COMPLETED.value
        hist.record(info, None if instance.groups else 0.0, None)
        if instance.groups:
            return Result(name, Termination.COMPLETED, reason="no viewpoint is reachable within E_max",
                          runtime_s=time.perf_counter() - t0, info=info)
        empty = Plan.of([[] for _ in range(instance.n_vehicles)])
        return Result(name, Termination.COMPLETED, plan=empty, runtime_s=time.perf_counter() - t0, info=info)

    clusters = cluster_stage(instance, clusterer, seed=seed, clusterer_options=clusterer_options)
    info["cluster_sizes"] = [int(c.size) for c in clusters]
    info["clusters"] = [c.tolist() for c in clusters]
    t1, c1 = time.perf_counter(), time.thread_time()
    return _route_stage(instance, clusters, router, rng, deadline, reinsert, name, info, t0, c0, t1, c1, hist,
                        router_options)


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
