"""Random SAR instances as in the paper's experiments: targets uniform in a 2000 m × 2000 m area."""

from __future__ import annotations

import numpy as np

from sarcover.formulations.errors import InstanceError
from sarcover.formulations.instance import SARInstance
from sarcover.formulations.limits import check_sar_size

AREA = 2000.0  # metres; targets uniform in [0, AREA]^2, base at the corner (0, 0)

# The paper leaves H, θ, E_F, E_I and E_max open. The "paper" preset is calibrated so that at
# M=20, N=5, K=3 coverage is neither trivially 100 % nor tiny, and so that two UAVs can still
# image every target in (nearly) every random instance, which the N = 2..6 sweep needs
# (README, "The paper preset").
PRESETS: dict[str, dict[str, float]] = {
    "paper": {
        "altitude": 800.0,  # H, metres
        "pitch_deg": 40.0,  # θ; stand-off H·cosθ ≈ 613 m, so a target's K views spread widely
        "e_fly": 1.0,  # E_F, energy units per metre (1 unit = 1 m of level flight)
        "e_image": 50.0,  # E_I per imaged viewpoint: a SAR pass costs as much as 50 m of flight
        "e_max": 6000.0,  # E_max per UAV
    },
}

def generate(
    n_targets: int,
    n_views: int,
    n_uavs: int,
    seed: int,
    preset: str = "paper",
    **overrides: float,
) -> SARInstance:
    """Draw M targets uniformly in the 2000 m square (seeded) and apply a parameter preset."""
    if preset not in PRESETS:
        raise InstanceError(f"unknown preset {preset!r}; known: {', '.join(PRESETS)}")
    if isinstance(n_targets, bool) or not isinstance(n_targets, (int, np.integer)) or n_targets < 1:
        raise InstanceError(f"targets must be an integer >= 1, got {n_targets!r}")
    for name, value, least in (("views", n_views, 1), ("uavs", n_uavs, 1), ("seed", seed, 0)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < least:
            raise InstanceError(f"{name} must be an integer >= {least}, got {value!r}")
    check_sar_size(n_targets, n_views, n_uavs)  # before drawing M targets
    params = dict(PRESETS[preset])
    for key, value in overrides.items():
        if key not in params:
            raise InstanceError(f"unknown parameter {key!r}; known: {', '.join(params)}")
        if value is not None:
            params[key] = value
    rng = np.random.default_rng(seed)
    targets = rng.uniform(0.0, AREA, size=(n_targets, 2))
    # A target exactly at the base has no first view; redraw (probability zero, kept for rigour).
    while np.any(np.linalg.norm(targets, axis=1) == 0.0):
        targets = rng.uniform(0.0, AREA, size=(n_targets, 2))
    return SARInstance(
        targets=targets,
        n_views=n_views,
        n_uavs=n_uavs,
        name=f"sar-m{n_targets}-k{n_views}-n{n_uavs}-s{seed}",
        **params,
    )
