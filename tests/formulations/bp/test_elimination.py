"""Arc elimination and the MILP column filter keep every plan better than the incumbent."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sarcover.formulations.bp import BPOptions

from bp_cases import arcs_of_plans_from, brute_force, random_tiny, top_instance


@pytest.mark.parametrize("name", ["p1.2.l", "p2.2.k", "p3.2.f"])
def test_milp_column_filter_keeps_every_better_plan(name):
    """The reduced-cost filter of the MILP's columns (duals that certified the root bound)
    never removes a better plan: with the incumbent set below the best plan over the generated
    routes, the filtered MILP finds a plan of that same value, from fewer routes."""
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = top_instance(name)
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
    assert not gone & arcs_of_plans_from(inst, best)
