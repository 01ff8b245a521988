"""Shared tour helpers: batched path lengths, padded batches of clusters, and 2-opt.

All indices here are SOLVER indices of a :class:`~sarcover.formulations.instance.TOPInstance` distance
or cost matrix: 0 = start, 1..V = nodes, V+1 = end. A tour is the path start → nodes → end.

The routers solve several clusters at once. :class:`ClusterBatch` stacks the clusters into one
``(B, L)`` array padded with the end index; a padded sequence keeps its pads at the tail, so its
length is ``path_lengths`` with ``D[end, end] = 0`` absorbing the pads.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np


def path_lengths(D: np.ndarray, seqs: np.ndarray, start: int, end: int) -> np.ndarray:
    """Lengths of the paths start → seqs[..., 0] → … → seqs[..., -1] → end, vectorised.

    ``seqs`` has shape (..., L) of solver indices; trailing entries equal to ``end`` are padding
    and add nothing since ``D[end, end] == 0``.
    """
    n = D.shape[1]
    flat = D.ravel()
    inner = flat.take(seqs[..., :-1] * n + seqs[..., 1:]).sum(axis=-1)
    return D[start].take(seqs[..., 0]) + inner + D[:, end].take(seqs[..., -1])


def route_length(D: np.ndarray, route, start: int, end: int) -> float:
    """Length (or energy, given a cost matrix) of one route; an empty route costs 0."""
    route = np.asarray(route, dtype=int)
    if route.size == 0:
        return 0.0
    return float(path_lengths(D, route, start, end))


@dataclass(frozen=True)
class ClusterBatch:
    """Clusters of at least two nodes stacked for batched routing.

    nodes: (B, L) solver indices, row b holds cluster ``which[b]`` then ``end`` padding.
    sizes: (B,) real nodes per row. which: (B,) position of each row in the caller's list.
    """

    nodes: np.ndarray
    sizes: np.ndarray
    which: np.ndarray
    start: int
    end: int

    @classmethod
    def of(cls, clusters: list[np.ndarray], start: int, end: int) -> "ClusterBatch":
        which = np.array([i for i, c in enumerate(clusters) if len(c) >= 2], dtype=int)
        sizes = np.array([len(clusters[i]) for i in which], dtype=int)
        width = int(sizes.max()) if sizes.size else 0
        nodes = np.full((which.size, width), end, dtype=int)
        for row, i in enumerate(which):
            nodes[row, : sizes[row]] = clusters[i]
        return cls(nodes, sizes, which, start, end)

    @property
    def pad(self) -> np.ndarray:
        """(B, L) True where a row is padding."""
        return np.arange(self.nodes.shape[1])[None, :] >= self.sizes[:, None]

    def to_global(self, local: np.ndarray) -> np.ndarray:
        """Map local positions (B, P, L) (values 0..L-1, pads last) to solver indices."""
        B, L = self.nodes.shape
        offset = (np.arange(B) * L).reshape((B,) + (1,) * (local.ndim - 1))
        return self.nodes.ravel().take(local + offset)

    def lengths(self, D: np.ndarray, local: np.ndarray) -> np.ndarray:
        """(B, P) path lengths of local orders (B, P, L) whose pads are at the tail."""
        return path_lengths(D, self.to_global(local), self.start, self.end)

    def routes(self, clusters: list[np.ndarray], best_local: np.ndarray) -> list[np.ndarray]:
        """Per input cluster, its order as solver indices (trivial clusters as given)."""
        out = [np.asarray(c, dtype=int) for c in clusters]
        for row, i in enumerate(self.which):
            n = self.sizes[row]
            order = best_local[row, :n]
            if not np.array_equal(np.sort(order), np.arange(n)):  # a router bug, never silent
                raise RuntimeError(f"router returned an invalid order for cluster {i}")
            out[i] = self.nodes[row, order]
        return out


@lru_cache(maxsize=256)
def _pairs(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Index pairs (i, j), j >= i + 2, of the edges 0..n-1 of a path (read-only arrays)."""
    i, j = np.triu_indices(n, k=2)
    i.setflags(write=False)
    j.setflags(write=False)
    return i, j


def invert(perm: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Reverse perm[r, lo[r]:hi[r]+1] in every row (lo > hi leaves the row unchanged)."""
    idx = np.arange(perm.shape[1])[None, :]
    inside = (idx >= lo[:, None]) & (idx <= hi[:, None])
    src = np.where(inside, lo[:, None] + hi[:, None] - idx, idx)
    return np.take_along_axis(perm, src, axis=1)


def best_two_opt_moves(D: np.ndarray, seqs: np.ndarray, sizes: np.ndarray, start: int, end: int):
    """Best 2-opt move of each padded row of ``seqs`` (R, L), vectorised over rows.

    Returns (lo, hi, gain): reversing ``seqs[r, lo:hi+1]`` shortens row r by ``gain[r]`` (≤ 0
    means no improving move; then lo > hi so :func:`invert` leaves the row as is).
    """
    R, L = seqs.shape
    full = np.concatenate([np.full((R, 1), start), seqs, np.full((R, 1), end)], axis=1)
    i, j = _pairs(L + 1)  # edge i = (full[i], full[i+1])
    a, b, c, d = full[:, i], full[:, i + 1], full[:, j], full[:, j + 1]
    gain = D[a, b] + D[c, d] - D[a, c] - D[b, d]
    gain = np.where(j[None, :] <= sizes[:, None], gain, -np.inf)  # stay inside the real part
    k = np.argmax(gain, axis=1)
    g = gain[np.arange(R), k]
    ok = g > 1e-9
    return np.where(ok, i[k], 1), np.where(ok, j[k] - 1, 0), np.where(ok, g, 0.0)


def two_opt(D: np.ndarray, route, start: int, end: int, max_moves: int = 1000) -> np.ndarray:
    """Best-improvement 2-opt on the path start → route → end (D symmetric).

    Each pass scores every segment reversal at once with numpy and applies the best improving
    one, until none improves by more than 1e-9 (a 2-opt local optimum) or ``max_moves``.
    """
    route = np.asarray(route, dtype=int)
    n = route.size
    if n < 2:
        return route
    seq = np.concatenate(([start], route, [end]))
    i, j = _pairs(n + 1)  # edges (seq[i], seq[i+1]) and (seq[j], seq[j+1])
    for _ in range(max_moves):
        a, b, c, d = seq[i], seq[i + 1], seq[j], seq[j + 1]
        delta = D[a, c] + D[b, d] - D[a, b] - D[c, d]
        k = int(np.argmin(delta))
        if delta[k] >= -1e-9:
            break
        lo, hi = i[k] + 1, j[k]
        seq[lo : hi + 1] = seq[lo : hi + 1][::-1].copy()
    return seq[1:-1].copy()
