"""An audit of a proof by route enumeration, made apart from the enumeration's kernels.

A complete root listing proves the incumbent optimal when no plan worth ``need`` (the incumbent
plus one step) is made of listed routes. That rests on two things this module checks by other
means than the ones the proof used (``audit_listings`` of :class:`.options.BPOptions`):

* **closure** (:func:`missing_neighbours`): every route one insertion, one removal or one swap
  away from a listed route, within the budget on the listing's graph and of reduced prize above
  the listing's threshold (its own order's limited-memory cut pays), is itself listed. (The
  graph is the listing's because an arc eliminated under an earlier certificate is in no plan
  better than the incumbent even where a route through it clears this threshold: the arc
  elimination is not audited here.) The completion and suffix bounds and the dominance that
  the listing shares with the pricing could only drop a route silently; a dropped route next
  to a listed one shows here.
* **packing** (:func:`packing_reaches`): an exhaustive search over every set of at most N
  pairwise disjoint listed routes for one worth ``need``, pruned only by the certificate: such a
  plan's routes have reduced prizes summing to at least need - (D - N·y0) (D the certificate's
  dual term, y0 its vehicle dual; every other row's use is bounded by its right-hand side). It
  replaces the LP over the listed routes, its cuts and reduced-cost filter, and the MILP.

The closure check is local: a region of the route space no listed route borders would go
unnoticed (the kernel's brute-force tests cover that on small graphs). Both checks only read
the listing's arrays; they never change the run.
"""

from __future__ import annotations

import time
from typing import NamedTuple

import numpy as np
from numba import njit
from sarcover.formulations.bp._label_store import out_of_time


@njit(cache=True)
def reduced_prize(route, k, profit, cmem, mmem, sig):
    """Reduced prize of the route start -> route[:k] -> end: its points' ``profit`` less the
    dual of each limited-memory cut it pairs in this order (a cut's parity is forgotten at a
    point outside its memory ``mmem``; ``cmem``: the cuts whose triple holds a point; ``sig``:
    the cut duals)."""
    parity = np.uint64(0)
    p = 0.0
    for i in range(k):
        w = route[i]
        p += profit[w]
        kept = parity & mmem[w]
        paired = kept & cmem[w]
        c = 0
        while paired:
            if paired & np.uint64(1):
                p -= sig[c]
            paired >>= np.uint64(1)
            c += 1
        parity = kept ^ cmem[w]
    return p


@njit(cache=True)
def _length(route, k, dist):
    end = dist.shape[0] - 1
    if k == 0:
        return dist[0, end]
    e = dist[0, route[0]] + dist[route[k - 1], end]
    for i in range(1, k):
        e += dist[route[i - 1], route[i]]
    return e


@njit(cache=True)
def _mask(route, k, words):
    m = np.zeros(words, np.uint64)
    for i in range(k):
        w = route[i]
        m[w >> 6] |= np.uint64(1) << np.uint64(w & 63)
    return m


@njit(cache=True)
def _listed(keys, m):
    """Whether mask ``m`` is a row of ``keys`` (rows sorted lexicographically)."""
    lo, hi = 0, keys.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        cmp = 0
        for j in range(m.size):
            if keys[mid, j] != m[j]:
                cmp = -1 if keys[mid, j] < m[j] else 1
                break
        if cmp == 0:
            return True
        if cmp < 0:
            lo = mid + 1
        else:
            hi = mid
    return False


@njit(cache=True)
def _check(cand, m, dist, budget, profit, cmem, mmem, sig, threshold, keys, counts):
    if _length(cand, m, dist) > budget:
        return
    if reduced_prize(cand, m, profit, cmem, mmem, sig) <= threshold + 1e-6:
        return
    counts[1] += 1
    if not _listed(keys, _mask(cand, m, keys.shape[1])):
        counts[0] += 1


@njit(cache=True)
def _closure(paths, dist, budget, profit, cmem, mmem, sig, threshold, keys):
    n = dist.shape[0]
    counts = np.zeros(2, np.int64)  # missing, tested
    cand = np.empty(paths.shape[1] + 1, np.int64)
    on = np.zeros(n, np.bool_)
    for r in range(paths.shape[0]):
        k = 0
        while k < paths.shape[1] and paths[r, k] >= 0:
            k += 1
        route = paths[r, :k].astype(np.int64)
        on[:] = False
        for i in range(k):
            on[route[i]] = True
        for i in range(k):  # removals
            m = 0
            for j in range(k):
                if j != i:
                    cand[m] = route[j]
                    m += 1
            _check(cand, m, dist, budget, profit, cmem, mmem, sig, threshold, keys, counts)
        for u in range(1, n - 1):
            if on[u]:
                continue
            for pos in range(k + 1):  # insertions, every position
                m = 0
                for j in range(k + 1):
                    if j == pos:
                        cand[m] = u
                        m += 1
                    if j < k:
                        cand[m] = route[j]
                        m += 1
                _check(cand, m, dist, budget, profit, cmem, mmem, sig, threshold, keys, counts)
            for i in range(k):  # swaps, in the place of the point swapped out
                for j in range(k):
                    cand[j] = u if j == i else route[j]
                _check(cand, k, dist, budget, profit, cmem, mmem, sig, threshold, keys, counts)
    return counts[0], counts[1]


def _masks(paths: np.ndarray, n: int) -> np.ndarray:
    """The point sets of ``paths`` (points below ``n``) as rows of 64-bit words."""
    words = (n + 63) // 64
    masks = np.zeros((len(paths), words), np.uint64)
    for r, row in enumerate(paths):
        masks[r] = _mask(row[row >= 0].astype(np.int64), int((row >= 0).sum()), words)
    return masks


def _keys(paths: np.ndarray, n: int) -> np.ndarray:
    """The listed routes' point sets (:func:`_masks`), sorted lexicographically."""
    keys = _masks(paths, n)
    return np.ascontiguousarray(keys[np.lexsort(keys.T[::-1])])


def missing_neighbours(paths, dist, budget, profit, threshold, cuts) -> tuple[int, int]:
    """(missing, tested): of the routes one insertion, removal or swap away from a listed route
    (rows of ``paths``: solver points, -1 padded), within ``budget`` on ``dist`` and of reduced
    prize (:func:`reduced_prize`, ``cuts`` = (cmem, mmem, duals)) above ``threshold``, how many
    were tested and how many are not listed (0 for a listing that is complete near itself)."""
    n = dist.shape[0]
    cmem, mmem, duals = cuts
    sig = np.zeros(64)
    sig[: len(duals)] = np.maximum(duals, 0.0)
    return _closure(np.ascontiguousarray(paths, dtype=np.int64), np.ascontiguousarray(dist, dtype=np.float64),
                    float(budget), np.ascontiguousarray(profit, dtype=np.float64),
                    np.ascontiguousarray(cmem, dtype=np.uint64), np.ascontiguousarray(mmem, dtype=np.uint64),
                    sig, float(threshold), _keys(paths, n))


@njit(cache=True)
def _pack(masks, red, val, vehicles, floor, need, deadline):
    """Iterative depth-first search over sets of pairwise disjoint routes (routes by ``red``
    descending) with reduced prizes summing to >= ``floor`` and values to >= ``need``; returns
    (route indices padded with -1, outcome): 1 found (the indices), 0 none exists, -1 the
    ``deadline`` (a :func:`time.perf_counter` moment) came first."""
    k, words = masks.shape
    pick = np.full(vehicles, -1, np.int64)
    acc = np.zeros((vehicles + 1, words), np.uint64)
    rsum = np.zeros(vehicles + 1)
    vsum = np.zeros(vehicles + 1)
    d = 0
    nxt = 0  # the next route to try at depth d
    steps = 0
    while True:
        # the routes after nxt add at most (slots left) x red[nxt], or red[nxt] if negative
        if nxt >= k or max((vehicles - d) * red[nxt], red[nxt]) < floor - rsum[d]:
            if d == 0:  # every set was examined
                return pick, 0
            d -= 1
            nxt = pick[d] + 1
            pick[d] = -1
            continue
        steps += 1
        if (steps & 0xFFFFF) == 0 and out_of_time(deadline):
            return pick, -1
        i = nxt
        nxt += 1
        clash = False
        for w in range(words):
            if acc[d, w] & masks[i, w]:
                clash = True
                break
        if clash:
            continue
        pick[d] = i
        for w in range(words):
            acc[d + 1, w] = acc[d, w] | masks[i, w]
        rsum[d + 1] = rsum[d] + red[i]
        vsum[d + 1] = vsum[d] + val[i]
        if rsum[d + 1] >= floor and vsum[d + 1] >= need:
            return pick, 1
        if d + 2 == vehicles:  # the last route: one tight scan (where most of the time goes)
            rest = floor - rsum[d + 1]
            for q in range(i + 1, k):
                if red[q] < rest:
                    break
                clash = False
                for w in range(words):
                    if acc[d + 1, w] & masks[q, w]:
                        clash = True
                        break
                if not clash and vsum[d + 1] + val[q] >= need:
                    pick[d + 1] = q
                    return pick, 1
            steps += 1
            pick[d] = -1
        elif d + 1 < vehicles:
            d += 1
            nxt = i + 1
        else:
            pick[d] = -1


def packing_reaches(paths, value, reduced, vehicles: int, need: float, floor: float,
                    max_seconds: float = 3600.0) -> tuple[list[int] | None, bool]:
    """(routes, finished): row indices of at most ``vehicles`` pairwise disjoint routes of
    ``paths`` whose ``value`` sums to >= ``need`` and whose ``reduced`` prizes sum to >=
    ``floor`` (None when there is none), and whether the search finished within ``max_seconds``
    (unfinished: None says nothing)."""
    masks = _masks(paths, int(paths.max()) + 1 if paths.size else 1)
    order = np.argsort(-np.asarray(reduced, dtype=float), kind="stable")
    pick, outcome = _pack(masks[order], np.asarray(reduced, dtype=float)[order] + 1e-6,
                          np.asarray(value, dtype=float)[order], int(vehicles), float(floor),
                          float(need) - 1e-6, time.perf_counter() + float(max_seconds))
    if outcome == 1:
        return [int(order[i]) for i in pick if i >= 0], True
    return None, outcome == 0


class Audit(NamedTuple):
    """What :func:`audit_listing` found: closure ``missing`` of ``tested`` neighbours, the
    ``packing`` found (route indices; None: none), whether the packing search ``finished``,
    and the seconds it took."""

    missing: int
    tested: int
    packing: list[int] | None
    finished: bool
    seconds: float

    @property
    def passed(self) -> bool:
        """Nothing missing, no packing worth ``need``, and the search finished."""
        return self.missing == 0 and self.packing is None and self.finished

    def summary(self) -> dict:
        return {"audit_missing": self.missing, "audit_tested": self.tested,
                "audit_packing": self.packing, "audit_finished": self.finished,
                "audit_passed": self.passed, "audit_s": round(self.seconds, 1)}


def audit_listing(paths, dist, budget, profit, threshold, cuts, *, prizes, vehicles: int,
                  need: float, floor: float, reduced, max_seconds: float = 3600.0) -> Audit:
    """Both checks of the module on one complete listing (``paths``), threshold ``threshold`` in
    reduced prize: the closure on the arc costs ``dist`` (inf: no arc), then the packing of
    routes worth ``need`` (``prizes``: per solver point) whose reduced prizes reach ``floor``
    (need - D + N·y0), for at most ``max_seconds``. ``reduced``: each listed set's best reduced
    prize over its orders (the kernel's, :attr:`.enumeration_kernel.Enumerated.values`)."""
    t = time.perf_counter()
    missing, tested = missing_neighbours(paths, dist, budget, profit, threshold, cuts)
    value = [float(prizes[row[row >= 0]].sum()) for row in paths]
    packing, finished = packing_reaches(paths, value, reduced, vehicles, need, floor, max_seconds)
    return Audit(int(missing), int(tested), packing, finished, time.perf_counter() - t)
