"""`pyvrp`: PyVRP's iterated local search as the strong peer a user would pick instead.

Model (PyVRP's ``Model`` builder):

- one location per useful node (reachable alone within the budget, with a prize or in a
  group), optional clients (``required=False``) with integer prizes, plus a start depot and,
  when it differs, an end depot; one vehicle type with ``num_available = N``,
  ``start_depot``/``end_depot``, ``max_distance = floor(S * E_max)``.
- energy folded into integer arc lengths, ``distance(i, j) = ceil(S * c_ij)`` with
  c_ij = e_fly·d_ij + e_image·[j is a node] (:mod:`sarcover.formulations.scaling`; S puts E_max at
  ``RESOLUTION`` units). Rounding arcs up and the budget down means every route PyVRP calls
  feasible is within the true budget (PyVRP would truncate floats, so we round ourselves).
- PyVRP minimises distance cost minus collected prizes. Prizes are scaled so that the smallest
  prize outweighs the largest possible total distance of a feasible plan (N·S·E_max), so the
  search maximises prize first and distance only breaks ties.
- groups: PyVRP's ``ClientGroup`` is mutually exclusive (a required group means exactly one of
  its clients), which does not express "at least one". Two passes:
  1. cover copies: per group a required client group of copies of its nodes (same place and
     prize), so exactly one copy per group is visited and PyVRP itself covers every group.
     PyVRP cannot forbid visiting a node and its copy both (that scores the prize twice; they
     are never adjacent), so such duplicates are dropped (never costs energy, triangle
     inequality) and the freed energy refilled (:func:`cover_groups` with ``refill``).
  2. no copies (so no double-prize distortion), warm-started from pass 1's plan; PyVRP may then
     drop group covers, so :func:`cover_groups` repairs coverage: each uncovered group gets its
     cheapest feasible insertion (hardest group first), evicting the visits with the least
     prize per saved energy (never a group's last visit) while nothing fits.
  The better covering plan wins (pass 1 on ties). Both passes together beat pass 1 alone; pass 2
  alone (cold, then repair) was worse and its repair could fail (``docs/heuristics.md``). No
  covering plan from either pass: no plan.
- stop: each pass ends at ``MaxIterations(iterations)`` (default :data:`ITERATIONS`, the
  reproducible stop: same seed, same plan) or at its share of the time limit (pass 1 at
  ``pass1_share`` of it, default :data:`PASS1_SHARE`, pass 2 at the limit itself), whichever
  comes first (``info[pass]["stopped_by"]``, its time in ``info[pass]["seconds"]``). The time
  limit is the caller's, with no cap of its own; ``iterations=None`` lets the time limit alone
  stop the passes. ``info["stop_reason"]`` is ``"iteration_limit"`` when both passes ended on
  their iterations, ``"time_limit"`` when the clock cut one short. Single-threaded.
- anytime history (``info["history"]``, :mod:`sarcover.formulations.history`): PyVRP's
  ``on_best`` callback hands over each new best solution; it is decoded and repaired exactly as
  the pass's final solution would be (pass 1: dedupe and refill; pass 2: group repair), and its
  prize is logged when it beats every plan so far. So the history's last incumbent is the
  returned plan's prize.
"""

from __future__ import annotations

import time
import warnings
from typing import Callable

import numpy as np
from pyvrp import Model, Solution
from pyvrp.IteratedLocalSearch import IteratedLocalSearchCallbacks, IteratedLocalSearchParams
from pyvrp.solve import SolveParams
from pyvrp.stop import MaxIterations, MaxRuntime, MultipleCriteria

from sarcover.formulations.history import History, StopReason
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Result, Termination
from sarcover.formulations.scaling import integer_prizes, scaled_costs
from sarcover.heuristics.insertion import RouteSet

RESOLUTION = 10**5  # integer distance units per E_max (rounding loses <= 1e-5 E_max per arc)
ITERATIONS = 2000  # ILS iterations per pass, the reproducible stop
PASS1_SHARE = 0.6  # with groups: share of the time limit pass 1 may use
# bp's later, time-stopped calls: pass 1 only finds a covering start, pass 2 improves it (at
# 360-600 points pass 2 gains in seconds what pass 1 does not in minutes; docs/heuristics.md)
LATE_PASS1_SHARE = 0.1


def _useful_nodes(instance: TOPInstance) -> np.ndarray:
    keep = instance.reachable() & ((instance.prizes > 0) | (instance.group_of >= 0))
    return np.flatnonzero(keep)


def _load(instance: TOPInstance, routes) -> RouteSet:
    rs = RouteSet(instance)
    for r, route in enumerate(routes):
        rs.routes[r] = [int(v) + 1 for v in route]
        seq = [0, *rs.routes[r], rs.end]
        rs.energy[r] = float(sum(rs.cost[a, b] for a, b in zip(seq, seq[1:]))) if route else 0.0
        rs.visited[rs.routes[r]] = True
    return rs


def _remove(rs: RouteSet, r: int, p: int) -> None:
    route = rs.routes[r]
    seq = [0, *route, rs.end]
    a, v, b = seq[p], seq[p + 1], seq[p + 2]
    route.pop(p)
    rs.energy[r] = rs.energy[r] - rs.cost[a, v] - rs.cost[v, b] + (rs.cost[a, b] if route else 0.0)
    if not route:
        rs.energy[r] = 0.0
    rs.visited[v] = False


def _prize(instance: TOPInstance, routes) -> float:
    return float(sum(instance.prizes[v] for r in routes for v in r))


def cover_groups(instance: TOPInstance, routes, refill: bool = False) -> list[list[int]] | None:
    """Repair a within-budget plan (node ids) so that every group is covered; None if stuck.

    Uncovered groups are inserted hardest first (the group whose cheapest feasible insertion
    costs most). When no node of a group fits anywhere, the visit with the least prize per
    saved energy whose group keeps another visit is removed, and the insertion is retried.
    If anything changed (or ``refill``), freed energy is refilled by the best prize per added
    energy.
    """
    rs = _load(instance, routes)
    reach = instance.reachable()
    group_nodes = [np.array([v + 1 for v in g if reach[v]], dtype=int) for g in instance.groups]
    prizes = instance.prizes

    def uncovered() -> list[int]:
        return [gi for gi, nodes in enumerate(group_nodes) if not rs.visited[nodes].any()]

    todo = uncovered()
    changed = bool(todo) or refill
    while todo:
        options = [(gi, rs.best_insertion(group_nodes[gi])) for gi in todo]
        stuck = [gi for gi, best in options if best is None]
        if not stuck:
            gi, best = max(options, key=lambda o: -o[1][0])  # cheapest insertion, most expensive first
            _, node, r, p, delta = best
            rs.insert(node, r, p, delta)
            todo = uncovered()
            continue
        # free energy: drop the visit with the least prize per saved energy, keeping group covers
        best_drop = None
        for r, route in enumerate(rs.routes):
            seq = [0, *route, rs.end]
            for p, v in enumerate(route):
                gi = int(instance.group_of[v - 1])
                if gi >= 0 and int(rs.visited[group_nodes[gi]].sum()) <= 1:
                    continue
                a, b = seq[p], seq[p + 2]
                saving = rs.cost[a, v] + rs.cost[v, b] - (rs.cost[a, b] if len(route) > 1 else 0.0)
                ratio = prizes[v - 1] / max(saving, 1e-12)
                if best_drop is None or ratio < best_drop[0]:
                    best_drop = (ratio, r, p)
        if best_drop is None:
            return None
        _remove(rs, best_drop[1], best_drop[2])
    if changed:
        idx = np.flatnonzero(reach & (prizes > 0)) + 1
        while True:
            free = idx[~rs.visited[idx]]
            if free.size == 0:
                break

            def score(delta, nodes):
                p = prizes[nodes - 1][:, None]
                return p / np.maximum(delta, 1e-12)

            best = rs.best_insertion(free, score)
            if best is None:
                break
            _, node, r, p, delta = best
            rs.insert(node, r, p, delta)
    return rs.node_routes()


def _with_callbacks(solve_params: SolveParams | None, callbacks) -> SolveParams:
    """``solve_params`` (None: PyVRP's defaults) with ``callbacks`` in its ILS parameters."""
    base = SolveParams() if solve_params is None else solve_params
    ils = IteratedLocalSearchParams(num_iters_no_improvement=base.ils.num_iters_no_improvement,
                                    history_length=base.ils.history_length,
                                    exhaustive_on_best=base.ils.exhaustive_on_best, callbacks=callbacks)
    return SolveParams(ils=ils, penalty=base.penalty, neighbourhood=base.neighbourhood, operators=base.operators,
                       display_interval=base.display_interval, perturbation=base.perturbation)


class _OnBest(IteratedLocalSearchCallbacks):
    """Hands each new feasible best solution of the search to ``see`` (PyVRP's ``on_best``)."""

    def __init__(self, see: Callable[[Solution], None]):
        self.see = see

    def on_best(self, best: Solution):
        if best.is_feasible():
            self.see(best)


def _routes(best: Solution, client_nodes: np.ndarray, n_veh: int) -> tuple[list[list[int]], int]:
    """A PyVRP solution as routes of node ids, and how many duplicate visits (a node visited as
    itself and as its cover copy) were dropped: the first visit is kept (never costs more)."""
    routes: list[list[int]] = [[] for _ in range(n_veh)]
    seen: set[int] = set()
    duplicates = 0
    for r, route in enumerate(best.routes()):
        for act in route:
            if not act.is_client():
                continue
            v = int(client_nodes[act.idx])
            if v in seen:
                duplicates += 1
            else:
                seen.add(v)
                routes[r].append(v)
    return routes, duplicates


def _solve(instance: TOPInstance, nodes: np.ndarray, with_covers: bool, seed: int, deadline: float | None,
           initial: list[list[int]] | None = None, iterations: int | None = ITERATIONS,
           on_routes: Callable[[list[list[int]], int], None] | None = None, solve_params=None):
    """One PyVRP run; returns (routes as node ids or None if PyVRP found no feasible plan, info).

    ``deadline`` (a ``time.perf_counter()`` value, None: none) stops the search; ``initial``
    (node ids, without covers only) is PyVRP's warm start; ``iterations``: the ILS iterations at
    most (None: the deadline alone stops it). ``on_routes(routes, duplicates)`` sees each new
    feasible best solution during the search, as :func:`_routes` decodes it; ``solve_params``:
    PyVRP's ``SolveParams`` (None: its defaults; the callbacks are added to a copy)."""
    n_veh = instance.n_vehicles
    sc = scaled_costs(instance, RESOLUTION)
    end = instance.n_nodes + 1
    prize_int = integer_prizes(instance.prizes[nodes], n_veh * sc.budget + 1)
    m = Model()
    start_loc = m.add_location(float(instance.start[0]), float(instance.start[1]), name="start")
    start = m.add_depot(start_loc, name="start")
    if instance.same_depot:
        end_loc, end_depot, depot_locs = start_loc, start, [(start_loc, 0, end)]
    else:
        end_loc = m.add_location(float(instance.end[0]), float(instance.end[1]), name="end")
        end_depot = m.add_depot(end_loc, name="end")
        depot_locs = [(start_loc, 0, None), (end_loc, None, end)]
    m.add_vehicle_type(num_available=n_veh, start_depot=start, end_depot=end_depot,
                       max_distance=sc.budget, unit_distance_cost=1)
    locs = []  # (location, solver index)
    for i, v in enumerate(nodes):
        loc = m.add_location(float(instance.coords[v, 0]), float(instance.coords[v, 1]), name=str(v))
        m.add_client(loc, prize=int(prize_int[i]), required=False, name=str(v))
        locs.append((loc, int(v) + 1))
    if with_covers:  # a required (mutually exclusive: exactly one) group of cover copies per group
        pos = {int(v): i for i, v in enumerate(nodes)}
        for gi, group in enumerate(instance.groups):
            members = [int(v) for v in group if int(v) in pos]
            if not members:
                continue
            cg = m.add_client_group(required=True, name=f"group {gi}")
            for v in members:
                loc = m.add_location(float(instance.coords[v, 0]), float(instance.coords[v, 1]), name=f"cover {v}")
                m.add_client(loc, prize=int(prize_int[pos[v]]), required=False, group=cg, name=f"cover {v}")
                locs.append((loc, v + 1))
    client_nodes = np.array([i - 1 for _, i in locs], dtype=int)  # PyVRP client index -> node id
    big = int(sc.budget) + 1  # arcs no feasible route uses
    for loc_a, ia in locs:
        for loc_b, ib in locs:
            if loc_a is not loc_b:  # a node and its cover copy are never adjacent
                m.add_edge(loc_a, loc_b, int(sc.arc[ia, ib]) if ia != ib else big)
    for dloc, out_idx, in_idx in depot_locs:
        for loc, i in locs:
            m.add_edge(dloc, loc, int(sc.arc[out_idx, i]) if out_idx is not None else big)
            m.add_edge(loc, dloc, int(sc.arc[i, in_idx]) if in_idx is not None else big)
    if not instance.same_depot:
        m.add_edge(start_loc, end_loc, 0)  # an empty route costs nothing
        m.add_edge(end_loc, start_loc, big)
    with warnings.catch_warnings(record=True) as caught:  # PenaltyBoundWarning on (near-)infeasible data
        warnings.simplefilter("always")
        start_sol = None
        if initial is not None and not with_covers:
            client_of = {int(v): i for i, v in enumerate(nodes)}
            start_sol = Solution(m.data(), [[client_of[v] for v in r] for r in initial if r])
        criteria = [] if iterations is None else [MaxIterations(iterations)]
        if deadline is not None:  # what is left of the deadline once the model is built
            criteria.append(MaxRuntime(max(deadline - time.perf_counter(), 0.01)))
        if not criteria:
            raise ValueError("pyvrp needs a time limit or an iteration limit")
        stop = criteria[0] if len(criteria) == 1 else MultipleCriteria(criteria)
        callbacks = None if on_routes is None else _OnBest(lambda sol: on_routes(*_routes(sol, client_nodes, n_veh)))
        params = _with_callbacks(solve_params, callbacks)
        res = m.solve(stop, seed=seed, collect_stats=False, display=False, params=params,
                      initial_solution=start_sol)
    best = res.best
    by_iterations = iterations is not None and res.num_iterations >= iterations
    info = {"scale": sc.scale, "iterations": int(res.num_iterations), "seconds": float(res.runtime),
            "covers": with_covers,
            "stopped_by": "iterations" if by_iterations else "time",
            "warnings": sorted({type(w.message).__name__ for w in caught})}
    if not best.is_feasible():
        return None, info
    routes, duplicates = _routes(best, client_nodes, n_veh)
    info["duplicates_dropped"] = duplicates
    return routes, info


def pyvrp(instance: TOPInstance, *, seed: int = 0, time_limit: float | None = 60.0,
          iterations: int | None = ITERATIONS, solve_params=None, pass1_share: float = PASS1_SHARE) -> Result:
    """Prize-collecting TOP by PyVRP (seeded, iteration-limited) plus group repair.

    With groups, pass 1 uses cover copies; pass 2 starts from pass 1's plan without them and
    repairs coverage afterwards (see the module docstring). ``iterations``: each pass's ILS
    iterations at most (None: only the time limit stops the passes); ``time_limit``: the
    seconds the whole method may take (None: none, then ``iterations`` must be given);
    ``solve_params``: PyVRP's ``SolveParams`` for each pass (None: PyVRP's defaults);
    ``pass1_share``: the share of the time limit pass 1 may take (with groups), in (0, 1].
    """
    if not 0.0 < pass1_share <= 1.0:
        raise ValueError(f"pass1_share must be in (0, 1], got {pass1_share}")
    t0 = time.perf_counter()
    hist = History(t0)
    deadline = None if time_limit is None else t0 + float(time_limit)
    nodes = _useful_nodes(instance)
    info: dict = {"nodes_modelled": int(len(nodes))}
    what = "target" if instance.kind == "sar" else "group"

    def done(routes, reason: str = "") -> Result:
        passes = [info[p] for p in ("pass1", "pass2") if p in info] or [info]
        skipped = "pass1" in info and "pass2" not in info  # the clock left pass 2 no time
        timed = skipped or any(p.get("stopped_by") == "time" for p in passes)
        if "stop_reason" not in info:
            info["stop_reason"] = (StopReason.TIME_LIMIT if timed else StopReason.ITERATION_LIMIT).value
        plan = None if routes is None else Plan.of(routes)
        hist.record(info, None if plan is None else _prize(instance, plan.routes), None)
        return Result("pyvrp", Termination.COMPLETED, plan=plan, reason=reason,
                      runtime_s=time.perf_counter() - t0, info=info)

    def seen(routes) -> None:
        if routes is not None:
            hist.update(_prize(instance, routes))

    if len(nodes) == 0:
        info["stop_reason"] = StopReason.COMPLETED.value
        if instance.groups:
            return done(None, f"no {what} node is reachable")
        info["stopped_by"] = "trivial"
        return done([[] for _ in range(instance.n_vehicles)])
    if not instance.groups:
        def plain(routes, duplicates):
            return cover_groups(instance, routes, refill=True) if duplicates else routes

        routes, run_info = _solve(instance, nodes, False, seed, deadline, iterations=iterations,
                                  on_routes=lambda r, d: seen(plain(r, d)), solve_params=solve_params)
        info.update(run_info)
        if routes is None:
            return done(None, "PyVRP found no plan within the budget")
        return done(plain(routes, run_info["duplicates_dropped"]))

    # pass 1: cover copies, so PyVRP itself covers every group; then dedupe and refill
    def first(routes, duplicates):
        return cover_groups(instance, routes, refill=bool(duplicates))

    reason = "PyVRP found no plan within the budget"
    best_routes = None
    share = None if deadline is None else t0 + pass1_share * float(time_limit)
    routes, run_info = _solve(instance, nodes, True, seed, share, iterations=iterations,
                              on_routes=lambda r, d: seen(first(r, d)), solve_params=solve_params)
    info["pass1"] = run_info
    if routes is not None:
        best_routes = first(routes, run_info["duplicates_dropped"])
        seen(best_routes)
    # pass 2: no covers (no duplicate distortion), warm-started from pass 1; repair coverage after
    if deadline is None or deadline - time.perf_counter() > 0.05:
        routes, run_info = _solve(instance, nodes, False, seed, deadline, initial=best_routes,
                                  iterations=iterations, on_routes=lambda r, d: seen(cover_groups(instance, r)),
                                  solve_params=solve_params)
        info["pass2"] = run_info
        if routes is not None:
            repaired = cover_groups(instance, routes)
            if repaired is None:
                reason = f"PyVRP's plan leaves a {what} uncovered and the repair found no room"
            elif best_routes is None or _prize(instance, repaired) > _prize(instance, best_routes) + 1e-9:
                best_routes = repaired
                info["best_pass"] = 2
    if best_routes is not None:
        info.setdefault("best_pass", 1)
        return done(best_routes)
    return done(None, reason)


def primal_routes(instance: TOPInstance, seed: int, late_pass1_share: float = LATE_PASS1_SHARE):
    """A primal heuristic for bp: ``run(seconds)`` returns PyVRP's routes (node ids) found within
    that time, or None without a plan. The first call is the registered method (``seed``,
    ``ITERATIONS`` per pass: a good plan in a few seconds); each later call searches with a new
    seed until its time is up, since on M = 20, K = 3 PyVRP still finds better plans after 2000
    iterations and another seed finds others, and on K = 5-6 a longer search finds better ones
    still (docs/bp.md): those calls take all the seconds bp gives them, pass 1 (cover copies)
    only ``late_pass1_share`` of them, since pass 2 is where a long search gains."""
    calls = 0

    def run(seconds: float):
        nonlocal calls
        first = calls == 0
        res = pyvrp(instance, seed=seed + calls, time_limit=max(seconds, 0.05),
                    iterations=ITERATIONS if first else None,
                    pass1_share=PASS1_SHARE if first else late_pass1_share)
        calls += 1
        return None if res.plan is None else [list(r) for r in res.plan.routes]

    return run
