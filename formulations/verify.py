"""Independent plan verifier: recomputes every quantity from coordinates, trusting no solver.

It deliberately uses plain Python arithmetic (``math.hypot``) rather than the matrices the
solvers use, so that a bug in a shared cost matrix cannot hide a violation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan

REL_TOL = 1e-9


@dataclass
class VerificationReport:
    """The verifier's verdict. ``valid`` is True only if ``violations`` is empty."""

    valid: bool
    violations: list[str] = field(default_factory=list)
    energy: list[float] = field(default_factory=list)
    covered: int = 0
    prize: float = 0.0
    coverage: float = 0.0
    groups_covered: int = 0

    def summary(self) -> str:
        if self.valid:
            return f"valid: prize {self.prize:g}, {self.covered} nodes, coverage {self.coverage:.4f}"
        return "invalid: " + "; ".join(self.violations)


def route_energy(instance: TOPInstance, route) -> float:
    """Energy of one route start → route... → end; an empty route costs 0."""
    if len(route) == 0:
        return 0.0
    pts = [tuple(map(float, instance.start))]
    pts += [tuple(map(float, instance.coords[v])) for v in route]
    pts.append(tuple(map(float, instance.end)))
    dist = sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(pts, pts[1:]))
    return instance.e_fly * dist + instance.e_image * len(route)


def verify(instance: TOPInstance, plan: Plan) -> VerificationReport:
    """Check ``plan`` against every constraint of ``instance`` and recompute its objective."""
    violations: list[str] = []
    n = instance.n_nodes
    routes = list(plan.routes)
    if len(routes) > instance.n_vehicles:
        violations.append(f"{len(routes)} routes for {instance.n_vehicles} vehicles")
    seen: dict[int, int] = {}
    energies: list[float] = []
    for r, route in enumerate(routes):
        valid_route = True
        for v in route:
            if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v < n:
                violations.append(f"route {r} visits unknown node {v!r}")
                valid_route = False
                continue
            if v in seen:
                violations.append(f"node {v} visited twice (routes {seen[v]} and {r})")
            else:
                seen[v] = r
        if not valid_route:
            energies.append(float("nan"))
            continue
        e = route_energy(instance, route)
        energies.append(e)
        if e > instance.budget * (1.0 + REL_TOL) + 1e-12:
            violations.append(f"route {r} uses energy {e:.9g} > budget {instance.budget:.9g}")
    groups_covered = 0
    for gi, group in enumerate(instance.groups):
        if any(v in seen for v in group):
            groups_covered += 1
        else:
            what = "target" if instance.kind == "sar" else "group"
            violations.append(f"{what} {gi} has no visited viewpoint")
    prize = float(sum(float(instance.prizes[v]) for v in seen))
    total = instance.total_prize
    return VerificationReport(
        valid=not violations,
        violations=violations,
        energy=energies,
        covered=len(seen),
        prize=prize,
        coverage=prize / total if total > 0 else 0.0,
        groups_covered=groups_covered,
    )
