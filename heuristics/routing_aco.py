"""Ant system (Dorigo, Maniezzo & Colorni 1996) with an elitist ant, for each cluster's tour order.

Each ant builds a tour from the start: at every step it moves to an unvisited viewpoint j with
probability ∝ τ_ij^α·η_ij^β, η = 1/distance. After all ants are built, pheromone evaporates,
τ ← (1-ρ)·τ, and every ant deposits 1/length on its arcs; the best tour so far deposits an extra
``elitist``/length (Dorigo's elitist ant system). τ starts uniform at P / L₀, L₀ the best length of
the first colony, so deposits and τ are on one scale. The return arc to the end point is fixed
and carries no pheromone. As Dorigo & Stützle recommend for the TSP, by default
(``local_search=True``) each colony also applies the best 2-opt move to the best tour so far,
which then deposits as the elitist ant (without it the ant system found the optimum of a random
10-point convex polygon in 27 of 30 runs, for any β ∈ {2, 3, 5}, ρ ∈ {0.1, 0.3, 0.5}).

Vectorised over ants and clusters at once: the colony is (B, P) ants, a step draws every ant's
next viewpoint by a roulette wheel (a cumulative sum over the candidates and one uniform draw per
ant), and deposits use one ``np.bincount``; the only Python loop is over the L construction
steps. With numba (default when importable) whole colonies run compiled
(:func:`sarcover.heuristics.kernels.aco_iterations`), 20 at a time between deadline checks, on uniforms
drawn by numpy in the same stream: the same tours as the numpy loop but for exact length ties
(a tour and its reverse when start = end), which the two paths' sums may break differently.
"""

from __future__ import annotations

import time

import numpy as np

from sarcover.heuristics.kernels import HAVE_NUMBA
from sarcover.heuristics.tour import ClusterBatch, best_two_opt_moves, invert

if HAVE_NUMBA:
    from sarcover.heuristics.kernels import aco_iterations

_PAD = -1e300
# Weight of a pad: absorbed in the wheel's total (≥ 1e-20 while real viewpoints remain, since
# the weights are normalised per row and floored), so a pad is drawn only once a row's viewpoints are done.
# Real weights are floored at 1e-20 (float32 keeps them apart from pads) before normalisation.
_PAD_WEIGHT = 1e-30  # normal in float32 (subnormals are slow), absorbed next to 1e-20
_MIN_WEIGHT = 1e-20
_CHUNK = 20  # compiled colonies between two deadline checks


class ACORouter:
    """Elitist ant system: ``n_ants`` ants, ``n_iterations`` colonies."""

    name = "aco"

    def __init__(
        self,
        n_ants: int = 30,
        n_iterations: int = 100,
        *,
        alpha: float = 1.0,
        beta: float = 3.0,
        rho: float = 0.5,
        elitist: float = 5.0,
        local_search: bool = True,
        use_numba: bool | None = None,
    ):
        self.use_numba = HAVE_NUMBA if use_numba is None else bool(use_numba and HAVE_NUMBA)
        self.n_ants = n_ants
        self.n_iterations = n_iterations
        self.alpha, self.beta, self.rho, self.elitist = alpha, beta, rho, elitist
        self.local_search = local_search

    def solve(self, D: np.ndarray, batch: ClusterBatch, rng: np.random.Generator, deadline=None):
        """Best local order (B, L) per cluster row and its length (B,); pads at the tail."""
        B, L = batch.nodes.shape
        P = self.n_ants
        pad = batch.pad  # (B, L)
        # state L is the start; states 0..L-1 are local positions
        src = np.concatenate([batch.nodes, np.full((B, 1), batch.start)], axis=1)  # (B, L+1)
        dist = D[src[:, :, None], batch.nodes[:, None, :]]  # (B, L+1, L)
        log_eta = -self.beta * np.log(np.maximum(dist, 1e-9))
        log_eta = np.where(pad[:, None, :], _PAD, log_eta)
        tau = np.ones((B, L + 1, L))
        row_state = (np.arange(B) * (L + 1))[:, None]  # row of (b, state) in weight
        ant_base = (np.arange(B * P) * L).reshape(B, P)
        pad3 = np.broadcast_to(pad[:, None, :], (B, L + 1, L))
        flat_base = (np.arange(B) * (L + 1) * L)[:, None, None]
        best_f = np.full(B, np.inf)
        best = np.tile(np.arange(L), (B, 1))
        polished = np.zeros(B, dtype=bool)  # best tour is 2-opt optimal and unchanged since
        if self.use_numba:  # whole colonies compiled, _CHUNK at a time between deadline checks
            nodes, sizes = np.ascontiguousarray(batch.nodes), np.ascontiguousarray(batch.sizes)
            Dc, log_eta = np.ascontiguousarray(D, dtype=float), np.ascontiguousarray(log_eta)
            U = np.empty((min(_CHUNK, self.n_iterations), L, B, P), dtype=np.float32)
            done = 0
            while done < self.n_iterations:
                if deadline is not None and time.perf_counter() > deadline:
                    break
                n = min(_CHUNK, self.n_iterations - done)
                rng.random(out=U[:n], dtype=np.float32)  # the same stream as per-colony draws
                aco_iterations(tau, log_eta, nodes, sizes, Dc, batch.start, batch.end, U, n, done == 0,
                               self.alpha, self.rho, self.elitist, best, best_f, polished,
                               self.local_search)
                done += n
            return best, best_f
        for it in range(self.n_iterations):
            if deadline is not None and time.perf_counter() > deadline:
                break
            logw = self.alpha * np.log(tau) + log_eta  # (B, L+1, L), pads -1e300
            weight = np.maximum(np.exp(logw - logw.max(axis=-1, keepdims=True)), _MIN_WEIGHT)
            weight[pad3] = _PAD_WEIGHT
            weight = weight.astype(np.float32).reshape(B * (L + 1), L)
            u = rng.random((L, B, P), dtype=np.float32) * np.float32(1.0 - 1e-6)  # r < total
            avail = np.ones(B * P * L, dtype=np.float32)
            cur = np.full((B, P), L) + row_state
            tours = np.empty((L, B, P), dtype=int)
            for s in range(L - 1):
                w = np.take(weight, cur, axis=0)
                w *= avail.reshape(B, P, L)
                np.cumsum(w, axis=-1, out=w)  # roulette wheel over the unvisited
                nxt = np.argmax(w > (u[s] * w[..., -1])[..., None], axis=-1)
                tours[s] = nxt
                avail[ant_base + nxt] = 0.0
                cur = row_state + nxt
            tours[L - 1] = np.argmax(avail.reshape(B, P, L), axis=-1)  # the one left
            tours = tours.transpose(1, 2, 0)
            f = batch.lengths(D, tours)
            k = np.argmin(f, axis=1)
            fk = f[np.arange(B), k]
            improved = fk < best_f
            best = np.where(improved[:, None], tours[np.arange(B), k], best)
            best_f = np.minimum(fk, best_f)
            polished &= ~improved
            if self.local_search and not polished.all():
                seqs = batch.to_global(best)
                lo, hi, gain = best_two_opt_moves(D, seqs, batch.sizes, batch.start, batch.end)
                best, best_f, polished = invert(best, lo, hi), best_f - gain, gain <= 0
            if it == 0:
                tau = np.broadcast_to((P / best_f)[:, None, None], tau.shape).copy()
            prev = np.concatenate([np.full((B, P, 1), L), tours[:, :, :-1]], axis=-1)
            real = ~np.take_along_axis(np.broadcast_to(pad[:, None, :], tours.shape), tours, -1)
            idx = flat_base + prev * L + tours  # (B, P, L)
            w = np.broadcast_to((1.0 / f)[..., None], idx.shape)
            bprev = np.concatenate([np.full((B, 1), L), best[:, :-1]], axis=-1)
            bidx = (np.arange(B) * (L + 1) * L)[:, None] + bprev * L + best
            breal = ~np.take_along_axis(pad, best, -1)
            bw = np.broadcast_to((self.elitist / best_f)[:, None], bidx.shape)
            deposit = np.bincount(
                np.concatenate([idx[real], bidx[breal]]),
                weights=np.concatenate([w[real], bw[breal]]),
                minlength=B * (L + 1) * L,
            ).reshape(B, L + 1, L)
            tau = (1.0 - self.rho) * tau + deposit
            np.maximum(tau, 1e-300, out=tau)
        return best, best_f
