"""Compiling bp's numba kernels (or loading them from numba's on-disk cache) before a run, so
that compiling (tens of seconds on a fresh checkout) is never charged to a time limit. The
benchmark harness calls :func:`warm_up` before its workers start
(:func:`sarcover.benchmarks.registry.warm_up`), and :func:`.branch_price.solve_bp` before it
starts its clock."""

from __future__ import annotations

import numpy as np
import sarcover.formulations.bp._label_store as _label_store
import sarcover.formulations.bp.arc_bounds as arc_bounds
import sarcover.formulations.bp.bounds as bounds
import sarcover.formulations.bp.cut_duals as cut_duals
import sarcover.formulations.bp.enumerated_lp as enumerated_lp
import sarcover.formulations.bp.enumeration_kernel as enumeration_kernel
import sarcover.formulations.bp.labelling as labelling
import sarcover.formulations.bp.route_search as route_search
from sarcover.formulations.bp.graph import cheapest_return
from sarcover.formulations.bp.ng_sets import full_ng

# every module that holds numba kernels: warm_up compiles each kernel a run can call
KERNEL_MODULES = (_label_store, cut_duals, bounds, labelling, arc_bounds, enumeration_kernel,
                  enumerated_lp, route_search)

_WARM = False


def warm_up() -> None:
    """Compile every kernel once per process, on a three-point graph: the labelling in each mode
    (heuristic or exact, one-way or bidirectional), both arc bounds, the route enumeration,
    the enumerated LP's cut coefficients and the local search pricing."""
    global _WARM
    if _WARM:
        return
    cost = np.array([[0.0, 1.0, 2.0], [1.0, 0.0, 1.0], [2.0, 1.0, 0.0]])
    ret = cheapest_return(cost)
    prof = np.array([0.0, 1.0, 0.0])
    allowed = np.ones(3, dtype=bool)
    for bi in (False, True):
        for heur in (False, True):
            labelling.price(cost, ret, prof, 4.0, full_ng(3), allowed, heuristic=heur,
                            max_labels=100, n_cols=1, min_gain=0.5, bidirectional=bi)
    arc_bounds.arc_bounds(cost, prof, allowed, 4.0)
    arc_bounds.label_arc_bounds(cost, prof, allowed, 4.0, full_ng(3), -1.0, n_routes=1)
    enumeration_kernel.enumerate_routes(cost, prof, allowed, 4.0, -1.0)
    enumerated_lp.cut_coefficients(np.array([[1, 2, -1]], np.int32), np.ones((1, 4), np.bool_),
                                    np.ones((1, 4), np.bool_))
    route_search.improving_routes([(1,)], cost, prof, allowed, 4.0, -1.0, 1)
    _WARM = True
