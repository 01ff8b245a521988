"""Random-key particle swarm optimisation for the order of each cluster's tour.

Encoding (Bean 1994 random keys): a particle is a real vector with one key per viewpoint of the
cluster; the tour visits the viewpoints in increasing key order (``argsort``). Keys move with the
standard inertia-weight PSO update (Shi & Eberhart; constriction-equivalent w = 0.7298,
c1 = c2 = 1.49618), velocities clamped to ±``v_max``. Fitness is the flight distance
start → cluster → end.

Every cluster of the plan is solved in ONE numpy batch: the swarm is an array (B, P, L) for B
clusters, P particles and L the largest cluster size; pads get key +inf so they decode to the
tail, where they stand for the end point and add no length. No Python loop runs over particles or
clusters in the hot path; one iteration is a dozen numpy calls on the whole batch.

Plain random-key PSO stagnates on tours (on an 11-point convex polygon it found the optimal
tour in about 1 run of 2 with any of w ∈ {0.5, 0.73, 0.9}, c ∈ {1, 1.5, 2}, v_max ∈ {0.1..1}),
so by default (``local_search=True``) each iteration also applies the best 2-opt move to each
swarm's global best and writes the improved order back as keys (a memetic PSO: the swarm is
then attracted to a 2-opt-improved leader). This costs one (B, L²/2) array per iteration.

With numba (default when importable) whole iterations run compiled
(:func:`sarcover.heuristics.kernels.pso_iterations`: move, decoding, fitness, bests and the 2-opt move),
20 at a time between deadline checks, on r1, r2 drawn by numpy in the same stream as the numpy
loop (``use_numba=False``). Both paths give the same tours on the same seed except where a tour
and its reverse tie exactly in length (their sums run in another order); drawing the random
numbers is then about half of the PSO's time.
"""

from __future__ import annotations

import time

import numpy as np

from sarcover.heuristics.kernels import HAVE_NUMBA
from sarcover.heuristics.tour import ClusterBatch, best_two_opt_moves, invert

if HAVE_NUMBA:
    from sarcover.heuristics.kernels import keyed_lengths, pso_iterations


_PAD_KEY = 1e6
_CHUNK = 20  # compiled iterations between two deadline checks


class PSORouter:
    """Random-key PSO (population ``n_particles``, ``n_iterations`` iterations)."""

    name = "pso"

    def __init__(
        self,
        n_particles: int = 30,
        n_iterations: int = 100,
        *,
        w: float = 0.7298,
        c1: float = 1.49618,
        c2: float = 1.49618,
        v_max: float = 1.0,
        local_search: bool = True,
        use_numba: bool | None = None,
    ):
        self.use_numba = HAVE_NUMBA if use_numba is None else bool(use_numba and HAVE_NUMBA)
        self.n_particles = n_particles
        self.n_iterations = n_iterations
        self.w, self.c1, self.c2, self.v_max = w, c1, c2, v_max
        self.local_search = local_search

    def solve(self, D: np.ndarray, batch: ClusterBatch, rng: np.random.Generator, deadline=None):
        """Best local order (B, L) per cluster row and its length (B,); pads at the tail."""
        B, L = batch.nodes.shape
        P = self.n_particles
        pad = batch.pad[:, None, :]  # (B, 1, L)
        # pads hold a constant key far above the real ones and zero velocity; the update keeps
        # them there (their pbest and gbest keys are the same constant), so they decode last
        x = np.where(pad, _PAD_KEY, rng.random((B, P, L)))
        v = np.where(pad, 0.0, rng.uniform(-self.v_max, self.v_max, (B, P, L)))
        rows = np.arange(B)

        if self.use_numba:  # decode + lengths in one compiled call (sarcover.heuristics.kernels)
            nodes, sizes = np.ascontiguousarray(batch.nodes), np.ascontiguousarray(batch.sizes)
            Dc = np.ascontiguousarray(D, dtype=float)

            def evaluate(keys):
                return keyed_lengths(Dc, keys, nodes, sizes, batch.start, batch.end)
        else:
            def evaluate(keys):
                return batch.lengths(D, np.argsort(keys, axis=-1))

        f = evaluate(x)
        pbest, pbest_f = x.copy(), f
        g = np.argmin(f, axis=1)
        gbest, gbest_f = x[rows, g], f[rows, g]
        polished = np.zeros(B, dtype=bool)  # gbest is 2-opt optimal and unchanged since
        if self.use_numba:  # whole iterations compiled, CHUNK at a time between deadline checks
            gbest, gbest_f = np.ascontiguousarray(gbest), np.ascontiguousarray(gbest_f)
            done = 0
            R = np.empty((min(_CHUNK, self.n_iterations), 2, B, P, L))
            while done < self.n_iterations:
                if deadline is not None and time.perf_counter() > deadline:
                    break
                n = min(_CHUNK, self.n_iterations - done)
                rng.random(out=R[:n])  # the same stream as r1, r2 drawn per iteration
                pso_iterations(x, v, pbest, pbest_f, gbest, gbest_f, polished, R, n, self.w, self.c1,
                               self.c2, self.v_max, Dc, nodes, sizes, batch.start, batch.end,
                               self.local_search)
                done += n
            return np.argsort(gbest, axis=-1), gbest_f
        for _ in range(self.n_iterations):
            if deadline is not None and time.perf_counter() > deadline:
                break
            r1 = rng.random((B, P, L))
            r2 = rng.random((B, P, L))
            x, v, pbest, pbest_f = self._move(x, v, pbest, pbest_f, gbest, r1, r2, evaluate)
            g = np.argmin(pbest_f, axis=1)
            improved = pbest_f[rows, g] < gbest_f
            gbest = np.where(improved[:, None], pbest[rows, g], gbest)
            gbest_f = np.minimum(pbest_f[rows, g], gbest_f)
            polished &= ~improved
            if self.local_search and not polished.all():
                gbest, gbest_f, gain = self._improve(D, batch, gbest, gbest_f)
                polished = gain <= 0
        best = np.argsort(gbest, axis=-1)
        return best, gbest_f

    def _move(self, x, v, pbest, pbest_f, gbest, r1, r2, evaluate):
        """One PSO move, fitness and personal bests in numpy (compiled:
        :func:`sarcover.heuristics.kernels.pso_iterations`)."""
        v = self.w * v + self.c1 * r1 * (pbest - x) + self.c2 * r2 * (gbest[:, None, :] - x)
        np.clip(v, -self.v_max, self.v_max, out=v)
        x = x + v
        f = evaluate(x)
        better = f < pbest_f
        pbest = np.where(better[..., None], x, pbest)
        pbest_f = np.where(better, f, pbest_f)
        return x, v, pbest, pbest_f

    @staticmethod
    def _improve(D, batch: ClusterBatch, gbest: np.ndarray, gbest_f: np.ndarray):
        """One best-improvement 2-opt move on each swarm's global best, written back as keys."""
        order = np.argsort(gbest, axis=-1)
        seqs = batch.to_global(order)
        lo, hi, gain = best_two_opt_moves(D, seqs, batch.sizes, batch.start, batch.end)
        if not (gain > 0).any():
            return gbest, gbest_f, gain
        order = invert(order, lo, hi)
        keys = np.empty_like(gbest)
        np.put_along_axis(keys, order, np.sort(gbest, axis=-1), axis=-1)
        return keys, gbest_f - gain, gain
