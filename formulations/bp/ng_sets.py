"""ng sets: the points each point remembers. A label's remembered set is intersected with
``ng[w]`` on arrival at w, so a route may revisit a point it has forgotten (an ng-route): a
relaxation of the elementary routes whose labelling stays fast. ``ng[w]`` is a bitset of ``W``
64-bit words; all points for every point is the exact elementary labelling.
"""

from __future__ import annotations

import numpy as np


def n_words(n_points: int) -> int:
    """64-bit words of a set of ``n_points`` points."""
    return (n_points + 63) // 64


def full_ng(n_points: int) -> np.ndarray:
    """ng sets equal to all nodes: exact elementary labelling."""
    return np.full((n_points, n_words(n_points)), np.uint64(0xFFFFFFFFFFFFFFFF), dtype=np.uint64)


def nearest_ng(cost: np.ndarray, size: int) -> np.ndarray:
    """ng[w] = w and its ``size - 1`` cheapest neighbours (by symmetric arc cost)."""
    n = cost.shape[0]
    ng = np.zeros((n, n_words(n)), dtype=np.uint64)
    sym = np.minimum(cost, cost.T)
    for w in range(1, n - 1):
        d = sym[w, 1 : n - 1].copy()
        d[w - 1] = -1.0
        for u in np.argsort(d, kind="stable")[:size] + 1:
            add_to_ng(ng, w, int(u))
    return ng


def add_to_ng(ng: np.ndarray, w: int, u: int) -> None:
    """Remember ``u`` at ``w``."""
    ng[w, u >> 6] |= np.uint64(1) << np.uint64(u & 63)
