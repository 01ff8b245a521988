"""What sarcover refuses up front: sizes its methods cannot hold in memory, numbers that overflow.

Sizes. Every method works on the instance's dense (V+2) × (V+2) distance and cost matrices, and
every plan holds one route per vehicle, so the node count V and the vehicle count N are checked
when an instance is built, before anything of that size is allocated (:data:`MAX_NODES`,
:data:`MAX_VEHICLES`). Methods whose models grow faster (a MILP's arc variables, a CP-SAT model,
PyVRP's cover copies of every node) have lower limits of their own in the method registry. Every
limit keeps a method's peak memory within the address space a benchmark worker gets by default
(a suite's ``memory_mb``, 4096 MB); ``docs/limits.md`` says how each one was chosen.

Numbers. Every coordinate, altitude, energy rate, budget and prize must lie within
±:data:`MAX_MAGNITUDE`: then every distance, arc energy and route energy (a sum of at most
``MAX_NODES + 1`` arcs) stays far inside float64, and no method sees an overflow or an infinity.
"""

from __future__ import annotations

from sarcover.formulations.errors import InstanceError

MAX_NODES = 5000  # nodes (viewpoints, TOP customers): two dense (V+2)² float64 matrices
MAX_VEHICLES = 1000  # vehicles (UAVs): a route each in every plan, depots each in some models
MAX_MAGNITUDE = 1e15  # |x| of any input number; a distance is then < 3e15, an arc energy < 1e31


class TooLargeError(InstanceError):
    """An instance larger than sarcover (or one method) can hold in memory; the message names the limit."""


def too_large(what: str, limit: int, unit: str, holder: str = "sarcover") -> TooLargeError:
    """The error for ``what`` (e.g. ``"uavs = 5000"``) beyond ``limit`` ``unit`` of ``holder``."""
    return TooLargeError(f"{what}: more than {holder} can hold in memory (limit {limit} {unit})")


def check_sar_size(n_targets: int, n_views: int, n_uavs: int) -> None:
    """Raise :class:`TooLargeError` for a SAR instance of more viewpoints (M·K) or UAVs than the
    limits, before its targets are drawn or its viewpoints computed."""
    if n_targets * n_views > MAX_NODES:
        raise too_large(f"{shown(n_targets)} targets × {shown(n_views)} views = {shown(n_targets * n_views)} "
                        f"viewpoints", MAX_NODES, "nodes")
    if n_uavs > MAX_VEHICLES:
        raise too_large(f"uavs = {shown(n_uavs)}", MAX_VEHICLES, "vehicles")


def check_magnitude(name: str, value: float) -> float:
    """``value`` if within ±MAX_MAGNITUDE, else an InstanceError naming ``name`` and the limit."""
    if not -MAX_MAGNITUDE <= value <= MAX_MAGNITUDE:
        text = shown(value)
        if text.lstrip("-") == shown(MAX_MAGNITUDE):  # just beyond the limit: say by how much
            text = repr(float(value))
        raise InstanceError(f"{name} is {text}, beyond ±{MAX_MAGNITUDE:g} (larger numbers would overflow "
                            f"the energy sums)")
    return value


def shown(value) -> str:
    """A number for a one-line message: exact when short, else rounded (Python will not even print
    an integer of more than 4300 digits)."""
    if isinstance(value, int) and not isinstance(value, bool):
        if abs(value) < 10**18:
            return str(value)
        return f"about {'-' if value < 0 else ''}1e{int(abs(value).bit_length() * 0.30103)}"
    try:
        return f"{float(value):.6g}"
    except (TypeError, ValueError, OverflowError):
        return repr(value)[:40]
