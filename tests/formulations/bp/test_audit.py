"""The audit of a proof by route enumeration: its closure check finds a route a listing dropped,
its packing search agrees with brute force, and bp reports it on a proof by a root listing."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from sarcover.formulations.bp import BPOptions, solve_bp
from sarcover.formulations.bp.audit import missing_neighbours, packing_reaches, reduced_prize
from sarcover.formulations.io import load_instance
from sarcover.formulations.result import Status

from bp_cases import TOP_DIR, cut_priced


def _listing(seed: int, share: float = 0.4):
    from sarcover.formulations.bp.enumeration_kernel import enumerate_routes

    cost, _, profit, budget, (members, memory, sig), value, paths = cut_priced(seed, 200 + seed)
    thr = share * max(v for v, _ in paths)
    res = enumerate_routes(cost, profit, np.ones(cost.shape[0], dtype=bool), budget, thr,
                           cut_members=members, cut_memory=memory, cut_duals=sig)
    return cost, profit, budget, (members, memory, sig), value, thr, res


@pytest.mark.parametrize("seed", range(4))
def test_reduced_prize_pays_the_cuts_as_the_brute_force_does(seed):
    cost, profit, budget, (members, memory, sig), value, thr, res = _listing(seed)
    duals = np.zeros(64)
    duals[: len(sig)] = sig
    for r in res.routes:
        route = np.asarray(r, dtype=np.int64)
        assert reduced_prize(route, route.size, profit, members, memory, duals) == pytest.approx(value(r))


@pytest.mark.parametrize("seed", [0, 2, 3, 4, 5])
def test_closure_passes_a_complete_listing_and_finds_a_dropped_route(seed):
    """Nothing is missing next to a complete listing; drop a listed route that borders another
    (one point more or less) and the check counts it missing."""
    cost, profit, budget, cuts, value, thr, res = _listing(seed, 0.2)
    paths = res.paths
    missing, tested = missing_neighbours(paths, cost, budget, profit, thr, cuts)
    assert missing == 0 and tested > 0
    sets = [frozenset(r) for r in res.routes]
    bordered = next(i for i, s in enumerate(sets) if any(len(s ^ t) == 1 for t in sets))
    dropped = np.delete(paths, bordered, axis=0)
    assert missing_neighbours(dropped, cost, budget, profit, thr, cuts)[0] >= 1


@pytest.mark.parametrize("seed", range(6))
def test_packing_search_agrees_with_brute_force(seed):
    """At most N pairwise disjoint routes worth ``need`` whose reduced prizes reach ``floor``:
    found exactly when brute force over every such set finds one (and a found one is one)."""
    rng = np.random.default_rng(seed)
    n_routes, n_points, vehicles = 14, 12, 3
    sets = [frozenset(rng.choice(np.arange(1, n_points), size=rng.integers(1, 4), replace=False).tolist())
            for _ in range(n_routes)]
    width = max(max(s) for s in sets) + 1
    paths = np.full((n_routes, 4), -1, dtype=np.int64)
    for i, s in enumerate(sets):
        paths[i, : len(s)] = sorted(s)
    value = rng.integers(1, 10, n_routes).astype(float)
    reduced = rng.normal(1.0, 2.0, n_routes)
    assert width <= n_points
    for need, floor in [(8, 1.0), (14, 2.0), (20, 0.0), (25, 3.0), (12, -2.0)]:
        brute = any(
            sum(value[list(c)]) >= need and sum(reduced[list(c)]) >= floor
            and all(not (sets[a] & sets[b]) for a, b in itertools.combinations(c, 2))
            for k in range(1, vehicles + 1) for c in itertools.combinations(range(n_routes), k))
        found, finished = packing_reaches(paths, value, reduced, vehicles, need, floor)
        assert finished and (found is not None) == brute
        if found:
            assert len(found) <= vehicles and sum(value[found]) >= need and sum(reduced[found]) >= floor - 1e-5
            assert all(not (sets[a] & sets[b]) for a, b in itertools.combinations(found, 2))


def test_bp_reports_the_audit_of_a_proof_by_a_root_listing():
    """p2.2.k is proven by one complete root listing: the audit runs and passes; off by default."""
    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    res = solve_bp(inst, time_limit=60, options=BPOptions(enum_share=0.5, enum_gap=1.0, audit_listings=True))
    assert res.status == Status.OPTIMAL and res.info["enum_status"] == "infeasible"
    audit = res.info["audit"]
    assert audit["audit_passed"] and audit["audit_missing"] == 0 and audit["audit_packing"] is None
    assert audit["audit_finished"]
    plain = solve_bp(inst, time_limit=60, options=BPOptions(enum_share=0.5, enum_gap=1.0))
    assert plain.info["audit"] is None


def test_the_audit_flags_a_listing_that_dropped_routes(monkeypatch):
    """A listing that loses its routes that border others (as a wrong bound would) still lets
    bp claim its proof here, but the audit counts them missing and does not pass."""
    from sarcover.formulations.bp import enumeration

    real = enumeration.enumerate_routes

    def lossy(*args, **kwargs):
        res = real(*args, **kwargs)
        if res.paths is None or len(res.paths) < 2:
            return res
        sets = [frozenset(r) for r in res.routes]
        keep = [i for i, s in enumerate(sets) if not any(len(s ^ t) == 1 and len(t) < len(s) for t in sets)]
        return res._replace(paths=res.paths[keep], values=res.values[keep])

    monkeypatch.setattr(enumeration, "enumerate_routes", lossy)
    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    res = solve_bp(inst, time_limit=60, options=BPOptions(enum_share=0.5, enum_gap=1.0, audit_listings=True))
    audit = res.info["audit"]
    assert audit is not None and audit["audit_missing"] >= 1 and not audit["audit_passed"]


def test_a_packing_search_stopped_by_its_time_says_so():
    """Many small disjoint routes and a floor no set reaches: stopped at once, the search is
    unfinished and claims no packing; given the time, it finishes and finds none."""
    n_routes = 400
    paths = np.arange(1, n_routes + 1, dtype=np.int64).reshape(-1, 1)
    value, reduced = np.ones(n_routes), np.ones(n_routes)
    assert packing_reaches(paths, value, reduced, 4, need=10.0, floor=0.0, max_seconds=0.0) == (None, False)
    assert packing_reaches(paths, value, reduced, 4, need=10.0, floor=0.0, max_seconds=600.0) == (None, True)
