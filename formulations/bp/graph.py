"""The pricing graph: a branch-and-bound node's decisions (:class:`NodeState`), the graph they
leave (:func:`node_graph`), the cheapest energy to the end, and the reversed graph that backward
searches run on. What the labelling remembers on it: :mod:`.ng_sets`.

Every kind of decision keeps the pricing a plain labelling on a modified graph: a forbidden node
leaves the graph, a forced node only changes its master row (``= 1``); a bound on a group's
visits only changes the group's row (its dual joins the prizes of the group's points, as the
cover row's does); a forbidden arc is removed, a forced arc (a, b) removes every other arc out of
a and into b.

Solver points: 0 is the start, node id v is point v + 1, n - 1 is the end.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from sarcover.formulations.bp.search import Search


@dataclass(frozen=True)
class NodeState:
    """Branching decisions of one branch-and-bound node (solver points: node id + 1)."""

    forbidden_nodes: frozenset = frozenset()
    forced_nodes: frozenset = frozenset()
    forbidden_arcs: frozenset = frozenset()
    forced_arcs: frozenset = frozenset()
    group_bounds: frozenset = frozenset()  # (group, lo, hi): the group's visits within [lo, hi]
    depth: int = 0

    def child(self, **add) -> "NodeState":
        kw = {k: getattr(self, k) | frozenset(add.get(k, ())) for k in
              ("forbidden_nodes", "forced_nodes", "forbidden_arcs", "forced_arcs",
               "group_bounds")}
        return NodeState(**kw, depth=self.depth + 1)


def node_graph(search: "Search", state: NodeState):
    """The pricing graph at a node: (arc costs with the removed arcs at inf, cheapest energy to
    the end from each point, allowed points). Eliminated arcs (:mod:`.elimination`) are removed
    too, and a point whose every incoming arc is gone is no longer allowed."""
    cost = search.problem.cost.copy()
    n = search.problem.V + 2
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
    allowed = search.problem.reachable.copy()
    for p in state.forbidden_nodes:
        allowed[p] = False
    eliminated = search.master.eliminated
    if eliminated.any():
        cost[eliminated] = np.inf
        into = np.isfinite(cost)
        np.fill_diagonal(into, False)
        allowed &= into.any(axis=0)
    return cost, cheapest_return(cost), allowed


def sparse_graph(cost: np.ndarray, allowed: np.ndarray, k: int) -> np.ndarray:
    """The arc costs with every point's arcs cut to its ``k`` cheapest into allowed points (its
    arc into the end and the start's arcs all kept; the others at inf). A heuristic pricing on
    it finds improving routes of near neighbours with far fewer labels; every route it finds is
    a route of the full graph, but its best value bounds nothing."""
    n = cost.shape[0]
    end = n - 1
    if k >= n - 2:
        return cost
    inner = cost[1:end, 1:end].copy()
    inner[:, ~allowed[1:end]] = np.inf
    np.fill_diagonal(inner, np.inf)
    keep = np.argpartition(inner, k - 1, axis=1)[:, :k]
    cut = np.full_like(inner, np.inf)
    rows = np.arange(inner.shape[0])[:, None]
    cut[rows, keep] = inner[rows, keep]
    out = cost.copy()
    out[1:end, 1:end] = cut
    return out


def cheapest_return(cost: np.ndarray) -> np.ndarray:
    """Cheapest energy from each point to the end (index n-1) over allowed arcs (Bellman-Ford)."""
    n = cost.shape[0]
    ret = cost[:, n - 1].copy()
    ret[n - 1] = 0.0
    for _ in range(n):
        new = np.minimum(ret, (cost[:, 1 : n - 1] + ret[None, 1 : n - 1]).min(axis=1))
        new[n - 1] = 0.0
        if np.array_equal(new, ret):
            break
        ret = new
    return ret


def reversed_graph(cost, profit, allowed):
    """The reversed graph (start and end swapped, arcs turned): permutation, cost, profit,
    allowed. Points 1..n-2 keep their numbers."""
    end = cost.shape[0] - 1
    perm = np.concatenate([[end], np.arange(1, end), [0]])
    return (perm, np.ascontiguousarray(cost.T[np.ix_(perm, perm)]),
            np.ascontiguousarray(profit[perm]), allowed[perm])
