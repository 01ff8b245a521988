"""The branch-and-price's tunable settings (:class:`BPOptions`), and the defaults that follow
the user's time limit.

Subset-row cuts make every pricing call after them slower, so they only pay back on long runs:
they are on from ``CUTS_FROM_S``, and from ``OPEN_CUTS_FROM_S`` they are tried however far the
root LP is from a drop that matters. A caller that spends part of the user's limit before
:func:`~sarcover.formulations.bp.solve_bp` (the registered ``bp`` runs greedy first) decides
them on the user's limit with :meth:`BPOptions.for_time_limit`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

CUTS_FROM_S = 60.0  # time limits from which subset-row cuts are on by default
OPEN_CUTS_FROM_S = 300.0  # ... and from which they are tried however far the LP is from a drop
MORE_PRIMAL_FROM_S = 600.0  # time limits from which the root calls the primal heuristic 4 times
ENUM_FROM_S = 60.0  # time limits from which route enumeration is on by default
ENUM_LABELS = 1 << 24  # labels one enumeration try may make, by default from ENUM_LABELS_FROM_S
ENUM_LABELS_FROM_S = 300.0  # ... below which the labels are cut in proportion to the limit


def default_cut_rounds(time_limit: float | None) -> int:
    """Rounds of subset-row cuts by default: 6 from ``CUTS_FROM_S`` (and without a limit),
    else 0."""
    return 6 if time_limit is None or float(time_limit) >= CUTS_FROM_S else 0


def default_primal_calls(time_limit: float | None) -> int:
    """Calls of the caller's primal heuristic at the root by default (while the proof stays
    open): 2, and 4 from ``MORE_PRIMAL_FROM_S`` (and without a limit), where the two extra
    searches take a small share of the limit from the tree (docs/bp.md)."""
    return 4 if time_limit is None or float(time_limit) >= MORE_PRIMAL_FROM_S else 2


def default_enum_share(time_limit: float | None) -> float:
    """Share of the limit for one route enumeration try by default: 0.6 from ``ENUM_FROM_S``
    (and without a limit, where a try gets 30 s), else 0 (off). The root alone takes about a
    third of 300 s on M = 20, K = 5 and of 60 s on M = 20, K = 3, and a complete listing up to
    another third; at 60 s it closes the K = 3 roots that branching leaves open (docs/bp.md)."""
    return 0.6 if time_limit is None or float(time_limit) >= ENUM_FROM_S else 0.0


def default_enum_labels(time_limit: float | None) -> int:
    """Labels one route enumeration try may make before it gives up, by default: ``ENUM_LABELS``
    (about 1.2 GB) from ``ENUM_LABELS_FROM_S`` (and without a limit), below it in proportion to
    the limit (3.4 M at 60 s). A listing makes 0.3-0.8 M labels a second, so a try that cannot
    finish gives up before it takes the time the tree needs; at 60 s the listings that proved
    M = 20, K = 3 instances made at most 2 M (docs/bp.md)."""
    if time_limit is None or float(time_limit) >= ENUM_LABELS_FROM_S:
        return ENUM_LABELS
    return int(ENUM_LABELS * float(time_limit) / ENUM_LABELS_FROM_S)


def default_cut_gap(time_limit: float | None) -> float:
    """How close (in prize steps) the restricted root LP must be to a drop that matters (below
    the incumbent + one step, or below its own floor) for a cut round: 0.5 below
    ``OPEN_CUTS_FROM_S``, 1.0 from it (and without a limit), which is no gate at all since an LP
    value is always less than one step above its floor."""
    return 1.0 if time_limit is None or float(time_limit) >= OPEN_CUTS_FROM_S else 0.5


def _opt(default, help: str, minimum: float | None = None, maximum: float | None = None):
    """A field of :class:`BPOptions`: its default, its one-line meaning and the bounds (inclusive)
    a value given as the ``bp`` method's parameter is checked against."""
    return field(default=default, metadata={"help": help, "minimum": minimum, "maximum": maximum})


@dataclass(frozen=True)
class BPOptions:
    """Settings of one branch-and-price run, and the registered ``bp``'s parameters (each field's
    ``metadata["help"]`` is its one-line meaning, which ``sarcover methods bp`` prints). Shares
    are fractions of the time limit.

    Pricing and the ng-route relaxation:

    - ``ng_size``: starting ng set of a point: itself and its ``ng_size - 1`` cheapest
      neighbours (all points, i.e. elementary pricing, when it reaches the number of nodes).
    - ``bidirectional``: exact pricing direction (True: bidirectional labelling, False: one-way);
      None: the first exact call runs both and keeps the faster.
    - ``ng_columns``: improving ng-routes that repeat a point also enter the master (with
      visit counts), so that the LP stays the relaxation that the pricing bounds.
    - ``exact_keep``: exact pricing keeps the routes within this share of the best route's gain
      (over the vehicle dual) below it, instead of pruning against the best itself: more
      columns per call, more labels (:func:`.labelling.price`); 0 prunes against the best, 1
      never raises the threshold. 0.5: fewer exact calls at the root, more cut rounds in time
      (docs/bp.md).
    - ``sparse_arcs``, ``sparse_from``: from ``sparse_from`` points on (beyond the paper's
      grid), the heuristic pricing runs on each point's ``sparse_arcs`` cheapest arcs
      (:func:`.graph.sparse_graph`); its routes are routes of the full graph, and the exact
      pricing and every bound stay on the full graph. 0 arcs: never.
    - ``heuristic_columns``: the most routes one heuristic pricing call returns.
    - ``route_search_from``: from this many points on, each root round without cuts first
      looks for improving routes by local search from the LP's routes
      (:mod:`.route_search`), and only calls the labelling when that finds none; 0: never.
    - ``primal_simplex_from``: from this many points on, the route master's LPs run HiGHS's
      primal simplex (columns added to a solved LP leave its basis primal feasible; at 360
      points it halved the LP's time); below, HiGHS's default; 0: never.
    - ``ng_cap``: the most points an ng set grows to when LP routes repeat a point.
    - ``exact_labels``: an exact pricing call gives up beyond this many labels (memory: about
      100 bytes each). Such a call certifies no bound: at the root the last cut round is
      withdrawn; otherwise the node is branched on its unconverged LP.
    - ``grow_share``: ng sets only grow within this share of the limit (larger sets make pricing
      slower; after that, branching decides).

    Subset-row cuts (at the root only):

    - ``cut_rounds``: rounds of cuts; 0 turns them off; None: by the time limit
      (:func:`default_cut_rounds`).
    - ``cuts_per_round``: most violated triples added per round.
    - ``cut_gap``: a round is only tried while the restricted LP is within this many prize steps
      of a drop that matters; None: by the time limit (:func:`default_cut_gap`).
    - ``cut_share``: rounds only start within this share of the limit.

    Incumbents and branching:

    - ``primal_calls``: the most calls of the caller's ``primal`` heuristic, all at the root:
      one if the root and its first dive leave the proof open, the others one after the other
      while the root's cut rounds and last dive still do (each with a new seed, for the
      registered bp's PyVRP); None: by the time limit (:func:`default_primal_calls`).
    - ``primal_late_share``: if the root's bound is still not settled when this share of the
      limit is used up, the first call runs then (its routes also join the LP): on TOP set 4's
      two-vehicle files the root's column generation can take the whole limit, and without the
      heuristic the plan is only what the MILP over the generated routes finds (p4.2.r: 1115
      against a best known 1292).
    - ``primal_first_from``: from this many points on (beyond the paper's grid) the first call
      runs before the root's column generation: there the root takes most of the limit, the
      warm start (greedy) lies far below what PyVRP finds in seconds, and the LP starts from
      the heuristic's routes. The late call (``primal_late_share``) still runs after it.
    - ``primal_share``, ``primal_cap_s``: time for each call of the caller's ``primal``
      heuristic, at most ``primal_cap_s`` seconds. 30 s: on
      M = 20, K = 5-6 a 30 s PyVRP search found plans one better than bp's (10 s) on about a
      third of the instances bp left open, several of them then proven by the root's bound
      (docs/bp.md).
    - ``primal_scale_share``, ``primal_scale_cap_s``: the same from ``primal_first_from``
      points on, where the root takes most of the limit and the calls are few. 90 s: at 300
      points PyVRP's search kept finding better plans up to about 60-70 s, where the 30 s call
      stopped short of them (docs/bp.md).
    - ``dive_share``: time for a dive at the root (30 s without a limit); later dives get less.
    - ``dive_every``, ``milp_every``: a dive every this many nodes, a MILP over the generated
      routes every this many nodes (when new routes came in).
    - ``strong``: branching candidates of each kind compared by their children's restricted LPs
      (1: the most fractional candidate, no estimates).
    - ``group_branching``: also branch on a group's number of visits (:mod:`.branching`); off
      by default: on the M = 20, K = 3 tuning instances it proved no more, and at K >= 4 the
      tree is too small for the choice to matter (docs/bp.md).

    Arc elimination:

    - ``elim_share``: time for the exact labelling arc bounds (30 s without a limit).
    - ``pool_routes``: best elementary routes of that labelling that join the master as columns
      (for the MILP over the generated routes).

    Route enumeration (:mod:`.enumeration`), tried after the root once its certificate leaves
    the incumbent one step from a proof:

    - ``enum_share``: seconds for the tries under one certificate and incumbent (each:
      listing the routes, the LP over them with its cuts, the MILP over the routes left; a
      narrow try that listed no better plan is widened at once), as a share of the limit
      (30 s without one); 0 turns enumeration off. None: 0.6 from ``ENUM_FROM_S`` (60 s),
      else 0.
    - ``enum_gap``: the listing is complete (its outcome a proof) while the root certificate's
      bound is at most this many prize steps above the incumbent + one step; the number of
      routes to list grows four- to sixfold per 0.1 step on M = 20, K = 5 (docs/bp.md).
    - ``enum_primal_window``: above ``enum_gap``, list only the routes within this many prize
      steps of the best and search them for a better plan (no proof); when they hold none,
      try wider (by 0.1 steps, then by up to twice the last widening) while the listing would stay
      within the caps, were it to grow as over the narrow one's last 0.1 steps (complete once
      as wide as the window); 0: no such tries.
    - ``enum_labels``, ``enum_routes``: a try gives up beyond this many labels or routes. The
      labels take about 70 bytes each, so 2^24 (16.8 M) stay near 1.2 GB, within the
      harness's 4 GB per worker; a try that still runs out of memory gives up as well.
    - ``audit_listings``: when a complete root listing proves the incumbent optimal, check the
      proof by other means than the ones it used (:mod:`.audit`: every route one insertion,
      removal or swap from a listed one that should be listed is; no set of at most N disjoint
      listed routes is worth incumbent + step, searched exhaustively under the certificate) and
      report it in ``info`` (``audit_*``). Off by default: it takes minutes at 100 points and
      does not change the run's outcome, only what it reports.
      ``enum_labels`` None: by the time limit (:func:`default_enum_labels`).
    """

    ng_size: int = _opt(8, "starting ng set of a point: itself and its ng_size - 1 cheapest neighbours", 1)
    bidirectional: bool | None = _opt(None, "exact pricing bidirectional (true) or one-way (false); none: the"
                                            " faster of both on the first call")
    ng_columns: bool = _opt(True, "improving ng-routes that repeat a point also enter the master")
    exact_keep: float = _opt(0.5, "exact pricing keeps routes within this share of the best route's gain (0: "
                                  "prune against the best)", 0, 1)
    sparse_arcs: int = _opt(16, "from sparse_from points on, heuristic pricing keeps each point's this many "
                                "cheapest arcs (0: full graph)", 0)
    sparse_from: int = _opt(150, "points from which heuristic pricing runs on the sparse graph", 0)
    heuristic_columns: int = _opt(30, "most routes one heuristic pricing call returns", 1)
    primal_simplex_from: int = _opt(150, "from this many points on, the master LPs run HiGHS's primal simplex "
                                         "(0: never)", 0)
    route_search_from: int = _opt(150, "from this many points on, root rounds without cuts first seek improving "
                                     "routes by local search from the LP's routes (0: never)", 0)
    ng_cap: int = _opt(12, "most points an ng set grows to", 1)
    exact_labels: int = _opt(2_000_000, "an exact pricing call gives up beyond this many labels (about 100 "
                                        "bytes each)", 1)
    grow_share: float = _opt(0.3, "ng sets grow only within this share of the time limit", 0, 1)
    cut_rounds: int | None = _opt(None, "rounds of subset-row cuts at the root (0: off); none: 6 from 60 s, "
                                        "else 0", 0)
    cuts_per_round: int = _opt(16, "most violated subset-row triples added per round", 1)
    cut_gap: float | None = _opt(None, "a cut round only while the root LP is within this many prize steps of"
                                       " a drop that matters; none: by the limit", 0)
    cut_share: float = _opt(0.35, "cut rounds start only within this share of the time limit", 0, 1)
    primal_calls: int | None = _opt(None, "most calls of the primal heuristic (PyVRP) at the root; none: 2, "
                                          "or 4 from 600 s", 0)
    primal_first_from: int = _opt(150, "from this many points on, the first primal call runs before the root's "
                                       "column generation", 0)
    primal_share: float = _opt(0.1, "time of each primal heuristic call, as a share of the time limit", 0, 1)
    primal_late_share: float = _opt(0.5, "run the first primal call once this share of the limit is used if "
                                         "the root is still open", 0, 1)
    primal_cap_s: float = _opt(30.0, "at most this many seconds per primal heuristic call", 0)
    primal_scale_share: float = _opt(0.15, "from primal_first_from points on, primal_share's place", 0, 1)
    primal_scale_cap_s: float = _opt(90.0, "from primal_first_from points on, primal_cap_s's place", 0)
    dive_share: float = _opt(0.1, "time for a dive at the root, as a share of the time limit", 0, 1)
    dive_every: int = _opt(4, "a dive every this many nodes", 1)
    milp_every: int = _opt(10, "a MILP over the generated routes every this many nodes", 1)
    strong: int = _opt(5, "branching candidates compared by strong branching (1: most fractional)", 1)
    group_branching: bool = _opt(False, "also branch on a group's number of visits")
    elim_share: float = _opt(0.1, "time for the labelling arc bounds (arc elimination), as a share of the "
                                  "limit", 0, 1)
    pool_routes: int = _opt(2000, "best elementary routes of the arc-bound labelling that join the master", 0)
    enum_share: float | None = _opt(None, "time of the root's route enumeration tries (widened at once) "
                                          "as a share of the limit (0: enumeration off); none: 0.6 "
                                          "from 60 s, else 0", 0, 1)
    enum_gap: float = _opt(0.3, "enumeration is complete (a proof) while the root bound is at most this many "
                                "prize steps above incumbent + 1", 0)
    enum_primal_window: float = _opt(0.2, "above enum_gap, list routes within this many prize steps of the "
                                          "best to search for a plan (0: off)", 0)
    enum_labels: int | None = _opt(None, "an enumeration try gives up beyond this many labels; none: 2^24 "
                                         "from 300 s, less below", 1)
    enum_routes: int = _opt(3_000_000, "an enumeration try gives up beyond this many routes", 1)
    audit_listings: bool = _opt(False, "audit a proof by a complete root listing apart from the enumeration's "
                                       "kernels (closure and packing checks; slow: minutes at 100 points)")

    @classmethod
    def for_time_limit(cls, time_limit: float | None) -> "BPOptions":
        """The default options for a run whose user asked for ``time_limit`` seconds (None: no
        limit): cuts on from ``CUTS_FROM_S``, their gate open from ``OPEN_CUTS_FROM_S``, route
        enumeration on from ``ENUM_FROM_S``."""
        return cls().with_limit_defaults(time_limit)

    def with_limit_defaults(self, time_limit: float | None) -> "BPOptions":
        """These options with the settings left None (``cut_rounds``, ``cut_gap``,
        ``primal_calls``, ``enum_share``, ``enum_labels``) decided on ``time_limit``."""
        return replace(
            self,
            cut_rounds=(default_cut_rounds(time_limit) if self.cut_rounds is None
                        else self.cut_rounds),
            cut_gap=default_cut_gap(time_limit) if self.cut_gap is None else self.cut_gap,
            primal_calls=(default_primal_calls(time_limit) if self.primal_calls is None
                          else self.primal_calls),
            enum_share=(default_enum_share(time_limit) if self.enum_share is None
                        else self.enum_share),
            enum_labels=(default_enum_labels(time_limit) if self.enum_labels is None
                         else self.enum_labels))

