"""The `milp` exact method: hand-checkable instances, brute force, the TOP benchmark, time limits."""

from __future__ import annotations

import csv
import itertools
import math

import highspy
import numpy as np
import pytest

from sarcover.benchmarks.registry import run_method
from sarcover.formulations.bp.highs import quiet_highs
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.io import read_top
from sarcover.formulations.milp import build_milp, solve_milp
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Status
from sarcover.formulations.preprocess import floor_to_lattice, incompatible_cliques, prize_lattice, prune_arcs
from sarcover.formulations.verify import route_energy

from conftest import TOP_DIR

PUBLISHED = {r["instance"]: float(r["value"]) for r in csv.DictReader(open(TOP_DIR / "optimal.csv"))}


def top(coords, prizes, budget, n=1, start=(0.0, 0.0), end=None, **kw) -> TOPInstance:
    return TOPInstance(coords=np.array(coords, float), prizes=np.array(prizes, float), start=np.array(start),
                       end=np.array(start if end is None else end), budget=budget, n_vehicles=n, **kw)


def solve(inst, time_limit=30.0):
    result = run_method("milp", inst, time_limit=time_limit)
    assert result.status != Status.ERROR, result.reason
    return result, result.report


def brute_force(inst: TOPInstance) -> float | None:
    """Best verified prize over all assignments of nodes to vehicles and orders (tiny instances only)."""
    v, n = inst.n_nodes, inst.n_vehicles
    best_cost: dict[frozenset, float] = {}  # cheapest route through exactly this node set
    for k in range(1, v + 1):
        for subset in itertools.combinations(range(v), k):
            best_cost[frozenset(subset)] = min(route_energy(inst, p) for p in itertools.permutations(subset))
    limit = inst.budget * (1 + 1e-9) + 1e-12
    best = None
    for labels in itertools.product(range(n + 1), repeat=v):  # 0 = unvisited
        routes = [frozenset(i for i in range(v) if labels[i] == r) for r in range(1, n + 1)]
        if any(r and best_cost[r] > limit for r in routes):
            continue
        visited = {i for i in range(v) if labels[i]}
        if any(not visited.intersection(g) for g in inst.groups):
            continue
        prize = float(sum(inst.prizes[i] for i in visited))
        best = prize if best is None else max(best, prize)
    return best


def test_three_nodes_on_a_line():
    """Nodes at x = 1, 2, 3 from a depot at 0 with budget 4: only x=1 and x=2 fit, prize 2."""
    result, report = solve(top([[1, 0], [2, 0], [3, 0]], [1, 1, 5], 4.0))
    assert result.status == Status.OPTIMAL and result.objective == 2 and result.bound == 2
    assert sorted(result.plan.visited) == [0, 1]


def test_exact_budget_route_is_found():
    """A route whose length equals the budget exactly (the collinear x=3 round trip) is kept."""
    result, _ = solve(top([[1, 0], [2, 0], [3, 0]], [1, 1, 5], 6.0))
    assert result.status == Status.OPTIMAL and result.objective == 7


def test_start_differs_from_end():
    """Start (0,0), end (4,0): the detour node (2,3) of prize 10 beats the three line nodes."""
    coords = [[1, 0], [2, 0], [3, 0], [2, 3]]
    result, _ = solve(top(coords, [1, 1, 1, 10], 7.3, end=(4.0, 0.0)))
    assert result.status == Status.OPTIMAL and result.objective == 10
    result2, _ = solve(top(coords, [1, 1, 1, 10], 7.3, n=2, end=(4.0, 0.0)))
    assert result2.status == Status.OPTIMAL and result2.objective == 13


def test_group_forces_a_lower_prize_node():
    """Only one of two nodes fits; a group on the prize-1 node makes it the answer instead of prize 5."""
    coords, prizes = [[1, 0], [-1, 0]], [1, 5]
    free, _ = solve(top(coords, prizes, 2.0))
    forced, _ = solve(top(coords, prizes, 2.0, groups=((0,),)))
    assert free.objective == 5 and forced.status == Status.OPTIMAL and forced.objective == 1


def test_infeasible_groups_are_proven():
    """Two groups, each reachable alone, but one vehicle cannot serve both: INFEASIBLE with a reason."""
    result, _ = solve(top([[1, 0], [-1, 0]], [1, 5], 2.0, groups=((0,), (1,))))
    assert result.status == Status.INFEASIBLE and result.plan is None and "HiGHS proved" in result.reason


def test_image_cost_counts_per_node():
    """e_image = 1 per visited node: budget 4 covers x=1 (cost 2+1) but not x=1 and x=2 (4+2)."""
    result, _ = solve(top([[1, 0], [2, 0]], [1, 1], 4.0, e_image=1.0))
    assert result.status == Status.OPTIMAL and result.objective == 1


def test_coincident_points_subtour_is_cut():
    """Three coincident zero-cost nodes could form a subtour off the route; the answer must stay 3."""
    coords = [[1, 0], [1, 0], [1, 0], [-1, 0]]
    result, _ = solve(top(coords, [1, 1, 1, 1], 2.0))
    assert result.status == Status.OPTIMAL and result.objective == 3


@pytest.mark.parametrize("seed", range(12))
def test_matches_brute_force(seed):
    """Random tiny instances (start != end, groups, image cost, 1-2 vehicles) agree with enumeration."""
    rng = np.random.default_rng(seed)
    v = int(rng.integers(3, 6))
    coords = rng.uniform(0, 10, size=(v, 2))
    start, end = rng.uniform(0, 10, 2), rng.uniform(0, 10, 2) if seed % 2 else None
    groups = ((int(rng.integers(v)), int(rng.integers(v))),) if seed % 3 == 0 else ()
    inst = top(coords, rng.integers(1, 10, v), float(rng.uniform(12, 30)), n=1 + seed % 2,
               start=start, end=end, e_image=float(seed % 4 == 0), groups=groups)
    expected = brute_force(inst)
    result, _ = solve(inst)
    if expected is None:
        assert result.status == Status.INFEASIBLE
    else:
        assert result.status == Status.OPTIMAL and result.objective == pytest.approx(expected, abs=1e-9)


def test_pruning_keeps_only_usable_arcs():
    """An arc is kept iff c_0i + c_ij + c_j,end <= budget; the start→end arc is never an arc."""
    inst = read_top(TOP_DIR / "p1.2.g.txt")
    g = prune_arcs(inst)
    assert 0 < len(g.arcs) < g.n_arcs_full and (g.start, g.end) not in g.arcs
    for i, j in g.arcs:
        assert g.from_start[i] + g.cost[i, j] + g.to_end[j] <= g.budget + 1e-6


def test_incompatible_cliques_are_pairwise_incompatible():
    """Every clique has more nodes than vehicles and no two of its nodes fit on one route."""
    inst = read_top(TOP_DIR / "p3.4.r.txt")
    g = prune_arcs(inst)
    cliques = incompatible_cliques(g, inst.n_vehicles)
    assert cliques
    for clique in cliques:
        assert len(clique) > inst.n_vehicles
        for i, j in itertools.combinations(clique, 2):
            both = min(g.from_start[i] + g.cost[i, j] + g.to_end[j], g.from_start[j] + g.cost[j, i] + g.to_end[i])
            assert both > inst.budget


def test_lattice_rounding_is_safe():
    """Bounds round down to the prize lattice but never below a value within solver noise of a step."""
    assert prize_lattice(np.array([10.0, 15.0, 0.0])) == 5.0 and prize_lattice(np.array([0.5, 1.0])) is None
    assert floor_to_lattice(104.9, 5.0) == 100.0 and floor_to_lattice(99.99999, 5.0) == 100.0


def test_build_milp_has_documented_components():
    """The model is built without solving and exposes named, documented components."""
    m = build_milp(read_top(TOP_DIR / "p2.2.a.txt"))
    for name in ("x", "y", "z", "leave", "enter", "fleet", "cover", "flow", "budget_ub", "budget_lb",
                 "two_cycle_i", "clique", "path", "cuts"):
        assert m.component(name) is not None and m.component(name).doc
    assert all(v.value is None for v in m.x.values())


FAST = ["p1.2.e", "p1.2.f", "p1.3.g", "p1.4.i", "p1.4.j", "p2.2.f", "p2.2.j", "p2.3.k", "p2.4.k", "p3.2.b"]


@pytest.mark.parametrize("name", FAST)
def test_top_fast_subset_equals_published(name):
    """Quick TOP benchmark instances are proven optimal at exactly the published optimum."""
    result, _ = solve(read_top(TOP_DIR / f"{name}.txt"), time_limit=60.0)
    assert result.status == Status.OPTIMAL
    assert result.objective == PUBLISHED[name] and result.bound == PUBLISHED[name]


def test_time_limit_returns_valid_bound():
    """A 1 s limit on a harder instance stops with TIME_LIMIT and a bound no lower than the optimum."""
    name = "p3.2.j"  # bound still 550 against the optimum 510 after 60 s here
    result, _ = solve(read_top(TOP_DIR / f"{name}.txt"), time_limit=1.0)
    assert result.status == Status.TIME_LIMIT
    assert result.bound is not None and result.bound >= PUBLISHED[name]
    assert result.objective is None or result.objective <= PUBLISHED[name]


def test_warm_start_plan_is_kept_when_nothing_better_is_found():
    """A valid warm start survives as the incumbent even if HiGHS has no time to improve on it."""
    inst = top([[1, 0], [2, 0], [3, 0]], [1, 1, 5], 4.0)
    result = solve_milp(inst, time_limit=30.0, warm_start=Plan.of([[0]]))
    assert result.status == Status.OPTIMAL and sorted(result.plan.visited) == [0, 1]
    assert result.info["warm_start"] is True


def test_registered_method_starts_from_greedy():
    """The registered `milp` hands greedy's plan to HiGHS and still proves the optimum."""
    result, _ = solve(top([[1, 0], [2, 0], [3, 0]], [1, 1, 5], 4.0))
    assert result.info["warm_start"] is True and result.info["warm_start_prize"] is not None
    assert result.status == Status.OPTIMAL and result.objective == 2


def is_mip(h: highspy.Highs) -> bool:
    """Whether HiGHS's copy of the model has an integer column (a MILP solve, not an LP round)."""
    return any(t != highspy.HighsVarType.kContinuous for t in h.getLp().integrality_)


def test_highs_limits_count_the_models_translation(monkeypatch):
    """Pyomo translates the model for HiGHS when a solve starts (seconds at a few hundred
    points): it is translated once, before the time left is taken, so that every HiGHS solve
    (the root's LP rounds and the MILP, warm started) is limited to end by the run's deadline.
    An LP solve's limit counts on HiGHS's run clock, which goes on over the solves of one model
    (:func:`test_highs_stops_an_lp_on_its_run_clock_and_a_mip_on_its_own`): every LP round is
    given the time left, not the time left less what the rounds before it took."""
    import time

    from pyomo.contrib.solver.solvers.highs import Highs

    loads, solves = [], []
    set_instance, run = Highs.set_instance, Highs._solve

    def counted(self, model):
        loads.append(model)
        return set_instance(self, model)

    def timed(self):
        h = self._solver_model
        solves.append((time.perf_counter(), self._active_config.time_limit, h.getRunTime(), is_mip(h)))
        return run(self)

    monkeypatch.setattr(Highs, "set_instance", counted)
    monkeypatch.setattr(Highs, "_solve", timed)
    inst = read_top(TOP_DIR / "p3.2.j.txt")
    limit = 3.0
    t0 = time.perf_counter()
    result = solve_milp(inst, time_limit=limit, warm_start=Plan.of([]))
    assert result.status in (Status.TIME_LIMIT, Status.OPTIMAL) and result.info["warm_start"] is True
    lps = [s for s in solves if not s[3]]
    assert len(loads) == 1 and len(lps) >= 2 and len(solves) > len(lps)  # LP rounds, then the MILP
    assert lps[-1][2] > 0.01  # the rounds before the last took HiGHS time
    for start, tl, clock, mip in solves:
        end = start + (tl if mip else tl - clock)  # when HiGHS stops the solve
        # the solve's own check for changes since (milliseconds here) is all that may come after
        assert end <= t0 + limit + 0.05
        if not mip:  # and the time taken before the solve began is all that comes before
            assert end >= t0 + limit - 0.05


@pytest.mark.parametrize("limit, mip", [(3.6, None), (5.0, "off"), (9.0, "choose")])
def test_a_short_milp_runs_without_presolve(monkeypatch, limit, mip):
    """HiGHS's MIP presolve does not check the clock everywhere (seconds past a short limit at
    120 points, docs/scale.md), and HiGHS sets a MIP up before its first check. So after an LP
    round of 3 s (made slow here), a MILP given less than that runs without presolve, one
    given less than a second is not started, and one given more runs with it."""
    import time

    from pyomo.contrib.solver.solvers.highs import Highs

    run, mips = Highs._solve, []

    def slow_first_lp(self):
        if is_mip(self._solver_model):
            mips.append(dict(self._active_config.solver_options.items()).get("presolve"))
        elif not hasattr(self, "slowed"):
            self.slowed = True
            time.sleep(3.0)  # the MILP's window at 5 s, [1, 3) s left, holds a slow machine
        return run(self)

    monkeypatch.setattr(Highs, "_solve", slow_first_lp)
    result = solve_milp(read_top(TOP_DIR / "p3.2.j.txt"), time_limit=limit, warm_start=Plan.of([]))
    assert result.status in (Status.TIME_LIMIT, Status.OPTIMAL)
    assert result.info["lp_bounds"]  # the LP rounds ran
    assert mips == ([] if mip is None else [mip] * len(mips)) and (mip is None or mips)
    assert result.info.get("presolve_off", False) == (mip == "off")


def test_highs_stops_an_lp_on_its_run_clock_and_a_mip_on_its_own():
    """What :func:`solve_milp`'s limits rely on: HiGHS stops an LP solve once its run clock (the
    time of every solve of this Highs object) passes the limit, and a MIP solve once its own
    time does. If an upgrade of HiGHS changes this, milp's LP limits must change with it."""
    rng = np.random.default_rng(0)
    n, m = 2000, 1000
    h = quiet_highs()
    h.addVars(n, np.zeros(n), np.ones(n))
    h.changeColsCost(n, np.arange(n, dtype=np.int32), -rng.random(n))
    for _ in range(m):
        idx = np.sort(rng.choice(n, 30, replace=False)).astype(np.int32)
        h.addRow(-highspy.kHighsInf, 3.0, len(idx), idx, rng.random(30) + 0.5)
    h.run()
    assert h.getModelStatus() == highspy.HighsModelStatus.kOptimal
    clock = h.getRunTime()
    assert clock > 0.02

    h.changeColCost(0, -2.0)  # an LP a few pivots away, given less time than the clock shows
    h.setOptionValue("time_limit", clock / 2)
    h.run()
    assert h.getModelStatus() == highspy.HighsModelStatus.kTimeLimit
    h.setOptionValue("time_limit", h.getRunTime() + 30.0)  # the clock plus the time it may take
    h.run()
    assert h.getModelStatus() == highspy.HighsModelStatus.kOptimal

    h.clearModel()  # a tiny MIP, given less time than the clock shows: it is solved
    h.addVars(2, np.zeros(2), np.ones(2))
    h.changeColsCost(2, np.arange(2, dtype=np.int32), np.array([-1.0, -1.0]))
    h.changeColsIntegrality(2, np.arange(2, dtype=np.int32), np.array([highspy.HighsVarType.kInteger] * 2))
    h.addRow(-highspy.kHighsInf, 1.5, 2, np.arange(2, dtype=np.int32), np.ones(2))
    assert h.getRunTime() >= clock
    h.setOptionValue("time_limit", clock / 2)
    h.run()
    assert h.getModelStatus() == highspy.HighsModelStatus.kOptimal
    assert h.getInfo().objective_function_value == pytest.approx(-1.0)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(n for n in PUBLISHED if n.split(".")[0] in ("p1", "p2", "p3")))
def test_top_sets_1_to_3(name):
    """Every TOP instance of sets 1-3 in 60 s: optimal equals published, bound >= published >= objective."""
    result, _ = solve(read_top(TOP_DIR / f"{name}.txt"), time_limit=60.0)
    pub = PUBLISHED[name]
    if result.status == Status.OPTIMAL:
        assert result.objective == pub
    assert result.bound is None or result.bound >= pub
    assert result.objective is None or result.objective <= pub
    assert not math.isnan(pub)
