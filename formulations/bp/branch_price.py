"""The ``bp`` method's front door: :func:`solve_bp` runs one branch-and-price
(:class:`.tree.BranchAndPrice`) and turns what it proved into a :class:`Result`."""

from __future__ import annotations

import math
import time
from dataclasses import asdict

from sarcover.formulations.bp.compile import warm_up
from sarcover.formulations.bp.options import BPOptions
from sarcover.formulations.bp.tree import BranchAndPrice
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Result, Termination


def solve_bp(instance: TOPInstance, *, seed: int = 0, time_limit: float | None = 60.0,
             warm_start: Plan | None = None, primal=None,
             options: BPOptions | None = None) -> Result:
    """Branch-and-price: proven optimum, or the best plan and a certified bound at the limit.

    ``warm_start``: a plan (e.g. a heuristic's) whose routes are added as starting columns and
    as a first incumbent. ``primal(seconds) -> routes or None`` (node ids) is a heuristic run
    if the root does not settle the proof (after its first dive, and once more after its cut
    rounds and last dive), with ``options.primal_share`` of the time limit each (at most
    ``options.primal_cap_s``; from ``options.primal_first_from`` points on, the ``primal_scale``
    pair); its routes become columns and, if verified and better, the
    incumbent. ``options``: None means :meth:`BPOptions.for_time_limit` of ``time_limit``.
    ``seed`` is unused (no randomness; timing-based choices and the time limit can still change
    the path taken). There is no pre-check here (``run_method`` runs it once per call): a group
    out of reach leaves the root master infeasible, which proves the instance infeasible.
    """
    warm_up()  # JIT compilation (cached on disk after the first run) is not charged to the limit
    t0 = time.perf_counter()
    bp = BranchAndPrice(instance, time_limit=time_limit, warm_start=warm_start, primal=primal,
                        options=options)
    proven, bound = bp.run()
    info = bp.search.stats.info(columns=bp.search.master.n_routes,
                                bidirectional=bp.pricer.bidirectional, options=asdict(bp.options))
    return _result(bp, proven, bound, info, t0)


def _result(bp: BranchAndPrice, proven: bool, bound: float, info: dict, t0: float) -> Result:
    """The :class:`Result` of a finished run: its incumbent (node ids), termination and bound."""
    s = bp.search
    runtime = time.perf_counter() - t0
    plan = None if s.incumbent is None else Plan.of([[p - 1 for p in r] for r in s.incumbent])
    if plan is None:
        if proven:
            return Result("bp", Termination.INFEASIBLE, bound=None, runtime_s=runtime, info=info,
                          reason="branch-and-price proved that no plan covers every group")
        b = bound if math.isfinite(bound) else None
        if bp.stopped is not None:
            return Result("bp", Termination.COMPLETED, bound=b, runtime_s=runtime, info=info,
                          reason=f"stopped early, no plan covering every group: {bp.stopped}")
        return Result("bp", Termination.TIME_LIMIT, bound=b, runtime_s=runtime, info=info,
                      reason="time limit before a plan covering every group was found")
    if proven:
        return Result("bp", Termination.OPTIMAL, plan=plan, bound=s.incumbent_value, runtime_s=runtime,
                      info=info)
    b = bound if math.isfinite(bound) else None
    if bp.stopped is not None:  # an LP HiGHS failed on ended the search: its plan and bound hold
        return Result("bp", Termination.COMPLETED, plan=plan, bound=b, runtime_s=runtime, info=info,
                      reason=f"stopped early: {bp.stopped}")
    return Result("bp", Termination.TIME_LIMIT, plan=plan, bound=b, runtime_s=runtime, info=info,
                  reason="time limit")
