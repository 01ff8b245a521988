"""`routing`: the OR-Tools routing solver on the TOP form, guided local search (a heuristic: no bound).

:func:`solve_routing` is one search on the model below; :func:`routing` is the registered method:
a cold search gets ``COLD_SHARE`` of the time; if its best plan leaves a group uncovered, or
collects less than the `greedy` plan (which covers every group whenever greedy succeeds), a
second search starts from greedy's plan with the remaining time, and the better of the two plans
is returned. On tight SAR budgets the cold search sometimes never finds a covering plan, and with
little CPU it can end far below greedy. When the cold plan is at least greedy's, the second
search continues from the cold plan instead (a search from greedy's plan gave worse plans than a
cold one, ``docs/heuristics.md``), so the method uses the whole time limit it is given.

Model (the sequence of the OR-Tools samples: build, set limits and strategy, solve, extract):

- locations: 0 = start, 1..k = the k useful nodes (reachable alone within the budget, and with a
  prize or in a group), k+1 = end; one vehicle per UAV with ``starts=[0]*N``, ``ends=[k+1]*N``,
  so distinct start and end depots need nothing special.
- an ``energy`` dimension with the integer arc energies of :mod:`sarcover.formulations.scaling`
  (``ceil(scale*c_ij)``, capacity ``floor(scale*E_max)``): any plan the solver accepts is within
  the true budget. The start → end arc is 0 (an empty route costs nothing).
- one disjunction per node, penalty = its prize scaled so that the smallest prize outweighs any
  plan's total travel cost: collecting prize comes first, travel (the arc cost, energy scaled to
  1000 units per E_max) only breaks ties.
- groups ("at least one node of each group"): OR-Tools has no "at least one" disjunction (a
  penalised disjunction bounds the active count from above). Every group node v gets a cover
  copy at the same place: the disjunction {v, copy(v)} (at most one active, penalty prize_v if
  neither) keeps prizes exact and forbids double visits (a node may belong to several
  disjunctions in OR-Tools), and per group the disjunction {copies of its nodes} (at most one
  active) carries a penalty above all prizes and travel together, so covering every group
  comes first. A plan that still leaves a group uncovered comes back without a plan. The side
  constraint ``sum(ActiveVar) >= 1`` and a mandatory cover disjunction were tried: every
  first-solution strategy then failed (``docs/heuristics.md``).
- search: local cheapest insertion (or the given warm start), then guided local search,
  single-threaded. It stops at ``time_limit`` (the caller's, with no cap of its own) or after
  ``solution_limit`` solutions, whichever comes first. A run stopped by the solution limit is
  deterministic; one stopped by time is not (``info["stopped_by"]`` says which, and
  ``info["stop_reason"]`` is ``"iteration_limit"`` or ``"time_limit"``).
- anytime history (``info["history"]``, :mod:`sarcover.formulations.history`): a solution
  callback reads every solution the search accepts; one that lowers the search's objective and
  covers every group is decoded into a plan and its prize logged, so the last point of each
  search is the plan the search returns.
"""

from __future__ import annotations

import time

import numpy as np
from ortools.constraint_solver import pywrapcp, routing_enums_pb2

from sarcover.formulations.history import History, StopReason
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Result, Termination
from sarcover.formulations.scaling import integer_arcs, integer_prizes, scaled_costs
from sarcover.formulations.verify import verify
from sarcover.heuristics.greedy import greedy

SOLUTION_LIMIT = 1000  # local-search solutions; the reproducible stop (~1-10 s at 60 nodes)
METAHEURISTIC = "GUIDED_LOCAL_SEARCH"
FIRST_SOLUTION = "LOCAL_CHEAPEST_INSERTION"
GLS_LAMBDA = 10.0  # OR-Tools default 0.1; 10 cut the mean TOP gap from 5 % to 0.3-0.7 % (16 files, 3 s)
TIEBREAK_UNITS = 1000  # travel cost units per E_max in the objective (tie-break only)


def _useful_nodes(instance: TOPInstance) -> np.ndarray:
    """Node ids worth modelling: reachable alone, with a prize or belonging to a group."""
    keep = instance.reachable() & ((instance.prizes > 0) | (instance.group_of >= 0))
    return np.flatnonzero(keep)


def solve_routing(
    instance: TOPInstance,
    *,
    seed: int = 0,
    time_limit: float | None = 60.0,
    initial_routes: list[list[int]] | None = None,
    solution_limit: int = SOLUTION_LIMIT,
    metaheuristic: str = METAHEURISTIC,
    first_solution: str = FIRST_SOLUTION,
    gls_lambda: float = GLS_LAMBDA,
    history: History | None = None,
) -> Result:
    """Prize-collecting TOP by OR-Tools routing with guided local search.

    ``seed`` is unused (OR-Tools routing has no seed; the search is deterministic when stopped
    by ``solution_limit``). ``time_limit`` None: the solution limit alone stops it.
    ``initial_routes`` (node ids, e.g. a greedy plan) warm-starts the search; if the integer
    model rejects them (a route within rounding of the budget) the search starts from local
    cheapest insertion instead (``info["warm_start"]`` says which). ``metaheuristic``,
    ``first_solution``: names of OR-Tools' ``LocalSearchMetaheuristic`` and
    ``FirstSolutionStrategy``; ``gls_lambda``: guided local search's penalty coefficient.
    ``history``: where the search logs its improving plans (a caller running several searches
    passes one; by default the search keeps its own and ``info["history"]`` holds it).
    """
    t0 = time.perf_counter()
    own_history = history is None
    hist = History(t0) if own_history else history
    nodes = _useful_nodes(instance)
    k, n_veh = len(nodes), instance.n_vehicles
    def trivial(prize: float | None) -> dict:
        info = {"stopped_by": "trivial", "stop_reason": StopReason.COMPLETED.value}
        if own_history:
            hist.record(info, prize, None)
        return info

    if k == 0:
        if instance.groups:
            return Result("routing", Termination.COMPLETED, reason="no group node is reachable",
                          runtime_s=time.perf_counter() - t0, info=trivial(None))
        return Result("routing", Termination.COMPLETED, plan=Plan.of([[] for _ in range(n_veh)]),
                      runtime_s=time.perf_counter() - t0, info=trivial(0.0))

    # Groups: every group node v gets a "cover copy" at the same place. Disjunction {v, copy}
    # (at most one active, penalty prize_v if neither) keeps v's prize exact and forbids a
    # double visit; disjunction {copies of group g} with a negative penalty makes exactly one
    # copy per group mandatory. That is "at least one node per group" without side constraints.
    pos = {int(v): i + 1 for i, v in enumerate(nodes)}
    copies: list[int] = []  # node id of each cover copy, in model order after the originals
    group_locs: list[list[int]] = []
    for gi, group in enumerate(instance.groups):
        locs = []
        for v in group:
            if v in pos:
                copies.append(int(v))
                locs.append(k + len(copies))
        if not locs:
            return Result("routing", Termination.COMPLETED, reason=f"group {gi} has no reachable node",
                          runtime_s=time.perf_counter() - t0, info=trivial(None))
        group_locs.append(locs)
    model_nodes = np.concatenate([nodes, np.asarray(copies, dtype=int)]).astype(int)  # model loc - 1 -> node id
    n_loc = len(model_nodes) + 2

    sc = scaled_costs(instance)
    sel = np.concatenate([[0], model_nodes + 1, [instance.n_nodes + 1]])  # model order -> solver order
    energy = sc.arc[np.ix_(sel, sel)]
    # tie-break travel cost: TIEBREAK_UNITS per E_max, rounded up, start→end arc 0 like energy
    travel = integer_arcs(instance.cost_matrix()[np.ix_(sel, sel)], TIEBREAK_UNITS / max(instance.budget, 1e-300),
                          10 * TIEBREAK_UNITS)  # cut: arcs beyond the budget never fit
    np.fill_diagonal(travel, 0)
    travel[0, -1] = 0
    max_travel = n_veh * (TIEBREAK_UNITS + len(model_nodes) + 2)  # above any feasible plan's travel cost
    penalty = integer_prizes(instance.prizes[nodes], max_travel)

    manager = pywrapcp.RoutingIndexManager(n_loc, n_veh, [0] * n_veh, [n_loc - 1] * n_veh)
    model = pywrapcp.RoutingModel(manager)
    energy_cb = model.RegisterTransitMatrix(energy.tolist())
    travel_cb = model.RegisterTransitMatrix(travel.tolist())
    model.SetArcCostEvaluatorOfAllVehicles(travel_cb)
    model.AddDimension(energy_cb, 0, sc.budget, True, "energy")
    copy_of = {v: k + 1 + i for i, v in enumerate(copies)}
    for loc in range(1, k + 1):
        members = [loc] + ([copy_of[int(nodes[loc - 1])]] if int(nodes[loc - 1]) in copy_of else [])
        model.AddDisjunction([manager.NodeToIndex(loc_) for loc_ in members], int(penalty[loc - 1]), 1)
    group_penalty = int(penalty.sum()) + max_travel + 1  # one uncovered group outweighs everything else
    for locs in group_locs:
        model.AddDisjunction([manager.NodeToIndex(loc_) for loc_ in locs], group_penalty, 1)

    params = pywrapcp.DefaultRoutingSearchParameters()
    params.first_solution_strategy = getattr(routing_enums_pb2.FirstSolutionStrategy, first_solution)
    params.local_search_metaheuristic = getattr(routing_enums_pb2.LocalSearchMetaheuristic, metaheuristic)
    if metaheuristic == "GUIDED_LOCAL_SEARCH":
        params.guided_local_search_lambda_coefficient = gls_lambda
    remaining = None if time_limit is None else max(float(time_limit) - (time.perf_counter() - t0), 0.01)
    if remaining is not None:
        params.time_limit.FromMilliseconds(max(int(remaining * 1000), 10))
    params.log_search = False

    params.solution_limit = solution_limit
    warm = None
    if initial_routes is not None:
        covered: set[int] = set()
        loc_routes = []
        for route in initial_routes:
            locs = []
            for v in route:
                gi = int(instance.group_of[v])
                if gi >= 0 and gi not in covered and int(v) in copy_of:
                    covered.add(gi)
                    locs.append(copy_of[int(v)])  # the group's cover copy
                elif int(v) in pos:
                    locs.append(pos[int(v)])
            loc_routes.append([manager.NodeToIndex(loc_) for loc_ in locs])
        model.CloseModelWithParameters(params)
        warm = model.ReadAssignmentFromRoutes(loc_routes, True)
    def plan_routes(value) -> list[list[int]]:
        """The routes (node ids) of the current solution; ``value(var)`` reads a variable."""
        routes = []
        for veh in range(n_veh):
            idx, route = value(model.NextVar(model.Start(veh))), []
            while not model.IsEnd(idx):
                route.append(int(model_nodes[manager.IndexToNode(idx) - 1]))
                idx = value(model.NextVar(idx))
            routes.append(route)
        return routes

    group_sets = [set(int(v) for v in g) for g in instance.groups]
    seen = {"solutions": 0, "objective": None}

    def at_solution():
        seen["solutions"] += 1
        obj = model.CostVar().Value()
        if seen["objective"] is not None and obj >= seen["objective"]:
            return
        seen["objective"] = obj
        routes = plan_routes(lambda var: var.Value())
        visited = {v for r in routes for v in r}
        if all(visited.intersection(g) for g in group_sets):
            hist.update(float(sum(instance.prizes[v] for v in visited)))

    model.AddAtSolutionCallback(at_solution)
    t_solve = time.perf_counter()
    if warm is not None:
        solution = model.SolveFromAssignmentWithParameters(warm, params)
    else:
        solution = model.SolveWithParameters(params)
    solve_s = time.perf_counter() - t_solve
    by_solutions = seen["solutions"] >= solution_limit
    info = {"scale": sc.scale, "nodes_modelled": k, "time_limit_s": remaining, "solver_status": int(model.status()),
            "warm_start": warm is not None, "solutions": seen["solutions"],
            "stopped_by": "solution_limit" if by_solutions else "time",
            "stop_reason": (StopReason.ITERATION_LIMIT if by_solutions else StopReason.TIME_LIMIT).value}

    def done(termination, plan=None, reason=""):
        if own_history:
            hist.record(info, None if plan is None else float(sum(instance.prizes[v] for v in plan.visited)), None)
        return Result("routing", termination, plan=plan, reason=reason, runtime_s=time.perf_counter() - t0, info=info)

    if solution is None:
        what = "target" if instance.kind == "sar" else "group"
        reason = (f"OR-Tools routing found no plan covering every {what} in {solve_s:.3g} s"
                  if instance.groups else "OR-Tools routing found no solution")
        return done(Termination.COMPLETED, reason=reason)

    plan = Plan.of(plan_routes(solution.Value))
    routes = plan.routes
    visited = {v for r in routes for v in r}
    uncovered = [gi for gi, g in enumerate(instance.groups) if not visited.intersection(g)]
    if uncovered:
        what = "target" if instance.kind == "sar" else "group"
        info["uncovered"] = uncovered
        return done(Termination.COMPLETED,
                    reason=f"OR-Tools routing left {len(uncovered)} {what}(s) uncovered, e.g. {what} {uncovered[0]}")
    info["objective_int"] = int(solution.ObjectiveValue())
    report = verify(instance, plan)  # the integer model rounds up; this must never fail
    if not report.valid:
        return done(Termination.ERROR, plan, "routing plan failed verification: " + "; ".join(report.violations[:3]))
    return done(Termination.COMPLETED, plan)


COLD_SHARE = 0.6


def _prize(instance: TOPInstance, result: Result) -> float:
    """Prize of a result's plan (-1 without one, so any plan beats no plan)."""
    if result.plan is None or result.termination is Termination.ERROR:
        return -1.0
    return float(sum(instance.prizes[v] for v in result.plan.visited))


def routing(instance: TOPInstance, *, seed: int = 0, time_limit: float | None = 60.0, **search) -> Result:
    """OR-Tools routing heuristic: a plan or none, never a bound (``seed`` unused).

    ``time_limit`` (None: none, each search then ends at its solution limit) bounds the whole
    method, and the method uses all of it unless its searches end on their solution limits:
    with groups the cold search gets ``COLD_SHARE``, the second search the rest.
    ``info["history"]`` spans both searches; ``info["stop_reason"]`` is the last search's.
    ``search``: :func:`solve_routing`'s search settings (``solution_limit``, ``metaheuristic``,
    ``first_solution``, ``gls_lambda``) for both searches.
    """
    t0 = time.perf_counter()
    hist = History(t0)
    limit = None if time_limit is None else float(time_limit)
    result = solve_routing(instance, time_limit=COLD_SHARE * limit if instance.groups and limit is not None else limit,
                           history=hist, **search)
    result.info["phase"] = "cold"
    if instance.groups:
        remaining = None if limit is None else limit - (time.perf_counter() - t0)
        start, phase = greedy(instance), "greedy warm start"
        if _prize(instance, result) >= _prize(instance, start):
            start, phase = result, "continued from the cold plan"
        if start.plan is not None and (remaining is None or remaining > 0.05):
            warm = solve_routing(instance, time_limit=remaining, history=hist,
                                 initial_routes=[list(r) for r in start.plan.routes], **search)
            warm.info["phase"] = phase
            stop = warm.info.get("stop_reason")
            if _prize(instance, warm) >= _prize(instance, result):
                result = warm
            result.info["stop_reason"] = stop
        elif start.plan is not None:
            result.info["stop_reason"] = StopReason.TIME_LIMIT.value
    result.method = "routing"
    final = _prize(instance, result)
    hist.record(result.info, final if final >= 0 else None, None)
    result.runtime_s = time.perf_counter() - t0
    return result
