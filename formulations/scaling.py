"""Integer arc energies for solvers that only take integers (OR-Tools routing, PyVRP, CP-SAT).

OR-Tools callbacks must return ints (a float silently becomes 0), CP-SAT takes integer
coefficients only and PyVRP truncates float distances, so every such solver works on
``ceil(scale * c_ij)`` with the budget ``floor(scale * E_max)``. Rounding arcs up and the budget
down means a route the integer model accepts never exceeds the true budget:
``sum c_ij <= sum ceil(s*c_ij)/s <= floor(s*B)/s <= B``. The price is that routes within about
``(arcs in the route) / scale`` energy of the budget are rejected, so an integer-scaled solver may
miss a plan that uses the budget exactly (a heuristic that never over-claims). Every plan still
goes through the verifier.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sarcover.formulations.instance import TOPInstance

DEFAULT_RESOLUTION = 10**6  # integer units per budget: arc rounding loses <= 1e-6 of E_max per arc
MAX_EXPONENT = 300  # scales stay within 1e±300, so that a tiny budget cannot make one infinite


def power_of_ten_scale(target: float, reference: float) -> float:
    """The smallest power of ten s with s·reference >= target (1 when reference is 0), within
    1e±MAX_EXPONENT (computed on logarithms: target / reference may not be a float)."""
    if reference <= 0:
        return 1.0
    exponent = math.ceil(math.log10(target) - math.log10(reference))
    return 10.0 ** max(-MAX_EXPONENT, min(MAX_EXPONENT, exponent))


def integer_arcs(cost: np.ndarray, scale: float, cap: int) -> np.ndarray:
    """``ceil(scale * cost)`` as int64, arcs above ``cap`` cut to it. Give a cap above the integer
    budget: such an arc fits no route whatever its cost, and the cut keeps an arc far dearer than
    the budget from overflowing int64 (the multiplication comes after the cut, so it cannot
    overflow either). Arcs below the cap are exactly ``ceil(scale * cost)``."""
    return np.ceil(np.minimum(cost, cap / scale) * scale).astype(np.int64)


@dataclass(frozen=True)
class ScaledCosts:
    """Integer arc energies in solver order (0 = start, 1..V = nodes, V+1 = end).

    ``arc[i, j] = ceil(scale * c_ij)``; ``budget = floor(scale * E_max)``; the start → end arc
    (an empty route, which costs nothing) is 0.
    """

    scale: float
    arc: np.ndarray  # (V+2, V+2) int64
    budget: int

    def route_cost(self, route) -> int:
        """Integer energy of a route given in solver indices (without the depots)."""
        if len(route) == 0:
            return 0
        seq = [0, *route, self.arc.shape[0] - 1]
        return int(sum(int(self.arc[a, b]) for a, b in zip(seq, seq[1:])))


def scaled_costs(instance: TOPInstance, resolution: int = DEFAULT_RESOLUTION) -> ScaledCosts:
    """Scale so that the budget is at least ``resolution`` integer units (arcs up, budget down).

    The scale is a power of ten, so decimal data (integer coordinates on a grid, budgets like
    6 or 7.5) stays exact: a route using exactly the budget is then not lost to rounding.
    """
    cost = instance.cost_matrix()
    reference = instance.budget if instance.budget > 0 else float(cost.max(initial=0.0))
    scale = power_of_ten_scale(resolution, reference)
    budget = int(math.floor(instance.budget * scale))
    arc = integer_arcs(cost, scale, budget + 1)
    np.fill_diagonal(arc, 0)
    arc[0, -1] = 0  # an empty route stays home and costs nothing
    return ScaledCosts(scale=scale, arc=arc, budget=budget)


def integer_prizes(prizes: np.ndarray, dominate: int) -> np.ndarray:
    """Integer prizes in which the smallest positive prize outweighs ``dominate`` cost units.

    Used to make prize collection lexicographically first and travel cost a tie-break: with
    every plan's total integer travel cost below ``dominate``, no cost saving pays for a lost
    prize. Ratios between prizes are kept up to rounding (relative error <= 1 / dominate).
    """
    prizes = np.asarray(prizes, dtype=float)
    positive = prizes[prizes > 0]
    if positive.size == 0:
        return np.zeros(prizes.shape, dtype=np.int64)
    weight = (dominate + 1) / float(positive.min())
    return np.rint(prizes * weight).astype(np.int64)
