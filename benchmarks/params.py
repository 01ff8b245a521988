"""Method parameters: declared in one dataclass per method, checked and resolved in one place.

A method declares its parameters as a frozen dataclass whose fields carry a one-line meaning
(:func:`param`), and names it with :func:`takes`::

    @dataclass(frozen=True)
    class PSOParams:
        iterations: int = param(100, "PSO iterations per cluster", minimum=1)

    @takes(PSOParams)
    def adpc_pso(instance, *, seed, time_limit, **params): ...

:func:`resolve` turns what a user gave (``{"iterations": 300}``) into the method's fully resolved
parameters (every field, JSON-serialisable), or raises :class:`ParamError`, one line naming the
method's valid parameters. A method without a dataclass takes no parameters, unless it accepts
``**params``: then whatever is given passes through as it is.

A *variant* is a method with some parameters fixed, named as benchopt names them:
``adpc-pso[iterations=300]`` (:func:`variant_name`, read back by :func:`split_variant`).
Values are TOML literals (:func:`literal`), so a name reads back to the same values.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import json
import math
import tomllib
import types
import typing
from typing import Any, Callable, Literal

from sarcover.formulations.errors import SarcoverError


class ParamError(SarcoverError):
    """An unknown parameter or a bad value; the message names the method's valid parameters."""


def param(default, help: str, *, minimum: float | None = None, maximum: float | None = None):
    """A dataclass field: its default, its one-line meaning, and optional bounds (inclusive)."""
    return dataclasses.field(default=default, metadata={"help": help, "minimum": minimum, "maximum": maximum})


def takes(params_class: type | str) -> Callable:
    """Decorator: the method's parameters are the fields of ``params_class``, a dataclass or its
    ``"module:Name"`` (imported when first asked for, so that listing methods stays light)."""

    def mark(fn):
        fn.params = params_class
        return fn

    return mark


def params_class(fn) -> type | None:
    """The parameters dataclass a method declares (its ``params`` attribute), or None."""
    cls = getattr(fn, "params", None)
    if isinstance(cls, str):
        module, _, name = cls.partition(":")
        cls = getattr(importlib.import_module(module), name)
    return cls if isinstance(cls, type) and dataclasses.is_dataclass(cls) else None


def accepts_any(fn) -> bool:
    """True if ``fn`` takes ``**params`` (then parameters it does not declare pass through)."""
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return False
    return any(p.kind is inspect.Parameter.VAR_KEYWORD for p in sig.parameters.values())


# -- describing ------------------------------------------------------------------------------------
def type_name(tp) -> str:
    """A type as a user reads it: ``int``, ``float or none``, ``one of 'multi', 'vehicle'``."""
    origin = typing.get_origin(tp)
    if origin is Literal:
        return "one of " + ", ".join(literal(v) for v in typing.get_args(tp))
    if origin in (typing.Union, types.UnionType):
        args = typing.get_args(tp)
        return " or ".join("none" if a is type(None) else type_name(a) for a in args)
    return getattr(tp, "__name__", str(tp))


def fields(cls: type) -> list[tuple[str, Any, Any, str]]:
    """(name, type, default, one-line meaning) of each parameter of ``cls``."""
    hints = typing.get_type_hints(cls)
    return [(f.name, hints[f.name], f.default, f.metadata.get("help", "")) for f in dataclasses.fields(cls)]


def describe(cls: type | None) -> str:
    """The valid parameters of ``cls`` on one line: ``iterations (int, 100), xi (float, 0.25)``."""
    if cls is None:
        return "none"
    return ", ".join(f"{n} ({type_name(t)}, {literal(d)})" for n, t, d, _ in fields(cls))


# -- checking --------------------------------------------------------------------------------------
def _coerce(value, tp, where: str):
    """``value`` as type ``tp`` (an int is a float; a bool is never a number), or ParamError."""
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        args = typing.get_args(tp)
        if value is None and type(None) in args:
            return None
        for arg in args:
            if arg is type(None):
                continue
            try:
                return _coerce(value, arg, where)
            except ParamError:
                continue
        raise ParamError(f"{where} must be {type_name(tp)}, got {literal(value)}")
    if origin is Literal:
        if value in typing.get_args(tp) and type(value) in {type(a) for a in typing.get_args(tp)}:
            return value
        raise ParamError(f"{where} must be {type_name(tp)}, got {literal(value)}")
    if tp is bool:
        if isinstance(value, bool):
            return value
    elif tp is int:
        if isinstance(value, int) and not isinstance(value, bool):
            return value
    elif tp is float:
        if isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value):
            return float(value)
    elif tp is str:
        if isinstance(value, str):
            return value
    raise ParamError(f"{where} must be {type_name(tp)}, got {literal(value)}")


def resolve(method: str, fn, given: dict | None) -> dict:
    """The fully resolved parameters of ``method`` (entry point ``fn``) given ``given``.

    With a parameters dataclass: every field, the given values checked against its type and
    bounds, the others at their defaults. Without one: ``given`` as it is if ``fn`` accepts
    ``**params``, else nothing may be given. Raises :class:`ParamError` (one line).
    """
    given = dict(given or {})
    cls = params_class(fn)
    if cls is None:
        if given and not accepts_any(fn):
            raise ParamError(f"method {method!r} takes no parameters, got {sorted(given)[0]!r}")
        for key, value in given.items():
            try:
                json.dumps(value)
            except (TypeError, ValueError):
                raise ParamError(f"method {method!r}: parameter {key!r} is not a plain value") from None
        return given
    spec = {n: (t, d) for n, t, d, _ in fields(cls)}
    meta = {f.name: f.metadata for f in dataclasses.fields(cls)}
    for key in given:
        if key not in spec:
            raise ParamError(f"method {method!r}: unknown parameter {key!r}; valid: {describe(cls)}")
    out = {}
    for name, (tp, default) in spec.items():
        if name not in given:
            out[name] = default
            continue
        where = f"method {method!r}: parameter {name!r}"
        value = _coerce(given[name], tp, where)
        lo, hi = meta[name].get("minimum"), meta[name].get("maximum")
        if value is not None and not isinstance(value, (bool, str)):
            if (lo is not None and value < lo) or (hi is not None and value > hi):
                bounds = (f"in [{literal(lo)}, {literal(hi)}]" if lo is not None and hi is not None
                          else f">= {literal(lo)}" if lo is not None else f"<= {literal(hi)}")
                raise ParamError(f"{where} must be {bounds}, got {literal(value)}")
        out[name] = value
    try:  # a dataclass may check more in __post_init__ (a ValueError naming the problem)
        cls(**out)
    except (TypeError, ValueError) as exc:
        raise ParamError(f"method {method!r}: {exc}") from None
    return out


# -- values and variant names ----------------------------------------------------------------------
def literal(value) -> str:
    """``value`` as a TOML literal: ``300``, ``0.5``, ``true``, ``"tabu"``; None as ``none``."""
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        return f"{value:.1f}"
    return repr(value) if isinstance(value, (int, float)) else json.dumps(value)


def parse_literal(text: str):
    """A value from the command line or a variant name: a TOML literal (``300``, ``0.5``,
    ``true``, ``"a b"``, ``[1, 2]``), ``none`` for None (TOML has no null), else the text itself
    as a string (``tabu``)."""
    if text == "none":
        return None
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def parse_assignment(text: str) -> tuple[str, Any]:
    """``KEY=VALUE`` (``--param``) as (key, value read by :func:`parse_literal`)."""
    key, sep, value = text.partition("=")
    key = key.strip()
    if not sep or not key:
        raise ParamError(f"--param takes KEY=VALUE, got {text!r}")
    return key, parse_literal(value.strip())


def variant_name(base: str, values: dict) -> str:
    """``adpc-pso[iterations=300]``: ``base`` with the parameters of ``values`` fixed, in order."""
    if not values:
        return base
    return f"{base}[{','.join(f'{k}={_name_value(v)}' for k, v in values.items())}]"


def _name_value(value) -> str:
    """A value as it reads in a variant name: a TOML literal, a plain word unquoted."""
    if isinstance(value, str) and value and all(c.isalnum() or c in "_-." for c in value) \
            and parse_literal(value) == value:
        return value
    return literal(value)


def split_variant(name: str) -> tuple[str, dict]:
    """(base name, fixed parameters) of a variant name; (name, {}) for a plain name."""
    if not (name.endswith("]") and "[" in name):
        return name, {}
    base, _, inner = name[:-1].partition("[")
    values = {}
    for part in filter(str.strip, split_top(inner)):
        key, sep, text = part.partition("=")
        if not sep or not key.strip():
            raise ParamError(f"method {name!r}: {part!r} is not KEY=VALUE")
        values[key.strip()] = parse_literal(text.strip())
    return base, values


def split_top(text: str) -> list[str]:
    """``text`` split at the commas outside quotes and brackets (empty parts kept)."""
    parts, depth, quote, start = [], 0, None, 0
    for i, c in enumerate(text):
        if quote:
            quote = None if c == quote else quote
        elif c in "\"'":
            quote = c
        elif c == "[":
            depth += 1
        elif c == "]":
            depth -= 1
        elif c == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return parts
