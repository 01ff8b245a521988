"""Problem model: the paper's SAR instance and the general team orienteering (TOP) form.

Every solver works on :class:`TOPInstance`. A :class:`SARInstance` maps onto it with
:func:`to_top` (unit prizes, one group per target: constraint (5), each target at least one view).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from sarcover.formulations.errors import InstanceError
from sarcover.formulations.geometry import viewpoints
from sarcover.formulations.limits import (MAX_MAGNITUDE, MAX_NODES, MAX_VEHICLES, check_magnitude, check_sar_size,
                                          shown, too_large)


def _finite(name: str, value: float, *, positive: bool = False, nonnegative: bool = False) -> float:
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        check_magnitude(name, value)  # before float(): a huge integer does not convert
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InstanceError(f"{name} must be a number, got {shown(value)}") from None
    if not math.isfinite(value):
        raise InstanceError(f"{name} must be finite, got {shown(value)}")
    check_magnitude(name, value)
    if positive and value <= 0:
        raise InstanceError(f"{name} must be > 0, got {shown(value)}")
    if nonnegative and value < 0:
        raise InstanceError(f"{name} must be >= 0, got {shown(value)}")
    return value


def _count(name: str, value: int, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise InstanceError(f"{name} must be an integer, got {shown(value)}")
    if value < minimum:
        raise InstanceError(f"{name} must be >= {minimum}, got {shown(value)}")
    return int(value)


def _points(name: str, value, *, allow_empty: bool = False) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except OverflowError:  # an integer too large for a float
        raise InstanceError(f"{name} has a coordinate beyond ±{MAX_MAGNITUDE:g}") from None
    except (TypeError, ValueError):
        raise InstanceError(f"{name} must be a list of [x, y] number pairs") from None
    if arr.size == 0 and allow_empty:
        return arr.reshape(0, 2)
    if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] == 0:
        raise InstanceError(f"{name} must be a non-empty list of [x, y] number pairs")
    if not np.all(np.isfinite(arr)):
        row = int(np.flatnonzero(~np.isfinite(arr).all(axis=1))[0])
        raise InstanceError(f"{name}[{row}] has a coordinate that is not a finite number")
    if arr.size and np.abs(arr).max() > MAX_MAGNITUDE:
        row = int(np.flatnonzero((np.abs(arr) > MAX_MAGNITUDE).any(axis=1))[0])
        check_magnitude(f"{name}[{row}]", float(np.abs(arr[row]).max()))
    arr = arr.copy()
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True)
class SARInstance:
    """The paper's multi-view SAR coverage instance. The base is at (0, 0).

    targets: (M, 2) ground target positions in metres. n_views: K. n_uavs: N.
    altitude: H (m). pitch_deg: θ (degrees). e_fly: energy per metre flown (E_F).
    e_image: energy per imaged viewpoint (E_I). e_max: per-UAV energy budget (E_max).
    """

    targets: np.ndarray
    n_views: int
    n_uavs: int
    altitude: float
    pitch_deg: float
    e_fly: float
    e_image: float
    e_max: float
    name: str = "sar"

    def __post_init__(self):
        object.__setattr__(self, "targets", _points("targets", self.targets))
        object.__setattr__(self, "n_views", _count("views", self.n_views))
        object.__setattr__(self, "n_uavs", _count("uavs", self.n_uavs))
        check_sar_size(self.targets.shape[0], self.n_views, self.n_uavs)  # before the viewpoints are computed
        object.__setattr__(self, "altitude", _finite("altitude", self.altitude, positive=True))
        pitch = _finite("pitch_deg", self.pitch_deg)
        if not 0.0 <= pitch < 90.0:
            raise InstanceError(f"pitch_deg must be in [0, 90), got {pitch!r}")
        object.__setattr__(self, "pitch_deg", pitch)
        object.__setattr__(self, "e_fly", _finite("e_fly", self.e_fly, positive=True))
        object.__setattr__(self, "e_image", _finite("e_image", self.e_image, positive=True))
        object.__setattr__(self, "e_max", _finite("e_max", self.e_max, positive=True))
        views = viewpoints(self.targets, self.n_views, self.altitude, self.pitch_deg)  # raises on a target at base
        if not np.all(np.isfinite(views)):  # a target so close to the base that H·cosθ/‖t‖ overflows
            m = int(np.flatnonzero(~np.isfinite(views).all(axis=1))[0]) // self.n_views
            raise InstanceError(f"target {m} lies too close to the base (0, 0) for its viewpoints to be computed")
        if np.abs(views).max() > MAX_MAGNITUDE:  # a target near the limit, its views H·cosθ beyond it
            m = int(np.flatnonzero((np.abs(views) > MAX_MAGNITUDE).any(axis=1))[0]) // self.n_views
            raise InstanceError(f"target {m} has viewpoints beyond ±{MAX_MAGNITUDE:g} (larger numbers would "
                                f"overflow the energy sums)")

    @property
    def n_targets(self) -> int:
        return int(self.targets.shape[0])

    def viewpoints(self) -> np.ndarray:
        return viewpoints(self.targets, self.n_views, self.altitude, self.pitch_deg)


@dataclass(frozen=True)
class TOPInstance:
    """General team orienteering form shared by every solver.

    Nodes 0..V-1 are the visitable points (viewpoints or customers) at ``coords``; routes start
    at ``start`` and end at ``end`` (they may differ). Arc cost c_ij = e_fly·d_ij + e_image·[j is
    a node]. Each of ``n_vehicles`` routes must cost at most ``budget``; each node is visited at
    most once; every group in ``groups`` must have at least one visited node. Maximise the prize.
    An empty route costs nothing (the vehicle stays home).
    """

    coords: np.ndarray
    prizes: np.ndarray
    start: np.ndarray
    end: np.ndarray
    budget: float
    n_vehicles: int
    e_fly: float = 1.0
    e_image: float = 0.0
    groups: tuple[tuple[int, ...], ...] = ()
    name: str = "top"
    kind: str = "top"  # "sar" when built from a SARInstance, else "top"
    targets: np.ndarray | None = field(default=None, compare=False)  # SAR only, for plots
    group_of: np.ndarray | None = field(default=None, compare=False)  # node -> group id or -1

    def __post_init__(self):
        coords = _points("coords", self.coords, allow_empty=True)
        if coords.shape[0] > MAX_NODES:  # before any (V+2)² matrix exists
            raise too_large(f"{coords.shape[0]} nodes", MAX_NODES, "nodes")
        object.__setattr__(self, "coords", coords)
        prizes = np.asarray(self.prizes, dtype=float).reshape(-1)
        if prizes.shape[0] != coords.shape[0]:
            raise InstanceError(f"prizes has {prizes.shape[0]} entries for {coords.shape[0]} nodes")
        if not np.all(np.isfinite(prizes)) or np.any(prizes < 0):
            raise InstanceError("prizes must be finite and >= 0")
        if prizes.size and prizes.max() > MAX_MAGNITUDE:
            check_magnitude(f"prizes[{int(np.argmax(prizes))}]", float(prizes.max()))
        prizes = prizes.copy()
        prizes.setflags(write=False)
        object.__setattr__(self, "prizes", prizes)
        for name in ("start", "end"):
            pt = _points(name, [getattr(self, name)])[0]
            object.__setattr__(self, name, pt)
        object.__setattr__(self, "budget", _finite("budget", self.budget, nonnegative=True))
        object.__setattr__(self, "n_vehicles", _count("n_vehicles", self.n_vehicles))
        if self.n_vehicles > MAX_VEHICLES:
            raise too_large(f"n_vehicles = {shown(self.n_vehicles)}", MAX_VEHICLES, "vehicles")
        object.__setattr__(self, "e_fly", _finite("e_fly", self.e_fly, positive=True))
        object.__setattr__(self, "e_image", _finite("e_image", self.e_image, nonnegative=True))
        groups = tuple(tuple(int(i) for i in g) for g in self.groups)
        group_of = np.full(coords.shape[0], -1, dtype=int)
        for gi, g in enumerate(groups):
            if not g:
                raise InstanceError(f"group {gi} is empty")
            for i in g:
                if not 0 <= i < coords.shape[0]:
                    raise InstanceError(f"group {gi} names unknown node {i}")
                group_of[i] = gi
        group_of.setflags(write=False)
        object.__setattr__(self, "groups", groups)
        object.__setattr__(self, "group_of", group_of)

    @property
    def n_nodes(self) -> int:
        return int(self.coords.shape[0])

    @property
    def total_prize(self) -> float:
        return float(self.prizes.sum())

    @property
    def same_depot(self) -> bool:
        return bool(np.array_equal(self.start, self.end))

    def depot_coords(self) -> np.ndarray:
        """All points in solver order: index 0 = start, 1..V = nodes, V+1 = end."""
        return np.vstack([self.start[None, :], self.coords, self.end[None, :]])

    def _cached(self, name: str, make) -> np.ndarray:
        """A read-only array computed once per instance (the instance is immutable)."""
        cache = self.__dict__.setdefault("_cache", {})
        if name not in cache:
            value = make()
            value.setflags(write=False)
            cache[name] = value
        return cache[name]

    def distance_matrix(self) -> np.ndarray:
        """(V+2, V+2) Euclidean distances in solver order (see :meth:`depot_coords`); read-only."""
        def make():  # cdist: the result alone, without the (V+2, V+2, 2) temporaries of broadcasting
            from scipy.spatial.distance import cdist  # here, so that `import sarcover` does not load scipy.spatial

            return cdist(self.depot_coords(), self.depot_coords())

        return self._cached("distance", make)

    def cost_matrix(self) -> np.ndarray:
        """(V+2, V+2) arc energies c_ij = e_fly·d_ij + e_image·[j is a node], solver order; read-only."""
        def make():
            cost = self.e_fly * self.distance_matrix()
            cost[:, 1 : self.n_nodes + 1] += self.e_image
            return cost

        return self._cached("cost", make)

    def round_trip_cost(self) -> np.ndarray:
        """(V,) energy of the route start → node → end alone; read-only."""
        def make():
            cost = self.cost_matrix()
            idx = np.arange(1, self.n_nodes + 1)
            return cost[0, idx] + cost[idx, self.n_nodes + 1]

        return self._cached("round_trip", make)

    def reachable(self) -> np.ndarray:
        """(V,) bool: nodes some vehicle can visit alone and still end within the budget."""
        return self.round_trip_cost() <= self.budget * (1.0 + 1e-9)


def to_top(sar: SARInstance) -> TOPInstance:
    """Map a SAR instance onto the TOP form: unit prizes, one group (K views) per target."""
    views = sar.viewpoints()
    k = sar.n_views
    groups = tuple(tuple(range(m * k, (m + 1) * k)) for m in range(sar.n_targets))
    return TOPInstance(
        coords=views,
        prizes=np.ones(views.shape[0]),
        start=np.zeros(2),
        end=np.zeros(2),
        budget=sar.e_max,
        n_vehicles=sar.n_uavs,
        e_fly=sar.e_fly,
        e_image=sar.e_image,
        groups=groups,
        name=sar.name,
        kind="sar",
        targets=sar.targets,
    )


def precheck(instance: TOPInstance) -> str | None:
    """Return why the instance is infeasible on its face, or None.

    A group none of whose nodes can be reached and returned from within the budget cannot be
    covered. Whether all groups fit into N routes together is left to the solvers.
    """
    if not instance.groups:
        return None
    trip = instance.round_trip_cost()
    ok = trip <= instance.budget * (1.0 + 1e-9)
    for gi, g in enumerate(instance.groups):
        if not ok[list(g)].any():
            cheapest = float(trip[list(g)].min())
            what = "target" if instance.kind == "sar" else "group"
            return (
                f"{what} {gi} cannot be covered: its cheapest viewpoint round trip needs "
                f"{cheapest:.6g} energy > E_max {instance.budget:.6g}"
            )
    return None
