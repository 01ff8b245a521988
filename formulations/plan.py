"""Plans: one route per vehicle (what every method returns is in :mod:`.result`)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Plan:
    """One route per vehicle: ordered node ids (viewpoint ids on a SAR instance)."""

    routes: tuple[tuple[int, ...], ...]

    @classmethod
    def of(cls, routes) -> "Plan":
        return cls(tuple(tuple(int(v) for v in r) for r in routes))

    @property
    def visited(self) -> list[int]:
        return [v for r in self.routes for v in r]
