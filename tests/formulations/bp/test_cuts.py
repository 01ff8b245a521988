"""Subset-row cut rounds keep the optima and start only when they would end within their share."""

from __future__ import annotations

import math
import time

import pytest

from sarcover.formulations.bp import BPOptions, solve_bp
from sarcover.formulations.io import load_instance
from sarcover.formulations.result import Status

from bp_cases import OPTIMAL, TOP_DIR, brute_force, plan_prize, random_tiny


def test_purging_cuts_keeps_the_published_optimum():
    """Rounds of 48 cuts on p2.2.k pass the 64-cut limit, so idle cuts are purged between
    rounds; the published optimum is still proven."""
    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    r = solve_bp(inst, time_limit=60, options=BPOptions(cut_rounds=4, cuts_per_round=48, cut_gap=100.0,
                                                    cut_share=1.0))
    assert r.info["cuts_purged"] > 0
    assert r.status == Status.OPTIMAL and plan_prize(inst, r) == pytest.approx(OPTIMAL["p2.2.k"])
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
