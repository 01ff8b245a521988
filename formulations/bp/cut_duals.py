"""The subset-row cuts' duals as the labelling kernels pay them: bitsets of the cuts at each
point, and a byte table that sums the duals over a bitset of cuts in eight look-ups."""

from __future__ import annotations

import numpy as np
from numba import njit

ALL_CUTS = np.uint64(0xFFFFFFFFFFFFFFFF)  # a memory that holds every cut


@njit(cache=True)
def sigsum(bits, sig):
    """Sum of the cut duals over the set bits of ``bits``; ``sig[k, b]`` is the sum over the
    bits of byte value b in byte k (eight look-ups instead of a loop over 64 bits)."""
    s = 0.0
    for k in range(8):
        b = (bits >> np.uint64(8 * k)) & np.uint64(255)
        if b:
            s += sig[k, b]
    return s


def byte_sums(duals: np.ndarray) -> np.ndarray:
    """(8, 256) table for :func:`sigsum` from up to 64 cut duals."""
    d = np.zeros(64)
    d[: duals.size] = duals
    bits = (np.arange(256)[:, None] >> np.arange(8)[None, :]) & 1  # (256, 8)
    return np.ascontiguousarray(d.reshape(8, 8) @ bits.T)


def cut_arrays(n: int, cut_members, cut_memory, cut_duals):
    """The kernels' cut arguments ``(cmem, mmem, sig)`` on ``n`` points: ``cmem[w]`` the bitset
    of the cuts whose triple holds w, ``mmem[w]`` of those whose memory holds it (``cut_memory``
    None: every cut remembers every point), ``sig`` the byte sums of the duals. Only cuts with a
    positive dual change a path's value: the others are left out, so their parities neither
    split labels nor cost dominance tests. No cuts (or none with a positive dual): all zero."""
    if cut_members is None or cut_duals is None or not np.any(np.asarray(cut_duals) > 0):
        return np.zeros(n, np.uint64), np.zeros(n, np.uint64), np.zeros((8, 256))
    duals = np.asarray(cut_duals, dtype=np.float64)
    active = np.uint64(0)
    for c in np.flatnonzero(duals > 0):
        active |= np.uint64(1) << np.uint64(c)
    cmem = np.ascontiguousarray(np.asarray(cut_members, dtype=np.uint64) & active)
    mmem = (np.full(n, ALL_CUTS, dtype=np.uint64) if cut_memory is None
            else np.ascontiguousarray(cut_memory, dtype=np.uint64))
    return cmem, mmem, byte_sums(np.where(duals > 0, duals, 0.0))
