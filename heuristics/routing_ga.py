"""Genetic algorithm for the order of each cluster's tour (permutation encoding).

An individual is a permutation of the cluster's local positions. Each generation keeps the
``n_elite`` best unchanged (elitism), picks parents by binary tournament, recombines them with
order crossover (OX: the child copies a random slice of parent 1 in place and fills the other
positions left to right with the missing viewpoints in parent 2's order) with probability
``p_crossover``, and mutates a child with probability ``p_mutation`` by inverting a random slice
(the 2-opt move, the usual permutation mutation for tours). Fitness is the flight distance.

Like the PSO, all clusters run in one (B, P, L) batch: a row's pads sit in the tail positions of
every individual and stay there (cuts and inversions are drawn inside the real positions), so
no per-individual Python loop is needed; OX is done for the whole batch with two scatters.
With numba (default when importable) a whole generation (elitism, tournaments, OX, inversion,
fitness) runs in the compiled :func:`sarcover.heuristics.kernels.ga_generation` on the same draws as the
numpy generation; only the draws stay in Python (the same children, but for ties between
lengths summed in another order).
"""

from __future__ import annotations

import time

import numpy as np

from sarcover.heuristics.kernels import HAVE_NUMBA
from sarcover.heuristics.tour import ClusterBatch, invert

if HAVE_NUMBA:
    from sarcover.heuristics.kernels import ga_generation


def order_crossover(p1: np.ndarray, p2: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Row-wise OX of permutations p1, p2 (R, L) keeping p1[lo:hi+1] (inclusive) in place."""
    idx = np.arange(p1.shape[1])[None, :]
    seg = (idx >= lo[:, None]) & (idx <= hi[:, None])
    member = np.zeros(p1.shape, dtype=bool)  # member[r, v]: value v is in p1's slice
    np.put_along_axis(member, p1, seg, axis=1)
    keep = ~np.take_along_axis(member, p2, axis=1)
    child = p1.copy()
    child[~seg] = p2[keep]  # row-major order: row r gets its own L - |slice| values, in order
    return child


def _cuts(rng, sizes: np.ndarray):
    """Two sorted random cut positions inside each row's real part (inclusive slice)."""
    a = (rng.random(sizes.shape) * sizes).astype(int)
    b = (rng.random(sizes.shape) * sizes).astype(int)
    return np.minimum(a, b), np.maximum(a, b)


class GARouter:
    """Elitist GA with OX and inversion mutation (population ``n_population``)."""

    name = "ga"

    def __init__(
        self,
        n_population: int = 30,
        n_iterations: int = 100,
        *,
        p_crossover: float = 0.9,
        p_mutation: float = 0.3,
        n_elite: int = 2,
        use_numba: bool | None = None,
    ):
        self.use_numba = HAVE_NUMBA if use_numba is None else bool(use_numba and HAVE_NUMBA)
        self.n_population = n_population
        self.n_iterations = n_iterations
        self.p_crossover = p_crossover
        self.p_mutation = p_mutation
        self.n_elite = n_elite

    def solve(self, D: np.ndarray, batch: ClusterBatch, rng: np.random.Generator, deadline=None):
        """Best local order (B, L) per cluster row and its length (B,); pads at the tail."""
        B, L = batch.nodes.shape
        P, E = self.n_population, min(self.n_elite, self.n_population - 1)
        C = P - E  # children per generation
        pad = batch.pad[:, None, :]
        pop = np.argsort(np.where(pad, np.inf, rng.random((B, P, L))), axis=-1)
        f = batch.lengths(D, pop)
        rows = np.arange(B)[:, None]
        sizes = np.repeat(batch.sizes, C)  # one entry per child, row-major (B, C)
        if self.use_numba:
            nodes = np.ascontiguousarray(batch.nodes)
            bsizes = np.ascontiguousarray(batch.sizes)
            Dc = np.ascontiguousarray(D, dtype=float)
        for _ in range(self.n_iterations):
            if deadline is not None and time.perf_counter() > deadline:
                break
            if self.use_numba:  # the same draws, in the same order, as the numpy generation below
                t = rng.integers(0, P, size=(B, 2 * C, 2))
                ra, rb, rc = rng.random(B * C), rng.random(B * C), rng.random(B * C)
                rd, re, rm = rng.random(B * C), rng.random(B * C), rng.random(B * C)
                pop, f = ga_generation(pop, f, t, ra, rb, rc, rd, re, rm, self.p_crossover,
                                       self.p_mutation, E, Dc, nodes, bsizes, batch.start, batch.end)
                continue
            rank = np.argsort(f, axis=1, kind="stable")
            elite = pop[rows, rank[:, :E]]
            elite_f = f[rows, rank[:, :E]]
            t = rng.integers(0, P, size=(B, 2 * C, 2))  # binary tournaments
            win = np.where(f[rows, t[..., 0]] <= f[rows, t[..., 1]], t[..., 0], t[..., 1])
            lo1, hi1 = _cuts(rng, sizes)
            cross = rng.random(B * C) < self.p_crossover
            lo2, hi2 = _cuts(rng, sizes)
            mutate = rng.random(B * C) < self.p_mutation
            p1 = pop[rows, win[:, :C]].reshape(B * C, L)
            p2 = pop[rows, win[:, C:]].reshape(B * C, L)
            child = np.where(cross[:, None], order_crossover(p1, p2, lo1, hi1), p1)
            child = invert(child, np.where(mutate, lo2, 1), np.where(mutate, hi2, 0))
            child = child.reshape(B, C, L)
            pop = np.concatenate([elite, child], axis=1)
            f = np.concatenate([elite_f, batch.lengths(D, child)], axis=1)
        best = np.argmin(f, axis=1)
        return pop[np.arange(B), best], f[np.arange(B), best]
