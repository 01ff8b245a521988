"""numba kernels for the routers' innermost loops (compiled once, cached on disk).

Each kernel does exactly what the numpy code it replaces did, on the same random draws, so a seed
gives the same plan with or without it:

* :func:`construct_tours`: the ant system's L construction steps (roulette wheel over the unvisited
  viewpoints, float32 cumulative sums in the same order as ``np.cumsum``). The numpy version runs
  about six numpy calls per step and colony, i.e. ~7000 small calls a run at L = 12.
* :func:`keyed_lengths`: random-key decoding (sort the keys of every particle) and path lengths,
  one call per PSO iteration instead of argsort + gathers + sums.

``HAVE_NUMBA`` is False when numba cannot be imported; the routers then fall back to numpy.
"""

from __future__ import annotations

import numpy as np

try:
    from numba import njit

    HAVE_NUMBA = True
except ImportError:  # pragma: no cover - numba is a pinned dependency
    HAVE_NUMBA = False

if HAVE_NUMBA:

    @njit(cache=True, nogil=True)
    def construct_tours(weight, u, B, P, L):  # pragma: no cover - compiled
        """weight (B*(L+1), L) float32 (row b*(L+1)+state), u (L, B, P) float32 -> tours (L, B, P) int64."""
        tours = np.empty((L, B, P), dtype=np.int64)
        avail = np.ones(L, dtype=np.float32)
        w = np.empty(L, dtype=np.float32)
        for b in range(B):
            base = b * (L + 1)
            for p in range(P):
                avail[:] = 1.0
                cur = base + L
                for s in range(L - 1):
                    acc = np.float32(0.0)
                    for j in range(L):
                        acc = np.float32(acc + weight[cur, j] * avail[j])
                        w[j] = acc
                    thr = np.float32(u[s, b, p] * acc)
                    nxt = 0
                    for j in range(L):
                        if w[j] > thr:
                            nxt = j
                            break
                    tours[s, b, p] = nxt
                    avail[nxt] = 0.0
                    cur = base + nxt
                last = 0
                for j in range(L):
                    if avail[j] > 0.0:
                        last = j
                        break
                tours[L - 1, b, p] = last
        return tours

    @njit(cache=True, nogil=True)
    def keyed_lengths(D, keys, nodes, sizes, start, end):  # pragma: no cover - compiled
        """(B, P) lengths of the tours decoded from keys (B, P, L) (real entries sorted by key)."""
        B, P, L = keys.shape
        out = np.empty((B, P))
        order = np.empty(L, dtype=np.int64)
        for b in range(B):
            n = sizes[b]
            for p in range(P):
                for i in range(n):  # insertion sort of the (few) real keys: no allocation
                    k = keys[b, p, i]
                    j = i
                    while j > 0 and keys[b, p, order[j - 1]] > k:
                        order[j] = order[j - 1]
                        j -= 1
                    order[j] = i
                prev = start
                total = 0.0
                for i in range(n):
                    v = nodes[b, order[i]]
                    total += D[prev, v]
                    prev = v
                out[b, p] = total + D[prev, end]
        return out

    @njit(cache=True, nogil=True)
    def pso_step(x, v, pbest, pbest_f, gbest, r1, r2, w, c1, c2, v_max,
                 D, nodes, sizes, start, end):  # pragma: no cover - compiled
        """One in-place PSO move of every particle (same arithmetic order as the numpy code):
        v ← clip(w·v + c1·r1·(pbest−x) + c2·r2·(gbest−x)), x ← x + v, then fitness and pbest."""
        B, P, L = x.shape
        for b in range(B):
            for p in range(P):
                for i in range(L):
                    vi = w * v[b, p, i] + c1 * r1[b, p, i] * (pbest[b, p, i] - x[b, p, i]) \
                        + c2 * r2[b, p, i] * (gbest[b, i] - x[b, p, i])
                    if vi < -v_max:
                        vi = -v_max
                    elif vi > v_max:
                        vi = v_max
                    v[b, p, i] = vi
                    x[b, p, i] = x[b, p, i] + vi
        f = keyed_lengths(D, x, nodes, sizes, start, end)
        for b in range(B):
            for p in range(P):
                if f[b, p] < pbest_f[b, p]:
                    pbest_f[b, p] = f[b, p]
                    for i in range(L):
                        pbest[b, p, i] = x[b, p, i]
        return f

    @njit(cache=True, nogil=True)
    def ga_children(pop, win, lo1, hi1, cross, lo2, hi2, mutate):  # pragma: no cover - compiled
        """The GA's children (B, C, L): parents pop[b, win[b, c]] and pop[b, win[b, C + c]], order
        crossover keeping parent 1's slice lo1..hi1 where ``cross``, then the inversion of
        lo2..hi2 where ``mutate`` (flat child index b*C + c), exactly as the numpy version."""
        B, P, L = pop.shape
        C = win.shape[1] // 2
        child = np.empty((B, C, L), dtype=pop.dtype)
        member = np.zeros(L, dtype=np.bool_)
        tmp = np.empty(L, dtype=pop.dtype)
        for b in range(B):
            for c in range(C):
                k = b * C + c
                p1 = pop[b, win[b, c]]
                if cross[k]:
                    p2 = pop[b, win[b, C + c]]
                    lo, hi = lo1[k], hi1[k]
                    member[:] = False
                    for i in range(lo, hi + 1):
                        member[p1[i]] = True
                    j = 0
                    for i in range(L):
                        if lo <= i <= hi:
                            tmp[i] = p1[i]
                        else:
                            while member[p2[j]]:
                                j += 1
                            tmp[i] = p2[j]
                            j += 1
                else:
                    for i in range(L):
                        tmp[i] = p1[i]
                if mutate[k]:
                    lo, hi = lo2[k], hi2[k]
                    for i in range(L):
                        if lo <= i <= hi:
                            child[b, c, i] = tmp[lo + hi - i]
                        else:
                            child[b, c, i] = tmp[i]
                else:
                    for i in range(L):
                        child[b, c, i] = tmp[i]
        return child
