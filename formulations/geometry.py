"""Viewpoint geometry of the paper: K views per target around a circle of radius H·cos(θ)."""

from __future__ import annotations

import numpy as np

from sarcover.formulations.errors import InstanceError


def standoff(altitude: float, pitch_deg: float) -> float:
    """Horizontal distance between a target and each of its viewpoints: H·cos(θ)."""
    return float(altitude * np.cos(np.radians(pitch_deg)))


def viewpoints(targets: np.ndarray, n_views: int, altitude: float, pitch_deg: float) -> np.ndarray:
    """Return the (M·K, 2) viewpoints, target-major: row m·K + k is view k of target m.

    View 0 of target t is ``(1 - H·cosθ/‖t‖)·t``: on the base–target line, H·cosθ from the
    target toward the base at the origin. View k is view 0 rotated about t by k·360°/K.
    """
    targets = np.asarray(targets, dtype=float).reshape(-1, 2)
    norms = np.linalg.norm(targets, axis=1)
    if np.any(norms == 0.0):
        m = int(np.flatnonzero(norms == 0.0)[0])
        raise InstanceError(f"target {m} lies at the base (0, 0): its first viewpoint is undefined")
    r = standoff(altitude, pitch_deg)
    first = (1.0 - r / norms)[:, None] * targets  # (M, 2)
    offset = first - targets  # vector from target to its first view
    angles = 2.0 * np.pi * np.arange(n_views) / n_views  # (K,)
    cos, sin = np.cos(angles), np.sin(angles)
    rot_x = offset[:, None, 0] * cos - offset[:, None, 1] * sin  # (M, K)
    rot_y = offset[:, None, 0] * sin + offset[:, None, 1] * cos
    views = np.stack([targets[:, None, 0] + rot_x, targets[:, None, 1] + rot_y], axis=-1)
    return views.reshape(-1, 2)
