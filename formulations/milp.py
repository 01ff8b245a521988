"""`milp`: the team orienteering problem as a compact MILP on HiGHS, through Pyomo.

The model (:func:`build_milp`) is the two-index single-commodity "time-flow" formulation of the
TOP literature (Bianchessi, Mansini & Speranza 2018), aggregated over vehicles, so it has no
vehicle symmetry at all:

- ``x[i, j]`` binary: some vehicle travels arc (i, j); only arcs that a route within the budget
  can use exist (:func:`sarcover.formulations.preprocess.prune_arcs`).
- ``y[i]`` binary: node i is visited; ``sum(x[start, j]) <= N`` vehicles leave the start.
- ``z[i, j] >= 0``: the energy a vehicle has used when it arrives at j over (i, j). Flow
  conservation at a node adds the cost of the arc leaving it; the lifted bounds
  ``(c_0i + c_ij) x_ij <= z_ij <= (B - c_j,end) x_ij`` are the per-route budget (the paper's
  constraint (3)) with the tightest big-M the triangle inequality gives.
- each node at most once (4): in-degree = out-degree = ``y[i]``; each group at least one
  visited node (5); maximise the prize.

Valid inequalities added up front (they are what makes the root bound usable, see the table):

- 2-cycles ``x_ij + x_ji <= y_i, y_j``;
- incompatibility cliques: nodes no two of which fit on one route (by the triangle inequality,
  :func:`sarcover.formulations.preprocess.incompatible_cliques`): ``sum_K y <= vehicles used``;
- infeasible 2-arc paths: ``x_ik + sum_j x_kj <= y_k`` over the j that cannot follow i -> k.

Flow strictly increases along an arc of positive cost, so subtours can appear only among
coincident free points; they, and violated connectivity cuts (and LP-weighted cliques) of the
LP relaxation, are added in a loop (HiGHS has no cut callback): :func:`solve_milp` first runs a
few rounds of LP relaxation + cut separation (max-flow), then solves the MIP, checks the plan
for subtours and with the independent verifier, and re-solves with a cut if needed.

Root LP bound (after connectivity rounds) on TOP instances, optimum in brackets: p1.3.j (115)
plain 127.1, +2-cycles 125.8, +cliques 124.1, +paths 123.4; p3.3.k (440) 485.9 -> 473.1 with
cliques; p3.4.r (600) 653.6 -> 610.0 with cliques. Vehicle symmetry does not exist in the
aggregated model; a warm start (``warm_start=``) is accepted but greedy's plans are far below
what HiGHS's own heuristics find in the first seconds, so the registered method does not use it.

Exactness: HiGHS runs with ``mip_rel_gap = 0`` and, for integer prizes, an absolute gap below
the prize lattice step; the model budget is the verifier's own acceptance threshold, so no plan
the verifier accepts is cut off (the bound is valid). A plan HiGHS returns that the verifier
rejects (possible only within HiGHS's feasibility tolerance) is never reported: its route is cut
off by a no-good cut, which removes only that infeasible route, and the model is re-solved.

Time limit: every HiGHS solve is limited to end by the run's deadline. The model is translated
for HiGHS once, before the time left is taken. HiGHS stops an LP solve on its run clock, which goes
on over every solve of one model (a MIP solve counts from its own start), so an LP round's limit
is that clock plus the time left. HiGHS's MIP presolve does not check the clock everywhere, so a
MILP given less time than an LP round took (too little to solve its own root LP) runs without it,
and one given less than a second (or than an LP round took, if that was shorter) is not started.
What may still pass the deadline: HiGHS's setup of a MIP before its first check of the clock
(seconds at 120 points, docs/scale.md), and the root's separation rounds of a MIP, between
which it checks.

Anytime history (``info["history"]``, see :mod:`sarcover.formulations.history`): ``[t, incumbent, bound]``
points in prize units, t from the call of :func:`solve_milp`. Incumbents are verified plans only:
the warm start, and every improving MIP solution HiGHS reports (``cbMipImprovingSolution``, read
back into routes; a solution with subtours counts with its routes from the depot only, and only
if the verifier accepts them), so every incumbent is at most the optimum. Bounds are the LP bound
after each root cut round, and HiGHS's MIP dual bound during every solve of the loop
(``cbMipInterrupt``) and at its end, each rounded down to the prize lattice. They are all valid:
every model in the loop, relaxed or not and before or after any cut, is a relaxation of the
verifier's problem (the cuts are connectivity cuts, valid for every plan, and no-good cuts that
remove only routes the verifier rejects), so its LP or MIP dual bound is at least the optimum.
The callbacks are installed on the ``highspy.Highs`` object behind Pyomo's interface (a private
attribute); if that is not reachable, only the points at the end of each solve are recorded.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np
import pyomo.environ as pyo
from pyomo.contrib.solver.common.factory import SolverFactory
from pyomo.contrib.solver.common.results import TerminationCondition
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import maximum_flow

from sarcover.formulations.history import History, stop_reason_of
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Result, Termination
from sarcover.formulations.preprocess import (
    ArcGraph,
    floor_to_lattice,
    incompatibility,
    incompatible_cliques,
    prize_lattice,
    prune_arcs,
)
from sarcover.formulations.verify import verify

METHOD = "milp"
_CUT_TOL = 1e-4  # a connectivity cut is added when violated by more than this


def build_milp(
    instance: TOPInstance, graph: ArcGraph | None = None, *, two_cycle: bool = True, cliques: bool = True,
    paths: bool = True,
) -> pyo.ConcreteModel:
    """The time-flow TOP model of ``instance`` (see the module docstring). Pure: solves nothing.

    ``graph`` is the pruned arc set (computed if omitted). ``two_cycle`` adds
    x_ij + x_ji <= y_i for node pairs, which removes 2-node subtours and tightens the LP.
    ``cliques`` adds sum_{i in K} y_i <= (vehicles used) for sets K of pairwise incompatible
    nodes (:func:`sarcover.formulations.preprocess.incompatible_cliques`): a route visits at most one.
    Components: sets ``N`` (node solver indices), ``A`` (arcs); variables ``x``, ``y``, ``z``;
    ``cuts`` is an empty ConstraintList for the cuts added while solving.
    """
    g = prune_arcs(instance) if graph is None else graph
    cost, budget, s, e = g.cost, g.budget, g.start, g.end
    m = pyo.ConcreteModel(name=f"top_timeflow[{instance.name}]")
    m.N = pyo.Set(initialize=list(g.nodes), ordered=True, doc="reachable nodes (solver index = node id + 1)")
    m.A = pyo.Set(initialize=list(g.arcs), dimen=2, ordered=True, doc="arcs some within-budget route can use")
    out_arcs: dict[int, list] = {i: [] for i in (s, *g.nodes)}
    in_arcs: dict[int, list] = {j: [] for j in (*g.nodes, e)}
    for i, j in g.arcs:
        out_arcs[i].append((i, j))
        in_arcs[j].append((i, j))

    m.x = pyo.Var(m.A, domain=pyo.Binary, doc="1 if a vehicle travels the arc")
    m.y = pyo.Var(m.N, domain=pyo.Binary, doc="1 if the node is visited")
    m.z = pyo.Var(m.A, domain=pyo.NonNegativeReals, doc="energy used on arrival at the arc's head")

    m.prize = pyo.Objective(
        expr=sum(float(instance.prizes[i - 1]) * m.y[i] for i in m.N), sense=pyo.maximize,
        doc="total prize of the visited nodes",
    )

    @m.Constraint(m.N, doc="(4) a visited node is left exactly once")
    def leave(m, i):
        return sum(m.x[a] for a in out_arcs[i]) == m.y[i]

    @m.Constraint(m.N, doc="(4) a visited node is entered exactly once")
    def enter(m, j):
        return sum(m.x[a] for a in in_arcs[j]) == m.y[j]

    m.fleet = pyo.Constraint(expr=sum(m.x[a] for a in out_arcs[s]) <= instance.n_vehicles,
                             doc="at most N vehicles leave the start")

    @m.Constraint(range(len(instance.groups)), doc="(5) every group has a visited node")
    def cover(m, gi):
        nodes = [v + 1 for v in instance.groups[gi] if v + 1 in m.N]
        if not nodes:
            return pyo.Constraint.Infeasible
        return sum(m.y[i] for i in nodes) >= 1

    @m.Constraint(m.N, doc="time flow: out-flow = in-flow + cost of the arc taken out")
    def flow(m, i):
        return (sum(m.z[a] for a in out_arcs[i]) - sum(m.z[a] for a in in_arcs[i])
                == sum(float(cost[a]) * m.x[a] for a in out_arcs[i]))

    @m.Constraint(out_arcs[s], doc="time flow leaving the start is the first arc's cost")
    def flow_start(m, i, j):
        return m.z[i, j] == float(cost[i, j]) * m.x[i, j]

    @m.Constraint(m.A, doc="(3) lifted budget: z_ij <= (B - c_j,end) x_ij")
    def budget_ub(m, i, j):
        cap = budget if j == e else budget - float(g.to_end[j])
        return m.z[i, j] <= max(cap, 0.0) * m.x[i, j]

    @m.Constraint([a for a in g.arcs if a[0] != s], doc="lifted lower bound: z_ij >= (c_0i + c_ij) x_ij")
    def budget_lb(m, i, j):
        return m.z[i, j] >= float(g.from_start[i] + cost[i, j]) * m.x[i, j]

    pairs = [(i, j) for (i, j) in g.arcs if i != s and j != e and i < j and (j, i) in m.A] if two_cycle else []

    @m.Constraint(pairs, doc="no 2-node subtour: x_ij + x_ji <= y_i, y_j")
    def two_cycle_i(m, i, j):
        return m.x[i, j] + m.x[j, i] <= m.y[i]

    @m.Constraint(pairs, doc="no 2-node subtour: x_ij + x_ji <= y_j")
    def two_cycle_j(m, i, j):
        return m.x[i, j] + m.x[j, i] <= m.y[j]

    cl = incompatible_cliques(g, instance.n_vehicles) if cliques else []
    m._clique_sets = list(cl)  # for the solve loop: cliques already in the model

    @m.Constraint(range(len(cl)), doc="a route visits at most one node of a pairwise-incompatible set")
    def clique(m, k):
        return sum(m.y[i] for i in cl[k]) <= sum(m.x[a] for a in out_arcs[s])

    # Infeasible 2-arc paths i -> k -> j (c_0i + c_ik + c_kj + c_j,end > B): after entering k
    # from i a vehicle cannot leave to any such j, so x_ik + sum_j x_kj <= y_k.
    limit = budget * (1.0 + 1e-9)
    path_rows = []
    if paths:
        for i, k in g.arcs:
            if i == s or k == e:
                continue
            base = float(g.from_start[i] + cost[i, k])
            bad = [(k2, j) for (k2, j) in out_arcs[k] if j != i and j != e and base + cost[k, j] + g.to_end[j] > limit]
            if bad:
                path_rows.append(((i, k), bad))

    @m.Constraint(range(len(path_rows)), doc="no infeasible 2-arc path i -> k -> j")
    def path(m, r):
        (i, k), bad = path_rows[r]
        return m.x[i, k] + sum(m.x[a] for a in bad) <= m.y[k]

    m.cuts = pyo.ConstraintList(doc="connectivity and no-good cuts added while solving")
    m._graph = g  # kept for the solve loop (not a Pyomo component)
    return m


# ---------------------------------------------------------------- reading solutions and cuts


def _values(var) -> dict:
    return {k: (v.value if v.value is not None else 0.0) for k, v in var.items()}


def _routes(g: ArcGraph, xval: dict) -> tuple[list[list[int]], set[int], dict[int, int]]:
    """Routes (solver indices) followed from the start, nodes left on subtours, successor map."""
    succ: dict[int, int] = {}
    for (i, j), v in xval.items():
        if v > 0.5:
            succ.setdefault(i, j)  # an integer solution has one out-arc per visited node
    firsts = [j for (i, j), v in xval.items() if i == g.start and v > 0.5]
    routes, seen = [], set()
    for j in firsts:
        route = []
        while j != g.end and j not in seen:
            seen.add(j)
            route.append(j)
            j = succ.get(j, g.end)
        routes.append(route)
    stray = {i for i in succ if i != g.start and i not in seen}
    return routes, stray, succ


def _cycles(stray: set[int], succ: dict[int, int]) -> list[list[int]]:
    cycles, left = [], set(stray)
    while left:
        i = min(left)
        cyc = []
        while i in left:
            left.discard(i)
            cyc.append(i)
            i = succ.get(i, -1)
        cycles.append(cyc)
    return cycles


def _add_connectivity_cut(m, subset: set[int]) -> None:
    """sum of x over arcs entering S >= y_k for every k in S (S contains no depot)."""
    inflow = [a for a in m.A if a[1] in subset and a[0] not in subset]
    for k in subset:
        m.cuts.add(sum(m.x[a] for a in inflow) >= m.y[k])


def _separate_lp(m, g: ArcGraph, xval: dict, yval: dict, max_cuts: int = 40) -> int:
    """Connectivity cuts violated by a fractional point: min start→k cut < y_k (max-flow)."""
    size = g.n_nodes + 2
    scale = 1_000_000
    rows, cols, caps = [], [], []
    for (i, j), v in xval.items():
        c = int(v * scale)
        if c > 0:
            rows.append(i)
            cols.append(j)
            caps.append(c)
    if not caps:
        return 0
    cap = csr_matrix((np.array(caps, dtype=np.int32), (rows, cols)), shape=(size, size))
    added, covered = 0, set()
    order = sorted(g.nodes, key=lambda k: -yval[k])
    for k in order:
        if added >= max_cuts or yval[k] < _CUT_TOL or k in covered:
            continue
        res = maximum_flow(cap, g.start, k)
        if res.flow_value >= (yval[k] - _CUT_TOL) * scale:
            continue
        # source side of the min cut: reachable from the start in the residual graph
        residual = (cap - res.flow).tocsr()
        residual.data = np.where(residual.data > 0, residual.data, 0)
        residual.eliminate_zeros()
        reach = {g.start}
        stack = [g.start]
        while stack:
            u = stack.pop()
            for w in residual.indices[residual.indptr[u]:residual.indptr[u + 1]]:
                if w not in reach:
                    reach.add(int(w))
                    stack.append(int(w))
        subset = {i for i in g.nodes if i not in reach}
        if k not in subset:
            continue
        _add_connectivity_cut(m, subset)
        covered |= subset
        added += 1
    return added


def _separate_cliques(m, g: ArcGraph, inc: np.ndarray, yval: dict, xval: dict, n_vehicles: int) -> int:
    """Clique inequalities violated by a fractional point, grown greedily by LP weight."""
    w = np.array([yval[i] for i in g.nodes])
    used = sum(v for (i, _), v in xval.items() if i == g.start)
    have = {tuple(sorted(c)) for c in getattr(m, "_clique_sets", [])}
    added = 0
    for cl in incompatible_cliques(g, n_vehicles, weights=w, inc=inc):
        if cl in have or sum(yval[i] for i in cl) <= used + _CUT_TOL:
            continue
        m.cuts.add(sum(m.y[i] for i in cl) <= sum(m.x[a] for a in m.A if a[0] == g.start))
        have.add(cl)
        added += 1
    m._clique_sets = list(have)
    return added


# ---------------------------------------------------------------- the solve loop


@dataclass
class _Best:
    plan: Plan | None = None
    prize: float = -math.inf


def _to_plan(routes: list[list[int]]) -> Plan:
    return Plan.of([[i - 1 for i in r] for r in routes if r])


def _set_warm_start(opt, m, plan: Plan, g: ArcGraph) -> bool:
    """Give HiGHS a starting solution (x, y, z) built from ``plan``; False if it does not fit."""
    x = {a: 0.0 for a in m.A}
    z = {a: 0.0 for a in m.A}
    y = {i: 0.0 for i in m.N}
    for route in plan.routes:
        if not route:
            continue
        path = [g.start] + [v + 1 for v in route] + [g.end]
        used = 0.0
        for i, j in zip(path, path[1:]):
            if (i, j) not in x:
                return False
            used += float(g.cost[i, j])
            x[i, j] = 1.0
            z[i, j] = used
            if j != g.end:
                y[j] = 1.0
    colmap = getattr(opt, "_pyomo_var_to_solver_var_map", None)
    if colmap is None:  # private attribute of Pyomo's HiGHS interface; skip if it changes
        return False
    idx, val = [], []
    for var, vals in ((m.x, x), (m.y, y), (m.z, z)):
        for k, v in vals.items():
            idx.append(colmap[id(var[k])])
            val.append(v)
    opt._solver_model.setSolution(len(idx), np.array(idx, dtype=np.int32), np.array(val, dtype=float))
    return True


def _install_history(opt, m, instance: TOPInstance, g: ArcGraph, lattice, best: _Best, hist: History) -> bool:
    """Report HiGHS's improving solutions and dual bounds to ``hist`` while it solves.

    Wraps the Pyomo interface's ``_solve`` so that the callbacks are subscribed on whichever
    ``highspy.Highs`` object it holds when a solve starts (``set_instance`` makes a new one).
    An improving solution is decoded into routes and verified; a valid one that beats ``best``
    replaces it. Callbacks never raise into HiGHS. Returns False (nothing installed) if the
    private attributes this relies on are missing.
    """
    solve = getattr(opt, "_solve", None)
    if solve is None or not hasattr(opt, "_solver_model") or not hasattr(opt, "_pyomo_var_to_solver_var_map"):
        return False
    hooked: dict = {"highs": None, "cols": None}

    def dual(e) -> float | None:
        b = float(e.data_out.mip_dual_bound)  # HiGHS reports it in the model's (maximisation) sense
        return floor_to_lattice(b, lattice) if math.isfinite(b) else None

    def on_interrupt(e) -> None:
        try:
            hist.update(bound=dual(e))
        except Exception:  # noqa: BLE001 - a recording failure must not stop the solve
            pass

    def on_solution(e) -> None:
        try:
            sol = e.data_out.mip_solution
            xval = {a: float(sol[c]) for a, c in hooked["cols"]}
            routes, _, _ = _routes(g, xval)
            plan = _to_plan(routes)
            rep = verify(instance, plan)
            if rep.valid and rep.prize > best.prize:
                best.plan, best.prize = plan, rep.prize
            hist.update(incumbent=best.prize if best.plan is not None else None, bound=dual(e))
        except Exception:  # noqa: BLE001
            pass

    def wrapped():
        h = opt._solver_model
        if h is not None and h is not hooked["highs"]:
            try:
                cmap = opt._pyomo_var_to_solver_var_map
                hooked["cols"] = [(a, cmap[id(m.x[a])]) for a in m.A]
                h.cbMipImprovingSolution.subscribe(on_solution)
                h.cbMipInterrupt.subscribe(on_interrupt)
                hooked["highs"] = h
            except Exception:  # noqa: BLE001 - fall back to the points at the end of each solve
                hooked["highs"] = h
        return solve()

    opt._solve = wrapped
    return True


def solve_milp(
    instance: TOPInstance,
    *,
    seed: int = 0,
    time_limit: float | None = 60.0,
    threads: int = 1,
    warm_start: Plan | None = None,
    root_rounds: int = 10,
    two_cycle: bool = True,
    cliques: bool = True,
    paths: bool = True,
    tee: bool = False,
    graph: ArcGraph | None = None,
    extend: Callable[[pyo.ConcreteModel, ArcGraph], None] | None = None,
) -> Result:
    """Solve ``instance`` exactly with HiGHS (see the module docstring for the method).

    ``warm_start``: a valid plan handed to HiGHS as its first incumbent (the registered ``milp``
    method, :mod:`sarcover.benchmarks.registry`, passes greedy's plan).
    ``root_rounds``: rounds of LP connectivity-cut separation before the MIP (0 turns it off).
    Terminates OPTIMAL only when the verified plan reaches HiGHS's proven bound.

    ``graph`` and ``extend`` solve a restriction of the problem with the same loop (the clustered
    optimum of :mod:`sarcover.formulations.clustered` does): ``graph`` is a subset of
    :func:`~sarcover.formulations.preprocess.prune_arcs`'s arcs, ``extend(model, graph)`` adds
    constraints after :func:`build_milp`. Every bound is then a bound of the restricted problem,
    and ``warm_start`` must be a plan of it (the caller checks).
    """
    t0 = time.perf_counter()
    deadline = None if time_limit is None else t0 + float(time_limit)
    info: dict = {"threads": threads, "seed": seed}
    hist = History(t0)

    def left() -> float | None:
        return None if deadline is None else max(deadline - time.perf_counter(), 0.0)

    loaded = False  # HiGHS holds a copy of the model
    # HiGHS's run clock: the seconds its solves of this copy took in all. HiGHS stops an LP solve
    # once this total passes the LP's limit (a MIP solve counts from its own start), so an LP
    # round after the first is given the clock plus the time left.
    highs_clock = 0.0

    def load() -> float | None:
        """HiGHS's copy of the model brought up to date, then the time left: Pyomo translates the
        model when a solve starts (seconds at a few hundred points), so a limit taken before
        that would end the solve past the run's time limit."""
        nonlocal loaded
        if loaded:
            opt.update()
        else:
            opt.set_instance(m)
            loaded = True
        return left()

    def run(time_limit: float | None, **options):
        """One HiGHS solve; ``options`` are added to the run's HiGHS options for this solve."""
        nonlocal highs_clock
        kw = dict(common, solver_options={**common["solver_options"], **options})
        res = opt.solve(m, time_limit=time_limit, **kw)
        clock = getattr(res.timing_info, "highs_time", None)
        if clock is not None:
            highs_clock = float(clock)
        return res

    def done(termination, plan=None, bound=None, reason=""):
        hist.record(info, verify(instance, plan).prize if plan is not None else None, bound)
        info["stop_reason"] = stop_reason_of(termination)
        info["runtime_model_s"] = round(time.perf_counter() - t0, 4)
        return Result(METHOD, termination, plan=plan, bound=bound, runtime_s=time.perf_counter() - t0,
                      reason=reason, info=info)

    # no pre-check here (run_method runs it once per call): a group out of reach leaves its cover
    # row empty, which HiGHS proves infeasible, or no node at all is reachable (below)
    g = prune_arcs(instance) if graph is None else graph
    info.update(nodes=len(g.nodes), arcs=len(g.arcs), arcs_full=g.n_arcs_full)
    if not g.nodes:  # nothing reachable: the empty plan, unless a group needs a visit
        if instance.groups:
            return done(Termination.INFEASIBLE, reason="no node is reachable within the budget, and every group "
                        "needs a visit")
        return done(Termination.OPTIMAL, plan=Plan.of([]), bound=0.0, reason="no node is reachable within the budget")
    lattice = prize_lattice(instance.prizes[[i - 1 for i in g.nodes]])
    m = build_milp(instance, g, two_cycle=two_cycle, cliques=cliques, paths=paths)
    if extend is not None:
        extend(m, g)

    opt = SolverFactory("highs")
    options = {
        "mip_rel_gap": 0.0,
        "mip_abs_gap": 0.5 * lattice if lattice else 1e-9,
        "random_seed": int(seed),
        "threads": int(threads),
        "output_flag": bool(tee),
    }
    common = dict(raise_exception_on_nonoptimal_result=False, load_solutions=False, tee=tee,
                  solver_options=options)
    best = _Best()
    if warm_start is not None:
        rep0 = verify(instance, warm_start)
        if rep0.valid:  # the warm start is an incumbent from the start (HiGHS gets it too)
            best.plan, best.prize = warm_start, rep0.prize
            hist.update(incumbent=rep0.prize)
    info["history_callbacks"] = _install_history(opt, m, instance, g, lattice, best, hist)

    # Every bound seen is valid (each model relaxes the problem); keep the smallest. The trivial
    # one: every reachable node visited.
    bound = floor_to_lattice(float(sum(instance.prizes[i - 1] for i in g.nodes)), lattice)

    # Root cut loop on the LP relaxation: connectivity cuts the time flow leaves violated.
    cuts_lp, cuts_clique = 0, 0
    lp_s = 0.0  # the longest LP round
    inc = incompatibility(g) if cliques else None
    if root_rounds > 0:
        for v in m.x.values():
            v.domain = pyo.UnitInterval
        for v in m.y.values():
            v.domain = pyo.UnitInterval
        lp_bounds = []
        for _ in range(root_rounds):
            tl = left()
            if tl is None or tl >= 1.0:  # no translation once too little time is left
                tl = load()
            if tl is not None and tl < 1.0:
                break
            t_lp = time.perf_counter()
            res = run(None if tl is None else highs_clock + tl)
            lp_s = max(lp_s, time.perf_counter() - t_lp)
            if res.termination_condition != TerminationCondition.convergenceCriteriaSatisfied:
                break
            res.solution_loader.load_vars()
            lp_bounds.append(round(float(res.incumbent_objective), 6))
            bound = min(bound, floor_to_lattice(float(res.incumbent_objective), lattice))
            hist.update(bound=bound)
            xval, yval = _values(m.x), _values(m.y)
            n = _separate_lp(m, g, xval, yval)
            if cliques:
                nc = _separate_cliques(m, g, inc, yval, xval, instance.n_vehicles)
                cuts_clique += nc
                n += nc
            cuts_lp += n
            if n == 0:
                break
        for v in m.x.values():
            v.domain = pyo.Binary
        for v in m.y.values():
            v.domain = pyo.Binary
        info["lp_bounds"] = lp_bounds
    info["cuts_lp"] = cuts_lp
    info["cuts_clique"] = cuts_clique

    rounds, cuts_int, nogoods, warm = 0, 0, 0, False
    while True:
        rounds += 1
        tl = left()
        if tl is None or tl > 0.0:  # no translation once the time is up
            tl = load()
        # HiGHS sets a MIP up before it first checks the clock (seconds at 120 points), so a MIP is
        # not started with less than a second, or than an LP round took if that was shorter
        if tl is not None and (tl <= 0.0 or tl < min(1.0, lp_s)):
            proven = False
            break
        if rounds == 1 and warm_start is not None:
            warm = _set_warm_start(opt, m, warm_start, g)
        # HiGHS's MIP presolve does not check the clock everywhere and can run seconds past the
        # limit. A MIP given less time than an LP round took cannot solve its own root LP, so
        # presolve would buy it nothing but the overrun.
        short = tl is not None and tl < lp_s
        if short:
            info["presolve_off"] = True
        res = run(tl, presolve="off" if short else "choose")  # an option stays set on HiGHS's copy
        tc = res.termination_condition
        info["highs_termination"] = str(tc.name)
        info["mip_nodes"] = getattr(res.extra_info, "mip_node_count", None)
        if tc in (TerminationCondition.provenInfeasible, TerminationCondition.infeasibleOrUnbounded):
            # The model is bounded (binaries, bounded flow), so "infeasible or unbounded" is infeasible.
            info.update(rounds=rounds, cuts_int=cuts_int, nogoods=nogoods, warm_start=warm)
            what = "target" if instance.kind == "sar" else "group"
            return done(Termination.INFEASIBLE,
                        reason=f"HiGHS proved that no plan of {instance.n_vehicles} routes within the "
                               f"budget covers every {what}")
        if res.objective_bound is not None and math.isfinite(res.objective_bound):
            bound = min(bound, floor_to_lattice(float(res.objective_bound), lattice))
        if hist.bound is not None:  # a dual bound seen during the solve (all valid, see the module doc)
            bound = min(bound, hist.bound)
        hist.update(bound=bound)
        if tc not in (TerminationCondition.convergenceCriteriaSatisfied, TerminationCondition.maxTimeLimit):
            info.update(rounds=rounds)
            return done(Termination.ERROR, plan=best.plan, bound=bound, reason=f"HiGHS stopped: {tc.name}")
        if res.incumbent_objective is None:
            proven = False
            break
        res.solution_loader.load_vars()
        xval = _values(m.x)
        routes, stray, succ = _routes(g, xval)
        plan = _to_plan(routes)
        report = verify(instance, plan)
        if report.valid and report.prize > best.prize:
            best.plan, best.prize = plan, report.prize
        hist.update(incumbent=best.prize if best.plan is not None else None)
        changed = False
        if stray:  # subtours among coincident points: cut them off and re-solve
            for cyc in _cycles(stray, succ):
                _add_connectivity_cut(m, set(cyc))
                cuts_int += 1
            changed = True
        for r, route in enumerate(routes):
            if route and not (report.energy[r] <= g.budget):
                # HiGHS accepted this route within its tolerance; the verifier does not. It is
                # infeasible, so cutting off exactly its arcs keeps every feasible plan.
                path = [g.start, *route, g.end]
                arcs = list(zip(path, path[1:]))
                m.cuts.add(sum(m.x[a] for a in arcs) <= len(arcs) - 1)
                nogoods += 1
                changed = True
        if changed:
            continue
        proven = tc == TerminationCondition.convergenceCriteriaSatisfied
        break

    info.update(rounds=rounds, cuts_int=cuts_int, nogoods=nogoods, warm_start=warm)
    if best.plan is not None and best.prize >= bound - 1e-7 * max(1.0, abs(bound)):
        return done(Termination.OPTIMAL, plan=best.plan, bound=bound)  # a verified plan reaches a proven bound
    if proven:  # HiGHS optimal, yet the verified plan is below its bound: never claim it
        return done(Termination.COMPLETED, plan=best.plan, bound=bound,
                    reason="HiGHS reported optimal but the verified plan does not reach its bound")
    return done(Termination.TIME_LIMIT, plan=best.plan, bound=bound, reason="time limit")
