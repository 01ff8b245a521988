"""Branch-and-price for the team orienteering problem with group cover: the ``bp`` method.

Each branch-and-bound node runs column generation on the route master (:mod:`.master`) with the
labelling pricing (:mod:`.pricing`): heuristic pricing, then exact pricing over ng-routes (its
best reduced prize gives the node's certified Lagrangian bound; improving ng-routes that repeat a
point enter the master with visit counts), targeted below the root at the next point of the prize
lattice that matters; ng sets grow from the LP's repeated routes early in the run; at the root,
limited-memory subset-row cuts on long runs, and reduced-cost arc elimination under the duals
that certified the root bound. Branching on node visits, then arc flows, with strong branching;
nodes best floored bound first. Incumbents from dives, the caller's ``primal`` heuristic, integral
LP solutions and a MILP over the generated routes. The reported bound is max(incumbent, floored
bounds of the open nodes), certified at every stop.

The method in full, its measurements and what was tried and dropped: ``docs/bp.md``.
"""

from __future__ import annotations

import heapq
import math
import time
from dataclasses import dataclass, field

import numpy as np

from sarcover.formulations.bp.master import MAX_CUTS, Master
from sarcover.formulations.bp.options import BPOptions
from sarcover.formulations.bp.pricing import (add_to_ng, arc_bounds, cheapest_return, full_ng,
                                     label_arc_bounds, nearest_ng, price, warm_up)
from sarcover.formulations.instance import TOPInstance, precheck
from sarcover.formulations.plan import Plan, Result, Status
from sarcover.formulations.verify import verify

TOL = 1e-6


@dataclass(frozen=True)
class NodeState:
    """Branching decisions of one branch-and-bound node (solver points: node id + 1)."""

    forbidden_nodes: frozenset = frozenset()
    forced_nodes: frozenset = frozenset()
    forbidden_arcs: frozenset = frozenset()
    forced_arcs: frozenset = frozenset()
    depth: int = 0

    def child(self, **add) -> "NodeState":
        kw = {k: getattr(self, k) | frozenset(add.get(k, ())) for k in
              ("forbidden_nodes", "forced_nodes", "forbidden_arcs", "forced_arcs")}
        return NodeState(**kw, depth=self.depth + 1)


@dataclass
class _Stats:
    rounds: int = 0
    exact_pricings: int = 0
    labels: int = 0
    ng_growths: int = 0
    nodes: int = 0
    milp_calls: int = 0
    milp_s: float = 0.0
    strong_lps: int = 0
    strong_s: float = 0.0
    open_nodes: int = 0  # nodes left unsolved at the limit (0 when proven)
    milp_improved: int = 0  # MILP calls that raised the incumbent
    milp_columns: int | None = None  # routes the last MILP could use (reduced-cost filter)
    dives: int = 0
    dive_improved: int = 0  # dives that raised the incumbent
    primal_s: float | None = None  # the caller's heuristic: time, its plan's prize, improved?
    primal_prize: float | None = None
    primal_improved: bool | None = None
    primal_error: str | None = None
    cuts: int = 0
    cuts_purged: int = 0
    arcs_eliminated: int = 0  # arcs no plan better than the incumbent can use
    elim_s: float = 0.0  # time spent on their bounds
    elim_labels: bool | None = None  # the labelling bound ran to the end (None: not tried)
    pool_routes: int = 0  # routes its search added to the master
    root_lp: float | None = None  # restricted root LP value when cuts were first considered
    pricing_s: float = 0.0
    lp_s: float = 0.0
    root_bound: float | None = None
    root_s: float | None = None
    mode_times: tuple | None = None  # first exact pricing: (one-way s, bidirectional s)
    history: list = field(default_factory=list)  # (time, incumbent, bound)


class BranchAndPrice:
    def __init__(self, instance: TOPInstance, *, time_limit: float | None,
                 warm_start: Plan | None = None, primal=None, options: BPOptions | None = None):
        opts = (BPOptions.for_time_limit(time_limit) if options is None
                else options.with_limit_defaults(time_limit))
        self.options = opts
        self.primal = primal
        self.strong = opts.strong
        self.root_cert = None  # (duals, their dual term, best reduced prize bound, bound)
        self._arc_cert = None  # (root_cert the arc bounds belong to, arc bounds, labelled?)
        self.elim_version = 0  # bumped whenever more arcs are eliminated
        self.cut_rounds = opts.cut_rounds
        self.cut_gap = opts.cut_gap
        self.cuts_per_round = opts.cuts_per_round
        self.cut_round = 0
        self.labelled_before_cuts = False
        self.bidirectional = opts.bidirectional
        self.ng_columns = opts.ng_columns
        self.ng_cap = opts.ng_cap
        self.inst = instance
        self.t0 = time.perf_counter()
        limit = float(time_limit) if time_limit is not None else math.inf
        self.dive_limit = opts.dive_share * limit if math.isfinite(limit) else 30.0
        self.elim_limit = opts.elim_share * limit if math.isfinite(limit) else 30.0  # labelling arc bounds
        self.primal_limit = min(opts.primal_share * limit, opts.primal_cap_s)
        self.dived = False
        self.dive_starts: set[int] = set()  # first route fixed by each dive so far
        self.grow_until = self.t0 + (opts.grow_share * limit if math.isfinite(limit) else math.inf)
        self.cut_until = self.t0 + (opts.cut_share * limit if math.isfinite(limit) else math.inf)
        self.hard_deadline = self.t0 + limit
        self.reserve = min(5.0, 0.1 * limit)  # kept for a last MILP over the generated routes
        self.deadline = self.hard_deadline - self.reserve
        self.V = instance.n_nodes
        self.N = instance.n_vehicles
        self.cost = instance.cost_matrix()
        self.budget = instance.budget * (1.0 + 1e-9)
        self.integral = bool(np.all(instance.prizes == np.round(instance.prizes)))
        # every plan's prize is a multiple of the prizes' gcd (1 for SAR, 10 for TOP set 3)
        step = math.gcd(*(int(p) for p in instance.prizes)) if self.integral else 0
        self.step = float(step) if step > 0 else 1.0
        trip = self.cost[0, 1 : self.V + 1] + self.cost[1 : self.V + 1, self.V + 1]
        self.reachable = np.zeros(self.V + 2, dtype=bool)
        self.reachable[1 : self.V + 1] = trip <= self.budget
        self.master = Master(self.V, instance.prizes, instance.groups, self.N)
        n = self.V + 2
        self.ng = full_ng(n) if opts.ng_size >= self.V else nearest_ng(self.cost, opts.ng_size)
        self.stats = _Stats()
        self.incumbent_value = 0.0 if not instance.groups else -math.inf
        self.incumbent: list[tuple[int, ...]] | None = [] if not instance.groups else None
        initial_routes = warm_start.routes if warm_start is not None else ()
        cols = [(int(p),) for p in np.flatnonzero(self.reachable)]
        for r in initial_routes:
            pts = tuple(int(v) + 1 for v in r)
            if pts and self._energy(pts) <= self.budget:
                cols.append(pts)
        self.master.add_routes(cols)
        if initial_routes:
            self._offer([tuple(int(v) + 1 for v in r) for r in initial_routes if r])

    # -- helpers ---------------------------------------------------------------------------
    def _energy(self, pts) -> float:
        full = [0, *pts, self.V + 1]
        return float(sum(self.cost[a, b] for a, b in zip(full, full[1:])))

    def _time_left(self) -> float:
        return self.deadline - time.perf_counter()

    def _floor(self, bound: float) -> float:
        """The bound rounded down to the prize lattice (multiples of the prizes' gcd)."""
        if not self.integral:
            return bound
        return self.step * math.floor((bound + 1e-6) / self.step)

    def _offer(self, routes):
        """Accept a plan (solver points) as incumbent if the verifier agrees and it is better.
        Returns the verifier's report (None for no plan or more than N routes)."""
        if routes is None or len(routes) > self.N:
            return None
        plan = Plan.of([[p - 1 for p in r] for r in routes])
        rep = verify(self.inst, plan)
        if rep.valid and rep.prize > self.incumbent_value + 1e-9:
            self.incumbent_value = rep.prize
            self.incumbent = list(routes)
            self._log()
            self._eliminate_arcs()
        return rep

    def _log(self, bound: float | None = None) -> None:
        inc = None if self.incumbent is None else self.incumbent_value
        if bound is not None and inc is not None:
            bound = max(bound, inc)  # after arc elimination a bound only covers better plans
        self.stats.history.append((round(time.perf_counter() - self.t0, 4), inc, bound))

    def _prunable(self, bound: float) -> bool:
        b = self._floor(bound)
        if self.incumbent is None:
            return b < -TOL  # no plan (prize >= 0) exists below this node
        return b <= self.incumbent_value + TOL

    # -- column generation at one node -----------------------------------------------------
    def _node_graph(self, state: NodeState):
        cost = self.cost.copy()
        n = self.V + 2
        end = n - 1
        for a, b in state.forbidden_arcs:
            cost[a, b] = np.inf
        for a, b in state.forced_arcs:
            if a != 0:
                keep = cost[a, b]
                cost[a, :] = np.inf
                cost[a, b] = keep
            if b != end:
                keep = cost[a, b]
                cost[:, b] = np.inf
                cost[a, b] = keep
        allowed = self.reachable.copy()
        for p in state.forbidden_nodes:
            allowed[p] = False
        if self.master.eliminated.any():
            cost[self.master.eliminated] = np.inf
            into = np.isfinite(cost)
            np.fill_diagonal(into, False)
            allowed &= into.any(axis=0)  # a point whose every incoming arc is gone
        return cost, cheapest_return(cost), allowed

    def _price(self, cost, ret, prof, allowed, *, heuristic, y0, sig, max_labels=None):
        """Pricing; ``y0`` is the threshold a path's reduced prize must beat (the vehicle dual,
        or more for a targeted exact call); ``sig``: the subset-row cuts' duals."""
        t = time.perf_counter()
        if max_labels is None:
            max_labels = 200_000 if heuristic else 2_000_000
        res = price(cost, ret, prof, self.budget, self.ng, allowed, heuristic=heuristic,
                    max_labels=max_labels, n_cols=30 if heuristic else 60,
                    min_gain=y0 + TOL, deadline=self.deadline,
                    bidirectional=bool(self.bidirectional) and not heuristic,
                    cut_members=self.master.cut_members, cut_memory=self.master.cut_memory,
                    cut_duals=sig)
        self.stats.pricing_s += time.perf_counter() - t
        self.stats.labels += res.n_labels
        return res

    def _exact_price(self, cost, ret, prof, allowed, y0, sig):
        """Exact pricing. On the first call both searches run, the bidirectional one under the
        one-way search's time; the faster is kept for the rest of the run (neither dominates:
        bidirectional wins on long routes with many labels, loses when the join is large)."""
        if self.bidirectional is not None:
            return self._price(cost, ret, prof, allowed, heuristic=False, y0=y0, sig=sig)
        t = time.perf_counter()
        self.bidirectional = False
        uni = self._price(cost, ret, prof, allowed, heuristic=False, y0=y0, sig=sig)
        t_uni = time.perf_counter() - t
        if not uni.exact:
            return uni
        saved, self.deadline = self.deadline, min(self.deadline, time.perf_counter() + 0.8 * t_uni)
        t = time.perf_counter()
        self.bidirectional = True
        bi = self._price(cost, ret, prof, allowed, heuristic=False, y0=y0, sig=sig)
        self.deadline = saved
        t_bi = time.perf_counter() - t
        self.stats.mode_times = (round(t_uni, 4), round(t_bi, 4))
        self.bidirectional = bool(bi.exact) and t_bi < 0.8 * t_uni
        return uni

    def _grow_ng_from_lp(self, x) -> bool:
        """Dynamic ng sets: for every repeated route in the LP solution, remember the repeated
        point along its cycle (ng sets capped at ``ng_cap``), exclude the routes that stop being
        ng-routes, and report whether anything changed (the LP is then re-solved)."""
        m = self.master
        if time.perf_counter() > self.grow_until:
            return False  # growing makes pricing slower: past this point, branching decides
        grown = False
        for r in m.repeated:
            if x[r] <= TOL or r in m.dead:
                continue
            path = m.routes[r]
            last = {}
            for pos, u in enumerate(path):
                if u in last:
                    for w in path[last[u] + 1 : pos]:
                        if not (self.ng[w, u >> 6] >> np.uint64(u & 63)) & np.uint64(1) and \
                                self._ng_size(w) < self.ng_cap:
                            add_to_ng(self.ng, w, u)
                            grown = True
                last[u] = pos
        if grown:
            self.stats.ng_growths += 1
            m.kill_non_ng(self.ng)
        return grown

    def _ng_size(self, w: int) -> int:
        return int(sum(bin(int(word)).count("1") for word in self.ng[w]))

    def _slack(self, dual_value: float) -> float:
        """How much the best route's reduced prize may exceed the vehicle dual while
        dual_value + N·excess stays below the next value that matters: the next lattice point
        above dual_value, or incumbent + step if higher (integer prizes only)."""
        if not self.integral:
            return 0.0
        target = self._floor(dual_value) + self.step
        if self.incumbent is not None:
            target = max(target, self.incumbent_value + self.step)
        # reported best >= y0 + slack + TOL, so keep N·TOL and the floor's 1e-6 below target
        return max(0.0, (target - dual_value - 2e-6) / self.N - 2 * TOL)

    def _columns(self, res):
        return list(res.routes) + (list(res.ng_routes) if self.ng_columns else [])

    def column_generation(self, state: NodeState, bound: float):
        """Solve one node's LP by column generation. Returns (bound, x, x_art, converged)."""
        m = self.master
        version = None
        arcs_decided = bool(state.forbidden_arcs or state.forced_arcs)
        x = xa = None
        while True:
            if version != self.elim_version:  # first round, or more arcs eliminated since
                version = self.elim_version
                m.apply(state)
                cost, ret, allowed_base = self._node_graph(state)
                arcs_decided = arcs_decided or version > 0
            t = time.perf_counter()
            value, x, xa, y = m.solve()
            self.stats.lp_s += time.perf_counter() - t
            self.stats.rounds += 1
            if self._time_left() <= 0:
                return bound, x, xa, False
            prof = m.point_profit(y)
            sig = m.cut_duals(y)
            allowed = allowed_base.copy()
            if not arcs_decided:
                # With the triangle inequality a node of reduced prize <= 0 can be skipped.
                allowed &= prof > 1e-12
            y0 = float(y[0])
            res = self._price(cost, ret, prof, allowed, heuristic=True, y0=y0, sig=sig)
            if m.add_routes(self._columns(res)):
                continue
            if self._time_left() <= 0:
                return bound, x, xa, False
            # Targeted exact pricing: with integer prizes the node's bound only matters floored,
            # so a path must beat y0 + slack, where slack is what the reduced prize of N routes
            # may add to the dual value without reaching the next integer (or incumbent + 1).
            # If none does, floor(bound) is settled: the node is pruned or branched on now.
            # (Not at the root: its converged duals make the arc elimination much stronger.)
            gain = y0 + (self._slack(m.lagrangian_bound(y, y0)) if state.depth else 0.0)
            res = self._exact_price(cost, ret, prof, allowed, gain, sig)
            self.stats.exact_pricings += 1
            if res.exact:
                lag = m.lagrangian_bound(y, res.best)
                if state.depth == 0 and (self.root_cert is None or lag < self.root_cert[3]):
                    # duals that certify the root bound: they also filter the MILP's columns
                    self.root_cert = (y.copy(), m.lagrangian_bound(y, y0),
                                      max(0.0, res.best - y0), lag)
                    self._eliminate_arcs()
                bound = min(bound, lag)
                if state.depth == 0:
                    self._log(bound)
                if self._prunable(bound):
                    return bound, x, xa, True  # pruned (at the root: proven) before convergence
            if m.add_routes(self._columns(res)):
                continue
            if res.best - gain > TOL and res.cycles:
                for cyc in res.cycles:  # cycle u ... u: remember u at every node of the cycle
                    u = cyc[0]
                    for w in cyc[1:-1]:
                        add_to_ng(self.ng, w, u)
                self.stats.ng_growths += 1
                continue
            if not res.exact:
                return bound, x, xa, False
            if state.depth == 0 and not self.dived and self._time_left() > 0:
                # the root's floored bound is settled: find a plan before growing ng sets
                # (which only pays when the incumbent is below the floored bound)
                self.dived = True
                self.dive(min(self.dive_limit, 0.5 * self._time_left()))
                if not self._prunable(bound) and self.primal is not None:
                    self._call_primal()
                    if not self._prunable(bound):  # dive again, now with the heuristic's columns
                        m.apply(state)  # (its LP differs: any start route, even the first's)
                        self.dive(min(self.dive_limit, 0.5 * self._time_left()), fresh=True)
                m.apply(state)
                if self._prunable(bound):
                    return bound, x, xa, True
                continue  # re-solve with the heuristic's and the dive's columns
            if self._grow_ng_from_lp(x):
                m.apply(state)
                continue
            if self._add_cuts(state, x, y, value):
                continue
            return bound, x, xa, True

    def _add_cuts(self, state: NodeState, x, y, lp_value: float) -> bool:
        """Subset-row cuts on triples violated by the node's LP solution; report whether any was
        added. Cuts make every later pricing slower (labels pay their duals and dominate less),
        so they are only tried at the root, within the first ``cut_share`` of the time limit,
        while the restricted LP value is less than ``cut_gap`` steps above the value that would
        prove the incumbent optimal or above its own floor (a small drop then lowers the floored
        bound; larger drops are rare, and branching does better)."""
        if state.depth > 0 or self.cut_round >= self.cut_rounds or self._time_left() <= 0:
            return False
        if self.incumbent is None or time.perf_counter() > self.cut_until:
            return False
        if self.stats.root_lp is None:
            self.stats.root_lp = lp_value
        # the drop that proves the incumbent optimal, or lowers the floored bound by one step
        need = min(lp_value - (self.incumbent_value + self.step), lp_value - self._floor(lp_value))
        if need > self.cut_gap * self.step:
            return False
        if not self.labelled_before_cuts:
            # the labelling arc bounds first: cut rounds then price on the smaller graph
            self.labelled_before_cuts = True
            version, k = self.elim_version, self.master.n_routes
            self._eliminate_arcs(labels=True)
            if self.elim_version != version or self.master.n_routes != k:
                return True  # re-solve (smaller graph, the route pool), then separate
        self.cut_round += 1
        if len(self.master.cuts) + self.cuts_per_round > MAX_CUTS:  # make room: drop idle cuts
            purged = self.master.purge_cuts(y)
            self.stats.cuts_purged += purged
            if purged:
                self.root_cert = None  # its duals refer to rows that are gone
        cuts = self.master.separate_cuts(x, self.cuts_per_round)
        added = self.master.add_cuts(cuts)
        self.stats.cuts += added
        return added > 0

    # -- primal heuristics -----------------------------------------------------------------
    def _call_primal(self) -> None:
        """Run the caller's heuristic (``primal``) once, with ``primal_share`` of the time limit
        (at most ``primal_cap_s``): its plan becomes columns and, if the verifier passes it and
        it is better, the incumbent. Called when the root's floored bound is settled and the
        first dive has not found a plan that proves it, so instances the root or its first dive
        settle (most TOP instances) never pay for it."""
        if self.primal is None or self._time_left() <= 0:
            return
        t = time.perf_counter()
        allowance = min(self.primal_limit, 0.5 * self._time_left())
        try:
            routes = self.primal(allowance)
        except Exception as exc:  # a failing heuristic must not cost the proof search
            self.stats.primal_error = f"{type(exc).__name__}: {exc}"
            routes = None
        self.stats.primal_s = round(time.perf_counter() - t, 3)
        if not routes:
            return
        pts = [tuple(int(v) + 1 for v in r) for r in routes if len(r)]
        before = self.incumbent_value
        rep = self._offer(pts)
        self.stats.primal_prize = float(rep.prize) if rep is not None and rep.valid else None
        self.stats.primal_improved = self.incumbent_value > before
        self.master.add_routes([r for r in pts if self._energy(r) <= self.budget])

    def dive(self, limit: float, start: NodeState | None = None, *, fresh: bool = False) -> None:
        """Diving: fix the route of largest LP value (its nodes and arcs forced), re-solve the
        LP with heuristic pricing only, repeat until the LP solution is integral. A fixing that
        leaves the LP infeasible is undone and the next route tried (at most 3 times). Proves
        nothing; feeds incumbents and columns (routes that fit together) to the MILP. The first
        route fixed is one no earlier dive started from, unless ``fresh`` (the LP has new
        columns, as after the primal heuristic)."""
        m = self.master
        m.hide_repeated = True  # plans are made of elementary routes: ng-routes would only mislead
        before = self.incumbent_value
        try:
            self._dive(limit, start, fresh)
        finally:
            m.hide_repeated = False
        self.stats.dives += 1
        self.stats.dive_improved += self.incumbent_value > before

    def _dive(self, limit: float, start: NodeState | None, fresh: bool = False) -> None:
        m = self.master
        stop = min(self.deadline, time.perf_counter() + limit)
        state, parent = (start or NodeState()), None
        used: set[int] = set()  # routes fixed or tried: never picked again
        failures = 0
        while time.perf_counter() < stop:
            m.apply(state)
            cost, ret, allowed = self._node_graph(state)
            for _ in range(200):
                value, x, xa, y = m.solve()
                if xa.max() <= TOL and np.all(np.abs(x - np.round(x)) <= TOL):
                    self._offer([m.routes[r] for r in np.flatnonzero(x > 0.5)])
                if time.perf_counter() >= stop:
                    break
                res = self._price(cost, ret, m.point_profit(y), allowed, heuristic=True,
                                  y0=float(y[0]), sig=m.cut_duals(y))
                if not m.add_routes(res.routes):
                    break
            if xa.max() > TOL:  # the fixings cannot be completed (as far as heuristic pricing sees)
                failures += 1
                if parent is None or failures > 3:
                    break
                state, parent = parent, None
                continue
            pos = np.flatnonzero(x > TOL)
            if np.all(np.abs(x[pos] - np.round(x[pos])) <= TOL):
                self._offer([m.routes[r] for r in np.flatnonzero(x > 0.5)])
                break
            cand = [r for r in pos if r not in used]
            if not used and not fresh:  # first fixing: not where a previous dive started
                cand = [r for r in cand if r not in self.dive_starts] or cand
            if not cand:
                break
            r = max(cand, key=lambda k: x[k])
            if not used:
                self.dive_starts.add(r)
            used.add(r)
            full = [0, *m.routes[r], self.V + 1]
            parent = state
            state = state.child(forced_nodes=m.routes[r], forced_arcs=list(zip(full, full[1:])))

    # -- branch and bound ------------------------------------------------------------------
    def _branch_candidates(self, state: NodeState, x: np.ndarray, limit: int | None = None):
        """Child pairs to branch on, most fractional first (the first ``limit``): visits of a
        point (forced / forbidden) while some are fractional, else arc flows (forced /
        forbidden)."""
        m = self.master
        visits = m.node_visits(x)[1 : self.V + 1]
        frac = np.abs(visits - np.round(visits))
        pts = np.flatnonzero(frac > TOL)
        if pts.size:
            pts = pts[np.argsort(np.abs(visits[pts] - 0.5), kind="stable")][:limit] + 1
            return [[state.child(forced_nodes=[int(p)]), state.child(forbidden_nodes=[int(p)])]
                    for p in pts]
        arcs = [(abs(f - 0.5), a) for a, f in m.arc_flows(x).items() if min(f, 1 - f) > TOL]
        arcs.sort()
        return [[state.child(forced_arcs=[a]), state.child(forbidden_arcs=[a])]
                for _, a in arcs[:limit]]

    def _branch(self, state: NodeState, x: np.ndarray, lp_value: float):
        """Children of a node, or None if its LP solution is integral in visits and arcs.
        Strong branching on the restricted master: of the ``strong`` most fractional
        candidates, the one whose children's re-solved LPs (current columns, no pricing: a
        cheap estimate) drop most below the node's value (product of the two drops, each at
        least 1e-3 so that a free child does not hide the other)."""
        cands = self._branch_candidates(state, x, max(self.strong, 1))
        if not cands:
            return None
        if self.strong <= 1 or len(cands) == 1:
            return cands[0]
        m = self.master
        t = time.perf_counter()
        best, pick = -1.0, cands[0]
        for pair in cands:
            drops = []
            for ch in pair:
                m.apply(ch)
                value = m.solve()[0]
                drops.append(max(lp_value - value, 1e-3))
            score = drops[0] * drops[1]
            if score > best:
                best, pick = score, pair
        self.stats.strong_lps += 2 * len(cands)
        m.apply(state)
        self.stats.strong_s += time.perf_counter() - t
        return pick

    def _node_key(self, bound: float, depth: int, counter: int, state: NodeState):
        """Heap entry: best floored bound first, then deepest. Pruning only looks at floored
        bounds, so every open node of the best floor must be solved unless a plan of that value
        turns up; among them, depth first reaches integral LP solutions (plans) sooner."""
        return (-self._floor(bound), -depth, -bound, counter, state)

    def _rc_floor(self) -> float | None:
        """The reduced prize a route needs, under the duals y that certified the root bound, to
        be part of a plan better than the incumbent: a plan of elementary routes (at most N)
        containing route k is worth at most dual_term(y) + rc_k + (N-1)·rc*, where rc* bounds
        every route's reduced prize (the exact pricing's value). None: no certificate yet."""
        if self.root_cert is None or self.incumbent is None:
            return None
        _, dual_term, rc_star, _ = self.root_cert
        need = self.incumbent_value + (self.step if self.integral else 1e-9)
        return need - dual_term - (self.N - 1) * rc_star - 1e-6

    def _milp_columns(self):
        """Routes that can be part of a plan better than the incumbent (:meth:`_rc_floor`).
        None: no filter."""
        floor = self._rc_floor()
        if floor is None:
            return None
        return self.master.reduced_costs(self.root_cert[0]) >= floor

    def _eliminate_arcs(self, labels: bool = False) -> None:
        """Reduced-cost arc elimination: an arc that every route through it leaves below
        :meth:`_rc_floor` (under the root certificate's duals) is in no plan better than the
        incumbent, so it leaves the pricing graph and the LP of every node (and every later plan
        search) for good. Each node's bound then covers only the plans better than the
        incumbent, which is all that pruning and the reported bound (never below the incumbent)
        need. Re-checked when the incumbent improves or the root's certificate gets tighter.

        The arc bounds are computed once per certificate: :func:`arc_bounds` (a DP, milliseconds)
        always; with ``labels`` (once the root is solved) also :func:`label_arc_bounds` on the
        arcs the DP leaves (exact ng-labelling both ways, about as costly as two exact pricing
        calls, much tighter). The labelling bound only covers the paths above its threshold, so
        it stays valid as the incumbent, and with it the floor, rises. Its forward search also
        yields the ``pool_routes`` best elementary routes that a better plan may use; they join
        the master as columns, so that the MILP over the generated routes can combine them."""
        floor = self._rc_floor()
        if floor is None:
            return
        cached = self._arc_cert is not None and self._arc_cert[0] is self.root_cert
        if not cached or (labels and not self._arc_cert[2]):
            t = time.perf_counter()
            y = self.root_cert[0]
            cost, _, allowed = self._node_graph(NodeState())
            prof = self.master.point_profit(y)
            through = self._arc_cert[1] if cached else arc_bounds(cost, prof, allowed,
                                                                   self.budget)
            if labels:
                cost[through - y[0] < floor] = np.inf
                exact = label_arc_bounds(cost, prof, allowed, self.budget, self.ng, y[0] + floor,
                                         deadline=min(self.deadline, t + self.elim_limit),
                                         n_routes=self.options.pool_routes)
                if exact is not None:
                    through = np.minimum(through, exact[0])
                    # the same search's best routes: near-optimal columns for the MILP
                    self.stats.pool_routes = self.master.add_routes(exact[1])
                self.stats.elim_labels = exact is not None
            self.stats.elim_s += time.perf_counter() - t
            self._arc_cert = (self.root_cert, through, labels)
        m = self.master
        y0 = self.root_cert[0][0]
        new = (self._arc_cert[1] - y0 < floor) & ~m.eliminated & np.isfinite(self.cost)
        new[:, 0] = new[-1, :] = False
        np.fill_diagonal(new, False)
        if new.any():
            m.eliminated |= new
            self.elim_version += 1
            self.stats.arcs_eliminated = int(m.eliminated.sum())

    def _run_milp(self, limit: float) -> None:
        self.stats.milp_calls += 1
        limit = min(limit, max(0.0, self.hard_deadline - time.perf_counter() - 0.1))
        if limit > 0.05:
            t, before = time.perf_counter(), self.incumbent_value
            allowed = self._milp_columns()
            if allowed is not None:
                self.stats.milp_columns = int(allowed.sum())
                if not allowed.any():
                    return  # no generated route can be part of a better plan
            self._offer(self.master.milp(limit, allowed, start=self.incumbent))
            self.stats.milp_s += time.perf_counter() - t
            self.stats.milp_improved += self.incumbent_value > before

    def run(self):
        root = NodeState()
        trivial = float(self.inst.prizes[self.reachable[1 : self.V + 1]].sum())
        heap = [self._node_key(trivial, 0, 0, root)]
        counter = 1
        open_bound = math.inf
        unresolved = []  # nodes we cannot split further (should not happen) with their bounds
        last_milp_cols = 0
        proven = False
        while heap:
            if self._time_left() <= 0:
                break
            _, _, negb, _, state = heapq.heappop(heap)
            parent_bound = -negb
            if self._prunable(parent_bound):
                continue
            self.stats.nodes += 1
            bound, x, xa, converged = self.column_generation(state, parent_bound)
            if state.depth == 0 and converged and not self._prunable(bound):
                # the root LP is solved: tighter arc bounds by labelling, and if they remove
                # arcs, the root again on the smaller graph (its bound may now prove the plan)
                version = self.elim_version
                self._eliminate_arcs(labels=True)
                if self.elim_version != version and self._time_left() > 0:
                    bound, x, xa, converged = self.column_generation(state, bound)
                elif len(x) != self.master.n_routes:
                    # the route pool joined after the LP was solved (and no time is left to
                    # re-solve the root): the LP solution over all of the master's columns
                    self.master.apply(state)
                    _, x, xa, _ = self.master.solve()
            if state.depth == 0:
                self.stats.root_bound = bound if math.isfinite(bound) else None
                self.stats.root_s = time.perf_counter() - self.t0
                if converged and not self._prunable(bound) and self._time_left() > 0:
                    # dive again from the final root LP (the first dive ran before ng growth)
                    self.dived = True
                    self.dive(min(self.dive_limit, 0.5 * self._time_left()))
                    self.master.apply(state)  # back to the root, with the dive's columns
                    _, x, xa, _ = self.master.solve()
                if self._time_left() > 0:
                    self._run_milp(min(10.0, 0.25 * self._time_left()))
                    last_milp_cols = self.master.n_routes
            if not converged:
                heapq.heappush(heap, self._node_key(bound, state.depth, counter, state))
                counter += 1
                break
            if self._prunable(bound):
                continue
            if self.stats.nodes % self.options.dive_every == 0 and self._time_left() > 0:
                # dive again from this node (other fixings than the root's dive)
                self.dive(min(0.3 * self.dive_limit, 0.25 * self._time_left()), start=state)
                self.master.apply(state)
                _, x, xa, _ = self.master.solve()
                if self._prunable(bound):
                    continue
            if xa.max() <= TOL and np.all(np.abs(x - np.round(x)) <= TOL):
                self._offer([self.master.routes[r] for r in np.flatnonzero(x > 0.5)])
                continue
            lp_value = float(np.dot(self.master.route_prize, x[: self.master.n_routes]))
            children = self._branch(state, x, lp_value)
            if children is None:
                unresolved.append(bound)
                continue
            for ch in children:
                heapq.heappush(heap, self._node_key(bound, ch.depth, counter, ch))
                counter += 1
            if self.stats.nodes % self.options.milp_every == 0 and self.master.n_routes > last_milp_cols:
                self._run_milp(min(5.0, 0.1 * max(self._time_left(), 0.0)))
                last_milp_cols = self.master.n_routes
        else:
            proven = not unresolved
        if not proven and self.master.n_routes:
            self._run_milp(max(0.0, self.hard_deadline - time.perf_counter() - 0.1))
        open_bounds = [-item[2] for item in heap] + unresolved
        self.stats.open_nodes = sum(not self._prunable(b) for b in open_bounds)
        inc = self.incumbent_value if self.incumbent is not None else -math.inf
        if open_bounds:
            open_bound = max(self._floor(b) for b in open_bounds)
            bound = max(inc, open_bound)
            # every open node is prunable: the incumbent is optimal
            proven = self.incumbent is not None and not unresolved and open_bound <= inc + TOL
        else:
            bound = inc
        return proven, bound


def solve_bp(instance: TOPInstance, *, seed: int = 0, time_limit: float | None = 60.0,
             warm_start: Plan | None = None, primal=None, options: BPOptions | None = None) -> Result:
    """Branch-and-price: proven optimum, or the best plan and a certified bound at the limit.

    ``warm_start``: a plan (e.g. a heuristic's) whose routes are added as starting columns and
    as a first incumbent. ``primal(seconds) -> routes or None`` (node ids) is a heuristic run
    once if the root does not settle the proof, with ``options.primal_share`` of the time limit
    (at most ``options.primal_cap_s``); its routes become columns and, if verified and better,
    the incumbent. ``options``: None means :meth:`BPOptions.for_time_limit` of ``time_limit``.
    ``seed`` is unused (no randomness; timing-based choices and the time limit can still change
    the path taken).
    """
    warm_up()  # JIT compilation (cached on disk after the first run) is not charged to the limit
    t0 = time.perf_counter()
    reason = precheck(instance)
    if reason is not None:
        return Result("bp", Status.INFEASIBLE, reason=reason, runtime_s=time.perf_counter() - t0)
    bp = BranchAndPrice(instance, time_limit=time_limit, warm_start=warm_start, primal=primal,
                        options=options)
    proven, bound = bp.run()
    st = bp.stats
    info = {
        "nodes": st.nodes, "rounds": st.rounds, "columns": bp.master.n_routes,
        "exact_pricings": st.exact_pricings, "labels": st.labels, "ng_growths": st.ng_growths,
        "milp_calls": st.milp_calls, "milp_s": round(st.milp_s, 3),
        "milp_improved": st.milp_improved, "milp_columns": st.milp_columns, "dives": st.dives,
        "dive_improved": st.dive_improved, "strong_lps": st.strong_lps,
        "strong_s": round(st.strong_s, 3),
        "open_nodes": st.open_nodes,
        "cuts": st.cuts, "cuts_purged": st.cuts_purged, "arcs_eliminated": st.arcs_eliminated,
        "elim_s": round(st.elim_s, 3), "elim_labels": st.elim_labels,
        "pool_routes": st.pool_routes,
        "root_lp": st.root_lp, "primal_s": st.primal_s, "primal_prize": st.primal_prize,
        "primal_improved": st.primal_improved, "primal_error": st.primal_error,
        "pricing_s": round(st.pricing_s, 3), "lp_s": round(st.lp_s, 3),
        "root_bound": st.root_bound, "root_s": st.root_s, "history": st.history, "threads": 1,
        "bidirectional": bp.bidirectional, "mode_times": st.mode_times,
    }
    runtime = time.perf_counter() - t0
    plan = None if bp.incumbent is None else Plan.of([[p - 1 for p in r] for r in bp.incumbent])
    if plan is None:
        if proven:
            return Result("bp", Status.INFEASIBLE, bound=None, runtime_s=runtime, info=info,
                          reason="branch-and-price proved that no plan covers every group")
        b = bound if math.isfinite(bound) else None
        return Result("bp", Status.TIME_LIMIT, bound=b, runtime_s=runtime, info=info,
                      reason="time limit before a plan covering every group was found")
    if proven:
        return Result("bp", Status.OPTIMAL, plan=plan, bound=bp.incumbent_value, runtime_s=runtime,
                      info=info)
    b = bound if math.isfinite(bound) else None
    return Result("bp", Status.TIME_LIMIT, plan=plan, bound=b, runtime_s=runtime, info=info,
                  reason="time limit")
