"""Branch-and-price (`bp`): hand-checked optima, groups, infeasibility, bounds on the TOP benchmark."""

from __future__ import annotations

import csv
import itertools
import math
import time
from pathlib import Path

import numpy as np
import pytest
from sarcover.benchmarks.registry import run_method
from sarcover.formulations.bp import BPOptions, solve_bp
from sarcover.formulations.bp.options import (
    CUTS_FROM_S,
    ENUM_FROM_S,
    ENUM_LABELS,
    ENUM_LABELS_FROM_S,
    MORE_PRIMAL_FROM_S,
    OPEN_CUTS_FROM_S,
)
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.io import load_instance
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Status
from sarcover.formulations.verify import route_energy, verify

TOP_DIR = Path(__file__).resolve().parent.parent / "benchmarks" / "instances" / "top"
OPTIMAL = {r["instance"]: float(r["value"]) for r in csv.DictReader(open(TOP_DIR / "optimal.csv"))}


def _feasible_routes(inst: TOPInstance) -> list[tuple[int, ...]]:
    """Every route (node ids in visiting order, the empty one included) within the budget."""
    routes = [()]
    for k in range(1, inst.n_nodes + 1):
        for perm in itertools.permutations(range(inst.n_nodes), k):
            if route_energy(inst, perm) <= inst.budget * (1 + 1e-9):
                routes.append(perm)
    return routes


def brute_force(inst: TOPInstance) -> float | None:
    """Best prize over all plans of a tiny instance (None if no plan covers every group)."""
    sets = {frozenset(r) for r in _feasible_routes(inst)}
    best = None
    for combo in itertools.combinations_with_replacement(sorted(sets, key=sorted), inst.n_vehicles):
        nodes = [i for s in combo for i in s]
        if len(nodes) != len(set(nodes)):
            continue
        seen = set(nodes)
        if any(not seen.intersection(g) for g in inst.groups):
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


def test_line_instance_by_hand():
    """Two vehicles on a hand-checked instance: (1,0),(2,0) on one trip, (0,3) on the other: 8."""
    inst = TOPInstance(coords=[[1, 0], [2, 0], [0, 3]], prizes=[1, 2, 5], start=[0, 0], end=[0, 0],
                       budget=6.0, n_vehicles=2)
    res = run_method("bp", inst, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == 8.0 and res.bound == 8.0
    one = TOPInstance(coords=[[1, 0], [2, 0], [0, 3]], prizes=[1, 2, 5], start=[0, 0], end=[0, 0],
                      budget=4.5, n_vehicles=1)
    res = run_method("bp", one, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == 3.0


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("groups", [False, True])
def test_matches_brute_force(seed, groups):
    """The proven optimum equals exhaustive enumeration on tiny random instances, with and without groups."""
    inst = random_tiny(seed, groups=groups)
    best = brute_force(inst)
    res = run_method("bp", inst, time_limit=30)
    if best is None:
        assert res.status == Status.INFEASIBLE
    else:
        assert res.status == Status.OPTIMAL and res.objective == pytest.approx(best)
        assert res.bound == pytest.approx(best)


@pytest.mark.parametrize("seed", range(3))
def test_start_differs_from_end(seed):
    """Open routes from start to a different end: optimum equals enumeration."""
    inst = random_tiny(seed, groups=False, same_depot=False)
    best = brute_force(inst)
    res = run_method("bp", inst, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == pytest.approx(best)


def test_infeasible_groups_proven():
    """Two groups on opposite sides, each reachable alone but not both with one vehicle: infeasible."""
    inst = TOPInstance(coords=[[5, 0], [-5, 0], [0, 1]], prizes=[1, 1, 3], start=[0, 0], end=[0, 0],
                       budget=10.5, n_vehicles=1, groups=((0,), (1,)))
    res = run_method("bp", inst, time_limit=30)
    assert res.status == Status.INFEASIBLE and res.plan is None


def test_groups_force_lower_prize():
    """A group on a cheap node forces the vehicle away from the big prize (hand-checked: 1)."""
    inst = TOPInstance(coords=[[3, 0], [-3, 0]], prizes=[1, 10], start=[0, 0], end=[0, 0],
                       budget=6.5, n_vehicles=1, groups=((0,),))
    res = run_method("bp", inst, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == 1.0 and res.plan.visited == [0]


def test_initial_routes_are_used():
    """A warm-start plan is accepted as incumbent and the proof still reaches the optimum."""
    inst = load_instance(TOP_DIR / "p2.2.d.txt")
    res = solve_bp(inst, time_limit=30, warm_start=Plan.of([[0], [1]]))
    assert res.status == Status.OPTIMAL and res.bound == OPTIMAL["p2.2.d"]


FAST_TOP = ["p1.2.j", "p1.3.n", "p1.4.r", "p2.2.k", "p2.3.g", "p2.4.k", "p3.2.e", "p3.3.k", "p3.4.p"]


@pytest.mark.parametrize("name", FAST_TOP)
def test_top_benchmark_optimum(name):
    """On a fast TOP subset, bp proves exactly the published optimum."""
    inst = load_instance(TOP_DIR / f"{name}.txt")
    res = run_method("bp", inst, time_limit=60)
    assert res.status == Status.OPTIMAL, res.reason
    assert res.objective == OPTIMAL[name] and res.bound == OPTIMAL[name]


@pytest.mark.parametrize("name", ["p1.2.r", "p3.2.t", "p3.2.j"])
def test_stopped_run_bound_is_valid(name):
    """Stopped after 2 s on hard instances, the certified bound is never below the published optimum."""
    inst = load_instance(TOP_DIR / f"{name}.txt") if (TOP_DIR / f"{name}.txt").exists() else None
    if inst is None:
        pytest.skip(f"{name} not in the public part")
    res = run_method("bp", inst, time_limit=2)
    assert res.status in (Status.OPTIMAL, Status.TIME_LIMIT)
    assert res.bound is not None and res.bound >= OPTIMAL[name] - 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(n for n in OPTIMAL if n.split(".")[0] in ("p1", "p2", "p3")))
def test_top_sets_1_to_3_all(name):
    """Every TOP instance of sets 1-3: the published optimum, proven within 60 s."""
    inst = load_instance(TOP_DIR / f"{name}.txt")
    res = run_method("bp", inst, time_limit=60)
    assert res.bound is None or res.bound >= OPTIMAL[name] - 1e-6
    assert res.status == Status.OPTIMAL, res.reason
    assert res.objective == OPTIMAL[name]


def tiny_sar(e_max: float) -> TOPInstance:
    """Three targets, two views each, one UAV (explicit parameters: independent of the presets)."""
    from sarcover.formulations.instance import SARInstance, to_top

    targets = np.array([[1500.0, 200.0], [200.0, 1500.0], [900.0, 900.0]])
    return to_top(SARInstance(targets=targets, n_views=2, n_uavs=1, altitude=200.0, pitch_deg=45.0,
                              e_fly=1.0, e_image=150.0, e_max=e_max))


@pytest.mark.parametrize("e_max", [5000.0, 5500.0, 6000.0])
def test_small_sar_matches_brute_force(e_max):
    """SAR form (unit prizes, one group per target) with a binding budget: optimum equals enumeration."""
    inst = tiny_sar(e_max)
    best = brute_force(inst)
    assert best is not None and best < inst.total_prize  # feasible, and the budget binds
    res = run_method("bp", inst, time_limit=30)
    assert res.status == Status.OPTIMAL and res.objective == best


def test_sar_infeasible_when_targets_do_not_fit():
    """Every target reachable alone but not all in one flight: proven infeasible (precheck passes)."""
    from sarcover.formulations.instance import precheck

    inst = tiny_sar(4500.0)
    assert precheck(inst) is None and brute_force(inst) is None
    res = run_method("bp", inst, time_limit=30)
    assert res.status == Status.INFEASIBLE


# -- the pieces added for the M = 20 SAR instances -----------------------------------

def _tiny_pricing(seed: int, n_nodes: int = 7):
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


def _brute_paths(cost, profit, budget):
    """Every elementary path start -> nodes -> end within the budget: (prize, path)."""
    n = cost.shape[0]
    out = []
    for k in range(1, n - 1):
        for perm in itertools.permutations(range(1, n - 1), k):
            full = (0, *perm, n - 1)
            if sum(cost[a, b] for a, b in zip(full, full[1:])) <= budget:
                out.append((float(profit[list(perm)].sum()), perm))
    return out


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("bidirectional", [False, True])
def test_exact_pricing_matches_enumeration(seed, bidirectional):
    """Elementary labelling (heap order, buckets, reach-filtered completion bound): its best value
    is the best elementary path's prize, its routes are real improving paths; ng-8 labelling and the
    heuristic bracket it (ng value >= elementary best >= any heuristic route)."""
    from sarcover.formulations.bp.labelling import price
    from sarcover.formulations.bp.ng_sets import full_ng, nearest_ng

    cost, ret, profit, budget = _tiny_pricing(seed)
    paths = _brute_paths(cost, profit, budget)
    best = max(p for p, _ in paths)
    gain = 0.3 * best
    allowed = np.ones(cost.shape[0], dtype=bool)
    kw = dict(max_labels=1_000_000, n_cols=50, min_gain=gain)
    ex = price(cost, ret, profit, budget, full_ng(cost.shape[0]), allowed, heuristic=False,
               bidirectional=bidirectional, **kw)
    assert ex.exact and ex.best == pytest.approx(max(best, gain))
    value = {path: p for p, path in paths}
    for r in ex.routes:
        assert r in value and value[r] > gain
    assert ex.routes[0] in value and value[ex.routes[0]] == pytest.approx(best)
    ng = price(cost, ret, profit, budget, nearest_ng(cost, 2), allowed, heuristic=False,
               bidirectional=bidirectional, **kw)
    assert ng.exact and ng.best >= best - 1e-9
    heur = price(cost, ret, profit, budget, full_ng(cost.shape[0]), allowed, heuristic=True, **kw)
    assert all(r in value and value[r] <= best + 1e-9 for r in heur.routes)


@pytest.mark.parametrize("seed", range(6))
def test_exact_pricing_keeps_near_best_routes_without_losing_the_best(seed):
    """``keep`` holds the exact pricing's pruning threshold below the best path found: the best
    value stays the best elementary prize, every route returned is a real improving path, the
    best comes first, and more of the near-best routes come back (the point of it: more columns
    per exact call)."""
    from sarcover.formulations.bp.labelling import price
    from sarcover.formulations.bp.ng_sets import full_ng

    cost, ret, profit, budget = _tiny_pricing(seed, n_nodes=9)
    paths = _brute_paths(cost, profit, budget)
    best = max(p for p, _ in paths)
    value = {path: p for p, path in paths}
    allowed = np.ones(cost.shape[0], dtype=bool)
    routes = {}
    for keep in (0.0, 0.5, 1.0):
        res = price(cost, ret, profit, budget, full_ng(cost.shape[0]), allowed, heuristic=False,
                    max_labels=1_000_000, n_cols=1000, min_gain=0.0, keep=keep)
        assert res.exact and res.best == pytest.approx(best)
        assert all(r in value and value[r] > 0.0 for r in res.routes)
        assert value[res.routes[0]] == pytest.approx(best)
        routes[keep] = len(res.routes)
    assert routes[0.0] < routes[0.5] <= routes[1.0]


@pytest.mark.parametrize("seed", range(4))
def test_completion_bound_covers_every_suffix(seed):
    """_completion never undercuts the best elementary suffix of a path prefix (enumerated)."""
    from sarcover.formulations.bp.bounds import completion_bound as _completion
    from sarcover.formulations.bp.bounds import completion_data as _prepare
    from sarcover.formulations.bp.ng_sets import n_words

    cost, ret, profit, budget = _tiny_pricing(seed)
    n = cost.shape[0]
    order, cin, reach, lastord, cend = _prepare(cost, ret, profit, np.ones(n, dtype=bool))
    paths = _brute_paths(cost, profit, budget)
    for _, path in paths[:: max(1, len(paths) // 300)]:
        for cut in range(1, len(path) + 1):
            pre, v = path[:cut], path[cut - 1]
            used = sum(cost[a, b] for a, b in zip((0, *pre), pre))
            mask = np.zeros(n_words(n), dtype=np.uint64)
            for p in pre:
                mask[p >> 6] |= np.uint64(1) << np.uint64(p & 63)
            best_suffix = max(
                [sum(profit[list(q[cut:])]) for _, q in paths if q[:cut] == pre] or [0.0])
            ub = _completion(mask, v, budget - used, np.inf, order, profit, cin, reach, lastord, cend)
            assert ub >= best_suffix - 1e-9


def _branch_like(cost: np.ndarray, seed: int) -> None:
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


@pytest.mark.parametrize("seed", range(4))
def test_suffix_tables_cover_every_suffix(seed):
    """The DP suffix bound never undercuts the best elementary suffix of a path prefix
    (enumerated), also on a graph with forbidden arcs and no triangle inequality."""
    from sarcover.formulations.bp.bounds import dp_bound as _dp_bound
    from sarcover.formulations.bp.bounds import suffix_tables

    cost, ret, profit, budget = _tiny_pricing(seed)
    if seed >= 2:
        _branch_like(cost, 100 + seed)
    n = cost.shape[0]
    g1, s1, g2, delta, nb = suffix_tables(cost, profit, np.ones(n, dtype=bool), budget, units=64)
    assert nb > 0
    paths = _brute_paths(cost, profit, budget)
    assert paths
    for _, path in paths:
        for cut in range(1, len(path) + 1):
            pre, v = path[:cut], path[cut - 1]
            full = (0, *pre)
            used = sum(cost[a, b] for a, b in zip(full, full[1:]))
            prev = full[-2]
            best_suffix = max(
                [sum(profit[list(q[cut:])]) for _, q in paths if q[:cut] == pre] or [0.0])
            ub = _dp_bound(g1, s1, g2, v, prev, budget - used, delta, nb)
            assert ub >= best_suffix - 1e-9


@pytest.mark.parametrize("seed", range(4))
def test_arc_bounds_cover_every_path_through_an_arc(seed):
    """The arc bound (best prefix + arc + best suffix) is never below the prize of an elementary
    path through that arc (enumerated), also with forbidden arcs and no triangle inequality; and
    it is not vacuous: on these graphs it is finite and below the largest bound somewhere."""
    from sarcover.formulations.bp.arc_bounds import arc_bounds

    cost, ret, profit, budget = _tiny_pricing(seed)
    n = cost.shape[0]
    if seed >= 2:
        _branch_like(cost, 200 + seed)
    best = arc_bounds(cost, profit, np.ones(n, dtype=bool), budget, units=64)
    exact = np.full((n, n), -np.inf)
    for prize, path in _brute_paths(cost, profit, budget):
        full = (0, *path, n - 1)
        for a, b in zip(full, full[1:]):
            exact[a, b] = max(exact[a, b], prize)
            assert best[a, b] >= prize - 1e-9, (a, b, path)
    used = np.isfinite(exact)
    assert used.any() and np.all(np.isfinite(best[used]))
    assert np.any(best[used] < best[used].max() - 1e-6)


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("ng_size", [3, 8])
def test_label_arc_bounds_cover_every_path_above_the_threshold(seed, ng_size):
    """The labelling arc bound (ng-labels forward and backward, fixed threshold) is never below
    the prize of an elementary path through the arc whose prize beats the threshold; with
    elementary labels it is tighter than the DP arc bound on some arc."""
    from sarcover.formulations.bp.arc_bounds import arc_bounds, label_arc_bounds
    from sarcover.formulations.bp.ng_sets import nearest_ng

    cost, ret, profit, budget = _tiny_pricing(seed)
    n = cost.shape[0]
    allowed = np.ones(n, dtype=bool)
    paths = _brute_paths(cost, profit, budget)
    prizes = sorted(p for p, _ in paths)
    threshold = prizes[len(prizes) * 3 // 4]
    best, routes = label_arc_bounds(cost, profit, allowed, budget, nearest_ng(cost, ng_size),
                                    threshold, units=64, n_routes=5)
    dp = arc_bounds(cost, profit, allowed, budget, units=64)
    above = np.zeros((n, n), dtype=bool)
    for prize, path in paths:
        if prize <= threshold:
            continue
        full = (0, *path, n - 1)
        for a, b in zip(full, full[1:]):
            above[a, b] = True
            assert best[a, b] >= prize - 1e-9, (a, b, path)
    assert above.any() and not above.all()
    if ng_size == 8:
        assert np.any(best < dp - 1e-6)
    # its routes: elementary paths above the threshold (distinct sets, best first, the best one
    # among them; labels the dominance removed take their routes with them)
    above_paths = {p for pr, p in paths if pr > threshold}
    got = [float(profit[list(r)].sum()) for r in routes]
    assert 0 < len(routes) <= 5 and len({frozenset(r) for r in routes}) == len(routes)
    assert all(tuple(r) in above_paths for r in routes)
    assert got == sorted(got, reverse=True)
    assert got[0] == pytest.approx(max(pr for pr, _ in paths))


def test_suffix_tables_are_the_best_walk_without_turning_back():
    """On integer arc costs with a one-unit grid the tables are exact: the best walk (points may
    repeat, no immediate return) within b units, enumerated."""
    from sarcover.formulations.bp.bounds import suffix_dp as _suffix_dp

    rng = np.random.default_rng(7)
    n = 6  # start, 4 nodes, end
    cost = rng.integers(1, 5, size=(n, n)).astype(float)
    cost[:, 0] = np.inf
    cost[n - 1, :] = np.inf
    np.fill_diagonal(cost, 0.0)
    profit = np.concatenate([[0.0], rng.uniform(-1, 3, n - 2), [0.0]])
    nb = 9
    g1, s1, g2 = _suffix_dp(cost, profit, np.ones(n, dtype=bool), 1.0, nb)

    def best_walk(u, prev, b):
        out = 0.0 if cost[u, n - 1] <= b else -np.inf
        for w in range(1, n - 1):
            if w != u and w != prev and cost[u, w] <= b:
                out = max(out, profit[w] + best_walk(w, u, b - cost[u, w]))
        return out

    for u in range(n - 1):
        for b in range(nb + 1):
            assert g1[u, b] == pytest.approx(best_walk(u, -1, b))
            for v in range(1, n - 1):
                got = g1[u, b] if s1[u, b] != v else g2[u, b]
                assert got == pytest.approx(best_walk(u, v, b))


def test_ng_route_columns_count_visits():
    """A repeated point counts twice in its node row (never integer-feasible); routes that stop
    being ng-routes when the ng sets grow are excluded from the master."""
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.master import Master
    from sarcover.formulations.bp.ng_sets import add_to_ng, nearest_ng

    m = Master(4, np.ones(4), [(0, 1)], 2)
    m.add_routes([(1, 2, 3, 1), (1, 2), (3, 4)])
    assert m.repeated == [0]
    assert list(m.node_visits(np.array([1.0, 0.0, 0.0]))[1:5]) == [2.0, 1.0, 1.0, 0.0]
    assert m.milp(5.0) is not None and (1, 2, 3, 1) not in m.milp(5.0)
    cost = np.abs(np.subtract.outer(np.arange(6.0), np.arange(6.0)))
    ng = nearest_ng(cost, 1)  # each point remembers only itself: the cycle 1-2-3-1 is an ng-route
    assert m.kill_non_ng(ng) == 0
    add_to_ng(ng, 2, 1)
    add_to_ng(ng, 3, 1)  # now 1 is remembered at 2 and 3: revisiting it is forbidden
    assert m.kill_non_ng(ng) == 1
    assert list(m.incompatible(NodeState())) == [True, False, False]


def test_branching_decisions_exclude_exactly_the_conflicting_routes():
    """Master.incompatible against its definition, route by route (repeated visits included):
    a route is out iff it visits a forbidden point, uses a forbidden arc, or leaves the tail of a
    forced arc (not the start) or enters its head (not the end) by another arc."""
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.master import Master

    rng = np.random.default_rng(3)
    V, end = 7, 8
    m = Master(V, np.ones(V), [], 3)
    routes = {tuple(int(p) for p in rng.choice(np.arange(1, V + 1), size=rng.integers(1, 6)))
              for _ in range(300)}  # random, some with repeated points
    m.add_routes(sorted(routes))
    assert m.repeated
    arcs_of = [list(zip([0, *r], [*r, end])) for r in m.routes]

    def out(r, st):
        arcs = arcs_of[r]
        return (any(p in st.forbidden_nodes for p in m.routes[r])
                or any(a in st.forbidden_arcs for a in arcs)
                or any((a == fa and fa != 0 and b != fb) or (b == fb and fb != end and a != fa)
                       for fa, fb in st.forced_arcs for a, b in arcs))

    pts = list(range(0, V + 2))
    shared = 0  # states where two forced arcs leave the same point (or enter the same one)
    for _ in range(200):
        pick = lambda: (int(rng.choice(pts[:-1])), int(rng.choice(pts[1:])))  # noqa: E731
        st = NodeState(forbidden_nodes=frozenset(int(p) for p in rng.choice(
                           np.arange(1, V + 1), size=rng.integers(0, 2))),
                       forbidden_arcs=frozenset(pick() for _ in range(rng.integers(0, 3))),
                       forced_arcs=frozenset(pick() for _ in range(rng.integers(0, 5))))
        tails = [a for a, _ in st.forced_arcs if a != 0]
        heads = [b for _, b in st.forced_arcs if b != end]
        shared += len(set(tails)) < len(tails) or len(set(heads)) < len(heads)
        got = m.incompatible(st)
        assert list(got) == [out(r, st) for r in range(m.n_routes)]
    assert shared > 0
    m.hide_repeated = True
    assert all(m.incompatible(NodeState())[m.repeated])


@pytest.mark.parametrize("value,n", [(57.3, 5), (57.0, 5), (12.999, 3), (4.2, 1)])
def test_targeted_slack_keeps_the_floor(value, n):
    """The raised exact-pricing threshold: dual value + N * (slack + TOL) stays below the next
    integer (or incumbent + 1), so 'nothing found above the threshold' settles floor(bound)."""
    from sarcover.formulations.bp.constants import TOL
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = TOPInstance(coords=[[1, 0]], prizes=[1], start=[0, 0], end=[0, 0], budget=5.0, n_vehicles=n)
    bp = BranchAndPrice(inst, time_limit=10)
    for inc in (None, int(value) - 2, int(value) + 1):
        bp.search.incumbent, bp.search.incumbent_value = (None, -np.inf) if inc is None else ([], float(inc))
        slack = bp.colgen.slack(value)
        target = max(np.floor(value + 1e-6) + 1, (inc if inc is not None else -np.inf) + 1)
        assert slack >= 0
        if slack > 0:
            assert np.floor(value + n * (slack + TOL) + 1e-6) < target


@pytest.mark.parametrize("seed", range(6))
def test_dive_gives_a_verified_plan(seed):
    """The diving heuristic (root LP, then fixing routes) only returns plans the verifier accepts,
    never better than enumeration; on these tiny instances it finds the enumerated optimum
    whenever a plan exists."""
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = random_tiny(seed, groups=True)
    best = brute_force(inst)
    bp = BranchAndPrice(inst, time_limit=20)
    bp.colgen.solve(NodeState(), np.inf)
    bp.incumbents.dive(5.0)
    s = bp.search
    if best is None:
        assert s.incumbent is None
    else:
        assert s.incumbent is not None and s.incumbent_value == pytest.approx(best)


def test_registered_bp_starts_from_greedy():
    """The registered `bp` gets greedy's routes as first columns: stopped almost at once on a
    paper-size instance it still returns a verified plan at least as good as greedy's, under its bound."""
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(20, 3, 5, 11))
    g = run_method("greedy", inst)
    r = run_method("bp", inst, time_limit=0.5)
    assert g.status == Status.FEASIBLE and r.plan is not None and r.report.valid
    assert r.objective >= g.objective and r.bound >= r.objective
    assert r.info["warm_start_prize"] == g.objective
    # stopped with a gap, some node is left open; a proven run leaves none
    assert r.status != Status.OPTIMAL and r.bound > r.objective and r.info["open_nodes"] >= 1
    proven = solve_bp(_top("p3.3.o"), time_limit=30)
    assert proven.status == Status.OPTIMAL and proven.info["open_nodes"] == 0


def _top(name):
    return load_instance(TOP_DIR / f"{name}.txt")


def _prize(inst, result):
    rep = verify(inst, result.plan)
    assert rep.valid
    return rep.prize


def _p12p_with_optimum():
    """p1.2.p and bp's optimal routes on it (node ids), for tests that feed bp a primal plan."""
    inst = _top("p1.2.p")
    ref = solve_bp(inst, time_limit=30)
    assert ref.status == Status.OPTIMAL
    return inst, [list(r) for r in ref.plan.routes]


def test_primal_plan_becomes_the_incumbent_when_the_root_needs_it():
    """``primal`` runs once, after the root and its first dive leave the proof open (p1.2.p);
    a verified plan it returns is taken as incumbent and its routes as columns; the run still
    proves the published optimum."""
    inst, optimum = _p12p_with_optimum()
    calls = []

    def primal(seconds):
        calls.append(seconds)
        return optimum

    r = solve_bp(inst, time_limit=60, primal=primal)
    assert len(calls) == 1 and 0 < calls[0] <= 0.1 * 60 + 1e-9
    assert r.status == Status.OPTIMAL and _prize(inst, r) == pytest.approx(OPTIMAL["p1.2.p"])
    assert r.info["primal_prize"] == pytest.approx(OPTIMAL["p1.2.p"])
    assert r.info["primal_s"] is not None and r.info["primal_error"] is None


def test_primal_runs_again_after_the_root_when_the_proof_stays_open():
    """On an instance whose root bound stays above every plan (M = 12, K = 3, N = 3, seed 0,
    no cuts), the heuristic runs after the first dive and once more after the root's last
    dive, never more by default at 60 s, and primal_calls times in all when asked (0: never);
    the run still proves its plan optimal."""
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(12, 3, 3, 0))
    calls = []
    r = solve_bp(inst, time_limit=60, primal=lambda seconds: calls.append(seconds),
                 options=BPOptions(cut_rounds=0))
    rep = verify(inst, r.plan)
    assert r.status == Status.OPTIMAL and rep.valid
    assert math.floor(r.info["root_bound"] + 1e-6) > rep.prize  # the root left it open
    assert len(calls) == 2 == r.info["primal_calls"]
    assert all(0 < c <= 0.1 * 60 + 1e-9 for c in calls)
    calls.clear()
    r = solve_bp(inst, time_limit=60, primal=lambda seconds: calls.append(seconds),
                 options=BPOptions(cut_rounds=0, primal_calls=4))
    assert r.status == Status.OPTIMAL and verify(inst, r.plan).prize == rep.prize
    assert len(calls) == 4 == r.info["primal_calls"]  # the extra calls, one after the other
    calls.clear()
    r = solve_bp(inst, time_limit=60, primal=lambda seconds: calls.append(seconds),
                 options=BPOptions(cut_rounds=0, primal_calls=0))
    assert r.status == Status.OPTIMAL and verify(inst, r.plan).prize == rep.prize
    assert calls == [] and r.info["primal_calls"] == 0  # 0: the heuristic is never called


def test_later_primal_calls_stop_once_a_plan_proves_the_root():
    """The root calls the heuristic again only while its proof is open: on p1.2.p (root bound =
    optimum) with the dives off, a heuristic that finds nothing on its first call and the optimum
    on its second is not called a third time, whatever primal_calls allows."""
    inst, optimum = _p12p_with_optimum()
    calls = []

    def primal(seconds):
        calls.append(seconds)
        return optimum if len(calls) == 2 else None

    r = solve_bp(inst, time_limit=60, primal=primal, options=BPOptions(primal_calls=6, dive_share=0.0))
    assert r.status == Status.OPTIMAL and _prize(inst, r) == pytest.approx(OPTIMAL["p1.2.p"])
    assert len(calls) == 2 == r.info["primal_calls"]


def test_primal_is_not_run_when_the_root_proves():
    calls = []
    inst = _top("p1.2.a")
    r = solve_bp(inst, time_limit=30, primal=lambda s: calls.append(s))
    assert r.status == Status.OPTIMAL and _prize(inst, r) == pytest.approx(OPTIMAL["p1.2.a"])
    assert calls == [] and r.info["primal_s"] is None


@pytest.mark.parametrize("kind", ["raises", "over-budget", "empty"])
def test_a_bad_primal_costs_nothing_but_its_time(kind):
    """A failing heuristic, one returning a plan the verifier rejects, or none at all: the run
    goes on and proves the optimum; the rejected plan is never the incumbent."""
    inst = _top("p1.2.p")

    def primal(seconds):
        if kind == "raises":
            raise RuntimeError("boom")
        if kind == "over-budget":
            return [list(range(inst.n_nodes))]  # every node in one route: far over the budget
        return None

    r = solve_bp(inst, time_limit=60, primal=primal)
    assert r.status == Status.OPTIMAL and _prize(inst, r) == pytest.approx(OPTIMAL["p1.2.p"])
    assert r.info["primal_s"] is not None and r.info["primal_prize"] is None
    assert (r.info["primal_error"] == "RuntimeError: boom") == (kind == "raises")


def test_registered_bp_runs_pyvrp_as_its_primal():
    """The registered `bp` hands PyVRP to the search: on an instance the root leaves open its
    plan is verified and counted (p1.2.l)."""
    r = run_method("bp", _top("p1.2.l"), time_limit=60)
    assert r.report.valid and r.status == Status.OPTIMAL
    assert r.info["primal_prize"] is not None and r.info["primal_prize"] <= r.objective + 1e-9
    assert r.info["primal_error"] is None


@pytest.mark.parametrize("name", ["p1.2.l", "p2.2.k", "p3.2.f"])
def test_milp_column_filter_keeps_every_better_plan(name):
    """The reduced-cost filter of the MILP's columns (duals that certified the root bound)
    never removes a better plan: with the incumbent set below the best plan over the generated
    routes, the filtered MILP finds a plan of that same value, from fewer routes."""
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = _top(name)
    bp = BranchAndPrice(inst, time_limit=30)
    s, m = bp.search, bp.search.master
    bp.colgen.solve(NodeState(), np.inf)
    assert bp.elimination.cert is not None
    full = m.milp(20.0)
    best = sum(m.route_prize[m.routes.index(r)] for r in full)
    for below in (s.problem.step, 2 * s.problem.step, 4 * s.problem.step):
        s.incumbent, s.incumbent_value = [], best - below
        keep = bp.elimination.milp_columns()
        assert keep is not None and keep.sum() <= m.n_routes
        got = m.milp(20.0, keep)
        assert got is not None
        assert sum(m.route_prize[m.routes.index(r)] for r in got) == pytest.approx(best)
    s.incumbent_value = best  # nothing better among these routes: the filter may keep none,
    keep = bp.elimination.milp_columns()  # and whatever it keeps cannot beat the incumbent by a step
    sub = m.milp(20.0, keep) if keep.any() else []
    assert sum(m.route_prize[m.routes.index(r)] for r in sub or []) <= best + 1e-9


def test_strong_branching_proves_the_same_optimum():
    """Strong branching (children estimated on the current columns) changes which candidate is
    branched on, never the result: p3.3.o is proven at its published optimum either way, only
    the strong run pays for estimates, and the master's bounds are the node's again after them."""
    from sarcover.formulations.bp.branching import branch, branch_candidates
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = _top("p3.3.o")
    results = {st: solve_bp(inst, time_limit=30, options=BPOptions(strong=st)) for st in (1, 5)}
    for st, r in results.items():
        assert r.status == Status.OPTIMAL and _prize(inst, r) == pytest.approx(OPTIMAL["p3.3.o"])
        assert verify(inst, r.plan).valid
        assert (r.info["strong_lps"] > 0) == (st > 1)
    bp = BranchAndPrice(inst, time_limit=30)
    m = bp.search.master
    _, x, _, _ = bp.colgen.solve(NodeState(), np.inf)
    cands = branch_candidates(bp.search, NodeState(), x)
    assert len(cands) > 1
    before = m.col_ub.copy()
    lp = float(np.dot(m.route_prize, x[: m.n_routes]))
    pick = branch(bp.search, NodeState(), x, lp, bp.options.strong)
    assert pick in cands
    assert np.array_equal(m.col_ub, before)


def test_group_bounds_set_the_group_rows():
    """A node's bounds on a group's visits become the group row's bounds (the cover row's lower
    bound 1 stays the floor), bind in the LP, count in the Lagrangian bound, and go when the
    master is set to a node without them."""
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.master import Master

    m = Master(4, np.ones(4), [(0, 1, 2), (3,)], 4)  # group 0: points 1-3, group 1: point 4
    m.add_routes([(1,), (2,), (3,), (4,)])
    row = 1 + m.V  # group 0's row
    values = {}
    for hi in (np.inf, 2.0, 1.0):
        st = NodeState().child(group_bounds=[(0, -np.inf, hi)])
        m.apply(st)
        assert (m.cur_lo[row], m.cur_hi[row]) == (1.0, hi)
        value, x, xa, y = m.solve()
        assert xa.max() < 1e-9 and m.group_visits(x)[0] == pytest.approx(min(hi, 3.0))
        # nothing left to price: the certificate is the LP value
        assert m.lagrangian_bound(y, 0.0) == pytest.approx(value)
        values[hi] = value
    assert values == {np.inf: 4.0, 2.0: 3.0, 1.0: 2.0}
    m.apply(NodeState().child(group_bounds=[(0, 2.0, np.inf)]))
    assert (m.cur_lo[row], m.cur_hi[row]) == (2.0, np.inf)
    m.apply(NodeState())
    assert (m.cur_lo[row], m.cur_hi[row]) == (1.0, np.inf) and m.solve()[0] == pytest.approx(4.0)


def test_group_branching_proves_the_same_optimum():
    """Branching on a target's number of views changes the tree, never the result: on a SAR
    instance under a weak relaxation (ng sets of 2, no cuts, no route enumeration to close the
    root's gap), so that the tree is searched, bp proves the same optimum with and without it,
    and that optimum is the one the default run proves at its root. Only the run with it splits
    on groups."""
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(8, 4, 2, 2))
    ref = solve_bp(inst, time_limit=60)
    assert ref.status == Status.OPTIMAL
    weak = dict(strong=5, ng_size=2, ng_cap=2, cut_rounds=0, enum_share=0)
    for groups in (True, False):
        r = solve_bp(inst, time_limit=60, options=BPOptions(group_branching=groups, **weak))
        assert r.status == Status.OPTIMAL and verify(inst, r.plan).valid
        assert _prize(inst, r) == pytest.approx(_prize(inst, ref))
        assert r.info["nodes"] > 1 and (r.info["group_branches"] > 0) == groups


def test_milp_start_plan_is_a_floor():
    """The MILP takes a plan as its first solution: with only that plan's routes allowed it
    returns that plan, under any time limit it returns nothing worse, and a start that is not
    made of generated routes is ignored (p2.2.k)."""
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = _top("p2.2.k")
    bp = BranchAndPrice(inst, time_limit=30)
    bp.colgen.solve(NodeState(), np.inf)
    m = bp.search.master
    value = lambda routes: sum(m.route_prize[m.routes.index(r)] for r in routes)  # noqa: E731
    best = m.milp(20.0)
    start = sorted(best, key=len)[1:]  # a worse plan: the best without its shortest route
    assert value(start) < value(best)
    only = m.milp(5.0, np.zeros(m.n_routes, dtype=bool), start=start)
    assert sorted(only) == sorted(start)
    quick = m.milp(0.05, None, start=start)
    assert quick is not None and value(quick) >= value(start) - 1e-9
    unknown = [tuple(range(1, inst.n_nodes + 1))]  # not a generated route
    assert m.milp(5.0, np.zeros(m.n_routes, dtype=bool), start=unknown) in (None, [])


# -- limited-memory subset-row cuts ------------------------------------------------------------

def test_lm_coefficient_counts_pairs_and_forgets_outside_memory():
    """Pairs of visits to the triple; an unpaired visit is forgotten at a point outside the
    memory, so the coefficient never exceeds floor(visits / 2) (the full cut's)."""
    from sarcover.formulations.bp.master import _lm_coefficient

    S, full = (1, 2, 3), frozenset(range(10))
    assert _lm_coefficient((1, 5, 2), S, full) == 1
    assert _lm_coefficient((1, 5, 2), S, frozenset({1, 2, 3})) == 0  # 5 makes it forget 1
    assert _lm_coefficient((1, 5, 2), S, frozenset({1, 2, 3, 5})) == 1
    assert _lm_coefficient((1, 2, 3), S, frozenset(S)) == 1
    assert _lm_coefficient((4, 6), S, full) == 0
    assert _lm_coefficient((1, 2, 1, 2), S, full) == 2  # an ng-route's repeated visits count


def _random_cuts(rng, n, n_cuts):
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


def _cut_priced(seed: int, cut_seed: int):
    """A tiny pricing problem with six random subset-row cuts: (cost, ret, profit, budget,
    (cut members, cut memory, cut duals), value of a path with its cut duals paid, every
    elementary path as (value, path) by brute force)."""
    from sarcover.formulations.bp.master import _lm_coefficient

    cost, ret, profit, budget = _tiny_pricing(seed)
    cuts, mems, members, memory, sig = _random_cuts(np.random.default_rng(cut_seed), cost.shape[0], 6)

    def value(path):
        pen = sum(s * _lm_coefficient(path, S, M) for S, M, s in zip(cuts, mems, sig))
        return float(profit[list(path)].sum()) - pen

    paths = [(value(p), p) for _, p in _brute_paths(cost, profit, budget)]
    return cost, ret, profit, budget, (members, memory, sig), value, paths


@pytest.mark.parametrize("seed", range(8))
def test_exact_pricing_with_cuts_matches_enumeration(seed):
    """With subset-row cut duals, exact elementary labelling finds the best path's prize minus
    the duals of the cuts it pays (limited-memory coefficients, enumerated); every route it
    returns has the value it claims to beat; ng labelling stays an upper bound."""
    from sarcover.formulations.bp.labelling import price
    from sarcover.formulations.bp.ng_sets import full_ng, nearest_ng

    cost, ret, profit, budget, (members, memory, sig), value, paths = _cut_priced(seed, 100 + seed)
    n = cost.shape[0]
    best = max(v for v, _ in paths)
    gain = 0.2 * best
    kw = dict(max_labels=1_000_000, n_cols=50, min_gain=gain, cut_members=members,
              cut_memory=memory, cut_duals=sig)
    allowed = np.ones(n, dtype=bool)
    ex = price(cost, ret, profit, budget, full_ng(n), allowed, heuristic=False, **kw)
    assert ex.exact and ex.best == pytest.approx(max(best, gain))
    vals = {p: v for v, p in paths}
    assert ex.routes and vals[ex.routes[0]] == pytest.approx(best)
    assert all(vals[r] > gain - 1e-9 for r in ex.routes)
    ng = price(cost, ret, profit, budget, nearest_ng(cost, 2), allowed, heuristic=False, **kw)
    assert ng.exact and ng.best >= best - 1e-9
    # bidirectional search: its join pays the pairs it makes, so the same best value and routes
    # worth what they claim; its ng relaxation stays an upper bound
    bi = price(cost, ret, profit, budget, full_ng(n), allowed, heuristic=False, bidirectional=True, **kw)
    assert bi.exact and bi.best == pytest.approx(ex.best)
    assert bi.routes and vals[bi.routes[0]] == pytest.approx(best)
    assert all(vals[r] > gain - 1e-9 for r in bi.routes)
    bng = price(cost, ret, profit, budget, nearest_ng(cost, 2), allowed, heuristic=False,
                bidirectional=True, **kw)
    assert bng.exact and bng.best >= best - 1e-9


@pytest.mark.parametrize("seed", range(3))
def test_dominance_layout_changes_speed_not_labels(seed):
    """The labelling keeps each point's labels in energy sub-buckets sorted by prize and scans
    only where a dominator or a dominated label can be. On a paper-size graph (M = 20, K = 3)
    with random duals, ng sets and subset-row cuts, one plain bucket per point (nsub = 1) and
    the sub-buckets (default, and an odd count) create exactly the same labels: the same count,
    best value and routes, one-way and bidirectional, exact and heuristic; the most sub-buckets a
    label count may choose too."""
    from sarcover.formulations.bp.graph import cheapest_return
    from sarcover.formulations.bp.labelling import price, sub_buckets
    from sarcover.formulations.bp.ng_sets import nearest_ng
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(20, 3, 5, seed))
    cost = inst.cost_matrix()
    n = cost.shape[0]
    rng = np.random.default_rng(seed)
    profit = np.zeros(n)
    profit[1:-1] = rng.uniform(-0.2, 0.6, n - 2)
    _, _, members, memory, sig = _random_cuts(rng, n, 12)
    ret = cheapest_return(cost)
    allowed = np.ones(n, dtype=bool)
    assert sub_buckets(n) > 1
    for heuristic, bidirectional in ((False, False), (False, True), (True, False)):
        runs = [price(cost, ret, profit, inst.budget, nearest_ng(cost, 8), allowed,
                      heuristic=heuristic, bidirectional=bidirectional, max_labels=2_000_000,
                      n_cols=60, min_gain=1.0, cut_members=members, cut_memory=memory,
                      cut_duals=sig, keep=0.0 if heuristic else 0.5, nsub=nsub)
                for nsub in (1, None, 7, 256)]
        assert runs[0].n_labels > 1000
        assert runs[0].exact == (not heuristic)
        for r in runs[1:]:
            assert r.n_labels == runs[0].n_labels
            assert r.best == runs[0].best
            assert r.routes == runs[0].routes and r.ng_routes == runs[0].ng_routes


def test_sub_buckets_follow_the_expected_labels_per_point():
    """Without a label count the layout has NSUB sub-buckets per point; with one, about
    1.5·sqrt(labels per point) as a power of two within NSUB_RANGE, growing with the count, and
    never more than SUB_CELLS in all."""
    from sarcover.formulations.bp.labelling import (
        NSUB,
        NSUB_RANGE,
        SUB_CELLS,
        sub_buckets,
    )

    assert sub_buckets(62) == NSUB and sub_buckets(62, 0) == NSUB
    counts = [sub_buckets(62, labels) for labels in (100, 20_000, 100_000, 300_000, 10**8)]
    assert counts == sorted(counts)
    assert counts[0] == NSUB_RANGE[0] and counts[-1] == NSUB_RANGE[1]
    assert sub_buckets(62, 100_000) == 64 and sub_buckets(62, 300_000) == 128
    assert sub_buckets(102, 10**8) * 102 <= SUB_CELLS
    assert sub_buckets(5000, 10**8) == SUB_CELLS // 5000


def test_exact_pricing_is_laid_out_for_the_previous_exact_calls_labels(monkeypatch):
    """The search's exact calls pass the dominance layout sized by the previous exact call's
    label count (the first call, and every heuristic one, the default)."""
    import sarcover.formulations.bp.pricer as pricer_mod
    from sarcover.formulations.bp.labelling import sub_buckets
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top
    from sarcover.formulations.result import Termination

    seen = []
    real = pricer_mod.price

    def spy(*args, **kw):
        res = real(*args, **kw)
        seen.append((kw["heuristic"], kw["nsub"], res.n_labels, args[0].shape[0]))
        return res

    monkeypatch.setattr(pricer_mod, "price", spy)
    res = solve_bp(to_top(generate(8, 3, 2, 3)), time_limit=20)
    assert res.termination == Termination.OPTIMAL
    exact = [(nsub, labels, n) for heuristic, nsub, labels, n in seen if not heuristic]
    assert len(exact) >= 2
    assert all(nsub is None for heuristic, nsub, _, _ in seen if heuristic)
    assert exact[0][0] == sub_buckets(exact[0][2])
    for (_, before, _), (nsub, _, n) in zip(exact, exact[1:]):
        assert nsub == sub_buckets(n, before)


def test_master_cut_rows_hold_lm_coefficients():
    """Cut rows get the limited-memory coefficient of routes generated before and after the
    cut; separation finds a violated triple in a fractional LP and its memory keeps it violated."""
    from sarcover.formulations.bp.master import Master, _lm_coefficient

    m = Master(6, np.ones(6), [], 3)
    m.add_routes([(1, 2), (2, 3), (1, 3)])  # each x = 1/2 violates the cut on {1, 2, 3}: 3/2 > 1
    x = np.full(3, 0.5)
    cuts = m.separate_cuts(x, 4)
    assert [S for S, _ in cuts] == [(1, 2, 3)]
    assert m.add_cuts(cuts) == 1 and m.cuts == [(1, 2, 3)]
    m.add_routes([(1, 4, 2), (4, 5)])
    lp = m.h.getLp()
    a = lp.a_matrix_
    row = m.base_rows
    got = {}
    for j in range(m.n_routes):
        col = m.n_art + j
        lo, hi = a.start_[col], a.start_[col + 1]
        coef = dict(zip(a.index_[lo:hi], a.value_[lo:hi]))
        got[m.routes[j]] = coef.get(row, 0.0)
        assert got[m.routes[j]] == _lm_coefficient(m.routes[j], (1, 2, 3), m.memories[0])
    assert got[(1, 2)] == 1 and got[(4, 5)] == 0
    value, xs, xa, y = m.solve()
    assert sum(got[r] * xs[j] for j, r in enumerate(m.routes)) <= 1.0 + 1e-9  # the cut holds
    # memory {1, 2, 3}: (1, 4, 2) forgets 1 at 4 and pays nothing, so the LP uses it at 1/2
    assert got[(1, 4, 2)] == 0 and value == pytest.approx(4.5)
    assert m.cut_duals(y).shape == (1,)


def test_purged_cuts_leave_the_lp_and_free_their_bits():
    """Purging drops exactly the cuts of zero dual: same LP value, the rows and bitsets of the
    kept cuts renumbered, and routes and cuts added afterwards get the right coefficients."""
    from sarcover.formulations.bp.master import Master, _lm_coefficient

    m = Master(6, np.ones(6), [], 6)
    m.add_routes([(1, 2), (2, 3), (1, 3), (4,), (5,), (6,)])
    idle = ((4, 5, 6), frozenset({4, 5, 6}))  # no route visits two of them: zero dual
    assert m.add_cuts([idle, ((1, 2, 3), frozenset({1, 2, 3}))]) == 2
    value, _, _, y = m.solve()
    assert value == pytest.approx(5.0)  # one route of the triangle + the three singles
    assert m.cut_duals(y)[0] == 0 and m.cut_duals(y)[1] > 0
    assert m.purge_cuts(y) == 1
    assert m.cuts == [(1, 2, 3)] and m.n_rows == m.base_rows + 1
    assert m.h.getNumRow() == m.n_rows and len(m.row_lo) == len(m.row_hi) == m.n_rows
    assert [int(b) for b in m.cut_members[1:7]] == [1, 1, 1, 0, 0, 0]
    assert m.solve()[0] == pytest.approx(value)
    m.add_routes([(1, 2, 3)])  # pays 1 in the kept cut's row (now row base_rows)
    a = m.h.getLp().a_matrix_
    col = m.n_art + m.n_routes - 1
    coef = dict(zip(a.index_[a.start_[col] : a.start_[col + 1]], a.value_[a.start_[col] : a.start_[col + 1]]))
    assert coef.get(m.base_rows) == _lm_coefficient((1, 2, 3), (1, 2, 3), m.memories[0]) == 1
    assert m.solve()[0] == pytest.approx(6.0)
    assert m.add_cuts([idle]) == 1 and int(m.cut_members[4]) == 2  # the next free bit


def test_removed_cuts_leave_the_lp_whatever_their_dual():
    """remove_cuts drops the cuts asked for, even one the LP leans on: the LP gets weaker by
    exactly that row, and the kept cuts' rows and bits are renumbered."""
    from sarcover.formulations.bp.master import Master

    m = Master(6, np.ones(6), [], 6)
    m.add_routes([(1, 2), (2, 3), (1, 3), (4,), (5,), (6,)])
    idle = ((4, 5, 6), frozenset({4, 5, 6}))
    assert m.add_cuts([((1, 2, 3), frozenset({1, 2, 3})), idle]) == 2
    value, _, _, y = m.solve()
    assert value == pytest.approx(5.0) and m.cut_duals(y)[0] > 0
    assert m.remove_cuts([0]) == 1
    assert m.cuts == [(4, 5, 6)] and m.n_rows == m.base_rows + 1 == m.h.getNumRow()
    assert [int(b) for b in m.cut_members[1:7]] == [0, 0, 0, 1, 1, 1]
    assert m.solve()[0] == pytest.approx(6.0)  # the triangle at 1/2 each again
    assert m.remove_cuts([]) == 0 and m.cuts == [(4, 5, 6)]


def test_label_cap_under_cuts_withdraws_the_last_round_and_still_proves():
    """An exact pricing that hits its label cap certifies no bound. Under cuts, the root then
    withdraws the last round's cuts and tries no more rounds, instead of giving up the run (TOP
    set 5's p5.2.x stopped at 30 s of 600 that way). The cap is simulated on the first exact
    call after a cut round; p2.2.k's published optimum is still proven."""
    from sarcover.formulations.bp.labelling import PricingResult
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    bp = BranchAndPrice(inst, time_limit=60, options=BPOptions(cut_rounds=4, cut_gap=100.0, cut_share=1.0))
    exact, capped = bp.pricer.exact, []

    def capped_once_under_cuts(*args):
        res = exact(*args)
        if bp.search.master.cuts and not capped:
            capped.append(len(bp.search.master.cuts))
            return PricingResult(res.best, False, res.routes, [], res.n_labels, res.ng_routes)
        return res

    bp.pricer.exact = capped_once_under_cuts
    proven, bound = bp.run()
    stats = bp.search.stats
    assert capped and stats.label_caps == 1
    # the cap came right after the first round: all of its cuts were withdrawn, none are left
    assert stats.cuts_withdrawn == capped[0] > 0 and bp.search.master.cuts == []
    assert bp.cuts.rounds == bp.cuts.done  # no round after the withdrawal
    assert proven and bound == pytest.approx(OPTIMAL["p2.2.k"])


def test_label_cap_without_cuts_branches_instead_of_stopping():
    """With no cuts to withdraw, a node whose exact pricing hits the label cap is branched on
    its unconverged LP (its bound still holds) until the time is up: the run neither stops at
    the root nor claims more than it proved, and its plan is valid."""
    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    r = solve_bp(inst, time_limit=4, options=BPOptions(cut_rounds=0, exact_labels=1))
    assert r.info["label_caps"] > 1 and r.info["nodes"] > 1
    assert verify(inst, r.plan).valid and _prize(inst, r) <= OPTIMAL["p2.2.k"]
    assert r.bound >= OPTIMAL["p2.2.k"] - 1e-6
    if r.status == Status.OPTIMAL:
        assert _prize(inst, r) == pytest.approx(OPTIMAL["p2.2.k"])


def test_a_root_slow_to_settle_calls_the_heuristic_before_its_first_dive():
    """When the root's bound is not settled by primal_late_share of the limit (here 0: at once),
    the caller's heuristic runs before the first dive instead of waiting for it; by default
    (0.5) a root that settles early calls it only after its first dive. Both prove p2.2.k."""
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    for share, first_after_dive in [(0.0, False), (0.5, True)]:
        seen = []
        bp = BranchAndPrice(inst, time_limit=60, primal=lambda seconds: seen.append(bp.incumbents.dived),
                            options=BPOptions(primal_late_share=share, cut_rounds=0))
        proven, bound = bp.run()
        assert proven and bound == pytest.approx(OPTIMAL["p2.2.k"])
        assert seen[:1] == [first_after_dive] or (first_after_dive and not seen)


def test_purging_cuts_keeps_the_published_optimum():
    """Rounds of 48 cuts on p2.2.k pass the 64-cut limit, so idle cuts are purged between
    rounds; the published optimum is still proven."""
    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    r = solve_bp(inst, time_limit=60, options=BPOptions(cut_rounds=4, cuts_per_round=48, cut_gap=100.0,
                                                    cut_share=1.0))
    assert r.info["cuts_purged"] > 0
    assert r.status == Status.OPTIMAL and _prize(inst, r) == pytest.approx(OPTIMAL["p2.2.k"])
    assert r.bound == pytest.approx(OPTIMAL["p2.2.k"])


def test_cut_round_starts_only_if_it_would_end_within_the_share():
    """A round of cuts is started only if, taking ROUND_GROWTH times as long as the round before
    it, it would end within the cut share: with 30 s of the share left, a round after one of 1 s
    goes on (to the labelling arc bounds that come first), a round after one of 20 s does not."""
    from types import SimpleNamespace

    from sarcover.formulations.bp.cuts import ROUND_GROWTH, CutRounds

    class Reached(Exception):
        """The round went past the gate (to the arc elimination before its first cuts)."""

    search = SimpleNamespace(incumbent=object(), incumbent_value=10.0,
                             problem=SimpleNamespace(step=1.0, floor=math.floor),
                             master=SimpleNamespace(n_routes=0),
                             stats=SimpleNamespace(root_lp=None),
                             clock=SimpleNamespace(time_left=lambda: 100.0))
    elimination = SimpleNamespace(version=0, eliminate=lambda labels: (_ for _ in ()).throw(Reached()))
    state = SimpleNamespace(depth=0)

    def gate(last_round_s: float):
        now = time.perf_counter()
        cuts = CutRounds(search, elimination, rounds=6, per_round=16, gap=1.0, until=now + 30.0)
        cuts.started = now - last_round_s
        return cuts.add(state, None, None, 10.5)

    assert ROUND_GROWTH * 20.0 > 30.0 > ROUND_GROWTH * 1.0
    with pytest.raises(Reached):
        gate(1.0)
    assert gate(20.0) is False


@pytest.mark.parametrize("name", ["p1.3.n", "p3.2.k", "p2.2.k"])
def test_cuts_keep_the_published_optimum(name):
    """With subset-row cuts forced on (these files get 8 to 38 cuts at the root), bp still proves
    exactly the published optimum with a verified plan."""
    inst = load_instance(TOP_DIR / f"{name}.txt")
    r = solve_bp(inst, time_limit=60, options=BPOptions(cut_rounds=4, cut_gap=100.0, cut_share=1.0))
    assert r.info["cuts"] > 0
    assert r.status == Status.OPTIMAL
    assert sum(inst.prizes[v] for v in r.plan.visited) == pytest.approx(OPTIMAL[name])
    assert r.bound == pytest.approx(OPTIMAL[name])


@pytest.mark.parametrize("seed", range(4))
def test_cuts_match_brute_force(seed):
    """Tiny random instances with groups, cuts forced on: same optimum as enumeration."""
    inst = random_tiny(seed, groups=True)
    best = brute_force(inst)
    r = solve_bp(inst, time_limit=30, options=BPOptions(cut_rounds=4, cut_gap=100.0, cut_share=1.0))
    if best is None:
        assert r.status == Status.INFEASIBLE
    else:
        assert r.status == Status.OPTIMAL
        assert sum(inst.prizes[v] for v in r.plan.visited) == pytest.approx(best)


@pytest.mark.parametrize("offset", [0.0, -1.0])
@pytest.mark.parametrize("threshold", ["CUTS_FROM_S", "OPEN_CUTS_FROM_S", "MORE_PRIMAL_FROM_S", "ENUM_FROM_S",
                                       "ENUM_LABELS_FROM_S"])
def test_registered_bp_decides_cuts_on_the_users_limit(monkeypatch, offset, threshold):
    """The registered bp spends a moment on greedy before solve_bp; whether cuts are on, how
    open their gate is, how often the primal heuristic runs, whether route enumeration is on and
    how many labels its tries may make follow the user's time limit (at CUTS_FROM_S: on; at
    OPEN_CUTS_FROM_S: open; at MORE_PRIMAL_FROM_S: 4 calls; at ENUM_FROM_S: on; at
    ENUM_LABELS_FROM_S: the full cap), not the slightly smaller one left for solve_bp."""
    import sarcover.formulations.bp as bp_package
    import sarcover.formulations.bp.options as bp_options
    from sarcover.benchmarks.registry import METHODS
    from sarcover.formulations.bp.options import (
        CUTS_FROM_S,
        OPEN_CUTS_FROM_S,
        default_cut_gap,
        default_cut_rounds,
        default_enum_labels,
    )
    from sarcover.formulations.result import Result, Termination

    limit = getattr(bp_options, threshold) + offset
    seen = {}

    def fake_solve_bp(instance, **kw):
        seen.update(kw)
        return Result("bp", Termination.TIME_LIMIT, runtime_s=0.0, reason="stub")

    monkeypatch.setattr(bp_package, "solve_bp", fake_solve_bp)
    METHODS["bp"].run(random_tiny(0, groups=False), time_limit=limit)
    assert seen["time_limit"] < limit
    assert seen["options"].cut_rounds == default_cut_rounds(limit) == (6 if limit >= CUTS_FROM_S else 0)
    assert seen["options"].cut_gap == default_cut_gap(limit) == (1.0 if limit >= OPEN_CUTS_FROM_S else 0.5)
    assert seen["options"].primal_calls == (4 if limit >= MORE_PRIMAL_FROM_S else 2)
    assert seen["options"].enum_share == (0.6 if limit >= ENUM_FROM_S else 0.0)
    assert seen["options"].enum_labels == default_enum_labels(limit)


def test_enumeration_is_on_by_default_for_long_runs_only():
    """Route enumeration after the root: by default from ENUM_FROM_S seconds (and without a
    limit); an explicit enum_share wins either way. So does an explicit label cap."""
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = random_tiny(0, groups=False)
    assert BranchAndPrice(inst, time_limit=ENUM_FROM_S - 1).enumeration is None
    assert BranchAndPrice(inst, time_limit=ENUM_FROM_S).enumeration is not None
    assert BranchAndPrice(inst, time_limit=None).enumeration is not None
    assert BranchAndPrice(inst, time_limit=None, options=BPOptions(enum_share=0)).enumeration is None
    assert BranchAndPrice(inst, time_limit=10, options=BPOptions(enum_share=0.5)).enumeration is not None
    # a try's label cap: in proportion to the limit below ENUM_LABELS_FROM_S, an explicit one wins
    assert BranchAndPrice(inst, time_limit=ENUM_FROM_S).enumeration.max_labels == int(
        ENUM_LABELS * ENUM_FROM_S / ENUM_LABELS_FROM_S) < ENUM_LABELS
    assert BranchAndPrice(inst, time_limit=ENUM_LABELS_FROM_S).enumeration.max_labels == ENUM_LABELS
    assert BranchAndPrice(inst, time_limit=None).enumeration.max_labels == ENUM_LABELS
    assert BranchAndPrice(inst, time_limit=ENUM_FROM_S,
                          options=BPOptions(enum_labels=1000)).enumeration.max_labels == 1000


def test_cuts_are_on_by_default_for_long_runs_only():
    """Cuts slow pricing down; by default they are used from CUTS_FROM_S seconds (and without a
    limit) and can be forced either way."""
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = random_tiny(0, groups=False)
    assert BranchAndPrice(inst, time_limit=CUTS_FROM_S - 1).cuts.rounds == 0
    assert BranchAndPrice(inst, time_limit=CUTS_FROM_S).cuts.rounds > 0
    assert BranchAndPrice(inst, time_limit=None).cuts.rounds > 0
    assert BranchAndPrice(inst, time_limit=None, options=BPOptions(cut_rounds=0)).cuts.rounds == 0
    assert BranchAndPrice(inst, time_limit=10, options=BPOptions(cut_rounds=2)).cuts.rounds == 2


def test_cut_gate_opens_for_long_runs():
    """Below OPEN_CUTS_FROM_S a cut round needs the root LP within half a step of a useful drop;
    from it (and without a limit) the gate is open; an explicit cut_gap wins."""
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = random_tiny(0, groups=False)
    assert BranchAndPrice(inst, time_limit=OPEN_CUTS_FROM_S - 1).cuts.gap == 0.5
    assert BranchAndPrice(inst, time_limit=OPEN_CUTS_FROM_S).cuts.gap == 1.0
    assert BranchAndPrice(inst, time_limit=None).cuts.gap == 1.0
    assert BranchAndPrice(inst, time_limit=None, options=BPOptions(cut_gap=0.25)).cuts.gap == 0.25


@pytest.mark.parametrize("limit", [CUTS_FROM_S - 1, CUTS_FROM_S, OPEN_CUTS_FROM_S - 1,
                                   OPEN_CUTS_FROM_S, MORE_PRIMAL_FROM_S - 1, MORE_PRIMAL_FROM_S, None])
def test_options_for_time_limit(limit):
    """BPOptions.for_time_limit: the defaults, with the cut settings decided on the limit (cuts
    on from CUTS_FROM_S, their gate open from OPEN_CUTS_FROM_S), and so are the primal calls,
    route enumeration and its label cap; options that leave them None
    get the same from the solve's own limit; the options are frozen."""
    import dataclasses

    opts = BPOptions.for_time_limit(limit)
    on, open_gate = limit is None or limit >= CUTS_FROM_S, limit is None or limit >= OPEN_CUTS_FROM_S
    assert opts.cut_rounds == (6 if on else 0) and opts.cut_gap == (1.0 if open_gate else 0.5)
    assert opts.primal_calls == (4 if limit is None or limit >= MORE_PRIMAL_FROM_S else 2)
    assert opts.enum_share == (0.6 if limit is None or limit >= ENUM_FROM_S else 0.0)
    assert opts.enum_labels == (ENUM_LABELS if limit is None or limit >= ENUM_LABELS_FROM_S
                                else int(ENUM_LABELS * limit / ENUM_LABELS_FROM_S))
    assert dataclasses.replace(opts, cut_rounds=None, cut_gap=None, primal_calls=None,
                               enum_share=None, enum_labels=None) == BPOptions()
    assert BPOptions().with_limit_defaults(limit) == opts
    assert BPOptions(cut_rounds=2, strong=1).with_limit_defaults(limit).cut_rounds == 2
    with pytest.raises(dataclasses.FrozenInstanceError):
        opts.strong = 1


def test_solve_bp_options_override_a_default():
    """At 30 s cuts are off by default; options=BPOptions(...) turns them on for the same call
    (and the published optimum is proven either way)."""
    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    default = solve_bp(inst, time_limit=30)
    forced = solve_bp(inst, time_limit=30,
                      options=BPOptions(cut_rounds=4, cut_gap=100.0, cut_share=1.0))
    assert default.info["cuts"] == 0 and forced.info["cuts"] > 0
    # each run's info holds the settings it used, the limit's defaults filled in
    assert default.info["options"]["cut_rounds"] == 0 and forced.info["options"]["cut_rounds"] == 4
    assert forced.info["options"]["cut_share"] == 1.0 and "exact_keep" in default.info["options"]
    for r in (default, forced):
        assert r.status == Status.OPTIMAL and r.bound == pytest.approx(OPTIMAL["p2.2.k"])


def _arcs_of_plans_from(inst: TOPInstance, value: float) -> set:
    """Arcs (solver points: start 0, nodes 1..V, end V+1) of every plan worth at least ``value``."""
    v = inst.n_nodes
    arcs = set()
    for combo in itertools.combinations(_feasible_routes(inst), inst.n_vehicles):
        nodes = [i for r in combo for i in r]
        if len(nodes) != len(set(nodes)) or inst.prizes[nodes].sum() < value - 1e-9:
            continue
        for r in combo:
            full = (0, *(i + 1 for i in r), v + 1)
            arcs.update(zip(full, full[1:]))
    return arcs


@pytest.mark.parametrize("seed", range(6))
def test_arc_elimination_keeps_every_better_plan(seed):
    """With the incumbent one step below the optimum, reduced-cost arc elimination after the
    root LP (DP and labelling bounds) removes arcs, but none of any optimal plan (enumerated)."""
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = random_tiny(seed, groups=False)
    best = brute_force(inst)
    bp = BranchAndPrice(inst, time_limit=None, options=BPOptions(strong=1))
    s = bp.search
    bp.incumbents.dived = True  # no dive: it could find the optimum and move the floor above it
    s.incumbent, s.incumbent_value = [], best - s.problem.step
    bp.colgen.solve(NodeState(), math.inf)
    bp.elimination.eliminate(labels=True)
    gone = {(int(a), int(b)) for a, b in zip(*np.nonzero(s.master.eliminated))}
    assert gone and s.stats.elim_labels
    assert not gone & _arcs_of_plans_from(inst, best)


def test_labelling_arc_bounds_run_before_the_first_cut_round():
    """With cuts on, the root's labelling arc elimination runs before any cut is separated, so
    the cut rounds price on the smaller graph; the published optimum is still proven."""
    from sarcover.formulations.bp.tree import BranchAndPrice

    events = []
    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    bp = BranchAndPrice(inst, time_limit=60,
                        options=BPOptions(cut_rounds=4, cut_gap=100.0, cut_share=1.0))
    stats, eliminate, add_cuts = bp.search.stats, bp.elimination.eliminate, bp.cuts.add

    def recording_eliminate(labels=False):
        before = stats.arcs_eliminated
        eliminate(labels)
        if labels:
            events.append(("labels", stats.arcs_eliminated - before))

    def recording_add_cuts(state, x, y, lp_value):
        cuts = stats.cuts
        out = add_cuts(state, x, y, lp_value)
        if stats.cuts > cuts:
            events.append(("cuts", stats.cuts - cuts))
        return out

    bp.elimination.eliminate, bp.cuts.add = recording_eliminate, recording_add_cuts
    proven, bound = bp.run()
    kinds = [k for k, _ in events]
    assert "cuts" in kinds and "labels" in kinds
    assert kinds.index("labels") < kinds.index("cuts")
    assert proven and bound == pytest.approx(OPTIMAL["p2.2.k"])


def test_root_out_of_time_right_after_the_route_pool_joined():
    """The labelling's route pool adds columns to the master after the root LP was solved; when
    the time runs out right then (no re-solve, no dive), the root's LP solution must still match
    the master's columns. It used not to (a ValueError at M = 20, K = 6 in loaded runs); now the
    run stops with a valid bound."""
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    bp = BranchAndPrice(inst, time_limit=60, options=BPOptions(cut_rounds=0))
    s, eliminate, pool_added = bp.search, bp.elimination.eliminate, []

    def out_of_time(labels=False):
        before = s.master.n_routes
        eliminate(labels)
        if labels:
            pool_added.append(s.master.n_routes - before)
            s.clock.deadline = s.clock.hard_deadline = time.perf_counter() - 1.0

    bp.elimination.eliminate = out_of_time
    proven, bound = bp.run()
    assert pool_added[-1] > 0  # the pool did add columns after the root LP
    assert not proven and bound >= OPTIMAL["p2.2.k"] - 1e-6


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("with_ng", [False, True])
def test_enumeration_lists_every_route_above_the_threshold(seed, with_ng):
    """Route enumeration (cut duals paid, with and without the backward ng suffix table) lists
    one route per set of points for exactly the elementary routes whose best ordering's value
    beats the threshold (brute force)."""
    from sarcover.formulations.bp.enumeration_kernel import enumerate_routes
    from sarcover.formulations.bp.ng_sets import nearest_ng

    cost, _, profit, budget, (members, memory, sig), value, paths = _cut_priced(seed, 200 + seed)
    n = cost.shape[0]
    thr = 0.4 * max(v for v, _ in paths)
    want = {frozenset(p) for v, p in paths if v > thr + 1e-9}
    res = enumerate_routes(cost, profit, np.ones(n, dtype=bool), budget, thr,
                           ng=nearest_ng(cost, 3) if with_ng else None, cut_members=members,
                           cut_memory=memory, cut_duals=sig)
    got = [frozenset(r) for r in res.routes]
    assert len(got) == len(set(got))
    assert set(got) == want
    assert all(value(r) > thr for r in res.routes)


@pytest.mark.parametrize("seed", range(4))
def test_enumeration_counts_what_a_narrower_listing_would_give(seed):
    """With a margin, a listing counts the routes a listing at threshold + margin gives (exactly:
    the sets whose best ordering clears it) and about its labels; its growth is their ratio."""
    from sarcover.formulations.bp.enumeration_kernel import enumerate_routes
    from sarcover.formulations.bp.ng_sets import nearest_ng

    cost, _, profit, budget, (members, memory, sig), _, paths = _cut_priced(seed, 300 + seed)
    n = cost.shape[0]
    thr, margin = 0.3 * max(v for v, _ in paths), 0.2 * max(v for v, _ in paths)
    kw = dict(ng=nearest_ng(cost, 3), cut_members=members, cut_memory=memory, cut_duals=sig)
    wide = enumerate_routes(cost, profit, np.ones(n, dtype=bool), budget, thr, margin=margin, **kw)
    narrow = enumerate_routes(cost, profit, np.ones(n, dtype=bool), budget, thr + margin, **kw)
    assert 0 < narrow.inner_routes == len(narrow.routes) == wide.inner_routes < len(wide.routes)
    assert narrow.inner_labels == narrow.n_labels - 1  # every label but the start
    assert 0.5 * narrow.n_labels <= wide.inner_labels <= 2 * narrow.n_labels
    labels, routes = wide.growth()
    assert labels == pytest.approx(wide.n_labels / wide.inner_labels)
    assert routes == pytest.approx(len(wide.routes) / len(narrow.routes)) and routes > 1


def test_enumeration_keeps_the_published_optimum():
    """With enumeration on (any window), bp still proves the published TOP optima."""
    for name in ("p1.2.j", "p2.2.k", "p3.2.e", "p3.3.k"):
        inst = load_instance(TOP_DIR / f"{name}.txt")
        res = solve_bp(inst, time_limit=60, options=BPOptions(enum_share=0.5, enum_gap=1.0))
        assert res.status == Status.OPTIMAL
        assert verify(inst, res.plan).prize == pytest.approx(OPTIMAL[name])
