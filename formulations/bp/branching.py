"""Branching: on a fractional node visit (forbid the node / force it visited) and, with
``group_branching``, on a fractional number of a group's visits (the views of a target: at most
its floor / at least its ceiling); when all visits are integral, on a fractional arc flow (forbid
the arc / force it). With integral visits and arc flows an LP solution of elementary routes is
integral (each positive route follows the unique flow-1 arcs); a node where that still fails
(repeated routes) cannot be split.

A group's visits can split the LP more evenly than one of its points: the LP spreads a target's
views over several viewpoints, and forcing or forbidding one leaves the others to make up for it.
On the M = 20 SAR instances it proved no more (docs/bp-log.md), so it is off by default.

Strong branching picks among the ``strong`` most fractional candidates the one whose two
children, re-solved on the current columns without pricing (a cheap estimate), drop most below
the node's LP value.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np
from sarcover.formulations.bp.constants import TOL
from sarcover.formulations.bp.graph import NodeState

if TYPE_CHECKING:
    from sarcover.formulations.bp.search import Search


def branch_candidates(search: "Search", state: NodeState, x: np.ndarray,
                      limit: int | None = None, groups: bool = False):
    """Child pairs to branch on, most fractional first: the first ``limit`` groups with a
    fractional number of visits (at most floor / at least ceiling; if ``groups``) and the first
    ``limit`` points with a fractional visit (forced / forbidden) while some are fractional, else
    the first ``limit`` arc flows (forced / forbidden)."""
    m = search.master
    pairs = []
    if groups and m.G:
        gv = m.group_visits(x)
        gfrac = gv - np.floor(gv)
        gs = np.flatnonzero((gfrac > TOL) & (gfrac < 1 - TOL))
        gs = gs[np.argsort(np.abs(gfrac[gs] - 0.5), kind="stable")][:limit]
        pairs += [[state.child(group_bounds=[(int(g), -np.inf, float(np.floor(gv[g])))]),
                   state.child(group_bounds=[(int(g), float(np.ceil(gv[g])), np.inf)])]
                  for g in gs]
    visits = m.node_visits(x)[1 : search.problem.V + 1]
    frac = np.abs(visits - np.round(visits))
    pts = np.flatnonzero(frac > TOL)
    if pts.size or pairs:
        pts = pts[np.argsort(np.abs(visits[pts] - 0.5), kind="stable")][:limit] + 1
        return pairs + [[state.child(forced_nodes=[int(p)]), state.child(forbidden_nodes=[int(p)])]
                        for p in pts]
    arcs = [(abs(f - 0.5), a) for a, f in m.arc_flows(x).items() if min(f, 1 - f) > TOL]
    arcs.sort()
    return [[state.child(forced_arcs=[a]), state.child(forbidden_arcs=[a])]
            for _, a in arcs[:limit]]


def branch(search: "Search", state: NodeState, x: np.ndarray, lp_value: float, strong: int,
           groups: bool = False):
    """Children of a node, or None if its LP solution is integral in visits and arcs. Of the
    ``strong`` most fractional candidates of each kind (groups if ``groups``, points, or arcs),
    the one whose children's re-solved LPs drop most below the node's value (product of the two
    drops, each at least 1e-3 so that a free child does not hide the other). The estimates stop
    at the clock's deadline (each is an LP solve, seconds each at a few hundred points, and the
    time limit holds): the best candidate so far is taken, the first when none was estimated.
    The master's bounds are the node's again afterwards."""
    cands = branch_candidates(search, state, x, max(strong, 1), groups)
    if not cands:
        return None
    if strong <= 1 or len(cands) == 1:
        return cands[0]
    m = search.master
    t = time.perf_counter()
    best, pick = -1.0, cands[0]
    for pair in cands:
        if search.clock.time_left() <= 0:
            break
        drops = []
        for ch in pair:
            m.apply(ch)
            value = m.solve()[0]
            drops.append(max(lp_value - value, 1e-3))
        score = drops[0] * drops[1]
        if score > best:
            best, pick = score, pair
        search.stats.strong_lps += 2
    m.apply(state)
    search.stats.strong_s += time.perf_counter() - t
    return pick
