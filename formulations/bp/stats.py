"""What one branch-and-price run counts and reports (``Result.info``)."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class Stats:
    """Counters and timings of one run; :meth:`info` is what ``Result.info`` reports."""

    rounds: int = 0
    exact_pricings: int = 0
    labels: int = 0
    ng_growths: int = 0
    nodes: int = 0
    milp_calls: int = 0
    milp_s: float = 0.0
    strong_lps: int = 0
    strong_s: float = 0.0
    group_branches: int = 0  # nodes split on a group's number of visits
    open_nodes: int = 0  # nodes left unsolved at the limit (0 when proven)
    milp_improved: int = 0  # MILP calls that raised the incumbent
    milp_columns: int | None = None  # routes the last MILP could use (reduced-cost filter)
    dives: int = 0
    dive_improved: int = 0  # dives that raised the incumbent
    primal_calls: int = 0  # the caller's heuristic: calls, their time, best plan's prize, improved?
    primal_s: float | None = None
    primal_prize: float | None = None
    primal_improved: bool | None = None
    primal_error: str | None = None
    cuts: int = 0
    cuts_purged: int = 0
    cuts_withdrawn: int = 0  # removed because an exact pricing under them hit its label cap
    label_caps: int = 0  # exact pricings that hit their label cap (no exact bound from them)
    exact_label_cap: int | None = None  # the exact calls' cap, when the root raised it
    heuristic_labels: int | None = None  # the heuristic calls' cap, when a capped call raised it
    relaxed_bounds: int = 0  # node bounds lowered by a relaxed pricing bound (no exact pricing)
    open_integral: int = 0  # unconverged nodes (label cap) with an integral LP: kept open, not solved
    arcs_eliminated: int = 0  # arcs no plan better than the incumbent can use
    elim_s: float = 0.0  # time spent on their bounds
    elim_labels: bool | None = None  # the labelling bound ran to the end (None: not tried)
    pool_routes: int = 0  # routes its search added to the master
    enum_tries: int = 0  # route enumerations tried (closing the root gap)
    enum_complete: int = 0  # of them, complete listings (the others list a narrower window)
    enum_improved: int = 0  # tries whose MILP raised the incumbent
    enum_memory: int = 0  # tries stopped by a MemoryError (a process memory limit)
    enum_labels: int | None = None  # labels and routes of the last one (routes None: capped)
    enum_routes: int | None = None
    enum_growth: float | None = None  # its labels over those WIDEN steps further in (None: inf)
    enum_s: float = 0.0
    enum_lp_s: float = 0.0  # the LP over the enumerated routes, its cut rounds and filter
    enum_lp_bound: float | None = None  # its last bound
    enum_cuts: int = 0  # full-memory triples it added
    enum_left: int | None = None  # routes left after its reduced-cost filter
    enum_milp_s: float = 0.0  # the MILP over the enumerated routes
    enum_status: str | None = None  # its outcome: optimal, infeasible (proof) or open
    cap: float | None = None  # no plan is worth more: shown by a narrow listing (None: none did)
    audit: dict | None = None  # the audit of the proof by a root listing (audit_listings)
    node_enum_tries: int = 0  # of the tries, complete listings at nodes below the root
    node_enum_closed: int = 0  # nodes they closed
    root_lp: float | None = None  # restricted root LP value when cuts were first considered
    pricing_s: float = 0.0
    route_search_s: float = 0.0  # the local search pricing (part of pricing_s)
    route_search_columns: int = 0  # columns it added
    lp_s: float = 0.0
    root_bound: float | None = None
    root_s: float | None = None
    mode_times: tuple | None = None  # first exact pricing: (one-way s, bidirectional s)
    history: list = field(default_factory=list)  # (time, incumbent, bound)

    def info(self, *, columns: int, bidirectional: bool | None, options: dict) -> dict:
        """The run's ``Result.info``: these counters (times rounded to ms), the master's number
        of ``columns``, the exact pricing direction that was kept and the run's ``options`` (its
        :class:`.options.BPOptions` as a dict, so that stored rows say which settings made them)."""
        return {
            "nodes": self.nodes, "rounds": self.rounds, "columns": columns,
            "exact_pricings": self.exact_pricings, "labels": self.labels,
            "ng_growths": self.ng_growths, "milp_calls": self.milp_calls,
            "milp_s": round(self.milp_s, 3), "milp_improved": self.milp_improved,
            "milp_columns": self.milp_columns, "dives": self.dives,
            "dive_improved": self.dive_improved, "strong_lps": self.strong_lps,
            "strong_s": round(self.strong_s, 3), "group_branches": self.group_branches,
            "open_nodes": self.open_nodes,
            "cuts": self.cuts, "cuts_purged": self.cuts_purged,
            "cuts_withdrawn": self.cuts_withdrawn, "label_caps": self.label_caps,
            "exact_label_cap": self.exact_label_cap, "heuristic_labels": self.heuristic_labels,
            "relaxed_bounds": self.relaxed_bounds, "open_integral": self.open_integral,
            "arcs_eliminated": self.arcs_eliminated, "elim_s": round(self.elim_s, 3),
            "elim_labels": self.elim_labels, "pool_routes": self.pool_routes,
            "enum_tries": self.enum_tries, "enum_complete": self.enum_complete,
            "enum_improved": self.enum_improved, "enum_memory": self.enum_memory,
            "enum_labels": self.enum_labels,
            "enum_routes": self.enum_routes, "enum_growth": self.enum_growth,
            "enum_s": round(self.enum_s, 3),
            "enum_lp_s": round(self.enum_lp_s, 3), "enum_lp_bound": self.enum_lp_bound,
            "enum_cuts": self.enum_cuts, "enum_left": self.enum_left,
            "enum_milp_s": round(self.enum_milp_s, 3), "enum_status": self.enum_status,
            "cap": self.cap, "audit": self.audit,
            "node_enum_tries": self.node_enum_tries, "node_enum_closed": self.node_enum_closed,
            "root_lp": self.root_lp, "primal_calls": self.primal_calls,
            "primal_s": self.primal_s, "primal_prize": self.primal_prize,
            "primal_improved": self.primal_improved, "primal_error": self.primal_error,
            "pricing_s": round(self.pricing_s, 3),
            "route_search_s": round(self.route_search_s, 3),
            "route_search_columns": self.route_search_columns, "lp_s": round(self.lp_s, 3),
            "root_bound": self.root_bound, "root_s": self.root_s, "history": self.history,
            "threads": 1, "bidirectional": bidirectional, "mode_times": self.mode_times,
            "options": options,
        }
