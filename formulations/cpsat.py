"""`cpsat`: the team orienteering problem as an OR-Tools CP-SAT model.

Model (``model="multi"``, the default): one ``AddMultipleCircuit`` (CP-SAT's routes constraint)
over a merged depot node 0 and the reachable nodes. Arc 0→j costs c(start, j), arc i→0 costs
c(i, end), so a distinct start and end depot is just a different cost row and column; a node that
is not visited takes its self-loop; at most N arcs leave the depot. The per-route budget is
carried by an energy variable e_j per node (energy spent on arrival at j, imaging included),
domain [c(start, j), B - c(j, end)], and ``e_j >= e_i + c_ij`` enforced by arc literal i→j.
CP-SAT recognises these arc-enforced relations and uses them in its routing cuts. An aggregated
budget ``Σ c_ij x_ij <= N·B`` helps the LP. Each group needs at least one visited node
(``AddBoolOr``). No vehicle symmetry exists in this model.
``model="vehicle"`` is the alternative measured against it: one ``AddCircuit`` per vehicle with
skippable nodes, a linear budget per vehicle, and symmetry breaking (node t only on vehicles
k <= t; used vehicles first).

What pays (measured, 1 worker, noisy shared machine): the redundant flow rows turn the trivial
bound "every reachable node" into a useful one (p1.2.i after 30 s: bound 195 → 145, optimum
135); ``linearization_level=2`` proves small tight SAR cases the default level cannot (3 of 3
vs 0 of 3 at 12 s) and is on par on TOP sets 1 and 3; the per-vehicle model is far weaker
(p3.2.e: 4.5 s vs not proven in 30 s); a greedy hint is what lets one worker find any plan on
30-node TOP instances.

Pruning before any model: node i is dropped if c(s,i) + c(i,e) exceeds the budget, arc i→j if
c(s,i) + c_ij + c(j,e) does (valid because costs satisfy the triangle inequality).

Integer scaling and what it does to optimality
----------------------------------------------
CP-SAT needs integer costs. Costs are multiplied by S = 10^7 / B (so the scaled budget is about
10^7) and rounded two ways:

* relaxed: cost ⌈c·S⌉ - 1 (strictly below c·S even under floating-point noise), budget
  ⌊S·B·(1 + 1e-9)⌋ (the verifier's tolerance). Every truly feasible plan is feasible here, so
  this model's optimum, and any bound CP-SAT proves for it, is a valid upper bound of the true
  problem. Its plans can overrun the true budget by at most (#arcs)/S, i.e. about 1e-6·B.
* safe: cost ⌈c·S⌉, budget ⌊S·B⌋. Every plan it accepts is truly feasible.

The relaxed model is solved first. Its plan is checked with the independent verifier; if it is
truly feasible and CP-SAT proved it optimal, it is the true optimum (optimal for a relaxation and
feasible for the original): status OPTIMAL. Only if the relaxed optimum overruns the true budget
by that last 1e-6·B (a route tight to within S⁻¹ per arc) is the safe model solved in the
remaining time, with the objective capped at the relaxed bound; OPTIMAL is reported only if its
value reaches that bound, otherwise a plan without proof (termination COMPLETED) with the relaxed bound. So
scaling can cost a proof (never correctness): a reported OPTIMAL is always the optimum of the verifier's problem.

Prizes must be integers or decimals with at most 6 digits; they are scaled by the smallest power
of ten that makes them integral (exact), anything else raises :class:`CpsatInputError`.

Anytime history (``info["history"]``, see :mod:`sarcover.formulations.history`): ``[t, incumbent, bound]``
points in prize units (scaled objective / prize scale), t from the call of :func:`solve_cpsat`.
Incumbents: every solution CP-SAT reports (a solution callback) is read back into routes and
verified; only truly feasible plans count, so every incumbent is at most the optimum (and the
best of them is returned if the final plan is worse, e.g. a relaxed incumbent that had to be
repaired); a valid warm start counts as the first incumbent, at its start. Bounds: only the
relaxed model's, from ``best_bound_callback`` (and the final one),
as ⌈bound - 1e-6⌉ / prize scale: the relaxed model is a relaxation of the true problem, so they
are valid. The safe model is a restriction (capped at the relaxed bound), so its bounds say
nothing about the true problem and are never recorded; only its verified plans are.

Warm start: ``solve_cpsat(..., warm_start=plan)`` passes a plan as a CP-SAT hint; it changes
neither the model nor the proof, only where the search starts. The registered ``cpsat`` method
(:mod:`sarcover.benchmarks.registry`) passes greedy's plan: with one worker CP-SAT alone found
no plan within 60 s on some 30-node TOP instances that the hint solves quickly.
"""

from __future__ import annotations

import math
import time

import numpy as np
from ortools.sat.python import cp_model

from sarcover.formulations.errors import SarcoverError
from sarcover.formulations.history import History, stop_reason_of
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Result, Termination
from sarcover.formulations.scaling import integer_arcs
from sarcover.formulations.verify import REL_TOL, verify

TARGET_SCALED_BUDGET = 1e7
MAX_PRIZE_DECIMALS = 6


class CpsatInputError(SarcoverError, ValueError):
    """An instance the CP-SAT model cannot represent exactly (e.g. irrational prizes)."""


def prize_scale(prizes: np.ndarray) -> int:
    """Smallest power of ten P <= 10^6 with P·prize integral for every prize."""
    for d in range(MAX_PRIZE_DECIMALS + 1):
        p = 10**d
        scaled = prizes * p
        if np.all(np.abs(scaled - np.round(scaled)) <= 1e-9 * np.maximum(1.0, np.abs(scaled))):
            return p
    raise CpsatInputError(
        f"cpsat needs prizes with at most {MAX_PRIZE_DECIMALS} decimals; got e.g. {prizes[0]!r}"
    )


def cost_scale(budget: float) -> float:
    """S such that the scaled budget is about 10^7 (1 if the budget is 0). A budget below the
    verifier's absolute tolerance (1e-12) counts as that tolerance: the relaxed budget includes
    it, and S / budget would not even be a float for the smallest budgets."""
    return TARGET_SCALED_BUDGET / max(budget, 1e-12) if budget > 0 else 1.0


class _Data:
    """Reachable nodes, their integer arc costs (relaxed or safe) and the integer budget."""

    def __init__(self, instance: TOPInstance, relaxed: bool):
        self.instance = instance
        v = instance.n_nodes
        cost = instance.cost_matrix()
        self.scale = cost_scale(instance.budget)
        rb = math.floor(self.scale * (instance.budget * (1.0 + REL_TOL) + 1e-12))
        # an arc above the relaxed budget fits no route and is pruned below: cut at rb + 1, it
        # cannot overflow int64 however far it reaches (arcs below keep ceil(scale·cost) exactly)
        ceil = integer_arcs(cost, self.scale, rb + 1).astype(float)
        if relaxed:
            icost = np.maximum(ceil - 1.0, 0.0)
            ibudget = rb
        else:
            icost = ceil
            ibudget = math.floor(self.scale * instance.budget)
        self.budget = int(ibudget)
        # Pruning always uses the relaxed costs so both models see the same graph (pruning by
        # relaxed costs removes only arcs no truly feasible route uses).
        rc = np.maximum(ceil - 1.0, 0.0).astype(np.int64)
        nodes = np.arange(1, v + 1)
        trip = rc[0, nodes] + rc[nodes, v + 1]
        self.nodes = [int(i) - 1 for i in nodes[trip <= rb]]  # node ids
        idx = [i + 1 for i in self.nodes]  # solver indices
        self.cost = icost.astype(np.int64)
        self.arcs: list[tuple[int, int]] = []  # (t, u) in model numbering; 0 = depot
        for t, i in enumerate(idx, start=1):
            self.arcs.append((0, t))
            self.arcs.append((t, 0))
            for u, j in enumerate(idx, start=1):
                if t != u and rc[0, i] + rc[i, j] + rc[j, v + 1] <= rb:
                    self.arcs.append((t, u))
        self.idx = idx

    def arc_cost(self, t: int, u: int) -> int:
        v = self.instance.n_nodes
        i = 0 if t == 0 else self.idx[t - 1]
        j = v + 1 if u == 0 else self.idx[u - 1]
        if t == 0 and u == 0:
            return 0
        return int(self.cost[i, j])


def _route_arcs(route_nodes: list[int]) -> list[tuple[int, int]]:
    if not route_nodes:
        return []
    seq = [0, *route_nodes, 0]
    return list(zip(seq, seq[1:]))


class _Model:
    """A built CP-SAT model plus what is needed to read a plan back."""

    def __init__(self, data: _Data, prizes: np.ndarray, model: str, objective_cap: int | None,
                 flow: bool = True):
        self.data = data
        self.flow = flow
        self.kind = model
        self.m = cp_model.CpModel()
        inst = data.instance
        self.node_of = {t: i for t, i in enumerate(data.nodes, start=1)}
        self.t_of = {i: t for t, i in self.node_of.items()}
        n_t = len(data.nodes)
        self.iprize = prizes
        if model == "multi":
            self._build_multi(n_t)
        elif model == "vehicle":
            self._build_vehicle(n_t)
        else:
            raise ValueError(f"unknown cpsat model {model!r}")
        obj = sum(int(prizes[self.node_of[t]]) * self.visit[t] for t in range(1, n_t + 1) if prizes[self.node_of[t]])
        for gi, g in enumerate(inst.groups):
            lits = [self.visit[self.t_of[i]] for i in g if i in self.t_of]
            if not lits:
                self.m.add_bool_or([])  # unreachable group: an empty clause, proven infeasible
            else:
                self.m.add_bool_or(lits)
        if isinstance(obj, int):  # no positive prize among the reachable nodes
            obj = 0 * self.visit[1]
        if objective_cap is not None:
            self.m.add(obj <= objective_cap)
        self.m.maximize(obj)

    # -- aggregated routes constraint ---------------------------------------------------------
    def _build_multi(self, n_t: int):
        d, m = self.data, None
        m = self.m
        self.x: dict[tuple[int, int], cp_model.IntVar] = {}
        arcs = []
        for t, u in d.arcs:
            lit = m.new_bool_var(f"x_{t}_{u}")
            self.x[t, u] = lit
            arcs.append((t, u, lit))
        self.visit = {}
        for t in range(1, n_t + 1):
            skip = m.new_bool_var(f"skip_{t}")
            arcs.append((t, t, skip))
            self.visit[t] = ~skip
        if not n_t:
            return
        m.add_multiple_circuit(arcs)
        m.add(sum(self.x[0, t] for t in range(1, n_t + 1)) <= d.instance.n_vehicles)
        self.e = {}
        for t in range(1, n_t + 1):
            lo = d.arc_cost(0, t)
            hi = d.budget - d.arc_cost(t, 0)
            self.e[t] = m.new_int_var(lo, max(lo, hi), f"e_{t}")
        for (t, u), lit in self.x.items():
            if t and u:
                m.add(self.e[u] >= self.e[t] + d.arc_cost(t, u)).only_enforce_if(lit)
        m.add(sum(d.arc_cost(t, u) * lit for (t, u), lit in self.x.items()) <= d.instance.n_vehicles * d.budget)
        if self.flow:
            self._add_flow(n_t)

    def _add_flow(self, n_t: int):
        """Redundant single-commodity energy flow (Bianchessi et al. 2018) for a stronger LP.

        z_tu >= energy on arrival at u over arc t→u (0 as head means the end depot). Outflow of a
        node >= inflow + cost of the arc used, lifted bounds (c_0t + c_tu) x <= z <= (B - c_u,end) x.
        Valid for the relaxed costs too: z_tu := x_tu · e_u satisfies every row (see module doc).
        """
        d, m, b = self.data, self.m, self.data.budget
        z = {}
        for (t, u), lit in self.x.items():
            lo = d.arc_cost(0, t) + d.arc_cost(t, u) if t else d.arc_cost(0, u)
            hi = b if u == 0 else b - d.arc_cost(u, 0)
            zv = m.new_int_var(0, b, f"z_{t}_{u}")
            m.add(zv >= lo * lit)
            m.add(zv <= hi * lit)
            z[t, u] = zv
        out = {t: [] for t in range(n_t + 1)}
        inn = {t: [] for t in range(n_t + 1)}
        for (t, u), zv in z.items():
            out[t].append((u, zv))
            inn[u].append((t, zv))
        for t in range(1, n_t + 1):
            m.add(sum(zv for _, zv in out[t]) >= sum(zv for _, zv in inn[t])
                  + sum(d.arc_cost(t, u) * self.x[t, u] for u, _ in out[t]))

    # -- one circuit per vehicle --------------------------------------------------------------
    def _build_vehicle(self, n_t: int):
        d, m = self.data, self.m
        nv = d.instance.n_vehicles
        self.xk = []
        self.yk = []
        used = []
        for k in range(nv):
            arcs, x = [], {}
            for t, u in d.arcs:
                if u and u - 1 < k and t == 0:
                    continue  # symmetry: node t only on vehicles k <= t - 1
                lit = m.new_bool_var(f"x{k}_{t}_{u}")
                x[t, u] = lit
                arcs.append((t, u, lit))
            home = m.new_bool_var(f"home_{k}")
            arcs.append((0, 0, home))
            y = {}
            for t in range(1, n_t + 1):
                skip = m.new_bool_var(f"skip{k}_{t}")
                arcs.append((t, t, skip))
                y[t] = ~skip
                m.add_implication(y[t], ~home)
                if t - 1 < k:
                    m.add(skip == 1)
            if n_t:
                m.add_circuit(arcs)
            m.add(sum(d.arc_cost(t, u) * lit for (t, u), lit in x.items()) <= d.budget)
            self.xk.append(x)
            self.yk.append(y)
            used.append(~home)
        for k in range(nv - 1):
            m.add_implication(~used[k], ~used[k + 1])
        self.visit = {}
        for t in range(1, n_t + 1):
            vis = m.new_bool_var(f"visit_{t}")
            m.add(sum(self.yk[k][t] for k in range(nv)) == vis)
            self.visit[t] = vis

    # -- hints and extraction -----------------------------------------------------------------
    def add_hint(self, plan: Plan):
        routes = [[self.t_of[v] for v in r if v in self.t_of] for r in plan.routes if r]
        if self.kind == "multi":
            on = {a for r in routes for a in _route_arcs(r)}
            for a, lit in self.x.items():
                self.m.add_hint(lit, a in on)
        else:
            routes = sorted(routes, key=lambda r: min(r)) if routes else routes
            for k, x in enumerate(self.xk):
                on = set(_route_arcs(routes[k])) if k < len(routes) else set()
                for a, lit in x.items():
                    self.m.add_hint(lit, a in on)

    def routes(self, solver: cp_model.CpSolver) -> list[list[int]]:
        if self.kind == "multi":
            succ = {t: u for (t, u), lit in self.x.items() if t and solver.boolean_value(lit)}
            routes = []
            for (t, u), lit in self.x.items():
                if t == 0 and solver.boolean_value(lit):
                    r, cur = [], u
                    while cur != 0 and len(r) <= len(succ):
                        r.append(self.node_of[cur])
                        cur = succ[cur]
                    routes.append(r)
            return routes
        routes = []
        for x in self.xk:
            succ = {t: u for (t, u), lit in x.items() if solver.boolean_value(lit)}
            r, cur = [], succ.get(0)
            while cur not in (None, 0) and len(r) <= len(succ):
                r.append(self.node_of[cur])
                cur = succ.get(cur)
            if r:
                routes.append(r)
        return routes


def _pad(routes: list[list[int]], n: int) -> Plan:
    routes = [r for r in routes if r]
    return Plan.of(routes + [[] for _ in range(n - len(routes))])


def _repair(instance: TOPInstance, routes: list[list[int]]) -> Plan | None:
    """Drop nodes from over-budget routes (largest energy saving first) until the verifier agrees.

    Returns None if that uncovers a group. Used only when a time limit leaves the relaxed model's
    incumbent a hair over the true budget.
    """
    routes = [list(r) for r in routes]
    for _ in range(sum(len(r) for r in routes) + 1):
        rep = verify(instance, _pad(routes, instance.n_vehicles))
        if rep.valid:
            return _pad(routes, instance.n_vehicles)
        over = [k for k, e in enumerate(rep.energy) if e > instance.budget * (1.0 + REL_TOL)]
        if not over or rep.groups_covered < len(instance.groups):
            return None
        k = over[0]
        pts = np.vstack([instance.start, instance.coords[routes[k]], instance.end])
        d = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        skip = np.linalg.norm(pts[2:] - pts[:-2], axis=1)
        saving = d[:-1] + d[1:] - skip
        routes[k].pop(int(np.argmax(saving)))
    return None


class _Recorder(cp_model.CpSolverSolutionCallback):
    """Verifies each solution CP-SAT reports; keeps the best truly feasible plan, logs it to ``hist``."""

    def __init__(self, built: _Model, hist: History, best: dict):
        super().__init__()
        self.built, self.hist, self.best = built, hist, best

    def on_solution_callback(self) -> None:
        try:
            inst = self.built.data.instance
            plan = _pad(self.built.routes(self), inst.n_vehicles)
            rep = verify(inst, plan)
            if rep.valid and (self.best["plan"] is None or rep.prize > self.best["prize"]):
                self.best.update(plan=plan, prize=rep.prize)
                self.hist.update(incumbent=rep.prize)
        except Exception:  # noqa: BLE001 - a recording failure must not stop the search
            pass


def _solver(time_left: float | None, threads: int, seed: int, linearization: int = 2) -> cp_model.CpSolver:
    s = cp_model.CpSolver()
    s.parameters.linearization_level = int(linearization)
    if time_left is not None:
        s.parameters.max_time_in_seconds = max(time_left, 0.01)
    s.parameters.num_workers = max(1, int(threads))
    s.parameters.random_seed = int(seed)
    return s


def solve_cpsat(
    instance: TOPInstance,
    *,
    seed: int = 0,
    time_limit: float | None = 60.0,
    threads: int = 1,
    warm_start: Plan | None = None,
    model: str = "multi",
    flow: bool = True,
    linearization: int = 2,
) -> Result:
    """Solve ``instance`` with CP-SAT; OPTIMAL only when proven for the unscaled problem."""
    t0 = time.perf_counter()
    info: dict = {"threads": int(threads), "model": model, "flow": flow, "linearization": linearization}
    hist = History(t0)
    best: dict = {"plan": None, "prize": -math.inf}  # best verified plan the callbacks saw

    def left() -> float | None:
        return None if time_limit is None else time_limit - (time.perf_counter() - t0)

    def done(termination, plan=None, bound=None, reason=""):
        prize = verify(instance, plan).prize if plan is not None else None
        if termination != Termination.OPTIMAL and best["plan"] is not None and (prize is None or best["prize"] > prize):
            # a truly feasible plan seen during the search beats the final one (e.g. a repaired one)
            plan, prize = best["plan"], best["prize"]
            reason = (reason + "; " if reason else "") + "returned the best verified plan seen during the search"
        hist.record(info, prize, bound)
        info["stop_reason"] = stop_reason_of(termination)
        return Result("cpsat", termination, plan=plan, bound=bound, runtime_s=time.perf_counter() - t0,
                      reason=reason, info=info)

    # no pre-check here (run_method runs it once per call): a group out of reach is an empty
    # clause, which CP-SAT proves infeasible, or no node at all is reachable (below)
    pscale = prize_scale(instance.prizes)
    iprize = np.round(instance.prizes * pscale).astype(np.int64)
    relaxed = _Data(instance, relaxed=True)
    info.update(cost_scale=relaxed.scale, prize_scale=pscale, reachable=len(relaxed.nodes),
                arcs=len(relaxed.arcs))
    if not relaxed.nodes:  # nothing reachable: the empty plan, unless a group needs a visit
        if instance.groups:
            return done(Termination.INFEASIBLE, reason="no node is reachable within the budget, and every "
                        "group needs a visit")
        return done(Termination.OPTIMAL, plan=_pad([], instance.n_vehicles), bound=0.0)

    built = _Model(relaxed, iprize, model, None, flow)
    if warm_start is not None:
        built.add_hint(warm_start)
        rep0 = verify(instance, warm_start)
        if rep0.valid:  # held from the start: a stopped run returns it unless it found better (as milp)
            best["plan"], best["prize"] = warm_start, rep0.prize
            hist.update(incumbent=rep0.prize)
    solver = _solver(left(), threads, seed, linearization)
    # CP-SAT's bound on the scaled objective; the relaxed model's bound is valid for the true problem.
    solver.best_bound_callback = lambda b: hist.update(bound=math.ceil(b - 1e-6) / pscale)
    st = solver.solve(built.m, _Recorder(built, hist, best))
    info["relaxed_status"] = solver.status_name(st)
    info["relaxed_wall_s"] = solver.wall_time
    if st == cp_model.INFEASIBLE:
        return done(Termination.INFEASIBLE, reason="CP-SAT proved that no plan covers every group "
                    "(relaxed rounding, so the proof holds for the exact costs)")
    if st == cp_model.MODEL_INVALID:
        return done(Termination.ERROR, reason="CP-SAT: model invalid " + built.m.validate())
    if st not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        # No incumbent: CP-SAT's best_objective_bound is not reliable then (it reads 0); the last
        # bound its callback reported is (None if it reported none).
        if warm_start is not None and verify(instance, warm_start).valid:
            return done(Termination.TIME_LIMIT, warm_start, hist.bound,
                        reason="time limit; CP-SAT found no plan, the hint is returned")
        return done(Termination.TIME_LIMIT, bound=hist.bound, reason=f"CP-SAT found no plan ({solver.status_name(st)})")
    ivalue = int(round(solver.objective_value))
    # Integer objective: CP-SAT's bound is integral; ceil(x - 1e-6) never rounds it down.
    ibound = math.ceil(solver.best_objective_bound - 1e-6) if st == cp_model.FEASIBLE else ivalue
    ibound = max(ibound, ivalue)
    bound = ibound / pscale
    routes = built.routes(solver)
    plan = _pad(routes, instance.n_vehicles)
    truly = verify(instance, plan).valid
    info["relaxed_plan_valid"] = truly
    if truly:
        if st == cp_model.OPTIMAL:
            return done(Termination.OPTIMAL, plan, bound)
        return done(Termination.TIME_LIMIT, plan, bound, reason="time limit before optimality was proven")
    if st == cp_model.FEASIBLE:  # out of time: repair the relaxed incumbent
        fixed = _repair(instance, routes)
        return done(Termination.TIME_LIMIT, fixed, bound, reason="time limit; relaxed incumbent repaired"
                    if fixed else "time limit; the relaxed incumbent overran the budget")
    # Relaxed optimum overruns the true budget by < #arcs/S: solve the safe rounding.
    safe = _Data(instance, relaxed=False)
    built2 = _Model(safe, iprize, model, ibound, flow)
    if warm_start is not None:
        built2.add_hint(warm_start)
    solver2 = _solver(left(), threads, seed, linearization)
    st2 = solver2.solve(built2.m, _Recorder(built2, hist, best))  # plans only: its bounds are not valid
    info["safe_status"] = solver2.status_name(st2)
    if st2 in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        plan2 = _pad(built2.routes(solver2), instance.n_vehicles)
        value = int(round(solver2.objective_value))
        if value == ibound:
            return done(Termination.OPTIMAL, plan2, bound)
        termination = Termination.COMPLETED if st2 == cp_model.OPTIMAL else Termination.TIME_LIMIT
        return done(termination, plan2, bound, reason="integer rounding left a gap: the relaxed-cost "
                    "optimum overruns the budget by less than the scaling error")
    fixed = _repair(instance, routes)
    if fixed is not None:
        return done(Termination.TIME_LIMIT if st2 == cp_model.UNKNOWN else Termination.COMPLETED, fixed, bound,
                    reason="safe-rounding model gave no plan; relaxed optimum repaired")
    return done(Termination.TIME_LIMIT if st2 == cp_model.UNKNOWN else Termination.COMPLETED, None, bound,
                reason="the relaxed-cost plan overruns the budget by the scaling error and the "
                "safe-rounding model found no plan")
