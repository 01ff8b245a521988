"""One look per method in every figure of both reports: colour, marker, line style and group.

The paper's five methods are warm colours with solid lines; the peers (PyVRP, OR-Tools routing
and the greedy floor) cool colours and grey with dashed lines; the exact methods green, olive and
black with dotted lines. Within a group no two methods share a colour or a marker, so a line
stays identifiable where others run on top of it (:func:`dodge` spreads equal points apart).
Methods of one's own (``module:function`` in a suite) get a look from a reserve, fixed by name.
Legends list the groups in this order with a heading each (:func:`legend_entries`) and sit
outside the data (:func:`legend_outside`).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

GROUPS: dict[str, tuple[str, ...]] = {
    "paper": ("adpc-pso", "dpc-pso", "kmeans-pso", "adpc-ga", "adpc-aco"),
    "peers": ("pyvrp", "routing", "greedy"),
    "exact": ("bp", "milp", "cpsat"),
}
GROUP_TITLES = {"paper": "the paper's methods", "peers": "peers and floor", "exact": "exact methods",
                "other": "other methods"}
PAPER = list(GROUPS["paper"])
PEERS = list(GROUPS["peers"])
EXACT = list(GROUPS["exact"])
ORDER = PAPER + PEERS + EXACT


@dataclass(frozen=True)
class Look:
    color: str
    marker: str
    ls: str
    group: str

    def line(self) -> dict:
        """Keyword arguments of ``ax.plot`` / ``ax.errorbar`` for this method."""
        return {"color": self.color, "marker": self.marker, "ls": self.ls}


_SOLID, _DASHED, _DOTTED = "-", "--", ":"
LOOKS: dict[str, Look] = {
    "adpc-pso": Look("#d62728", "o", _SOLID, "paper"),  # red
    "dpc-pso": Look("#ff7f0e", "s", _SOLID, "paper"),  # orange
    "kmeans-pso": Look("#8c564b", "^", _SOLID, "paper"),  # brown
    "adpc-ga": Look("#e377c2", "v", _SOLID, "paper"),  # pink
    "adpc-aco": Look("#9467bd", "D", _SOLID, "paper"),  # purple
    "pyvrp": Look("#1f77b4", "P", _DASHED, "peers"),  # blue
    "routing": Look("#17becf", "X", _DASHED, "peers"),  # cyan
    "greedy": Look("#7f7f7f", "h", _DASHED, "peers"),  # grey
    "bp": Look("#000000", "*", _DOTTED, "exact"),  # black
    "milp": Look("#2ca02c", "p", _DOTTED, "exact"),  # green
    "cpsat": Look("#bcbd22", "d", _DOTTED, "exact"),  # olive
}
# the looks a method outside the table may get (colours and markers unused above)
_RESERVE = [Look(c, m, "-.", "other") for c, m in [
    ("#393b79", "<"), ("#637939", ">"), ("#8c6d31", "1"), ("#843c39", "2"), ("#7b4173", "3"),
    ("#3182bd", "4"), ("#e6550d", "8"), ("#31a354", "H"), ("#756bb1", "+"), ("#636363", "x"),
]]


def look(method: str) -> Look:
    """The look of ``method``: its own, or the reserve's fixed by the name (``bp-300s``, a run of
    bp at another limit, looks like bp with another line style)."""
    if method in LOOKS:
        return LOOKS[method]
    base = method.split("-")[0]
    if method.startswith("bp-") and base in LOOKS:
        return Look(LOOKS[base].color, LOOKS[base].marker, "-.", LOOKS[base].group)
    digest = int(hashlib.sha1(method.encode()).hexdigest(), 16)
    return _RESERVE[digest % len(_RESERVE)]


def ordered(methods) -> list[str]:
    """``methods`` in legend order: paper, peers, exact, then the others by name."""
    methods = list(dict.fromkeys(methods))
    known = [m for m in ORDER if m in methods]
    return known + sorted(m for m in methods if m not in ORDER)


def colors(methods) -> dict[str, str]:
    """method -> colour, for plot functions that take a colour map."""
    return {m: look(m).color for m in methods}


def dodge(methods, step: float) -> dict[str, float]:
    """A horizontal offset per method, centred on 0 and ``step`` apart, in legend order: on a
    categorical x axis, points of equal value then sit side by side instead of on top of each other."""
    methods = ordered(methods)
    mid = (len(methods) - 1) / 2
    return {m: (i - mid) * step for i, m in enumerate(methods)}


def legend_entries(methods, label=None) -> tuple[list, list[str]]:
    """(handles, labels) of a legend for ``methods``: per group a heading, then its methods with
    their colour, marker and line. ``label(method)`` gives a method's text (default: its name)."""
    from matplotlib.lines import Line2D

    handles, labels = [], []
    methods = ordered(methods)
    for group in list(GROUPS) + ["other"]:
        members = [m for m in methods if look(m).group == group]
        if not members:
            continue
        handles.append(Line2D([], [], ls="none", marker=""))
        labels.append(GROUP_TITLES[group])
        for m in members:
            lk = look(m)
            handles.append(Line2D([], [], color=lk.color, marker=lk.marker, ls=lk.ls, lw=1.5, ms=6))
            labels.append(label(m) if label else m)
    return handles, labels


def legend_outside(ax, methods, label=None, fontsize: float = 8, extra=()):
    """A grouped legend of ``methods`` to the right of ``ax``, outside the data; group headings in
    bold. ``extra``: further (handle, label) pairs at the end (line styles, an optimum line)."""
    handles, labels = legend_entries(methods, label)
    for h, lab in extra:
        handles.append(h)
        labels.append(lab)
    leg = ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0,
                    fontsize=fontsize, frameon=False)
    headings = set(GROUP_TITLES.values())
    for text in leg.get_texts():
        if text.get_text() in headings:
            text.set_fontweight("bold")
    return leg
