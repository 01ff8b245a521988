"""The root's policy: when the caller's heuristic runs, cut withdrawal, the labelling arc bounds' place."""

from __future__ import annotations

import math
import time

import pytest

from sarcover.formulations.bp import BPOptions, solve_bp
from sarcover.formulations.io import load_instance
from sarcover.formulations.result import Status
from sarcover.formulations.verify import verify

from bp_cases import OPTIMAL, TOP_DIR, p12p_with_optimum, plan_prize, top_instance


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


def test_primal_plan_becomes_the_incumbent_when_the_root_needs_it():
    """``primal`` runs once, after the root and its first dive leave the proof open (p1.2.p);
    a verified plan it returns is taken as incumbent and its routes as columns; the run still
    proves the published optimum."""
    inst, optimum = p12p_with_optimum()
    calls = []

    def primal(seconds):
        calls.append(seconds)
        return optimum

    r = solve_bp(inst, time_limit=60, primal=primal)
    assert len(calls) == 1 and 0 < calls[0] <= 0.1 * 60 + 1e-9
    assert r.status == Status.OPTIMAL and plan_prize(inst, r) == pytest.approx(OPTIMAL["p1.2.p"])
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
    inst, optimum = p12p_with_optimum()
    calls = []

    def primal(seconds):
        calls.append(seconds)
        return optimum if len(calls) == 2 else None

    r = solve_bp(inst, time_limit=60, primal=primal, options=BPOptions(primal_calls=6, dive_share=0.0))
    assert r.status == Status.OPTIMAL and plan_prize(inst, r) == pytest.approx(OPTIMAL["p1.2.p"])
    assert len(calls) == 2 == r.info["primal_calls"]


def test_primal_is_not_run_when_the_root_proves():
    """A root that proves the optimum by itself never calls the caller's heuristic."""
    calls = []
    inst = top_instance("p1.2.a")
    r = solve_bp(inst, time_limit=30, primal=lambda s: calls.append(s))
    assert r.status == Status.OPTIMAL and plan_prize(inst, r) == pytest.approx(OPTIMAL["p1.2.a"])
    assert calls == [] and r.info["primal_s"] is None


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


def test_at_scale_the_heuristic_runs_before_the_roots_column_generation():
    """From primal_first_from points on, the caller's heuristic runs before the root's first
    LP (no round solved yet); below it, not before the root has priced."""
    from sarcover.formulations.bp.tree import BranchAndPrice
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(6, 2, 2, 1))
    for first_from, before_any_round in [(0, True), (10**6, False)]:
        seen = []
        bp = BranchAndPrice(inst, time_limit=20, primal=lambda s: seen.append(bp.search.stats.rounds),
                            options=BPOptions(primal_first_from=first_from, primal_late_share=1.0,
                                              cut_rounds=0))
        bp.run()
        assert (seen[:1] == [0]) == before_any_round


def test_at_scale_the_heuristic_gets_the_scale_allowance():
    """From primal_first_from points on, each call of the caller's heuristic may take
    primal_scale_cap_s seconds (and primal_scale_share of the limit); below, primal_cap_s."""
    from sarcover.formulations.bp.tree import BranchAndPrice
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(6, 2, 2, 1))
    for first_from, cap in [(0, 7.0), (10**6, 3.0)]:
        seen = []
        bp = BranchAndPrice(inst, time_limit=60, primal=seen.append,
                            options=BPOptions(primal_first_from=first_from, primal_late_share=0.0,
                                              primal_share=1.0, primal_cap_s=3.0,
                                              primal_scale_share=1.0, primal_scale_cap_s=7.0,
                                              cut_rounds=0))
        bp.run()
        assert seen and seen[0] == pytest.approx(cap)
    bp = BranchAndPrice(inst, time_limit=60, primal=seen.append,
                        options=BPOptions(primal_first_from=0, primal_scale_share=0.05))
    assert bp.incumbents.primal_limit == pytest.approx(3.0)  # 5 % of 60 s, below the 90 s cap


def test_at_scale_a_root_slow_to_settle_calls_the_heuristic_again():
    """At scale the call before column generation does not stand in for the late one: a root
    not settled by primal_late_share of the limit (here 0: at once) calls the heuristic again
    before its first dive (the registered bp's first PyVRP search is a short one, the later
    ones search their whole allowance); below primal_first_from only the late call runs
    before the dive. Both prove p2.2.k."""
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    for first_from, before_dive in [(0, 2), (10**6, 1)]:
        seen = []
        bp = BranchAndPrice(inst, time_limit=60,
                            primal=lambda s: seen.append((bp.search.stats.rounds, bp.incumbents.dived)),
                            options=BPOptions(primal_first_from=first_from, primal_late_share=0.0,
                                              cut_rounds=0))
        proven, bound = bp.run()
        assert proven and bound == pytest.approx(OPTIMAL["p2.2.k"])
        assert sum(1 for _, dived in seen if not dived) == before_dive
        if first_from == 0:
            assert seen[0][0] == 0 and seen[1][0] >= 1  # the scale call, then the late one
