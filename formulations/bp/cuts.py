"""Rounds of limited-memory subset-row cuts at the root (the rows themselves: :mod:`.master`).

Cuts make every later pricing slower (labels carry cut parities, pay their duals and dominate
less), so a round is only tried at the root, once its floored bound is settled and the ng sets
stop growing, within the first ``cut_share`` of the time limit, and while the restricted LP is
less than ``cut_gap`` prize steps above the value that would prove the incumbent optimal or above
its own floor: a small drop then lowers the floored bound; larger drops are rare, and branching
does better. At most :data:`.master.MAX_CUTS` at a time: when a round would pass that, the cuts
of zero dual are removed first.

Each round makes the pricing slower (on M = 20, K = 5 an exact call took about twice as long
after each round of 16 cuts), so a round is started only if, taking twice as long as the round
before it (from its start to now), it would still end within the cut share: a round that starts
just before the share ends can otherwise hold the root for most of the run.

A round can also make the labelling explode (TOP set 5's two-vehicle files: an exact call of
38 000 labels before a round of 16 cuts passed the 2 000 000-label cap after it). An exact
call that hits the cap gives no bound, so the last round is withdrawn (:meth:`CutRounds.withdraw`)
and no more are tried: the bound certified before it stands, and the root goes on without it.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from sarcover.formulations.bp.graph import NodeState
from sarcover.formulations.bp.master import MAX_CUTS

if TYPE_CHECKING:
    from sarcover.formulations.bp.elimination import Elimination
    from sarcover.formulations.bp.search import Search


ROUND_GROWTH = 2.0  # a round's column generation against the one before it (measured, K = 5)


class CutRounds:
    """Up to ``rounds`` rounds of the ``per_round`` most violated triples, gated by ``gap``
    (prize steps) and started before ``until`` (a :func:`time.perf_counter` moment)."""

    def __init__(self, search: "Search", elimination: "Elimination", *, rounds: int,
                 per_round: int, gap: float, until: float):
        self.search = search
        self.elimination = elimination
        self.rounds = rounds
        self.per_round = per_round
        self.gap = gap
        self.until = until
        self.done = 0  # rounds separated so far
        self.started = None  # when the last round was separated (time.perf_counter())
        self.labelled = False  # the labelling arc bounds ran before the first round
        self.last = []  # the triples of the last round's cuts (withdrawn if pricing explodes)

    def add(self, state: NodeState, x, y, lp_value: float) -> bool:
        """Separate cuts violated by the node's LP solution ``x`` (duals ``y``, value
        ``lp_value``); report whether the LP changed (cuts added, or the graph or the columns
        changed by the labelling arc bounds run before the first round), so that it is
        re-solved."""
        s = self.search
        if state.depth > 0 or self.done >= self.rounds or s.clock.time_left() <= 0:
            return False
        now = time.perf_counter()
        if s.incumbent is None or now > self.until:
            return False
        if self.started is not None and now + ROUND_GROWTH * (now - self.started) > self.until:
            return False  # the next round would likely end past the cut share
        if s.stats.root_lp is None:
            s.stats.root_lp = lp_value
        # the drop that proves the incumbent optimal, or lowers the floored bound by one step
        need = min(lp_value - (s.incumbent_value + s.problem.step), lp_value - s.problem.floor(lp_value))
        if need > self.gap * s.problem.step:
            return False
        if not self.labelled:
            # the labelling arc bounds first: cut rounds then price on the smaller graph
            self.labelled = True
            version, k = self.elimination.version, s.master.n_routes
            self.elimination.eliminate(labels=True)
            if self.elimination.version != version or s.master.n_routes != k:
                return True  # re-solve (smaller graph, the route pool), then separate
        self.done += 1
        self.started = time.perf_counter()
        m = s.master
        if len(m.cuts) + self.per_round > MAX_CUTS:  # make room: drop idle cuts
            purged = m.purge_cuts(y)
            s.stats.cuts_purged += purged
            if purged:
                self.elimination.forget()  # its duals refer to rows that are gone
        added = m.add_cuts(m.separate_cuts(x, self.per_round))
        self.last = m.cuts[len(m.cuts) - added:]  # add_cuts appends
        s.stats.cuts += added
        return added > 0

    def withdraw(self) -> bool:
        """Remove the last round's cuts and try no more rounds (an exact pricing under them hit
        its label cap); report whether any were removed."""
        m = self.search.master
        self.rounds = self.done
        last = set(self.last)
        drop = [c for c, S in enumerate(m.cuts) if S in last]
        self.last = []
        if not drop:
            return False
        removed = m.remove_cuts(drop)
        self.search.stats.cuts_withdrawn += removed
        self.elimination.forget()  # its duals refer to rows that are gone
        return True
