"""Column generation below the root: targeted pricing keeps the floor; a label cap leads to branching."""

from __future__ import annotations

import numpy as np
import pytest

from sarcover.formulations.bp import BPOptions, solve_bp
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.io import load_instance
from sarcover.formulations.result import Status
from sarcover.formulations.verify import verify

from bp_cases import OPTIMAL, TOP_DIR, plan_prize


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


def test_label_cap_without_cuts_branches_instead_of_stopping():
    """With no cuts to withdraw, a node whose exact pricing hits the label cap is branched on
    its unconverged LP (its bound still holds) until the time is up: the run neither stops at
    the root nor claims more than it proved, and its plan is valid."""
    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    r = solve_bp(inst, time_limit=4, options=BPOptions(cut_rounds=0, exact_labels=1))
    assert r.info["label_caps"] > 1 and r.info["nodes"] > 1
    assert verify(inst, r.plan).valid and plan_prize(inst, r) <= OPTIMAL["p2.2.k"]
    assert r.bound >= OPTIMAL["p2.2.k"] - 1e-6
    if r.status == Status.OPTIMAL:
        assert plan_prize(inst, r) == pytest.approx(OPTIMAL["p2.2.k"])


def test_relaxed_bound_certifies_when_no_exact_pricing_finishes():
    """With every exact pricing stopped at its label cap, the node bounds come from the
    relaxed pricing bound alone: the run lowers its bound below the trivial sum of prizes at
    least once, and the bound it reports is still never below the optimum."""
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(6, 2, 1, 3))
    proof = solve_bp(inst, time_limit=30)  # the optimum, by a run with exact pricing
    assert proof.status == Status.OPTIMAL
    optimum = plan_prize(inst, proof)
    r = solve_bp(inst, time_limit=4, options=BPOptions(cut_rounds=0, exact_labels=1))
    assert r.info["exact_pricings"] >= 1 and r.info["relaxed_bounds"] >= 1
    assert r.bound >= optimum - 1e-6
    assert verify(inst, r.plan).valid and plan_prize(inst, r) <= optimum + 1e-9


def test_label_cap_that_brings_new_routes_leaves_the_lp_solution_readable():
    """An exact pricing stopped by its label cap whose routes join the master (at 600 points it
    finds many before the cap): the node is branched on its LP solution, which covers every
    column the master now holds (new ones at 0), instead of failing on the length (scale
    suite, M = 100, K = 6: 'shapes not aligned'). The run ends with a valid plan and bound."""
    from sarcover.formulations.bp.labelling import PricingResult
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    bp = BranchAndPrice(inst, time_limit=20, options=BPOptions(cut_rounds=0))
    bp.pricer.max_exact_labels = bp.pricer.exact_labels  # the root may not raise its cap here
    exact, capped = bp.pricer.exact, []

    def capped_with_new_routes(*args):
        res = exact(*args)
        if not capped and res.routes:
            capped.append(len(res.routes))
            return PricingResult(res.best, False, res.routes, [], res.n_labels, res.ng_routes)
        return res

    bp.pricer.exact = capped_with_new_routes
    proven, bound = bp.run()
    assert capped and bp.search.stats.label_caps == 1 and bp.search.stats.nodes > 1
    assert bound >= OPTIMAL["p2.2.k"] - 1e-6
    assert bp.search.incumbent_value <= OPTIMAL["p2.2.k"] + 1e-9


def test_unconverged_node_with_an_integral_lp_solution_stays_open():
    """A node whose column generation stopped unconverged (an exact pricing at its label cap)
    while its restricted LP solution is integral: that solution is offered as a plan, but the
    node is not solved, since the LP over all routes may be higher. The run must not report
    the plan optimal (scale suite, M = 100, K = 6, seed 302: the degenerate LP sat at PyVRP's
    routes, the capped root was closed as solved, and 499 was reported optimal under a root
    bound of 594)."""
    from sarcover.formulations.bp.tree import BranchAndPrice
    from sarcover.formulations.plan import Plan

    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    weak = Plan.of([[0]] + [[]] * (inst.n_vehicles - 1))  # a plan far below the optimum
    assert verify(inst, weak).valid
    bp = BranchAndPrice(inst, time_limit=20, warm_start=weak, options=BPOptions(cut_rounds=0))
    m = bp.search.master

    def capped_root(state, bound):  # the LP at the warm start's routes, pricing capped
        x = np.zeros(m.n_routes)
        x[m.routes.index((1,))] = 1.0
        return bound, x, np.zeros(m.n_art), False

    bp.root.solve = capped_root
    proven, bound = bp.run()
    assert not proven
    assert bound >= OPTIMAL["p2.2.k"] - 1e-6
    assert bp.search.stats.open_integral == 1  # counted: a row says when this happened
    assert "label cap" in bp.stopped  # the run says why it ended before its limit


def test_label_capped_root_without_cuts_raises_the_cap_and_goes_on():
    """An exact pricing at the root hits its label cap with no cut round to withdraw: the root
    doubles the exact calls' cap and its column generation goes on, instead of branching on an
    unconverged LP (at 600 points such a root with an integral LP ended the run at 265 s of
    600). The cap is simulated on the first two exact calls; p2.2.k's published optimum is
    proven at the root, the cap four times the option's."""
    from sarcover.formulations.bp.labelling import PricingResult
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    bp = BranchAndPrice(inst, time_limit=30, options=BPOptions(cut_rounds=0))
    exact, capped = bp.pricer.exact, []
    first_cap = bp.pricer.exact_labels

    def capped_twice(*args):
        res = exact(*args)
        if len(capped) < 2:
            capped.append(bp.pricer.exact_labels)
            return PricingResult(res.best, False, res.routes, [], res.n_labels, res.ng_routes)
        return res

    bp.pricer.exact = capped_twice
    proven, bound = bp.run()
    stats = bp.search.stats
    assert capped == [first_cap, 2 * first_cap] and stats.label_caps == 2
    assert stats.exact_label_cap == bp.pricer.exact_labels == 4 * first_cap
    assert stats.open_integral == 0 and bp.stopped is None
    assert proven and bound == pytest.approx(OPTIMAL["p2.2.k"])


def test_label_cap_grows_no_further_than_its_limit():
    """The root raises the exact calls' cap at most to ROOT_LABEL_GROWTH times the option's;
    after that a capped root is branched on as before."""
    from sarcover.formulations.bp.pricer import ROOT_LABEL_GROWTH
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    bp = BranchAndPrice(inst, time_limit=5, options=BPOptions(cut_rounds=0, exact_labels=1000))
    grown = []
    while bp.pricer.raise_exact_cap():
        grown.append(bp.pricer.exact_labels)
    assert grown and grown[-1] == ROOT_LABEL_GROWTH * 1000
    assert grown == sorted(grown) and not bp.pricer.raise_exact_cap()


def test_heuristic_pricing_capped_without_a_route_runs_again_with_a_larger_cap():
    """A heuristic pricing call that stops at its label cap before it finds an improving route
    runs again with four times the cap (labels go in order of energy: a capped call has not
    reached the long routes). With a cap of 5 labels the run still proves p2.2.k's optimum,
    the cap grown along the way."""
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = load_instance(TOP_DIR / "p2.2.k.txt")
    bp = BranchAndPrice(inst, time_limit=30, options=BPOptions(cut_rounds=0))
    bp.pricer.heuristic_labels = 5
    seen, price = [], bp.pricer.price

    def recording(*args, **kw):
        res = price(*args, **kw)
        if kw.get("heuristic"):
            seen.append((bp.pricer.heuristic_labels, res.stopped, bool(bp.pricer.columns(res))))
        return res

    bp.pricer.price = recording
    proven, bound = bp.run()
    # some capped call found nothing and was run again at once with four times the cap
    assert any(cap * 4 == seen[i + 1][0] and stopped and not found
               for i, (cap, stopped, found) in enumerate(seen[:-1]))
    assert bp.search.stats.heuristic_labels == bp.pricer.heuristic_labels > 5
    assert proven and bound == pytest.approx(OPTIMAL["p2.2.k"])
