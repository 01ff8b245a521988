"""Shared preprocessing for the exact models: reachable nodes, pruned arcs, the prize lattice.

Everything here is in SOLVER ORDER (index 0 = start, 1..V = nodes, V+1 = end, as
:meth:`TOPInstance.cost_matrix`). The pruning is safe for the verifier's tolerance: an arc is
dropped only if every route using it costs more than ``budget_with_tolerance(instance)``, the
largest route energy :func:`sarcover.formulations.verify.verify` accepts. The argument is the triangle
inequality: with Euclidean distances and a non-negative per-node cost, the cheapest way from the
start to node i is the direct arc (c_0i), and from j to the end is c_j,end, so any route using
arc (i, j) costs at least c_0i + c_ij + c_j,end.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.verify import REL_TOL

# Float noise between the cost matrix (numpy) and the verifier (math.hypot) is ~1e-15 relative;
# pruning keeps this much extra slack so that it can never drop an arc of an accepted route.
_PRUNE_SLACK = 1e-9


def budget_with_tolerance(instance: TOPInstance) -> float:
    """The largest route energy the verifier accepts (its budget test, made an equality)."""
    return instance.budget * (1.0 + REL_TOL) + 1e-12


@dataclass(frozen=True)
class ArcGraph:
    """The arcs any within-budget route can use, in solver order.

    ``nodes``: solver indices of reachable nodes (node id + 1). ``arcs``: (i, j) pairs with i in
    {start} ∪ nodes, j in nodes ∪ {end}, i != j; the arc start → end (an empty route) is left
    out. ``cost``: the full (V+2, V+2) cost matrix. ``to_end[i]``: c_i,end, ``from_start[i]``:
    c_0i, both lower bounds on the cost of the rest / first part of a route.
    """

    n_nodes: int
    start: int
    end: int
    nodes: tuple[int, ...]
    arcs: tuple[tuple[int, int], ...]
    cost: np.ndarray
    from_start: np.ndarray
    to_end: np.ndarray
    budget: float  # the verifier's acceptance threshold, see budget_with_tolerance
    n_arcs_full: int  # arcs before pruning (all ordered pairs as above)


def prune_arcs(instance: TOPInstance) -> ArcGraph:
    """Reachable nodes and the arcs some route within the budget could use."""
    v = instance.n_nodes
    start, end = 0, v + 1
    cost = instance.cost_matrix()
    from_start = cost[0, :].copy()
    to_end = cost[:, end].copy()
    budget = budget_with_tolerance(instance)
    limit = budget + _PRUNE_SLACK * max(1.0, budget)
    node_idx = np.arange(1, v + 1)
    reach = node_idx[from_start[node_idx] + to_end[node_idx] <= limit]
    reach_set = set(reach.tolist())
    arcs: list[tuple[int, int]] = [(start, int(j)) for j in reach]
    if reach.size:
        sub = from_start[reach][:, None] + cost[np.ix_(reach, reach)] + to_end[reach][None, :]
        ok = sub <= limit
        np.fill_diagonal(ok, False)
        ii, jj = np.nonzero(ok)
        arcs += [(int(reach[a]), int(reach[b])) for a, b in zip(ii, jj)]
    arcs += [(int(i), end) for i in reach]
    assert all(i in reach_set or i == start for i, _ in arcs)
    return ArcGraph(
        n_nodes=v,
        start=start,
        end=end,
        nodes=tuple(int(i) for i in reach),
        arcs=tuple(arcs),
        cost=cost,
        from_start=from_start,
        to_end=to_end,
        budget=budget,
        n_arcs_full=v * v + v,  # start→nodes, nodes→end, node→node (i != j): v + v + v(v-1)
    )


def incompatibility(g: ArcGraph) -> np.ndarray:
    """(len(nodes), len(nodes)) bool: nodes i and j can never be on the same route.

    True when min(c_0i + c_ij + c_j,end, c_0j + c_ji + c_i,end) exceeds the budget: by the
    triangle inequality every route visiting both costs at least that.
    """
    c = g.cost
    limit = g.budget + _PRUNE_SLACK * max(1.0, g.budget)
    nodes = np.array(g.nodes, dtype=int)
    fwd = g.from_start[nodes][:, None] + c[np.ix_(nodes, nodes)] + g.to_end[nodes][None, :]
    inc = np.minimum(fwd, fwd.T) > limit
    np.fill_diagonal(inc, False)
    return inc


def incompatible_cliques(
    g: ArcGraph, n_vehicles: int, weights: np.ndarray | None = None, inc: np.ndarray | None = None
) -> list[tuple[int, ...]]:
    """Sets of pairwise incompatible nodes (see :func:`incompatibility`) larger than the fleet.

    A route visits at most one node of such a clique K, so sum_{i in K} y_i <= vehicles used is
    valid. One clique is grown greedily from every node (duplicates removed): by the candidate
    incompatible with most other candidates, or, given ``weights`` (e.g. LP values of y, one per
    node of ``g.nodes``), by the heaviest candidate. Returned in solver indices.
    """
    nodes = np.array(g.nodes, dtype=int)
    if nodes.size < 2:
        return []
    inc = incompatibility(g) if inc is None else inc
    cliques: set[tuple[int, ...]] = set()
    for s in range(nodes.size):
        clique, cand = [s], inc[s].copy()
        while cand.any():
            if weights is None:
                score = np.where(cand, (inc & cand[None, :]).sum(axis=1), -1)
            else:
                score = np.where(cand, weights, -np.inf)
            k = int(np.argmax(score))
            clique.append(k)
            cand &= inc[k]
        if len(clique) > n_vehicles:
            cliques.add(tuple(sorted(int(nodes[k]) for k in clique)))
    return sorted(cliques)


def prize_lattice(prizes: np.ndarray) -> float | None:
    """The largest g > 0 with every prize an integer multiple of g, if prizes are integers.

    Returns None when some prize is not an integer (then no rounding of bounds is done) or every
    prize is zero. Used to round a solver's upper bound down to an attainable value.
    """
    p = np.asarray(prizes, dtype=float)
    if p.size == 0 or not np.all(np.abs(p - np.round(p)) <= 1e-9):
        return None
    g = 0
    for q in np.round(p).astype(np.int64):
        g = math.gcd(g, int(q))
    return float(g) if g > 0 else None


def floor_to_lattice(bound: float, lattice: float | None) -> float:
    """Round an upper bound down to the prize lattice, allowing 1e-3 lattice steps of solver noise.

    A bound of 99.99999 with lattice 5 becomes 100, not 95: solver bounds carry tolerances, and
    rounding down past an attainable value would be a wrong bound. Without a lattice the bound is
    returned unchanged.
    """
    if lattice is None or not math.isfinite(bound):
        return bound
    return lattice * math.floor(bound / lattice + 1e-3)


__all__ = ["ArcGraph", "budget_with_tolerance", "floor_to_lattice", "incompatibility", "incompatible_cliques",
           "prize_lattice", "prune_arcs"]
