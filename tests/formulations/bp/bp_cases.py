"""Shared cases for the bp tests: tiny instances, brute force, the published TOP optima."""

from __future__ import annotations

import csv
import itertools
from pathlib import Path

import numpy as np

from sarcover.formulations.bp import solve_bp
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.io import load_instance
from sarcover.formulations.result import Status
from sarcover.formulations.verify import route_energy, verify

TOP_DIR = Path(__file__).resolve().parents[3] / "benchmarks" / "instances" / "top"
OPTIMAL = {r["instance"]: float(r["value"]) for r in csv.DictReader(open(TOP_DIR / "optimal.csv"))}


def feasible_routes(inst: TOPInstance) -> list[tuple[int, ...]]:
    """Every route (node ids in visiting order, the empty one included) within the budget."""
    routes = [()]
    for k in range(1, inst.n_nodes + 1):
        for perm in itertools.permutations(range(inst.n_nodes), k):
            if route_energy(inst, perm) <= inst.budget * (1 + 1e-9):
                routes.append(perm)
    return routes


def brute_force(inst: TOPInstance, visit: int | None = None) -> float | None:
    """Best prize over all plans of a tiny instance (None if no plan covers every group), among
    those that visit node ``visit`` if given."""
    sets = {frozenset(r) for r in feasible_routes(inst)}
    best = None
    for combo in itertools.combinations_with_replacement(sorted(sets, key=sorted), inst.n_vehicles):
        nodes = [i for s in combo for i in s]
        if len(nodes) != len(set(nodes)):
            continue
        seen = set(nodes)
        if any(not seen.intersection(g) for g in inst.groups) or (visit is not None
                                                                  and visit not in seen):
            continue
        prize = float(sum(inst.prizes[i] for i in seen))
        best = prize if best is None else max(best, prize)
    return best


def random_tiny(seed: int, *, groups: bool, same_depot: bool = True) -> TOPInstance:
    rng = np.random.default_rng(seed)
    coords = rng.uniform(0, 10, size=(6, 2))
    end = np.zeros(2) if same_depot else np.array([10.0, 10.0])
    return TOPInstance(
        coords=coords, prizes=rng.integers(1, 6, size=6).astype(float), start=np.zeros(2), end=end,
        budget=18.0 if same_depot else 20.0, n_vehicles=2, e_fly=1.0, e_image=0.5,
        groups=((0, 1), (2, 3)) if groups else (),
    )


FAST_TOP = ["p1.2.j", "p1.3.n", "p1.4.r", "p2.2.k", "p2.3.g", "p2.4.k", "p3.2.e", "p3.3.k", "p3.4.p"]


def tiny_sar(e_max: float) -> TOPInstance:
    """Three targets, two views each, one UAV (explicit parameters: independent of the presets)."""
    from sarcover.formulations.instance import SARInstance, to_top

    targets = np.array([[1500.0, 200.0], [200.0, 1500.0], [900.0, 900.0]])
    return to_top(SARInstance(targets=targets, n_views=2, n_uavs=1, altitude=200.0, pitch_deg=45.0,
                              e_fly=1.0, e_image=150.0, e_max=e_max))


def tiny_pricing(seed: int, n_nodes: int = 7):
    """A random pricing problem: Euclidean arcs with an image cost, reduced prizes of both signs."""
    from sarcover.formulations.bp.graph import cheapest_return

    rng = np.random.default_rng(seed)
    inst = TOPInstance(coords=rng.uniform(0, 10, size=(n_nodes, 2)), prizes=np.ones(n_nodes),
                       start=np.zeros(2), end=np.zeros(2) if seed % 2 else np.array([10.0, 0.0]),
                       budget=float(rng.uniform(18, 30)), n_vehicles=1, e_fly=1.0, e_image=1.5)
    cost = inst.cost_matrix().copy()
    profit = np.zeros(n_nodes + 2)
    profit[1:-1] = rng.uniform(-0.5, 2.0, n_nodes)
    return cost, cheapest_return(cost), profit, inst.budget * (1 + 1e-9)


def brute_paths(cost, profit, budget):
    """Every elementary path start -> nodes -> end within the budget: (prize, path)."""
    n = cost.shape[0]
    out = []
    for k in range(1, n - 1):
        for perm in itertools.permutations(range(1, n - 1), k):
            full = (0, *perm, n - 1)
            if sum(cost[a, b] for a, b in zip(full, full[1:])) <= budget:
                out.append((float(profit[list(perm)].sum()), perm))
    return out


def branch_like(cost: np.ndarray, seed: int) -> None:
    """A branching-like graph, in place: a few forbidden arcs, a few arcs made cheaper (no
    triangle inequality any more)."""
    rng = np.random.default_rng(seed)
    n = cost.shape[0]
    for a, b in rng.integers(1, n - 1, size=(4, 2)):
        if a != b:
            cost[a, b] = np.inf
    for a, b in rng.integers(1, n - 1, size=(3, 2)):
        if a != b and np.isfinite(cost[a, b]):
            cost[a, b] *= 0.5


def top_instance(name):
    return load_instance(TOP_DIR / f"{name}.txt")


def plan_prize(inst, result):
    rep = verify(inst, result.plan)
    assert rep.valid
    return rep.prize


def p12p_with_optimum():
    """p1.2.p and bp's optimal routes on it (node ids), for tests that feed bp a primal plan."""
    inst = top_instance("p1.2.p")
    ref = solve_bp(inst, time_limit=30)
    assert ref.status == Status.OPTIMAL
    return inst, [list(r) for r in ref.plan.routes]


def random_cuts(rng, n, n_cuts):
    """Random triples of inner points, memories of S plus random points, positive duals."""
    inner = np.arange(1, n - 1)
    cuts, mems = [], []
    for _ in range(n_cuts):
        S = tuple(int(p) for p in rng.choice(inner, 3, replace=False))
        extra = rng.choice(inner, int(rng.integers(0, len(inner))), replace=False)
        cuts.append(S)
        mems.append(frozenset(S) | {int(p) for p in extra})
    members = np.zeros(n, dtype=np.uint64)
    memory = np.zeros(n, dtype=np.uint64)
    for c, (S, M) in enumerate(zip(cuts, mems)):
        for p in S:
            members[p] |= np.uint64(1) << np.uint64(c)
        for p in M:
            memory[p] |= np.uint64(1) << np.uint64(c)
    return cuts, mems, members, memory, rng.uniform(0.05, 0.8, n_cuts)


def cut_priced(seed: int, cut_seed: int):
    """A tiny pricing problem with six random subset-row cuts: (cost, ret, profit, budget,
    (cut members, cut memory, cut duals), value of a path with its cut duals paid, every
    elementary path as (value, path) by brute force)."""
    from sarcover.formulations.bp.master import _lm_coefficient

    cost, ret, profit, budget = tiny_pricing(seed)
    cuts, mems, members, memory, sig = random_cuts(np.random.default_rng(cut_seed), cost.shape[0], 6)

    def value(path):
        pen = sum(s * _lm_coefficient(path, S, M) for S, M, s in zip(cuts, mems, sig))
        return float(profit[list(path)].sum()) - pen

    paths = [(value(p), p) for _, p in brute_paths(cost, profit, budget)]
    return cost, ret, profit, budget, (members, memory, sig), value, paths


def arcs_of_plans_from(inst: TOPInstance, value: float) -> set:
    """Arcs (solver points: start 0, nodes 1..V, end V+1) of every plan worth at least ``value``."""
    v = inst.n_nodes
    arcs = set()
    for combo in itertools.combinations(feasible_routes(inst), inst.n_vehicles):
        nodes = [i for r in combo for i in r]
        if len(nodes) != len(set(nodes)) or inst.prizes[nodes].sum() < value - 1e-9:
            continue
        for r in combo:
            full = (0, *(i + 1 for i in r), v + 1)
            arcs.update(zip(full, full[1:]))
    return arcs
