"""numba kernels for the routers' innermost loops (compiled once, cached on disk).

Each kernel does what the numpy code it replaces does, on the same random draws (drawn by numpy
in the same stream), so a seed gives the same plan with or without it, except where two tours tie
exactly in length (a tour and its reverse when start = end): path lengths are summed
sequentially here and pairwise by numpy, and such ties may break the other way.

* :func:`pso_iterations`: whole PSO iterations (move, random-key decoding, fitness, bests, the
  2-opt move on each swarm's best).
* :func:`aco_iterations` with :func:`construct_tours`: whole ant-system colonies (wheel weights,
  construction by roulette wheel in float32 as ``np.cumsum``, deposits, evaporation).
* :func:`ga_generation` with :func:`ga_children`: one GA generation (elitism, tournaments, OX,
  inversion, fitness); the GA's draws stay in numpy (integers and uniforms interleave).

They exist for speed: the per-iteration numpy calls dominated the routing stage (the timings
are in ``docs/heuristics.md``).

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
    def construct_tours(weight, u, sizes, B, P, L):  # pragma: no cover - compiled
        """weight (B*(L+1), L) float32 (row b*(L+1)+state), u (L, B, P) float32 -> tours (L, B, P) int64.

        Ant p of row b draws each next viewpoint by a roulette wheel over the unvisited ones among
        the row's ``sizes[b]`` real positions: the float32 running sum in position order (as
        ``np.cumsum``), the first position where it exceeds u·total. Visited positions add an
        exact 0 and pads (weight 1e-30 next to real weights >= 1e-20) vanish in float32, so
        skipping them draws what the wheel over all L positions draws; pads follow in order.
        """
        tours = np.empty((L, B, P), dtype=np.int64)
        avail = np.ones(L, dtype=np.bool_)
        for b in range(B):
            base = b * (L + 1)
            n = sizes[b]
            for p in range(P):
                avail[:n] = True
                cur = base + L
                for s in range(n - 1):
                    total = np.float32(0.0)
                    for j in range(n):
                        if avail[j]:
                            total = np.float32(total + weight[cur, j])
                    thr = np.float32(u[s, b, p] * total)
                    acc = np.float32(0.0)
                    nxt = 0
                    for j in range(n):
                        if avail[j]:
                            acc = np.float32(acc + weight[cur, j])
                            if acc > thr:
                                nxt = j
                                break
                    tours[s, b, p] = nxt
                    avail[nxt] = False
                    cur = base + nxt
                for j in range(n):
                    if avail[j]:
                        tours[n - 1, b, p] = j
                        break
                for j in range(n, L):
                    tours[j, b, p] = j
        return tours

    @njit(cache=True, nogil=True)
    def _path_length(D, row_nodes, local, n, start, end):  # pragma: no cover - compiled
        """Length of start → row_nodes[local[0]] → … → row_nodes[local[n-1]] → end, summed in order
        (pads after the n real positions would add D[end, end] = 0)."""
        prev = start
        total = 0.0
        for i in range(n):
            node = row_nodes[local[i]]
            total += D[prev, node]
            prev = node
        return total + D[prev, end]

    @njit(cache=True, nogil=True)
    def keyed_lengths(D, keys, nodes, sizes, start, end):  # pragma: no cover - compiled
        """(B, P) lengths of the tours decoded from keys (B, P, L) (real entries sorted by key)."""
        B, P, L = keys.shape
        out = np.empty((B, P))
        order = np.empty(L, dtype=np.int64)
        for b in range(B):
            n = sizes[b]
            for p in range(P):
                _sort_real(keys[b, p], n, order)
                out[b, p] = _path_length(D, nodes[b], order, n, start, end)
        return out

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

    @njit(cache=True, nogil=True)
    def _sort_real(keys, n, order):  # pragma: no cover - compiled
        """order[:n] = argsort(keys[:n]) by insertion sort (distinct keys: same as np.argsort)."""
        for i in range(n):
            k = keys[i]
            j = i
            while j > 0 and keys[order[j - 1]] > k:
                order[j] = order[j - 1]
                j -= 1
            order[j] = i

    @njit(cache=True, nogil=True)
    def best_two_opt_move(D, seq, n, start, end):  # pragma: no cover - compiled
        """Best 2-opt move on start → seq[:n] → end, as :func:`sarcover.heuristics.tour.best_two_opt_moves`
        scores it (same arithmetic, first maximum in the same pair order): (lo, hi, gain), with
        lo > hi and gain 0 when no move gains more than 1e-9."""
        best_g = -np.inf
        bi = 0
        bj = 0
        L = seq.shape[0]
        for i in range(L + 1):
            a = start if i == 0 else seq[i - 1]
            b = seq[i] if i < n else end
            for j in range(i + 2, L + 1):
                if j > n:
                    break
                c = seq[j - 1]
                d = seq[j] if j < n else end
                g = D[a, b] + D[c, d] - D[a, c] - D[b, d]
                if g > best_g:
                    best_g, bi, bj = g, i, j
        if best_g > 1e-9:
            return bi, bj - 1, best_g
        return 1, 0, 0.0

    @njit(cache=True, nogil=True)
    def pso_iterations(x, v, pbest, pbest_f, gbest, gbest_f, polished, R, n_iter, w, c1, c2,
                       v_max, D, nodes, sizes, start, end, local_search):  # pragma: no cover - compiled
        """``n_iter`` whole PSO iterations in place, R[t, 0] and R[t, 1] the r1, r2 (B, P, L) of
        iteration t: the move, decoding, fitness, personal and swarm bests, then one best 2-opt
        move on each swarm's global best written back as keys; the steps and arithmetic of
        :class:`sarcover.heuristics.routing_pso.PSORouter`'s numpy loop (path lengths are summed in another
        order, so exact ties between a tour and its reverse may break the other way)."""
        B, P, L = x.shape
        order = np.empty(L, dtype=np.int64)
        seq = np.empty(L, dtype=np.int64)
        srt = np.empty(L)
        for t in range(n_iter):
            for b in range(B):
                n = sizes[b]
                for p in range(P):
                    for i in range(n):  # pads keep their key and zero velocity
                        vi = w * v[b, p, i] + c1 * R[t, 0, b, p, i] * (pbest[b, p, i] - x[b, p, i]) \
                            + c2 * R[t, 1, b, p, i] * (gbest[b, i] - x[b, p, i])
                        if vi < -v_max:
                            vi = -v_max
                        elif vi > v_max:
                            vi = v_max
                        v[b, p, i] = vi
                        x[b, p, i] = x[b, p, i] + vi
                    _sort_real(x[b, p], n, order)
                    total = _path_length(D, nodes[b], order, n, start, end)
                    if total < pbest_f[b, p]:
                        pbest_f[b, p] = total
                        for i in range(n):
                            pbest[b, p, i] = x[b, p, i]
            all_polished = True
            for b in range(B):
                g = 0
                for p in range(1, P):
                    if pbest_f[b, p] < pbest_f[b, g]:
                        g = p
                if pbest_f[b, g] < gbest_f[b]:
                    gbest_f[b] = pbest_f[b, g]
                    for i in range(L):
                        gbest[b, i] = pbest[b, g, i]
                    polished[b] = False
                all_polished = all_polished and polished[b]
            if not local_search or all_polished:
                continue
            for b in range(B):
                n = sizes[b]
                _sort_real(gbest[b], n, order)
                for i in range(n):
                    seq[i] = nodes[b, order[i]]
                lo, hi, gain = best_two_opt_move(D, seq[:n], n, start, end)
                polished[b] = gain <= 0
                if gain > 0:
                    for i in range(n):
                        srt[i] = gbest[b, order[i]]
                    for i in range(lo, hi + 1):  # reverse the visiting order of lo..hi
                        gbest[b, order[lo + hi - i]] = srt[i]
                    gbest_f[b] = gbest_f[b] - gain

    @njit(cache=True, nogil=True)
    def aco_iterations(tau, log_eta, nodes, sizes, D, start, end, U, n_iter, first, alpha, rho,
                       elitist, best, best_f, polished, local_search):  # pragma: no cover - compiled
        """``n_iter`` colonies of the elitist ant system in place, as
        :class:`sarcover.heuristics.routing_aco.ACORouter`'s numpy loop does them on the same draws U[t]
        (L, B, P) float32: wheel weights from τ^α·η^β (float32), tour construction
        (:func:`construct_tours`), lengths, the best tour so far and its 2-opt move, τ set to
        P / L₀ after the ``first`` colony, evaporation and the deposits of every ant and the
        elitist best. States 0..L-1 are local positions, state L the start."""
        B, L1, L = tau.shape
        P = U.shape[3]
        weight = np.empty((B * L1, L), dtype=np.float32)
        logt = np.empty(L)
        f = np.empty((B, P))
        seq = np.empty(L, dtype=np.int64)
        deposit = np.empty((B, L1, L))
        shrink = np.float32(1.0 - 1e-6)
        for t in range(n_iter):
            for b in range(B):
                n = sizes[b]
                for s in range(L1):
                    if n <= s < L:  # a pad is never the current state
                        continue
                    m = -np.inf  # pads (log_eta -1e300) are never the row maximum
                    for j in range(n):
                        lw = alpha * np.log(tau[b, s, j]) + log_eta[b, s, j]
                        logt[j] = lw
                        if lw > m:
                            m = lw
                    for j in range(n):
                        wj = np.exp(logt[j] - m)
                        if wj < 1e-20:
                            wj = 1e-20
                        weight[b * L1 + s, j] = np.float32(wj)
                    for j in range(n, L):
                        weight[b * L1 + s, j] = np.float32(1e-30)
            u = U[t]
            for s in range(L):
                for b in range(B):
                    for p in range(P):
                        u[s, b, p] = u[s, b, p] * shrink
            tours = construct_tours(weight, u, sizes, B, P, L)  # (L, B, P) local positions
            for b in range(B):
                k = 0
                for p in range(P):
                    f[b, p] = _path_length(D, nodes[b], tours[:, b, p], sizes[b], start, end)
                    if f[b, p] < f[b, k]:
                        k = p
                if f[b, k] < best_f[b]:
                    best_f[b] = f[b, k]
                    for s in range(L):
                        best[b, s] = tours[s, b, k]
                    polished[b] = False
            if local_search:
                done = True
                for b in range(B):
                    done = done and polished[b]
                if not done:
                    for b in range(B):
                        n = sizes[b]
                        for i in range(n):
                            seq[i] = nodes[b, best[b, i]]
                        lo, hi, gain = best_two_opt_move(D, seq[:n], n, start, end)
                        if gain > 0:
                            for i in range(lo, hi + 1):
                                seq[i] = best[b, lo + hi - i]
                            for i in range(lo, hi + 1):
                                best[b, i] = seq[i]
                        best_f[b] = best_f[b] - gain
                        polished[b] = gain <= 0
            if first and t == 0:
                for b in range(B):
                    v0 = P / best_f[b]
                    for s in range(L1):
                        for j in range(L):
                            tau[b, s, j] = v0
            deposit[:] = 0.0
            for b in range(B):
                n = sizes[b]
                for p in range(P):
                    w = 1.0 / f[b, p]
                    prev = L
                    for s in range(L):
                        j = tours[s, b, p]
                        if j < n:
                            deposit[b, prev, j] += w
                        prev = j
            for b in range(B):
                n = sizes[b]
                w = elitist / best_f[b]
                prev = L
                for s in range(L):
                    j = best[b, s]
                    if j < n:
                        deposit[b, prev, j] += w
                    prev = j
            for b in range(B):
                for s in range(L1):
                    for j in range(L):
                        x = (1.0 - rho) * tau[b, s, j] + deposit[b, s, j]
                        tau[b, s, j] = x if x > 1e-300 else 1e-300

    @njit(cache=True, nogil=True)
    def ga_generation(pop, f, t, ra, rb, rc, rd, re, rm, p_crossover, p_mutation, E,
                      D, nodes, sizes, start, end):  # pragma: no cover - compiled
        """One GA generation from the draws of :class:`sarcover.heuristics.routing_ga.GARouter`'s numpy loop
        (tournaments ``t`` (B, 2C, 2), cut, crossover and mutation uniforms (B*C,)): the E best
        kept (stable order), parents by binary tournament, OX + inversion (:func:`ga_children`),
        children's lengths. Returns the new population and lengths."""
        B, P, L = pop.shape
        C = P - E
        new = np.empty_like(pop)
        nf = np.empty((B, P))
        taken = np.zeros(P, dtype=np.bool_)
        win = np.empty((B, 2 * C), dtype=np.int64)
        for b in range(B):
            taken[:] = False
            for e in range(E):  # the E smallest, ties to the first: np.argsort(kind="stable")[:E]
                k = -1
                for p in range(P):
                    if not taken[p] and (k < 0 or f[b, p] < f[b, k]):
                        k = p
                taken[k] = True
                nf[b, e] = f[b, k]
                for i in range(L):
                    new[b, e, i] = pop[b, k, i]
            for c in range(2 * C):
                x, y = t[b, c, 0], t[b, c, 1]
                win[b, c] = x if f[b, x] <= f[b, y] else y
        n_child = B * C
        lo1 = np.empty(n_child, dtype=np.int64)
        hi1 = np.empty(n_child, dtype=np.int64)
        lo2 = np.empty(n_child, dtype=np.int64)
        hi2 = np.empty(n_child, dtype=np.int64)
        cross = np.empty(n_child, dtype=np.bool_)
        mutate = np.empty(n_child, dtype=np.bool_)
        for b in range(B):
            for c in range(C):
                k = b * C + c
                n = sizes[b]
                a1, b1 = int(ra[k] * n), int(rb[k] * n)
                lo1[k], hi1[k] = min(a1, b1), max(a1, b1)
                cross[k] = rc[k] < p_crossover
                a2, b2 = int(rd[k] * n), int(re[k] * n)
                lo2[k], hi2[k] = min(a2, b2), max(a2, b2)
                mutate[k] = rm[k] < p_mutation
        child = ga_children(pop, win, lo1, hi1, cross, lo2, hi2, mutate)
        for b in range(B):
            for c in range(C):
                nf[b, E + c] = _path_length(D, nodes[b], child[b, c], sizes[b], start, end)
                for i in range(L):
                    new[b, E + c, i] = child[b, c, i]
        return new, nf
