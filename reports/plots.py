"""Plot functions. Each takes ``ax=None``, draws, and neither shows nor saves."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from formulations.instance import TOPInstance  # noqa: E402
from formulations.plan import Plan  # noqa: E402


def plot_plan(instance: TOPInstance, plan: Plan | None, ax=None, title: str | None = None):
    """The paper's Fig. 2: base, targets, viewpoints (covered filled, missed hollow), routes."""
    if ax is None:
        _, ax = plt.subplots(figsize=(7, 7))
    visited = set(plan.visited) if plan is not None else set()
    mask = np.array([i in visited for i in range(instance.n_nodes)], dtype=bool)
    pts = instance.coords
    ax.scatter(pts[~mask, 0], pts[~mask, 1], s=22, facecolors="none", edgecolors="0.45",
               linewidths=0.8, label="viewpoint (missed)", zorder=3)
    ax.scatter(pts[mask, 0], pts[mask, 1], s=22, c="0.15", label="viewpoint (covered)", zorder=3)
    if instance.targets is not None:
        ax.scatter(instance.targets[:, 0], instance.targets[:, 1], marker="x", c="tab:red",
                   s=30, label="target", zorder=4)
    ax.scatter(*instance.start, marker="s", c="k", s=70, label="base", zorder=5)
    if not instance.same_depot:
        ax.scatter(*instance.end, marker="D", c="k", s=60, label="end depot", zorder=5)
    colors = plt.get_cmap("tab10")
    if plan is not None:
        for r, route in enumerate(plan.routes):
            if not route:
                continue
            path = np.vstack([instance.start, pts[list(route)], instance.end])
            ax.plot(path[:, 0], path[:, 1], "-", color=colors(r % 10), lw=1.4,
                    label=f"UAV {r + 1}", zorder=2)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)" if instance.kind == "sar" else "x")
    ax.set_ylabel("y (m)" if instance.kind == "sar" else "y")
    if title:
        ax.set_title(title)
    ax.legend(loc="best", fontsize=7, framealpha=0.8)
    return ax
