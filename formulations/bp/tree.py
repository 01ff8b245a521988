"""The branch-and-bound tree: builds one run's parts, then explores nodes best floored bound
first and reports what it proved.

Nodes are explored best floored bound first, deepest first among equals (depth first until a
plan of the best floored value turns up); a node is pruned when its floored bound does not exceed
the incumbent. The root gets more than the other nodes (its policy: :mod:`.root`), and a MILP
over the generated routes once it is solved; later nodes get a dive every ``dive_every`` nodes
and a MILP every ``milp_every`` nodes, and before each, route enumeration under the root's
certificate (:mod:`.enumeration`) is tried when the certificate or the incumbent has changed. A
node whose LP value comes within the enumeration's window of the incumbent is converged fully
and its routes listed under its own duals, which can close it without branching
(:meth:`BranchAndPrice._solve_node`).
The reported bound is max(incumbent, floored bounds of the open nodes), each capped by what a
narrow route listing showed no plan exceeds (:attr:`.search.Search.cap`), certified at every
stop; a run whose open nodes all floor to the incumbent, or whose cap is the incumbent, is proven.
"""

from __future__ import annotations

import heapq
import logging
import math
import time

import numpy as np
from sarcover.formulations.bp.branching import branch
from sarcover.formulations.bp.colgen import ColumnGeneration
from sarcover.formulations.bp.constants import TOL
from sarcover.formulations.bp.cuts import CutRounds
from sarcover.formulations.bp.elimination import Elimination
from sarcover.formulations.bp.enumeration import Enumeration
from sarcover.formulations.bp.graph import NodeState
from sarcover.formulations.bp.highs import LPFailure
from sarcover.formulations.bp.incumbent import IncumbentSearch
from sarcover.formulations.bp.options import BPOptions
from sarcover.formulations.bp.pricer import Pricer
from sarcover.formulations.bp.root import Root
from sarcover.formulations.bp.search import Search
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan

log = logging.getLogger(__name__)


class BranchAndPrice:
    """One branch-and-price run. ``warm_start``: a plan whose routes become starting columns and
    the first incumbent; ``primal(seconds) -> routes or None`` (node ids): the caller's heuristic
    (:class:`.incumbent.IncumbentSearch`); ``options``: None means
    :meth:`BPOptions.for_time_limit` of ``time_limit``, and settings left None in them are
    decided on ``time_limit`` too."""

    def __init__(self, instance: TOPInstance, *, time_limit: float | None,
                 warm_start: Plan | None = None, primal=None, options: BPOptions | None = None):
        opts = (BPOptions.for_time_limit(time_limit) if options is None
                else options.with_limit_defaults(time_limit))
        self.options = opts
        self.stopped = None  # why the search stopped before its time was up (an LP, memory)
        s = self.search = Search(instance, time_limit, opts)

        def share(f: float) -> float:  # seconds for a root dive, the labelling arc bounds
            return f * s.clock.limit if math.isfinite(s.clock.limit) else 30.0

        self.pricer = Pricer(s, opts.bidirectional, opts.ng_columns, opts.exact_keep,
                             opts.exact_labels, sparse_arcs=opts.sparse_arcs,
                             sparse_from=opts.sparse_from,
                             heuristic_columns=opts.heuristic_columns)
        self.elimination = Elimination(s, elim_limit=share(opts.elim_share),
                                       pool_routes=opts.pool_routes)
        at_scale = s.problem.V >= opts.primal_first_from
        primal_share, primal_cap = ((opts.primal_scale_share, opts.primal_scale_cap_s) if at_scale
                                    else (opts.primal_share, opts.primal_cap_s))
        self.incumbents = IncumbentSearch(
            s, self.pricer, self.elimination, primal, dive_limit=share(opts.dive_share),
            primal_limit=min(primal_share * s.clock.limit, primal_cap))
        self.cuts = CutRounds(s, self.elimination, rounds=opts.cut_rounds,
                              per_round=opts.cuts_per_round, gap=opts.cut_gap,
                              until=s.clock.until(opts.cut_share))
        self.enumeration = (Enumeration(s, self.elimination, self.incumbents,
                                        limit=share(opts.enum_share), gap=opts.enum_gap,
                                        max_labels=opts.enum_labels, max_routes=opts.enum_routes,
                                        primal_window=opts.enum_primal_window,
                                        audit=opts.audit_listings)
                            if opts.enum_share > 0 else None)
        self.colgen = ColumnGeneration(s, self.pricer, self.elimination, ng_cap=opts.ng_cap,
                                       grow_until=s.clock.until(opts.grow_share),
                                       route_search_from=opts.route_search_from)
        self.root = Root(s, self.colgen, self.elimination, self.incumbents, self.cuts)
        self.colgen.root = self.root
        # starting columns: every reachable point alone, and the warm start's routes
        routes = warm_start.routes if warm_start is not None else ()
        cols = [(int(p),) for p in np.flatnonzero(s.problem.reachable)]
        for r in routes:
            pts = tuple(int(v) + 1 for v in r)
            if pts and s.problem.energy(pts) <= s.problem.budget:
                cols.append(pts)
        s.master.add_routes(cols)
        if routes:
            self.incumbents.offer([tuple(int(v) + 1 for v in r) for r in routes if r])

    def _node_key(self, bound: float, depth: int, counter: int, state: NodeState):
        """Heap entry: best floored bound first, then deepest. Pruning only looks at floored
        bounds, so every open node of the best floor must be solved unless a plan of that value
        turns up; among them, depth first reaches integral LP solutions (plans) sooner."""
        return (-self.search.problem.floor(bound), -depth, -bound, counter, state)

    def run(self):
        """Explore the tree until it is closed or the time is up. Returns (proven, bound)."""
        s, m, inc, opts = self.search, self.search.master, self.incumbents, self.options
        root = NodeState()
        trivial = float(s.problem.inst.prizes[s.problem.reachable[1 : s.problem.V + 1]].sum())
        heap = [self._node_key(trivial, 0, 0, root)]
        counter = 1
        unresolved = []  # nodes not split (nothing fractional in an unconverged LP) and their bounds
        last_milp_cols = 0
        proven = False
        state, parent_bound = root, trivial
        try:
            while heap:
                if s.clock.time_left() <= 0:
                    break
                if s.stats.nodes and self.enumeration is not None and self.enumeration.close():
                    return self._close([], [], True)  # every better plan was among its routes
                _, _, negb, _, state = heapq.heappop(heap)
                parent_bound = -negb
                if s.prunable(parent_bound):
                    continue
                s.stats.nodes += 1
                if state.depth == 0:
                    bound, x, xa, converged = self.root.solve(state, parent_bound)
                    if s.clock.time_left() > 0:
                        inc.run_milp(min(10.0, 0.25 * s.clock.time_left()))
                        last_milp_cols = m.n_routes
                else:
                    bound, x, xa, converged = self._solve_node(state, parent_bound)
                    if bound is None:
                        continue  # closed by listing its routes
                if s.prunable(bound):
                    continue
                if s.clock.time_left() <= 0:
                    # no time to dive or branch (strong branching alone is ten LP solves, seconds
                    # each at scale): the node is solved if its converged LP optimum is a plan,
                    # else it stays open with its bound
                    if not (converged and inc.offer_if_integral(x, xa)):
                        heapq.heappush(heap, self._node_key(bound, state.depth, counter, state))
                    break
                # not converged with time left: an exact pricing hit its label cap. The node's
                # bound (its parent's, or one certified before the cap) still holds, so it is
                # branched on its current LP: the children's pricing graphs are smaller
                if s.stats.nodes % opts.dive_every == 0:
                    # dive again from this node (other fixings than the root's dive)
                    inc.dive(min(0.3 * inc.dive_limit, 0.25 * s.clock.time_left()), start=state)
                    m.apply(state)
                    _, x, xa, _ = m.solve()
                    if s.prunable(bound):
                        continue
                if inc.offer_if_integral(x, xa):
                    if converged:
                        continue  # the node's LP optimum is a plan: the node is solved
                    # not converged (a label cap): the LP optimum over all routes is unknown, so an
                    # integral LP solution closes nothing (at 600 points the degenerate LP sits at
                    # the incumbent's routes); with nothing fractional to branch on, its bound stays
                    unresolved.append(bound)
                    s.stats.open_integral += 1
                    continue
                lp_value = float(np.dot(m.route_prize, x[: m.n_routes]))
                children = branch(s, state, x, lp_value, opts.strong, opts.group_branching)
                if children is None:
                    unresolved.append(bound)
                    continue
                s.stats.group_branches += children[0].group_bounds != state.group_bounds
                for ch in children:
                    heapq.heappush(heap, self._node_key(bound, ch.depth, counter, ch))
                    counter += 1
                if s.stats.nodes % opts.milp_every == 0 and m.n_routes > last_milp_cols:
                    inc.run_milp(min(5.0, 0.1 * max(s.clock.time_left(), 0.0)))
                    last_milp_cols = m.n_routes
            else:
                proven = not unresolved
                if unresolved and s.clock.time_left() > 0:
                    # nothing left to branch on before the limit: say so, not "time limit"
                    self.stopped = (f"{len(unresolved)} node(s) left open with nothing to branch on "
                                    "(an exact pricing at its label cap, an integral LP)")
        except (LPFailure, MemoryError) as exc:
            # HiGHS could not solve an LP even after retries, or an allocation failed (a pricing's
            # labels at hundreds of points under a worker's memory limit): stop the search. The
            # node being solved keeps its parent's bound, so the reported bound stays certified
            self.stopped = str(exc) if isinstance(exc, LPFailure) else f"out of memory ({exc})"
            log.warning("bp stopped early: %s", self.stopped)
            heapq.heappush(heap, self._node_key(parent_bound, state.depth, counter, state))
        if not proven and m.n_routes:
            # the time kept in reserve: a last MILP over everything generated
            inc.run_milp(max(0.0, s.clock.hard_deadline - time.perf_counter() - 0.1))
        return self._close([-item[2] for item in heap], unresolved, proven)

    def _solve_node(self, state: NodeState, parent_bound: float):
        """Column generation at a node below the root: (bound, x, x_art, converged), bound None
        when the node was closed by route enumeration. A converged node whose LP value lies
        within the enumeration's window of the incumbent converges fully (untargeted pricing),
        then its routes are listed (:meth:`.enumeration.Enumeration.close_node`)."""
        s, m, enum = self.search, self.search.master, self.enumeration
        bound, x, xa, converged = self.colgen.solve(state, parent_bound)
        if enum is None or not converged or s.prunable(bound) or self.colgen.priced is None:
            return bound, x, xa, converged
        y = self.colgen.priced[0]
        if enum.node_window(m.lagrangian_bound(y, y[0])) is None:
            return bound, x, xa, converged
        bound, x, xa, converged = self.colgen.solve(state, bound, targeted=False)
        if not converged or s.prunable(bound) or self.colgen.priced is None:
            return bound, x, xa, converged
        y, rc_star = self.colgen.priced
        if enum.close_node(state, y, m.lagrangian_bound(y, y[0]), rc_star):
            return None, x, xa, converged
        return bound, x, xa, converged

    def _close(self, open_bounds: list, unresolved: list, finished: bool):
        """(proven, bound) from the nodes left open (their bounds) and those that could not be
        split: the bound is the incumbent or the best floored open bound, whichever is higher;
        the incumbent is proven optimal when every open node is prunable and none is
        unresolved. ``finished``: the tree was closed (no node open, none unresolved)."""
        s = self.search
        open_bounds = open_bounds + unresolved
        s.stats.open_nodes = sum(not s.prunable(b) for b in open_bounds)
        inc = s.incumbent_value if s.incumbent is not None else -math.inf
        if not open_bounds:
            return finished, inc
        open_bound = max(s.problem.floor(min(b, s.cap)) for b in open_bounds)
        proven = s.incumbent is not None and (
            s.cap <= inc + TOL or (not unresolved and open_bound <= inc + TOL))
        return proven, max(inc, open_bound)
