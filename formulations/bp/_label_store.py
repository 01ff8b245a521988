"""The label store that the pricing's labelling (:mod:`.labelling`) and the route enumeration
(:mod:`.enumeration_kernel`) share: the labels in creation order (point, predecessor, energy,
prize, alive, remembered set, cut parities), the binary heap that hands them out in order of
energy, their extension by one arc, the deadline poll and the arrays' growth.

Label 0 is the root: the start (point 0), no energy, no prize. Sets are bitsets of ``W`` 64-bit
words.

The searches call these in their innermost loops, so they pass what costs nothing to pass:
:func:`extend`, called once per arc, takes scalars only, and the per-label functions return no
arrays; arrays passed per arc, or returned per label, slow the searches down measurably
(docs/bp-log.md, "the label store").
"""

from __future__ import annotations

import time

import numpy as np
from numba import njit, objmode

CAPACITY = 1024  # labels the store holds before its arrays first double


@njit(cache=True)
def grow(arr, size):
    """``arr`` with room for ``size`` rows (its own rows copied first)."""
    out = np.empty((size,) + arr.shape[1:], dtype=arr.dtype)
    out[: arr.shape[0]] = arr
    return out


@njit(cache=True)
def heap_push(key, val, n, k, v):
    """Push (k, v) on the binary min-heap key[:n]/val[:n]; return the new size."""
    i = n
    while i > 0:
        parent = (i - 1) >> 1
        if key[parent] <= k:
            break
        key[i] = key[parent]
        val[i] = val[parent]
        i = parent
    key[i] = k
    val[i] = v
    return n + 1


@njit(cache=True)
def heap_pop(key, val, n):
    """Remove the minimum (key[0], val[0]) of the heap key[:n]; return the new size."""
    n -= 1
    if n == 0:
        return 0
    k = key[n]
    v = val[n]
    i = 0
    while True:
        c = 2 * i + 1
        if c >= n:
            break
        if c + 1 < n and key[c + 1] < key[c]:
            c += 1
        if key[c] >= k:
            break
        key[i] = key[c]
        val[i] = val[c]
        i = c
    key[i] = k
    val[i] = v
    return n


@njit(cache=True)
def next_label(hkey, hval, hn, alive):
    """The alive label of least energy, taken off the heap (labels dominated since they were
    stored are dropped on the way): (label, the heap's new size); label -1 once the heap is
    empty."""
    while hn > 0:
        qi = hval[0]
        hn = heap_pop(hkey, hval, hn)
        if alive[qi]:
            return qi, hn
    return -1, hn


@njit(cache=True)
def new_store(W):
    """An empty store of ``CAPACITY`` labels with ``W``-word sets, holding the root label, and
    the heap holding it: (node, pred, energy, prize, alive, mask, cut parities, heap keys, heap
    values)."""
    cap = CAPACITY
    node = np.empty(cap, np.int32)
    pred = np.empty(cap, np.int32)
    en = np.empty(cap, np.float64)
    pr = np.empty(cap, np.float64)
    alive = np.empty(cap, np.bool_)
    mask = np.zeros((cap, W), np.uint64)
    srb = np.zeros(cap, np.uint64)
    hkey = np.empty(cap, np.float64)
    hval = np.empty(cap, np.int32)
    node[0] = 0
    pred[0] = -1
    en[0] = 0.0
    pr[0] = 0.0
    alive[0] = True
    hkey[0] = 0.0
    hval[0] = 0
    return node, pred, en, pr, alive, mask, srb, hkey, hval


@njit(cache=True)
def grow_store(node, pred, en, pr, alive, mask, srb, hkey, hval):
    """The store's arrays (as :func:`new_store` returns them) at twice their capacity."""
    cap = 2 * node.shape[0]
    return (grow(node, cap), grow(pred, cap), grow(en, cap), grow(pr, cap), grow(alive, cap),
            grow(mask, cap), grow(srb, cap), grow(hkey, cap), grow(hval, cap))


@njit(cache=True)
def write_label(node, pred, en, pr, alive, mask, srb, count, w, qi, e2, p2, s2, newmask):
    """Label ``count``, alive: at point ``w``, extended from label ``qi``, with energy ``e2``,
    prize ``p2``, cut parities ``s2`` and remembered set ``newmask`` (the arrays have room)."""
    node[count] = w
    pred[count] = qi
    en[count] = e2
    pr[count] = p2
    alive[count] = True
    srb[count] = s2
    for k in range(newmask.shape[0]):
        mask[count, k] = newmask[k]


@njit(cache=True)
def extend(e, p, parities, word, w, allowed_w, c, ret_w, budget, prize_w, mmem_w, cmem_w):
    """A label of energy ``e``, prize ``p`` and cut ``parities`` extended by an arc of cost
    ``c`` into point ``w``: (fits, energy, prize, the cuts it pairs, parities). It does not fit
    when w is not allowed, when the end is then out of reach within the budget (``ret_w``: the
    cheapest way there from w; a removed arc, at inf, never fits) or when w is in the label's
    remembered set (``word``: the set's 64-bit word that holds w). The prize gains ``prize_w``;
    the caller pays the duals of the cuts paired (those whose triple, ``cmem_w``, holds w and
    whose parity was odd), and a cut's parity is forgotten outside its memory (``mmem_w``).
    Scalars only: it is called once per arc."""
    if not allowed_w:
        return False, e, p, np.uint64(0), np.uint64(0)
    e2 = e + c
    if not (e2 + ret_w <= budget):  # also rejects inf (removed arcs)
        return False, e2, p, np.uint64(0), np.uint64(0)
    if word & (np.uint64(1) << np.uint64(w & 63)):
        return False, e2, p, np.uint64(0), np.uint64(0)
    sq = parities & mmem_w
    return True, e2, p + prize_w, sq & cmem_w, sq ^ cmem_w


@njit(cache=True)
def out_of_time(deadline):
    """Whether the clock has passed ``deadline`` (a :func:`time.perf_counter` moment); the
    searches ask every 4096 labels, so that the clock is read rarely."""
    with objmode(now="float64"):
        now = time.perf_counter()
    return now > deadline


def chain(node, pred, j):
    """Points of label ``j``'s path, from the root's successor to the label's point."""
    path = []
    while j > 0:
        path.append(int(node[j]))
        j = int(pred[j])
    path.reverse()
    return path
