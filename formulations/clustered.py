"""The clustered optimum OPT|C: the best plan when UAV i may visit only the viewpoints of C_i.

A clustering C = (C_1 … C_N) (disjoint sets of node ids, one per UAV; the output of a
cluster-then-route method's clustering stage) restricts the team orienteering problem: route i
visits only nodes of C_i, under the same budget, each node at most once, and every group (target)
still needs one visited node; a group whose nodes lie in several clusters may be covered by any
of their UAVs. OPT|C is the optimum of that restriction: what a perfect router could make of the
clustering. Every restricted plan is a plan, so OPT|C <= OPT, and OPT − OPT|C is the loss of the
clustering stage.

Two exact methods; they agree with each other and with brute force (tests/formulations/test_clustered.py).

:func:`solve_clustered` (the one to use) decomposes by cluster. Cluster i alone is a
single-vehicle orienteering problem; the clusters interact only through the groups split across
them. Each cluster's problem is solved exactly with a set R_i of groups its route must cover
(:func:`solve_orienteering`: the suite's branch-and-price ``bp`` and the restricted MILP below as
a portfolio), starting from R_i = the groups only cluster i can cover. The sum of the clusters'
optima bounds every restricted plan whose route i covers R_i; when the optimal routes together
cover every group they are such a plan, and the search node is solved. Otherwise the search
branches on a group g no route covers, one child per cluster k that can cover g (g joins R_k):
every restricted plan covers g through some cluster, so it stays feasible in one child, and
best-first search with pruning at the incumbent ends with the optimum. On the paper's instances
the root alone is usually the answer (each cluster's optimal route covers the split targets
anyway), so OPT|C costs N orienteering problems of 10-65 nodes.

:func:`solve_clustered_milp` is the joint model: the time-flow MILP of
:mod:`sarcover.formulations.milp`, solved by the same HiGHS loop (root connectivity and clique cuts,
subtour and no-good re-solves, verified incumbents, a bound rounded to the prize lattice), on a
restricted arc set plus rows per cluster:

- nodes: the reachable nodes of the clusters; arcs: start → i and i → end for those nodes, and
  i → j only when i and j are in the same cluster (from the budget-pruned arcs), so every route,
  a path from the start along arcs, stays inside the cluster of its first node;
- per cluster i, ``u_i = sum_{j in C_i} x[start, j] <= 1``: at most one route (UAV i's) enters
  it. Routes and clusters are then in one-to-one correspondence, and the feasible integer points
  are exactly the restricted plans; the group rows stay as they are, so a split group is covered
  by whichever cluster's route visits one of its nodes;
- valid strengthening (not needed for exactness): the knapsack row ``sum of c_ij x_ij over the
  cluster's arcs <= B·u_i`` (one route per cluster, so the budget is linear), ``y_v <= u_i`` for v
  in C_i, and ``sum_{v in K} y_v <= u_i`` for sets K ⊂ C_i of nodes no two of which fit on one
  route (:func:`sarcover.formulations.preprocess.incompatible_cliques` on the cluster alone).

It is exact but its LP bound is loose on large clusters (tens of seconds to no proof at K = 6),
so it serves as the independent cross-check and as the portfolio's solver for the clusters that
branch-and-price finds hard.

Both return a plan of N routes, route i inside C_i (empty when UAV i stays home), and a proven
upper bound on OPT|C, equal to the objective when the status is OPTIMAL. INFEASIBLE means no
restricted plan covers every group (for instance a group with no reachable node in any cluster):
the clustering itself rules out every plan. :func:`oracle_clusters` gives the clustering a plan
induces (route i's nodes as C_i), whose OPT|C is the plan's value when the plan is optimal.
"""

from __future__ import annotations

import heapq
import math
import time
from dataclasses import dataclass, replace

import numpy as np
import pyomo.environ as pyo

from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.milp import solve_milp
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Result, Status, Termination
from sarcover.formulations.preprocess import ArcGraph, incompatible_cliques, prune_arcs
from sarcover.formulations.verify import verify

METHOD = "opt-c"


def normalise_clusters(instance: TOPInstance, clusters) -> list[list[int]]:
    """The clusters as N lists of node ids (missing ones empty); ValueError unless they are at most
    N disjoint sets of valid node ids."""
    out = [sorted(int(v) for v in c) for c in clusters]
    if len(out) > instance.n_vehicles:
        raise ValueError(f"{len(out)} clusters for {instance.n_vehicles} vehicles")
    flat = [v for c in out for v in c]
    if any(not 0 <= v < instance.n_nodes for v in flat):
        raise ValueError("a cluster names a node id outside 0..V-1")
    if len(set(flat)) != len(flat):
        raise ValueError("clusters overlap: a node is in two clusters (or twice in one)")
    return out + [[] for _ in range(instance.n_vehicles - len(out))]


def inside(plan: Plan, clusters) -> bool:
    """True when route i of ``plan`` visits only nodes of ``clusters[i]`` (a restricted plan)."""
    clusters = [set(int(v) for v in c) for c in clusters]
    return all(not route or (i < len(clusters) and set(route) <= clusters[i])
               for i, route in enumerate(plan.routes))


def cluster_of(clusters) -> dict[int, int]:
    """Node id -> index of its cluster."""
    return {int(v): i for i, c in enumerate(clusters) for v in c}


def restricted_graph(instance: TOPInstance, clusters: list[list[int]]) -> ArcGraph:
    """The budget-pruned arcs (:func:`prune_arcs`) that a route confined to one cluster can use."""
    g = prune_arcs(instance)
    owner = {v + 1: i for v, i in cluster_of(clusters).items()}  # solver index -> cluster
    nodes = tuple(i for i in g.nodes if i in owner)
    keep = set(nodes)
    arcs = tuple((i, j) for i, j in g.arcs
                 if (i == g.start and j in keep) or (j == g.end and i in keep)
                 or (i in keep and j in keep and owner[i] == owner[j]))
    return replace(g, nodes=nodes, arcs=arcs)


def _cluster_rows(clusters: list[list[int]], strengthen: bool = True):
    """``extend`` hook for :func:`solve_milp`: at most one route per cluster, and (``strengthen``)
    the valid rows that tighten its LP: knapsack budget per cluster, visits need the cluster's
    route, incompatible sets per cluster."""

    def extend(m: pyo.ConcreteModel, g: ArcGraph) -> None:
        present = set(g.nodes)
        members = [[v + 1 for v in c if v + 1 in present] for c in clusters]
        members = [c for c in members if c]
        m.cluster_route = pyo.Expression(
            range(len(members)), rule=lambda m, k: sum(m.x[g.start, j] for j in members[k]),
            doc="routes entering cluster k (0 or 1)")
        m.one_route = pyo.Constraint(range(len(members)), rule=lambda m, k: m.cluster_route[k] <= 1,
                                     doc="at most one route (its UAV's) per cluster")
        if not strengthen:
            return
        member_of = {v: k for k, c in enumerate(members) for v in c}
        arcs_of: list[list] = [[] for _ in members]
        for i, j in g.arcs:
            arcs_of[member_of[j] if i == g.start else member_of[i]].append((i, j))
        m.cluster_budget = pyo.Constraint(
            range(len(members)),
            rule=lambda m, k: sum(float(g.cost[a]) * m.x[a] for a in arcs_of[k]) <= g.budget * m.cluster_route[k],
            doc="the one route of cluster k: its arcs cost at most the budget (knapsack row)")
        pairs = [(k, v) for k, c in enumerate(members) for v in c]
        m.needs_route = pyo.Constraint(pairs, rule=lambda m, k, v: m.y[v] <= m.cluster_route[k],
                                       doc="a node is visited only if its cluster's route runs")
        rows = []
        for k, c in enumerate(members):
            sub = replace(g, nodes=tuple(c))
            rows += [(k, cl) for cl in incompatible_cliques(sub, 1)]
        m.cluster_clique = pyo.Constraint(
            range(len(rows)), rule=lambda m, r: sum(m.y[v] for v in rows[r][1]) <= m.cluster_route[rows[r][0]],
            doc="a cluster's route visits at most one node of a pairwise-incompatible set")

    return extend


def split_groups(instance: TOPInstance, clusters) -> int:
    """Number of groups whose reachable nodes lie in two or more clusters."""
    owner = cluster_of(clusters)
    reach = instance.reachable()
    return sum(len({owner[v] for v in g if v in owner and reach[v]}) > 1 for g in instance.groups)


def solve_clustered_milp(
    instance: TOPInstance,
    clusters,
    *,
    time_limit: float | None = 60.0,
    seed: int = 0,
    threads: int = 1,
    warm_start: Plan | None = None,
    strengthen: bool = True,
) -> Result:
    """OPT|C exactly (see the module docstring): HiGHS on the cluster-restricted time-flow MILP.

    ``clusters``: at most N disjoint lists of node ids, cluster i for UAV i. ``warm_start``: a plan
    whose route i lies inside cluster i (ignored otherwise). ``strengthen=False`` leaves out the
    valid inequalities (the one-route-per-cluster rows stay). The plan has N routes, route i
    inside cluster i; ``info["clusters"]`` holds the clusters as solved.
    """
    t0 = time.perf_counter()
    clusters = normalise_clusters(instance, clusters)
    info: dict = {"clusters": clusters, "split_groups": split_groups(instance, clusters)}

    def result(status, plan=None, bound=None, reason="", extra=None):
        info.update(extra or {})
        return Result(METHOD, status, plan=plan, bound=bound, runtime_s=time.perf_counter() - t0,
                      reason=reason, info=info)

    # no pre-check: the cluster check below finds every group out of reach, and more
    owner = cluster_of(clusters)
    reach = instance.reachable()
    for gi, group in enumerate(instance.groups):
        if not any(v in owner and reach[v] for v in group):
            what = "target" if instance.kind == "sar" else "group"
            return result(Termination.INFEASIBLE, reason=f"{what} {gi} has no reachable node in any cluster")
    if warm_start is not None and not (inside(warm_start, clusters) and verify(instance, warm_start).valid):
        info["warm_start_ignored"] = True
        warm_start = None
    g = restricted_graph(instance, clusters)
    extend = _cluster_rows(clusters, strengthen)
    res = solve_milp(instance, seed=seed, time_limit=time_limit, threads=threads, warm_start=warm_start,
                     graph=g, extend=extend)
    extra = {k: v for k, v in res.info.items()}
    if res.status == Status.INFEASIBLE:
        return result(Termination.INFEASIBLE, extra=extra,
                      reason="HiGHS proved that no plan with each route inside its own cluster covers every "
                             + ("target" if instance.kind == "sar" else "group"))
    plan = None
    if res.plan is not None:
        routes: list[list[int]] = [[] for _ in range(instance.n_vehicles)]
        for route in res.plan.routes:
            if route:
                routes[owner[route[0]]] = list(route)
        plan = Plan.of(routes)
        if not inside(plan, clusters) or len([r for r in res.plan.routes if r]) != len([r for r in routes if r]):
            # cannot happen with the restricted arcs and one route per cluster; never report it
            return result(Termination.ERROR, bound=res.bound, extra=extra,
                          reason="the restricted model returned a route outside its cluster")
    return result(res.termination, plan=plan, bound=res.bound, reason=res.reason, extra=extra)




# ---------------------------------------------------------------- OPT|C by cluster decomposition


def cluster_instance(instance: TOPInstance, nodes, required) -> TOPInstance:
    """The single-vehicle orienteering problem of one cluster: its ``nodes`` (ids of ``instance``,
    in that order; local id k is ``nodes[k]``), the same depots, costs and budget, and one group per
    id in ``required``, made of that group's nodes inside the cluster."""
    nodes = [int(v) for v in nodes]
    local = {v: k for k, v in enumerate(nodes)}
    groups = tuple(tuple(local[v] for v in instance.groups[g] if v in local) for g in sorted(required))
    return TOPInstance(coords=instance.coords[nodes].reshape(-1, 2), prizes=instance.prizes[nodes],
                       start=instance.start, end=instance.end, budget=instance.budget, n_vehicles=1,
                       e_fly=instance.e_fly, e_image=instance.e_image, groups=groups,
                       name=f"{instance.name}[cluster]", kind="top")


def solve_orienteering(sub: TOPInstance, *, time_limit: float | None = 60.0, seed: int = 0,
                       bp_share: float = 0.4, milp_share: float = 0.5) -> Result:
    """Exact single-vehicle orienteering (with groups) by a portfolio of the suite's exact solvers.

    Both are exact and they are slow on different clusters: branch-and-price (``bp``, without its
    subset-row cuts) proves most clusters, the large ones (40-65 nodes) included, in well under a
    second, where the restricted MILP (:func:`solve_clustered_milp` with one cluster: knapsack
    budget row and incompatible sets on top of the time flow) needs seconds to minutes; but bp can
    label for a long time on a cluster whose nodes nearly all fit on one route (every subset fits,
    so few labels dominate), which the MILP proves at once. So: bp for ``bp_share`` of the time,
    then the MILP for ``milp_share`` of what is left (from bp's plan), then bp with the rest and its
    default cuts (from the best plan). The best verified plan and the smallest proven bound of all
    stages are returned; OPTIMAL when they meet, INFEASIBLE when a stage proves it.
    """
    from sarcover.formulations.bp import BPOptions, solve_bp  # numba: imported only when a cluster needs it

    t0 = time.perf_counter()
    deadline = None if time_limit is None else t0 + float(time_limit)
    best_plan, best_prize, bound, stages = None, -math.inf, math.inf, []

    def left() -> float | None:
        return None if deadline is None else max(deadline - time.perf_counter(), 0.0)

    def start() -> Plan | None:
        return best_plan if best_plan is not None and best_plan.routes[0] else None

    def take(res: Result, stage: str) -> Result | None:
        nonlocal best_plan, best_prize, bound
        stages.append([stage, str(res.status), round(res.runtime_s, 3)])
        if res.status == Status.INFEASIBLE:
            return Result("orienteering", Termination.INFEASIBLE, runtime_s=time.perf_counter() - t0,
                          reason=res.reason, info={"stages": stages})
        if res.plan is not None:
            rep = verify(sub, res.plan)
            if rep.valid and rep.prize > best_prize:
                best_plan, best_prize = res.plan, rep.prize
        if res.bound is not None and res.status != Status.ERROR:
            bound = min(bound, float(res.bound))
        if best_plan is not None and best_prize >= bound - 1e-9 * max(1.0, abs(bound)):
            return Result("orienteering", Termination.OPTIMAL, plan=best_plan, bound=best_prize,
                          runtime_s=time.perf_counter() - t0, info={"stages": stages})
        return None

    def more() -> bool:
        return left() is None or left() > 0

    first = 60.0 if deadline is None else bp_share * left()  # without a limit the later stages still get a turn
    done = take(solve_bp(sub, time_limit=first, options=BPOptions(cut_rounds=0)), "bp")
    if done is None and more():
        share = None if left() is None else milp_share * left()
        done = take(solve_clustered_milp(sub, [list(range(sub.n_nodes))], time_limit=share, seed=seed,
                                         warm_start=best_plan), "milp")
    if done is None and more():
        done = take(solve_bp(sub, time_limit=left(), warm_start=start()), "bp")
    if done is not None:
        return done
    return Result("orienteering", Termination.TIME_LIMIT, plan=best_plan,
                  bound=bound if math.isfinite(bound) else None, runtime_s=time.perf_counter() - t0,
                  reason="time limit", info={"stages": stages})


@dataclass(frozen=True)
class _Op:
    """One cluster's orienteering problem with a set of required groups, as solved."""

    bound: float  # proven upper bound on the cluster's prize (-inf: proven infeasible)
    route: tuple[int, ...] | None  # best route found (node ids of the instance), None if none
    prize: float
    proven: bool  # bound == prize, or infeasibility, is proven
    covers: frozenset  # groups the route visits


class _Decomposition:
    """The per-cluster orienteering problems of a clustering, solved once per required set."""

    def __init__(self, instance: TOPInstance, clusters: list[list[int]], deadline, seed: int):
        self.instance, self.deadline, self.seed = instance, deadline, seed
        reach = instance.reachable()
        self.nodes = [[v for v in c if reach[v]] for c in clusters]
        owner = cluster_of(self.nodes)
        # clusters able to cover each group (through a reachable node)
        self.where = [sorted({owner[v] for v in g if v in owner}) for g in instance.groups]
        self.memo: dict[tuple[int, frozenset], _Op] = {}
        self.solves, self.solve_s, self.stages = 0, 0.0, {}

    def left(self) -> float | None:
        return None if self.deadline is None else max(self.deadline - time.perf_counter(), 0.0)

    def op(self, i: int, required: frozenset) -> _Op:
        key = (i, required)
        if key not in self.memo:
            self.memo[key] = self._solve(i, required)
        return self.memo[key]

    def _solve(self, i: int, required: frozenset) -> _Op:
        nodes = self.nodes[i]
        if any(i not in self.where[g] for g in required):
            return _Op(-math.inf, None, -math.inf, True, frozenset())
        if not nodes:
            return _Op(0.0, (), 0.0, True, frozenset())
        t = time.perf_counter()
        res = solve_orienteering(cluster_instance(self.instance, nodes, required), time_limit=self.left(),
                                 seed=self.seed)
        self.solves += 1
        self.solve_s += time.perf_counter() - t
        for stage, status, _ in res.info.get("stages", []):
            self.stages[f"{stage}:{status}"] = self.stages.get(f"{stage}:{status}", 0) + 1
        if res.status == Status.INFEASIBLE:
            return _Op(-math.inf, None, -math.inf, True, frozenset())
        route = None if res.plan is None else tuple(nodes[k] for k in res.plan.routes[0])
        prize = -math.inf if route is None else float(sum(self.instance.prizes[v] for v in route))
        bound = math.inf if res.bound is None else float(res.bound)
        covers = frozenset() if route is None else frozenset(
            int(self.instance.group_of[v]) for v in route if self.instance.group_of[v] >= 0)
        return _Op(bound, route, prize, res.status == Status.OPTIMAL, covers)


def solve_clustered(
    instance: TOPInstance,
    clusters,
    *,
    time_limit: float | None = 60.0,
    seed: int = 0,
    warm_start: Plan | None = None,
) -> Result:
    """OPT|C exactly: per-cluster orienteering problems joined by branching on the split groups.

    Each cluster's single-vehicle orienteering problem is solved exactly (:func:`solve_orienteering`)
    with a set R_i of groups its route must cover, starting from R_i = the groups only cluster i can
    cover. A node of the search is (R_1 … R_N); its bound is the sum of the clusters' optima, a
    valid upper bound on every restricted plan whose route i covers R_i. If the clusters' optimal
    routes together cover every group they form a restricted plan of that value and the node is
    solved. Otherwise a group g that no route covers is branched on: one child per cluster k that
    can cover g, with g added to R_k. Every restricted plan covers g through some cluster, so it
    stays feasible in one child, and best-first search with pruning at the incumbent ends with the
    optimum. When no group is split the root is the answer (N independent orienteering problems).
    The plan has N routes, route i inside cluster i. ``warm_start``: a restricted plan (route i
    inside cluster i) used as the first incumbent.
    """
    t0 = time.perf_counter()
    deadline = None if time_limit is None else t0 + float(time_limit)
    clusters = normalise_clusters(instance, clusters)
    info: dict = {"clusters": clusters, "split_groups": split_groups(instance, clusters)}

    def result(status, plan=None, bound=None, reason=""):
        return Result(METHOD, status, plan=plan, bound=bound, runtime_s=time.perf_counter() - t0,
                      reason=reason, info=info)

    # no pre-check: the cluster check below finds every group out of reach, and more
    dec = _Decomposition(instance, clusters, deadline, seed)
    what = "target" if instance.kind == "sar" else "group"
    for gi, where in enumerate(dec.where):
        if not where:
            return result(Termination.INFEASIBLE, reason=f"{what} {gi} has no reachable node in any cluster")
    n = instance.n_vehicles
    best_plan, best_value = None, -math.inf
    if warm_start is not None and inside(warm_start, clusters):
        rep = verify(instance, warm_start)
        if rep.valid:
            best_plan, best_value = Plan.of(list(warm_start.routes) + [()] * (n - len(warm_start.routes))), rep.prize

    heap: list = []  # (-bound, counter, R) of nodes to branch on
    stuck: list[float] = []  # bounds of nodes left open because a cluster's problem was not proven
    counter = 0
    seen: set = set()

    def evaluate(R: tuple) -> None:
        nonlocal best_plan, best_value, counter
        ops = [dec.op(i, R[i]) for i in range(n)]
        if any(o.bound == -math.inf for o in ops):
            return  # some cluster cannot cover what it must
        bound = float(sum(o.bound for o in ops))
        if bound <= best_value + 1e-9:
            return
        if all(o.route is not None for o in ops):
            covered = frozenset().union(*(o.covers for o in ops))
            if len(covered) == len(instance.groups):
                value = float(sum(o.prize for o in ops))
                if value > best_value:
                    best_plan, best_value = Plan.of([o.route for o in ops]), value
                if not all(o.proven for o in ops) and bound > value + 1e-9:
                    stuck.append(bound)
                return
        counter += 1
        heapq.heappush(heap, (-bound, counter, R))

    root = tuple(frozenset(g for g, w in enumerate(dec.where) if w == [i]) for i in range(n))
    seen.add(root)
    evaluate(root)
    bb_nodes, open_bound = 1, None
    while heap:
        if best_value >= -heap[0][0] - 1e-9:
            break
        if dec.left() == 0.0:
            open_bound = -heap[0][0]
            break
        negb, _, R = heapq.heappop(heap)
        ops = [dec.op(i, R[i]) for i in range(n)]
        if any(o.route is None for o in ops):  # a cluster found no route in time: cannot branch
            stuck.append(-negb)
            continue
        covered = frozenset().union(*(o.covers for o in ops))
        open_groups = [g for g in range(len(instance.groups)) if g not in covered]
        g = min(open_groups, key=lambda g: (len(dec.where[g]), g))
        children = [tuple(R[i] | {g} if i == k else R[i] for i in range(n)) for k in dec.where[g]]
        for c, child in enumerate(children):
            if dec.left() == 0.0:  # out of time with children unsolved: the parent's bound stays open
                open_bound = max(-negb, -heap[0][0]) if heap else -negb
                break
            if child not in seen:
                seen.add(child)
                bb_nodes += 1
                evaluate(child)
        if open_bound is not None:
            break
    info.update(bb_nodes=bb_nodes, op_solves=dec.solves, op_time_s=round(dec.solve_s, 3), op_stages=dec.stages)
    bounds = [b for b in [open_bound, *stuck] if b is not None]
    bound = max([best_value, *bounds]) if (bounds or best_plan is not None) else None
    bound = bound if bound is not None and math.isfinite(bound) else None
    if best_plan is None:
        if open_bound is None and not stuck:
            return result(Termination.INFEASIBLE, reason=f"no plan with each route inside its own cluster covers "
                                                    f"every {what}")
        return result(Termination.TIME_LIMIT, bound=bound, reason="time limit before a restricted plan was found")
    rep = verify(instance, best_plan)
    if not rep.valid or not inside(best_plan, clusters):  # never report a plan outside the restriction
        return result(Termination.ERROR, reason="decomposed plan failed verification: " + "; ".join(rep.violations[:3]))
    if bound is None or bound <= best_value + 1e-9:
        return result(Termination.OPTIMAL, plan=best_plan, bound=best_value)
    return result(Termination.TIME_LIMIT, plan=best_plan, bound=bound, reason="time limit")



def oracle_clusters(instance: TOPInstance, plan: Plan, unvisited: str = "assign") -> list[list[int]]:
    """The clustering a plan induces: cluster i holds route i's nodes.

    ``unvisited="drop"`` leaves the nodes no route visits out of every cluster (a router then gets
    exactly the plan's node sets). ``"assign"`` puts each reachable unvisited node into the cluster
    whose route it joins at the least added energy (cheapest insertion, ties to the lower index),
    so that, like a clusterer's output, the clusters partition the reachable nodes and a router must
    also choose what to leave out. Either way the plan is a restricted plan of its own clustering,
    so OPT|C of an optimal plan's clustering is OPT.
    """
    if unvisited not in ("assign", "drop"):
        raise ValueError(f"unvisited must be 'assign' or 'drop', got {unvisited!r}")
    routes = [list(r) for r in plan.routes] + [[] for _ in range(instance.n_vehicles - len(plan.routes))]
    clusters = [list(r) for r in routes]
    if unvisited == "drop":
        return clusters
    C = instance.cost_matrix()
    end = instance.n_nodes + 1
    visited = {v for r in routes for v in r}
    for v in np.flatnonzero(instance.reachable()):
        if int(v) in visited:
            continue
        best, where = math.inf, 0
        for i, route in enumerate(routes):
            seq = [0, *(u + 1 for u in route), end]
            added = min(C[a, v + 1] + C[v + 1, b] - C[a, b] for a, b in zip(seq, seq[1:])) if route \
                else C[0, v + 1] + C[v + 1, end]
            if added < best - 1e-12:
                best, where = added, i
        clusters[where].append(int(v))
    return clusters


__all__ = ["METHOD", "cluster_instance", "cluster_of", "inside", "normalise_clusters", "restricted_graph",
           "oracle_clusters", "solve_clustered", "solve_clustered_milp", "solve_orienteering", "split_groups"]
