"""Benchmark suites as data: a TOML file names instance sets × methods × runs, with time limits.

Schema (every key but ``methods`` and ``[[instances]]`` is optional)::

    name = "quick"                     # default: the file name without .toml
    description = "one line"
    methods = ["greedy", "milp"]       # registry names (see `sarcover methods`), or "module:function"
    time_limit = 10.0                  # seconds per job (default 60)
    seeds = 1                          # method seeds per instance (default 1)
    grace = 5.0                        # hard kill at time_limit + grace (default 5 s + 20 % of the limit)
    memory_mb = 4096                   # address-space limit per worker process in MB; 0 = none (default 4096)

    [method.milp]                      # per-method overrides: time_limit, seeds, grace
    time_limit = 30
    [method.bp.params]                 # the method's parameters (`sarcover methods bp` lists them)
    enum_share = 0.0
    [method.adpc-pso.grid]             # lists: one variant per combination, a method of its own
    iterations = [100, 300]            # named adpc-pso[iterations=100], adpc-pso[iterations=300]

    [[instances]]                      # random SAR instances: the grid M × K × N, `runs` instances each
    M = 20                             # an integer or a list of integers (same for K, N)
    K = 3
    N = [2, 3, 4, 5, 6]
    runs = 1000                        # random instances per (M, K, N) setting: seeds seed, seed+1, ...
    seed = 0                           # first instance seed (default 0)
    preset = "paper"                   # generator preset; overrides: altitude, pitch_deg, e_fly, e_image, e_max
    methods = ["greedy"]               # optional: only these of the suite's methods on this set
    [instances.method.bp]              # optional: per-method overrides for this set only
    time_limit = 300

    [[instances]]                      # instance files
    files = ["p2.2.*", "my.json"]      # a bare name or glob is looked up among the TOP benchmark files
                                       # (benchmarks/instances/top); anything else is a path (glob allowed)
                                       # relative to the suite file

What a run is. A job is one (instance, method, method seed). On a random SAR set a *run* is a new
random instance, as in the paper (1000 random instances per setting): the instance seeds are
``seed .. seed + runs - 1``, and ``sarcover bench --runs R`` replaces every set's ``runs``. On top
of that each method runs with ``seeds`` method seeds (0 .. seeds-1) per instance, so a setting has
runs × seeds jobs per method. Files are fixed instances: only ``seeds`` repeats them.

A method named ``"package.module:function"`` (an importable module-level function with the method
signature) is registered for the run under that name; this is how tests add crashing or hanging
methods. A method may also be named as a variant (``"adpc-pso[iterations=300]"``), and a
``[method.NAME.grid]`` makes one variant per combination of its lists (their cross product, in
the order the keys are written), each a method of its own in rows, tables and plots; a
``[[instances]]`` set's ``methods`` and ``[instances.method.NAME]`` name the methods as the
suite's ``methods`` does, and apply to all their variants. Each job carries its method's fully
resolved parameters (``Job.params``). Everything is checked at load: an unknown method, a bad
parameter or a missing file gives one :class:`SuiteError` line naming the problem.
"""

from __future__ import annotations

import glob
import hashlib
import itertools
import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path

from sarcover.benchmarks.catalog import TOP_DIR, is_benchmark_name, published
from sarcover.benchmarks.methods import DEFAULT_TIME_LIMIT
from sarcover.formulations.errors import SarcoverError

SUITES_DIR = Path(__file__).resolve().parent / "suites"

DEFAULT_MEMORY_MB = 4096
_SUITE_KEYS = {"name", "description", "methods", "time_limit", "seeds", "grace", "memory_mb", "method", "instances"}
_METHOD_KEYS = {"time_limit", "seeds", "grace", "params", "grid"}
_GEN_KEYS = {"M", "K", "N", "runs", "seed", "preset", "methods", "label", "method"}
_GEN_OVERRIDES = ("altitude", "pitch_deg", "e_fly", "e_image", "e_max")
_FILE_KEYS = {"files", "methods", "label", "method"}


class SuiteError(SarcoverError):
    """A suite file that cannot be run; the message names the file and the problem."""


@dataclass(frozen=True)
class Job:
    """One (instance, method, method seed). ``source`` tells a worker how to build the instance."""

    key: str
    instance: str
    method: str
    seed: int
    run: int
    time_limit: float
    grace: float
    source: dict = field(hash=False, compare=False)
    params: dict = field(default_factory=dict, hash=False, compare=False)  # the method's, fully resolved

    def as_dict(self) -> dict:
        return {
            "key": self.key, "instance": self.instance, "method": self.method, "seed": self.seed,
            "run": self.run, "time_limit": self.time_limit, "grace": self.grace, "source": self.source,
            "params": self.params,
        }


@dataclass
class Suite:
    name: str
    path: Path
    text: str
    description: str
    methods: list[str]
    jobs: list[Job]
    memory_mb: int

    @property
    def n_instances(self) -> int:
        return len({j.instance for j in self.jobs})


def builtin_suites() -> list[str]:
    return sorted(p.stem for p in SUITES_DIR.glob("*.toml"))


def resolve_suite_path(name_or_path: str) -> Path:
    """A built-in suite name (``quick``) or a path to a TOML file."""
    builtin = SUITES_DIR / f"{name_or_path}.toml"
    if "/" not in name_or_path and not name_or_path.endswith(".toml") and builtin.exists():
        return builtin
    path = Path(name_or_path)
    if path.is_file():
        return path
    known = ", ".join(builtin_suites())
    raise SuiteError(f"no suite {name_or_path!r}: not a built-in suite ({known}) nor an existing file")


def load_suite(name_or_path: str, *, runs: int | None = None, methods: list[str] | None = None) -> Suite:
    """Read, validate and expand a suite into jobs. ``runs`` replaces every random set's ``runs``;
    ``methods`` keeps only those of the suite's methods (a name as the suite lists it keeps all
    its variants; job keys stay the same, so a run of a subset and a later run of the whole suite
    with ``--resume`` share one results directory)."""
    path = resolve_suite_path(name_or_path)
    where = path.name
    try:
        text = path.read_text()
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SuiteError(f"suite {where}: not valid TOML ({exc})") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SuiteError(f"suite {where}: cannot read ({exc})") from None
    suite, listed = _build(data, path, text, runs)
    if methods is not None:
        unknown = [m for m in methods if m not in suite.methods and m not in listed]
        if unknown:
            raise SuiteError(f"suite {where}: --methods names {unknown[0]!r}, not one of the suite's methods "
                             f"({', '.join(suite.methods)})")
        wanted = set(methods) | {v for m in methods for v in listed.get(m, ())}
        keep = [m for m in suite.methods if m in wanted]
        suite = replace(suite, methods=keep, jobs=[j for j in suite.jobs if j.method in keep])
    return suite


def _build(data: dict, path: Path, text: str, runs_override: int | None) -> tuple[Suite, dict[str, list[str]]]:
    """The suite, and the variant names of each method as the suite lists it."""
    where = f"suite {path.name}"
    _no_unknown(data, _SUITE_KEYS, where)
    name = data.get("name", path.stem)
    if not isinstance(name, str) or not name or "/" in name:
        raise SuiteError(f"{where}: name must be a non-empty string without '/', got {name!r}")
    methods = data.get("methods")
    if not isinstance(methods, list) or not methods or not all(isinstance(m, str) for m in methods):
        raise SuiteError(f"{where}: methods must be a non-empty list of method names")
    if len(set(methods)) != len(methods):
        raise SuiteError(f"{where}: methods lists a method twice")
    exact = {m: check_method(m, where) for m in methods}
    defaults = {
        "time_limit": _number(data.get("time_limit", DEFAULT_TIME_LIMIT), f"{where}: time_limit"),
        "seeds": _integer(data.get("seeds", 1), f"{where}: seeds", 1),
        "grace": data.get("grace"),
    }
    if defaults["grace"] is not None:
        defaults["grace"] = _number(defaults["grace"], f"{where}: grace", allow_zero=True)
    memory_mb = _integer(data.get("memory_mb", DEFAULT_MEMORY_MB), f"{where}: memory_mb", 0)
    per_method = data.get("method", {})
    if not isinstance(per_method, dict):
        raise SuiteError(f"{where}: [method.NAME] tables expected")
    options = {}
    for m in methods:
        options[m] = dict(defaults)
    options = _method_options(per_method, options, methods, where, "method")
    variants = {m: _variants(m, per_method.get(m, {}), where) for m in methods}
    names = [v for m in methods for v, _ in variants[m]]
    if len(set(names)) != len(names):
        twice = next(n for n in names if names.count(n) > 1)
        raise SuiteError(f"{where}: method {twice!r} is listed twice (by name or by a grid)")
    sets = data.get("instances")
    if not isinstance(sets, list) or not sets or not all(isinstance(s, dict) for s in sets):
        raise SuiteError(f"{where}: at least one [[instances]] table is needed")
    jobs: dict[str, Job] = {}
    sources: dict[str, dict] = {}
    for i, spec in enumerate(sets, 1):
        swhere = f"{where}: [[instances]] #{i}"
        set_methods = spec.get("methods", methods)
        if not isinstance(set_methods, list) or not set_methods:
            raise SuiteError(f"{swhere}: methods must be a non-empty list")
        for m in set_methods:
            if m not in methods:
                raise SuiteError(f"{swhere}: method {m!r} is not in the suite's methods")
        set_options = _method_options(spec.get("method", {}), options, methods, swhere, "instances.method")
        if "files" in spec:
            _no_unknown(spec, _FILE_KEYS, swhere)
            instances = _file_sources(spec["files"], path.parent, swhere)
        else:
            instances = _generated_sources(spec, swhere, runs_override, set_methods)
        for inst_id, source, run in instances:
            if sources.setdefault(inst_id, source) != source:
                raise SuiteError(f"{swhere}: instance name {inst_id!r} is used for two different instances")
            for m in set_methods:
                opt = set_options[m]
                for variant, params in variants[m]:
                    for s in range(opt["seeds"]):
                        tl = opt["time_limit"]
                        grace = opt["grace"] if opt["grace"] is not None else 5.0 + 0.2 * tl
                        key = f"{inst_id}|{variant}|{s}"
                        jobs.setdefault(key, Job(key, inst_id, variant, s, run * opt["seeds"] + s, tl, grace,
                                                 {**source, "exact": exact[m]}, params))
    if runs_override is not None and all("files" in spec for spec in sets):
        raise SuiteError(f"{where}: --runs sets the random instances per setting, and this suite has only files")
    suite = Suite(name, path, text, str(data.get("description", "")), names, list(jobs.values()), memory_mb)
    return suite, {m: [v for v, _ in variants[m]] for m in methods}


def _variants(method: str, table: dict, where: str) -> list[tuple[str, dict]]:
    """(name, fully resolved parameters) of each variant of ``method`` (as the suite lists it):
    its ``[method.NAME.params]`` for all, and one variant per combination of its
    ``[method.NAME.grid]`` lists, named by the grid's values (``adpc-pso[iterations=300]``)."""
    from sarcover.benchmarks.params import ParamError, variant_name
    from sarcover.benchmarks.registry import get_method

    twhere = f"{where}: [method.{method}"
    params = table.get("params", {})
    if not isinstance(params, dict):
        raise SuiteError(f"{twhere}.params] must be a table of parameter = value")
    grid = table.get("grid", {})
    if not isinstance(grid, dict) or not all(isinstance(v, list) and v for v in grid.values()):
        raise SuiteError(f"{twhere}.grid] must be a table of parameter = [values, ...] (non-empty lists)")
    twice = sorted(set(params) & set(grid))
    if twice:
        raise SuiteError(f"{twhere}]: parameter {twice[0]!r} is both in params and in grid")
    try:
        spec = get_method(method)
        out = []
        for combo in itertools.product(*grid.values()):
            values = dict(zip(grid, combo))
            resolved = spec.resolve({**params, **values})
            base = spec.base or spec.name
            name = variant_name(base, {**spec.fixed, **{k: resolved[k] for k in values}})
            out.append((name, resolved))
    except ParamError as exc:
        raise SuiteError(f"{where}: {exc}") from None
    return out


def _method_options(tables, base: dict, methods: list[str], where: str, table: str) -> dict:
    """``base`` (method -> options) with the ``[table.NAME]`` overrides of ``tables`` applied:
    the suite's ``[method.NAME]``, or an instance set's ``[instances.method.NAME]``."""
    if not isinstance(tables, dict):
        raise SuiteError(f"{where}: [{table}.NAME] tables expected")
    options = {m: dict(o) for m, o in base.items()}
    for m, opts in tables.items():
        if m not in methods:
            raise SuiteError(f"{where}: [{table}.{m}] names a method not in methods")
        if not isinstance(opts, dict):
            raise SuiteError(f"{where}: [{table}.{m}] must be a table")
        # parameters and grids are the suite's, for all its instance sets
        _no_unknown(opts, _METHOD_KEYS if table == "method" else _METHOD_KEYS - {"params", "grid"},
                    f"{where}: [{table}.{m}]")
        if "time_limit" in opts:
            options[m]["time_limit"] = _number(opts["time_limit"], f"{where}: [{table}.{m}] time_limit")
        if "seeds" in opts:
            options[m]["seeds"] = _integer(opts["seeds"], f"{where}: [{table}.{m}] seeds", 1)
        if "grace" in opts:
            options[m]["grace"] = _number(opts["grace"], f"{where}: [{table}.{m}] grace", allow_zero=True)
    return options


def check_method(name: str, where: str) -> bool:
    """Raise SuiteError unless ``name`` is a registered method, a plugin's, an importable
    module:function, or a variant of one. Returns whether the method is exact.
    """
    from sarcover.benchmarks.registry import get_method

    try:
        return get_method(name).exact
    except SarcoverError as exc:
        raise SuiteError(f"{where}: {exc}") from None


def _generated_sources(spec: dict, where: str, runs_override: int | None, methods: list[str]):
    from sarcover.benchmarks.registry import check_size
    from sarcover.formulations.errors import InstanceError
    from sarcover.formulations.generate import PRESETS, generate
    from sarcover.formulations.limits import check_sar_size

    unknown = set(spec) - _GEN_KEYS - set(_GEN_OVERRIDES)
    if unknown:
        raise SuiteError(f"{where}: unknown key {sorted(unknown)[0]!r}; a random set takes "
                         f"{', '.join(sorted(_GEN_KEYS | set(_GEN_OVERRIDES)))}, a file set takes files")
    for key in ("M", "K", "N"):
        if key not in spec:
            raise SuiteError(f"{where}: {key} is missing (or give files = [...])")
    grid = {key: _int_list(spec[key], f"{where}: {key}") for key in ("M", "K", "N")}
    runs = runs_override if runs_override is not None else _integer(spec.get("runs", 1), f"{where}: runs", 1)
    seed0 = _integer(spec.get("seed", 0), f"{where}: seed", 0)
    preset = spec.get("preset", "paper")
    if preset not in PRESETS:
        raise SuiteError(f"{where}: unknown preset {preset!r}; known: {', '.join(PRESETS)}")
    overrides = {k: _number(spec[k], f"{where}: {k}") for k in _GEN_OVERRIDES if k in spec}
    suffix = "" if preset == "paper" else f"-{preset}"
    if overrides:
        suffix += "-" + "-".join(f"{k}{v:g}" for k, v in sorted(overrides.items()))
    try:  # sizes first (no job may be beyond what its method holds), then one trial draw
        for m, k, n in itertools.product(grid["M"], grid["K"], grid["N"]):
            check_sar_size(m, k, n)
            for method in methods:
                check_size(method, m * k, n)
        generate(grid["M"][0], grid["K"][0], grid["N"][0], seed0, preset, **overrides)
    except InstanceError as exc:
        raise SuiteError(f"{where}: {exc}") from None
    out = []
    for m, k, n in itertools.product(grid["M"], grid["K"], grid["N"]):
        for r in range(runs):
            seed = seed0 + r
            inst_id = f"sar-m{m}-k{k}-n{n}-s{seed}{suffix}"
            source = {"type": "generate", "M": m, "K": k, "N": n, "instance_seed": seed,
                      "preset": preset, "overrides": overrides}
            out.append((inst_id, source, r))
    return out


def _file_sources(files, base: Path, where: str):
    if isinstance(files, str):
        files = [files]
    if not isinstance(files, list) or not files or not all(isinstance(f, str) for f in files):
        raise SuiteError(f"{where}: files must be a non-empty list of file names")
    out = []
    for entry in files:
        if is_benchmark_name(entry):
            pattern = str(TOP_DIR / f"{entry}.txt")
        else:
            pattern = str(base / entry)
        matches = sorted(glob.glob(pattern))
        if not matches:
            raise SuiteError(f"{where}: instance file {entry!r} not found ({pattern})")
        for f in matches:
            p = Path(f).resolve()
            if not p.is_file():
                raise SuiteError(f"{where}: {entry!r} is not a file")
            value, status = published(p) or (None, None)
            inst_id = p.stem
            if p.parent != TOP_DIR:
                inst_id = f"{p.stem}-{hashlib.sha1(str(p).encode()).hexdigest()[:6]}"
            out.append((inst_id, {"type": "file", "path": str(p),
                                  "reference": value if status == "optimal" else None,
                                  "best_known": value if status == "best_known" else None}, 0))
    return out


def _no_unknown(table: dict, allowed: set, where: str) -> None:
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise SuiteError(f"{where}: unknown key {unknown[0]!r}; allowed: {', '.join(sorted(allowed))}")


def _number(value, where: str, *, allow_zero: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise SuiteError(f"{where} must be a finite number, got {value!r}")
    if value < 0 or (value == 0 and not allow_zero):
        raise SuiteError(f"{where} must be {'>= 0' if allow_zero else '> 0'}, got {value!r}")
    return float(value)


def _integer(value, where: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise SuiteError(f"{where} must be an integer, got {value!r}")
    if value < minimum:
        raise SuiteError(f"{where} must be >= {minimum}, got {value}")
    return value


def _int_list(value, where: str) -> list[int]:
    values = value if isinstance(value, list) else [value]
    if not values:
        raise SuiteError(f"{where} must not be empty")
    return [_integer(v, where, 1) for v in values]
