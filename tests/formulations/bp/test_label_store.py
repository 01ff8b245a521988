"""The label store hands out alive labels by energy, grows without loss, and extends a label by one arc."""

from __future__ import annotations

import numpy as np

from sarcover.formulations.bp._label_store import (chain, extend, grow_store, new_store, next_label,
                                                   write_label)
from sarcover.formulations.bp.cut_duals import byte_sums, sigsum


def test_labels_come_back_in_order_of_energy_past_the_first_growth():
    """3000 labels stored at random energies (the arrays doubled twice on the way) come off the
    heap in order of energy, the dead ones skipped, with their points, predecessors and sets."""
    from sarcover.formulations.bp._label_store import heap_push

    rng = np.random.default_rng(0)
    node, pred, en, pr, alive, mask, srb, hkey, hval = new_store(2)
    assert next_label(hkey.copy(), hval.copy(), 1, alive) == (0, 0)  # the root alone
    hn = 1
    energies = rng.uniform(0.0, 100.0, 3000)
    for count, e in enumerate(energies, start=1):
        if count == node.shape[0]:
            node, pred, en, pr, alive, mask, srb, hkey, hval = grow_store(
                node, pred, en, pr, alive, mask, srb, hkey, hval)
        bits = np.array([count, 3 * count], np.uint64)
        write_label(node, pred, en, pr, alive, mask, srb, count, count % 7 + 1, count - 1, e, -e,
                    np.uint64(count), bits)
        hn = heap_push(hkey, hval, hn, e, count)
    assert node.shape[0] >= 3001 and hn == 3001
    alive[1:3001:3] = False
    order = []
    while True:
        qi, hn = next_label(hkey, hval, hn, alive)
        if qi < 0:
            break
        order.append(qi)
    want = [0] + sorted((i for i in range(1, 3001) if i % 3 != 1), key=lambda i: energies[i - 1])
    assert order == want
    assert all(node[i] == i % 7 + 1 and pred[i] == i - 1 and mask[i, 1] == 3 * i and srb[i] == i
               for i in order[1:])
    assert chain(node, pred, 3) == [2, 3, 4]


def test_extending_by_one_arc():
    """The energy adds up; a point not allowed, remembered, or past which the end is out of
    reach refuses the arc; visiting a cut's triple twice pairs it; memory forgets a parity."""
    cut = np.uint64(1)
    args = dict(c=1.0, ret_w=1.0, budget=10.0, prize_w=3.0, mmem_w=cut, cmem_w=cut)
    fits, e2, p2, paired, s2 = extend(1.0, 2.0, np.uint64(0), np.uint64(0b0010), 2, True, **args)
    assert fits and (e2, p2, paired, s2) == (2.0, 5.0, 0, cut)  # first visit: odd parity
    fits, e2, p2, paired, s2 = extend(1.0, 2.0, cut, np.uint64(0b0010), 2, True, **args)
    assert fits and paired == cut and s2 == 0  # second visit: a pair, whose dual the caller pays
    assert sigsum(paired, byte_sums(np.array([0.5]))) == 0.5
    assert extend(1.0, 2.0, cut, np.uint64(0), 2, True, **{**args, "mmem_w": np.uint64(0)})[3] == 0
    assert not extend(1.0, 2.0, cut, np.uint64(0b0100), 2, True, **args)[0]  # remembered
    assert not extend(1.0, 2.0, cut, np.uint64(0), 2, False, **args)[0]  # not allowed
    assert not extend(1.0, 2.0, cut, np.uint64(0), 2, True, **{**args, "budget": 2.5})[0]  # no way back
    assert not extend(1.0, 2.0, cut, np.uint64(0), 2, True, **{**args, "c": np.inf})[0]  # removed arc
