"""Instance files: the sarcover JSON format and the classic TOP benchmark text format."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from sarcover.formulations.errors import InstanceError
from sarcover.formulations.instance import SARInstance, TOPInstance, to_top
from sarcover.formulations.limits import MAX_MAGNITUDE, MAX_NODES, MAX_VEHICLES, TooLargeError, shown, too_large

FORMAT = "sarcover-instance"
FORMAT_VERSION = 1
SAR_FIELDS = ("targets", "views", "uavs", "altitude", "pitch_deg", "e_fly", "e_image", "e_max")
ALL_FIELDS = ("format", "version", "name") + SAR_FIELDS  # a file with any other field is refused


def sar_to_dict(sar: SARInstance) -> dict:
    return {
        "format": FORMAT,
        "version": FORMAT_VERSION,
        "name": sar.name,
        "targets": sar.targets.tolist(),
        "views": sar.n_views,
        "uavs": sar.n_uavs,
        "altitude": sar.altitude,
        "pitch_deg": sar.pitch_deg,
        "e_fly": sar.e_fly,
        "e_image": sar.e_image,
        "e_max": sar.e_max,
    }


def save_json(sar: SARInstance, path: str | Path) -> None:
    Path(path).write_text(json.dumps(sar_to_dict(sar), indent=1) + "\n")


def sar_from_dict(data, source: str = "instance") -> SARInstance:
    """Validate a decoded JSON object and build the instance; errors name the field."""
    if not isinstance(data, dict):
        raise InstanceError(f"{source}: top level must be a JSON object")
    if data.get("format") != FORMAT:
        raise InstanceError(f"{source}: field 'format' must be {FORMAT!r}")
    if "version" not in data:
        raise InstanceError(f"{source}: missing field 'version'")
    if isinstance(data["version"], bool) or data["version"] != FORMAT_VERSION:
        raise InstanceError(
            f"{source}: field 'version' is {shown(data['version'])}; this sarcover reads version {FORMAT_VERSION}"
        )
    for name in SAR_FIELDS:
        if name not in data:
            raise InstanceError(f"{source}: missing field '{name}'")
    unknown = sorted(str(k) for k in data if k not in ALL_FIELDS)
    if unknown:  # a misspelt field would otherwise be ignored silently
        raise InstanceError(f"{source}: unknown field {unknown[0][:40]!r}; a sarcover instance has "
                            f"{', '.join(ALL_FIELDS)}")
    if not isinstance(data.get("name", ""), str):
        raise InstanceError(f"{source}: field 'name' must be a string")
    targets = data["targets"]
    if not isinstance(targets, list) or not targets:
        raise InstanceError(f"{source}: field 'targets' must be a non-empty list of [x, y] pairs")
    for i, t in enumerate(targets):
        if (
            not isinstance(t, list)
            or len(t) != 2
            or not all(isinstance(c, (int, float)) and not isinstance(c, bool) for c in t)
        ):
            raise InstanceError(f"{source}: field 'targets[{i}]' must be a pair of numbers, got {shown(t)}")
        if not all(isinstance(c, int) or math.isfinite(c) for c in t):
            raise InstanceError(f"{source}: field 'targets[{i}]' has a coordinate that is not finite")
        if not all(abs(c) <= MAX_MAGNITUDE for c in t):
            raise InstanceError(f"{source}: field 'targets[{i}]' has a coordinate beyond ±{MAX_MAGNITUDE:g} "
                                f"(larger numbers would overflow the energy sums)")
    for name in ("altitude", "pitch_deg", "e_fly", "e_image", "e_max"):
        v = data[name]
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise InstanceError(f"{source}: field '{name}' must be a number, got {v!r}")
    try:
        return SARInstance(
            targets=np.array(targets, dtype=float),
            n_views=data["views"],
            n_uavs=data["uavs"],
            altitude=data["altitude"],
            pitch_deg=data["pitch_deg"],
            e_fly=data["e_fly"],
            e_image=data["e_image"],
            e_max=data["e_max"],
            name=data.get("name", source),
        )
    except TooLargeError as exc:
        raise TooLargeError(f"{source}: {exc}") from None
    except InstanceError as exc:
        raise InstanceError(f"{source}: field {exc}") from None


def load_sar(path: str | Path) -> SARInstance:
    path = Path(path)
    return sar_from_dict(read_json_file(path), source=str(path))


def read_json_file(path: Path, error: type[Exception] = InstanceError, kind: str = "an instance file"):
    """The JSON value in ``path``, or ``error`` with one line naming why it cannot be read."""
    text = read_text_file(path, error, kind)
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise error(f"{path}: not valid JSON ({exc.msg} at line {exc.lineno})") from None
    except ValueError as exc:  # e.g. an integer of more digits than Python converts
        raise error(f"{path}: not valid JSON ({str(exc).splitlines()[0][:80]})") from None
    except RecursionError:
        raise error(f"{path}: not valid JSON (nested too deeply)") from None


def read_top(path: str | Path) -> TOPInstance:
    """Read a Chao–Golden–Wasil TOP file: E_F = 1, E_I = 0, budget tmax, Euclidean distances."""
    path = Path(path)
    lines = [ln.split() for ln in read_text_file(path).splitlines() if ln.strip()]
    header: dict[str, float] = {}
    for key, row in zip(("n", "m", "tmax"), lines[:3]):
        if len(row) != 2 or row[0] != key:
            raise InstanceError(f"{path}: expected a '{key} <value>' line, got {' '.join(row)!r}")
        try:
            header[key] = float(row[1])
        except ValueError:
            raise InstanceError(f"{path}: '{key}' is not a number: {row[1]!r}") from None
    if len(header) < 3:
        raise InstanceError(f"{path}: missing the n, m, tmax header")
    for key in ("n", "m"):
        if not header[key].is_integer() or header[key] < 1:  # also refuses nan and inf
            raise InstanceError(f"{path}: '{key}' must be a positive integer, got {shown(header[key])}")
    n, m = int(header["n"]), int(header["m"])
    if n > MAX_NODES + 2:  # checked before any point array is built
        raise too_large(f"{path}: n = {shown(n)} points", MAX_NODES + 2, "points")
    if m > MAX_VEHICLES:
        raise too_large(f"{path}: m = {shown(m)} vehicles", MAX_VEHICLES, "vehicles")
    rows = lines[3:]
    if n < 2 or len(rows) != n:
        raise InstanceError(f"{path}: header says n {n} points, file has {len(rows)} point rows")
    try:
        pts = np.array([[float(c) for c in r[:3]] for r in rows])
    except ValueError:
        raise InstanceError(f"{path}: a point row is not 'x y score' numbers") from None
    if pts.shape[1] != 3 or not np.all(np.isfinite(pts)):
        raise InstanceError(f"{path}: every point row needs finite 'x y score'")
    try:
        return TOPInstance(
            coords=pts[1:-1, :2],
            prizes=pts[1:-1, 2],
            start=pts[0, :2],
            end=pts[-1, :2],
            budget=header["tmax"],
            n_vehicles=m,
            e_fly=1.0,
            e_image=0.0,
            name=path.stem,
            kind="top",
        )
    except InstanceError as exc:
        raise type(exc)(f"{path}: {exc}") from None


def load_instance(path: str | Path) -> TOPInstance:
    """Load a JSON SAR instance or a TOP benchmark file into the TOP form."""
    path = Path(path)
    text = read_text_file(path).lstrip()
    if text.startswith("{") or path.suffix.lower() == ".json":
        return to_top(load_sar(path))
    if text.startswith("n"):
        return read_top(path)
    raise InstanceError(f"{path}: neither a sarcover JSON instance nor a TOP benchmark file")


def read_text_file(path: Path, error: type[Exception] = InstanceError, kind: str = "an instance file") -> str:
    """The text of ``path``, or ``error`` with one line naming why it cannot be read (``kind``
    names what the file should have been)."""
    try:
        return path.read_text()
    except FileNotFoundError:
        raise error(f"{path}: no such file") from None
    except IsADirectoryError:
        raise error(f"{path}: is a directory, not {kind}") from None
    except UnicodeDecodeError:
        raise error(f"{path}: not a text file") from None
    except OSError as exc:
        raise error(f"{path}: cannot read ({exc.strerror})") from None
    except ValueError:  # a name the operating system cannot take (a NUL byte)
        raise error(f"{str(path)!r}: not a usable file name") from None
