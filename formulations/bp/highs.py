"""The HiGHS helpers the branch-and-price's LPs and MILPs share: a silent single-thread solver,
and the set-packing MILP over routes."""

from __future__ import annotations

import highspy
import numpy as np
from pyomo.common.tee import capture_output

INF = highspy.kHighsInf


def quiet_highs() -> highspy.Highs:
    """A silent single-thread HiGHS. Its constructor prints a banner on file descriptor 1 (C++
    output: `sarcover solve --json` must print one JSON object only), so it is built with fd 1
    captured, as Pyomo's own HiGHS interface does."""
    with capture_output(capture_fd=True):
        h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    h.setOptionValue("threads", 1)
    return h


class LPFailure(RuntimeError):
    """HiGHS ended an LP with a status other than optimal, even after :func:`solve_lp`'s
    retries. The branch-and-price stops its search on it and reports its plan and the bound
    it has certified so far."""


# Re-runs after a non-optimal LP status, as (random seed offset, from no basis): HiGHS's simplex
# can end a degenerate LP (the route master is one) with status "unknown" when its anti-cycling
# stops it; run again, or with another random seed, or from no basis, it solves the same LP
# (HiGHS issues 1528, 2108).
RETRIES = ((0, False), (1, False), (2, True))


def solve_lp(h: highspy.Highs, what: str) -> None:
    """Run ``h`` (an LP) to optimality: on another status run it again (the same seed, then
    other random seeds, the last time from no basis); raise :class:`LPFailure` naming ``what``
    if none is optimal. The random seed is left as it was."""
    h.run()
    status = h.getModelStatus()
    if status == highspy.HighsModelStatus.kOptimal:
        return
    seed = h.getOptionValue("random_seed")
    seed = seed[1] if isinstance(seed, tuple) else seed  # highspy returns (status, value)
    try:
        for offset, cold in RETRIES:
            h.setOptionValue("random_seed", seed + offset)
            if cold:
                h.clearSolver()
            h.run()
            if h.getModelStatus() == highspy.HighsModelStatus.kOptimal:
                return
    finally:
        h.setOptionValue("random_seed", seed)
    raise LPFailure(f"{what}: HiGHS status {h.getModelStatus()} (first {status}) after {len(RETRIES)} retries")


def packing_milp(lo, hi, prize, ub, starts, index, value, time_limit: float, *,
                 first: np.ndarray | None = None, abs_gap: bool = False,
                 presolve: bool = True) -> highspy.Highs:
    """HiGHS run on a set-packing MILP over routes: binary columns (``prize``, upper bounds
    ``ub``, CSC arrays ``starts``, ``index``, ``value`` with ``starts`` holding the columns'
    first entries), rows between ``lo`` and ``hi``, maximised to a zero relative gap (and zero
    absolute gap with ``abs_gap``) within ``time_limit`` seconds; ``first``: a 0/1 first
    solution. ``presolve=False`` where the time limit must hold to the second: HiGHS's MIP
    presolve does not look at the clock everywhere, and over thousands of routes it can run
    seconds past a short limit (docs/bp.md, "The time limit"). The caller reads the outcome from
    the returned solver."""
    k = len(prize)
    h = quiet_highs()
    h.setOptionValue("time_limit", max(0.05, float(time_limit)))
    if not presolve:
        h.setOptionValue("presolve", "off")
    h.setOptionValue("mip_rel_gap", 0.0)
    if abs_gap:
        h.setOptionValue("mip_abs_gap", 0.0)
    h.changeObjectiveSense(highspy.ObjSense.kMaximize)
    h.addRows(len(lo), lo, hi, 0, np.zeros(len(lo), np.int32), np.zeros(0, np.int32), np.zeros(0))
    h.addCols(k, prize, np.zeros(k), ub, len(index), starts, index, value)
    h.changeColsIntegrality(k, np.arange(k, dtype=np.int32), np.full(k, highspy.HighsVarType.kInteger))
    if first is not None:
        sol = highspy.HighsSolution()
        sol.col_value = np.asarray(first, dtype=float).tolist()
        sol.value_valid = True
        h.setSolution(sol)
    h.run()
    return h
