"""Plot functions. Each takes ``ax=None``, draws, and neither shows nor saves. Methods keep the
look :mod:`sarcover.reports.style` gives them; legends sit outside the data.

No module of :mod:`sarcover.reports` chooses a matplotlib backend: with ``ax=None`` a plot
function opens a pyplot figure in the caller's backend (a notebook's inline one, say), and the
report writers draw on :func:`subplots` figures, which no backend manages and which save to files
anywhere, a machine without a display included. The command line chooses Agg for itself.
"""

from __future__ import annotations

import matplotlib
import numpy as np
from matplotlib.figure import Figure

from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan
from sarcover.reports.style import look


def subplots(nrows: int = 1, ncols: int = 1, *, figsize=None, **kwargs):
    """``(fig, axes)`` as ``pyplot.subplots`` gives them, on a :class:`~matplotlib.figure.Figure`
    outside pyplot: drawing and saving it never touches the caller's backend or open figures."""
    fig = Figure(figsize=figsize)
    return fig, fig.subplots(nrows, ncols, **kwargs)


def save_figure(fig, path, dpi: int = 110) -> None:
    """Save ``fig`` to ``path`` with the legends outside its axes in the picture, and close it if
    pyplot holds it (a :func:`subplots` figure is freed with its last reference)."""
    fig.savefig(path, dpi=dpi, bbox_inches="tight")
    if fig.canvas.manager is not None:
        import matplotlib.pyplot as plt

        plt.close(fig)


def new_axes(figsize):
    """Axes of a new pyplot figure, in the caller's backend (for ``ax=None``)."""
    import matplotlib.pyplot as plt

    return plt.subplots(figsize=figsize)[1]


def plot_plan(instance: TOPInstance, plan: Plan | None, ax=None, title: str | None = None, legend: bool = True):
    """The paper's Fig. 2: base, targets, viewpoints (covered filled, missed hollow), routes.

    The legend sits to the right of the axes; ``legend=False`` leaves it to the caller (one for a
    figure of panels: :func:`plan_legend`)."""
    if ax is None:
        ax = new_axes((7, 7))
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
    colors = matplotlib.colormaps["tab10"]
    what = "UAV" if instance.kind == "sar" else "vehicle"
    if plan is not None:
        for r, route in enumerate(plan.routes):
            if not route:
                continue
            path = np.vstack([instance.start, pts[list(route)], instance.end])
            ax.plot(path[:, 0], path[:, 1], "-", color=colors(r % 10), lw=1.4,
                    label=f"{what} {r + 1}", zorder=2)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)" if instance.kind == "sar" else "x")
    ax.set_ylabel("y (m)" if instance.kind == "sar" else "y")
    if title:
        ax.set_title(title)
    if legend:
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, fontsize=7, frameon=False)
    return ax


def plan_legend(fig, axes) -> None:
    """One legend for a figure of :func:`plot_plan` panels, below them: every entry of any panel once."""
    seen: dict[str, object] = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            seen.setdefault(label, handle)
    fig.legend(list(seen.values()), list(seen), loc="lower center", ncol=min(len(seen), 8), fontsize=9,
               frameon=False)


def plot_anytime(series: dict, ax=None, title: str | None = None, reference: float | None = None,
                 colors: dict | None = None, legend: bool = True):
    """Bound and incumbent against time, one colour per method.

    ``series`` maps a method name to its history ``[[t, incumbent, bound], ...]`` (see
    :mod:`sarcover.formulations.history`; None where a value is not known yet). The incumbent is a solid
    step line, the bound a dashed one, each drawn from its first known value and ending in the
    method's marker (filled for the incumbent, open for the bound); ``reference`` (a proven or
    published optimum) is a thin grey dotted line; each method has its colour of
    :mod:`sarcover.reports.style` unless ``colors`` (method -> colour) says otherwise; the legend
    sits to the right of the axes, and ``legend=False`` leaves it to the caller (one for a
    figure of panels). Time is on a symlog axis (linear below
    1 s). The y range follows the bounds and the final incumbents, so a trivial early incumbent
    (0) does not flatten the curves; it enters from below.
    """
    if ax is None:
        ax = new_axes((6.5, 4.2))
    lows, highs, t_max, used = [], [], 0.0, {}
    for method, points in series.items():
        c = used[method] = (colors or {}).get(method, look(method).color)
        for col, style in ((1, "-"), (2, "--")):
            pts = [(float(p[0]), float(p[col])) for p in points if p[col] is not None]
            if not pts:
                continue
            t, v = zip(*pts)
            t_max = max(t_max, t[-1])
            ax.step(t, v, where="post", ls=style, color=c, lw=1.5 if col == 1 else 1.2)
            ax.plot(t[-1:], v[-1:], marker=look(method).marker, color=c, ms=6,
                    mfc=c if col == 1 else "white")
            (lows if col == 1 else highs).append(v[-1])
            highs.append(max(v) if col == 2 else v[-1])
    if reference is not None and np.isfinite(reference):
        ax.axhline(reference, color="0.5", lw=0.8, ls=":")
        lows.append(reference)
        highs.append(reference)
    if lows or highs:
        lo, hi = min(lows or highs), max(highs or lows)
        span = max(hi - lo, 1e-9 + 0.05 * abs(hi))
        ax.set_ylim(lo - 0.25 * span, hi + 0.05 * span)
    ax.set_xscale("symlog", linthresh=1.0)
    ticks = [x for x in (0, 0.5, 1, 2, 5, 10, 20, 60, 120, 300, 600, 1800, 3600) if x <= 1.05 * max(t_max, 1.0)]
    ax.set_xticks(ticks, [f"{x:g}" for x in ticks])
    ax.set_xlim(0, max(t_max, 1.0) * 1.05)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("objective")
    ax.grid(alpha=0.3)
    if title:
        ax.set_title(title, fontsize=10)
    if legend:
        ax.legend(handles=anytime_legend(used, reference is not None and np.isfinite(reference)), fontsize=7,
                  loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, frameon=False)
    return ax


def anytime_legend(colors: dict, optimum: bool = True) -> list:
    """Legend handles for :func:`plot_anytime`: one per method (its colour and marker), then the line styles."""
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=c, lw=2, marker=look(m).marker, label=m) for m, c in colors.items()]
    handles += [Line2D([], [], color="k", ls="-", label="incumbent"),
                Line2D([], [], color="k", ls="--", label="bound")]
    if optimum:
        handles.append(Line2D([], [], color="0.5", ls=":", label="optimum"))
    return handles
