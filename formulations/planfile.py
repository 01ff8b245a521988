"""Plan files: a plan written down as JSON, so plans can come from outside sarcover.

A plan file names its instance and gives one route per vehicle::

    {"format": "sarcover-plan", "version": 1, "instance": "sar-m20-k3-n5-s7",
     "routes": [[0, 4, 5], [31, 30], []], "method": "greedy"}

- ``instance``: the instance's name (a sarcover JSON instance's ``name`` field; a TOP file's
  name without ``.txt``, such as ``p2.3.g``). A plan read against an instance of another name is
  refused: it was made for another instance.
- ``routes``: at most one list per vehicle (fewer lists: the other vehicles stay at the base),
  each the ids of the nodes the vehicle visits, in order, leaving out the base (every route
  starts at the instance's start and ends at its end). Ids are 0-based node indices of the
  instance's TOP form (:func:`~sarcover.formulations.instance.to_top`): on a SAR instance view
  ``k`` of target ``m`` (both from 0) is ``m * K + k``; on a TOP file customer ``i`` is the
  ``i``-th point row after the start depot's row (the first row is the start depot and the last
  the end depot, neither of which has an id). These are the ids of ``routes`` in ``sarcover
  solve --json`` and of :class:`~sarcover.formulations.plan.Plan`.
- ``method``: optional, who made the plan (``sarcover solve --plan-out`` writes it).

Reading checks the shape: ids that are not integers or name no node of the instance are bad input
(:class:`PlanFileError`), while a plan that breaks a constraint (a node twice, a route over the
budget, a target without a view, more routes than vehicles) is read as it is, for the verifier
to reject.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from sarcover.formulations.errors import SarcoverError
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.io import read_json_file
from sarcover.formulations.limits import shown
from sarcover.formulations.plan import Plan

FORMAT = "sarcover-plan"
FORMAT_VERSION = 1
REQUIRED = ("format", "version", "instance", "routes")
ALL_FIELDS = REQUIRED + ("method",)  # a file with any other field is refused


class PlanFileError(SarcoverError, ValueError):
    """A plan file that cannot be read, or that does not fit its instance; the message names it."""


@dataclass(frozen=True)
class PlanFile:
    """A plan as read from a file: the instance it names, its routes, who made it."""

    instance: str
    plan: Plan
    method: str | None = None


def _shown(value) -> str:
    """A JSON value for a one-line message: a number as :func:`shown` writes it, anything else
    (a string, a list) as its short repr, so that ``"3"`` is not mistaken for ``3``."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return shown(value)
    return repr(value)[:40]


def plan_to_dict(plan: Plan, instance: str, method: str | None = None) -> dict:
    """The JSON object of a plan file for ``plan`` on the instance named ``instance``."""
    data = {"format": FORMAT, "version": FORMAT_VERSION, "instance": instance,
            "routes": [list(r) for r in plan.routes]}
    if method is not None:
        data["method"] = method
    return data


def save_plan(plan: Plan, path: str | Path, instance: str, method: str | None = None) -> None:
    """Write ``plan`` as a plan file (one route per line, so that a reader can follow it)."""
    data = plan_to_dict(plan, instance, method)
    routes = ",\n  ".join(json.dumps(r) for r in data.pop("routes"))
    head = json.dumps(data)[:-1]  # the fields before the routes, without the closing brace
    Path(path).write_text(f'{head}, "routes": [\n  {routes}\n]}}\n' if routes else f'{head}, "routes": []}}\n')


def plan_from_dict(data, instance: TOPInstance | None = None, source: str = "plan") -> PlanFile:
    """Validate a decoded plan object; with ``instance``, also that it names that instance and
    every id is one of its nodes. Errors name the field (``routes[1][3]``)."""
    if not isinstance(data, dict):
        raise PlanFileError(f"{source}: top level must be a JSON object")
    if data.get("format") != FORMAT:
        raise PlanFileError(f"{source}: field 'format' must be {FORMAT!r}")
    for name in REQUIRED:
        if name not in data:
            raise PlanFileError(f"{source}: missing field '{name}'")
    if isinstance(data["version"], bool) or data["version"] != FORMAT_VERSION:
        raise PlanFileError(f"{source}: field 'version' is {shown(data['version'])}; this sarcover reads "
                            f"version {FORMAT_VERSION}")
    unknown = sorted(str(k) for k in data if k not in ALL_FIELDS)
    if unknown:  # a misspelt field would otherwise be ignored silently
        raise PlanFileError(f"{source}: unknown field {unknown[0][:40]!r}; a sarcover plan has "
                            f"{', '.join(ALL_FIELDS)}")
    name = data["instance"]
    if not isinstance(name, str):
        raise PlanFileError(f"{source}: field 'instance' must be the instance's name (a string)")
    if instance is not None and name != instance.name:  # checked first: the likeliest mistake
        raise PlanFileError(f"{source}: the plan is for instance {name[:80]!r}, not {instance.name[:80]!r}")
    method = data.get("method")
    if method is not None and not isinstance(method, str):
        raise PlanFileError(f"{source}: field 'method' must be a string")
    routes = data["routes"]
    if not isinstance(routes, list):
        raise PlanFileError(f"{source}: field 'routes' must be a list of routes (lists of node ids)")
    n = instance.n_nodes if instance is not None else None
    for r, route in enumerate(routes):
        if not isinstance(route, list):
            raise PlanFileError(f"{source}: field 'routes[{r}]' must be a list of node ids, got {_shown(route)}")
        for i, v in enumerate(route):
            if isinstance(v, bool) or not isinstance(v, int):
                raise PlanFileError(f"{source}: field 'routes[{r}][{i}]' must be an integer node id, got {_shown(v)}")
            if v < 0 or (n is not None and v >= n):
                what = "viewpoints" if instance is not None and instance.kind == "sar" else "nodes"
                have = f"{what} 0..{n - 1}" if n else f"no {what}"
                raise PlanFileError(f"{source}: field 'routes[{r}][{i}]' is {shown(v)}, not a node id"
                                    + (f" (instance {instance.name!r} has {have})" if n is not None else ""))
    return PlanFile(instance=name, plan=Plan.of(routes), method=method)


def load_plan(path: str | Path, instance: TOPInstance | None = None) -> PlanFile:
    """Read and validate the plan file at ``path`` (against ``instance`` if given)."""
    path = Path(path)
    return plan_from_dict(read_json_file(path, PlanFileError, "a plan file"), instance, source=str(path))
