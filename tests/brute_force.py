"""Brute force by enumeration for tiny instances: the ground truth of the exact and clustered solvers' tests."""

from __future__ import annotations

import itertools

from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.verify import REL_TOL, route_energy


def feasible_subsets(inst: TOPInstance, nodes) -> dict[frozenset, tuple[int, ...]]:
    """Every subset of ``nodes`` that one route can visit within the budget (the verifier's
    test), with a cheapest order, by trying all orders."""
    limit = inst.budget * (1.0 + REL_TOL) + 1e-12
    out = {frozenset(): ()}
    nodes = list(nodes)
    for r in range(1, len(nodes) + 1):
        for sub in itertools.combinations(nodes, r):
            best = min(itertools.permutations(sub), key=lambda p: route_energy(inst, p))
            if route_energy(inst, best) <= limit:
                out[frozenset(sub)] = best
    return out


def covers_all(inst: TOPInstance, visited: set) -> bool:
    return all(any(v in visited for v in g) for g in inst.groups)


def brute_clustered(inst: TOPInstance, clusters) -> float | None:
    """OPT|C by enumeration: one feasible subset per cluster, every group covered; None if none."""
    per = [list(feasible_subsets(inst, c).keys()) for c in clusters]
    best = None
    for combo in itertools.product(*per):
        visited = set().union(*combo)
        if covers_all(inst, visited):
            value = float(sum(inst.prizes[v] for v in visited))
            best = value if best is None else max(best, value)
    return best


def brute_opt(inst: TOPInstance) -> float | None:
    """OPT by enumeration: N disjoint feasible subsets of all nodes, every group covered."""
    subsets = list(feasible_subsets(inst, range(inst.n_nodes)).keys())
    best = None
    for combo in itertools.combinations_with_replacement(subsets, inst.n_vehicles):
        if sum(len(s) for s in combo) != len(set().union(*combo)):
            continue  # a node twice
        visited = set().union(*combo)
        if covers_all(inst, visited):
            value = float(sum(inst.prizes[v] for v in visited))
            best = value if best is None else max(best, value)
    return best
