"""sarcover: exact and heuristic benchmarking for multi-view SAR-UAV coverage path planning.

N UAVs leave a base at (0, 0) to image M ground targets from K viewpoints each, within an energy
budget per UAV: a team orienteering problem with unit prizes and "every target at least one
view". sarcover runs the source paper's heuristics, strong peers and exact solvers on the same
instances, verifies every plan independently, and reports optimality gaps.

The public API, in the order a script uses it::

    import sarcover

    inst = sarcover.generate(targets=20, views=3, uavs=5, seed=7)   # the paper preset
    for name in ("adpc-pso", "bp"):
        run = sarcover.solve(inst, name, time_limit=30)              # verified result
        print(name, run.status, run.objective, run.bound)

Instances
    :func:`generate` (paper preset and overrides), :func:`read_instance` (sarcover JSON, a TOP
    file, or a TOP benchmark name such as ``"p2.3.g"``), :func:`to_top`, :class:`SARInstance`,
    :class:`TOPInstance`.
Methods and results
    :func:`list_methods` (built in, and plugins of the entry-point group ``sarcover.methods``),
    :func:`solve` (any method, with its ``params``; returns a :class:`VerifiedResult`),
    :func:`verify`, :class:`Plan`, :class:`Result` (what a method of one's own returns),
    :class:`Termination` (why a run stopped), :class:`SolutionStatus` (what it found),
    :class:`Status` (both in one word).
Plans from outside
    :func:`read_plan` and :func:`write_plan` (plan files, the format of ``sarcover verify``),
    :func:`verify_plan` (violations, or objective, coverage and gap to the known optimum or
    bound: a :class:`PlanCheck`).
Benchmarks and reports
    :func:`run_suite` (locally or on a Dask scheduler), :func:`load_results` (a pandas
    DataFrame, one row per job), :func:`gap_tables` (per-method and per-instance gaps),
    :func:`write_report`, :func:`plot_plan`.

The subpackages hold the rest: ``sarcover.formulations`` (problem, verifier, exact methods),
``sarcover.heuristics`` (every method that proves nothing), ``sarcover.benchmarks`` (method
registry, suites, harness, CLI) and ``sarcover.reports`` (gap tables and plots).
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as _version
from pathlib import Path

from sarcover.benchmarks.methods import DEFAULT_TIME_LIMIT
from sarcover.benchmarks.plancheck import PlanCheck
from sarcover.formulations.instance import SARInstance, TOPInstance, to_top
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Result, SolutionStatus, Status, Termination, VerifiedResult
from sarcover.formulations.verify import VerificationReport, verify

try:
    __version__ = _version("sarcover")
except PackageNotFoundError:  # pragma: no cover - running from a checkout that was never installed
    __version__ = "unknown"

__all__ = [
    "SARInstance", "TOPInstance", "generate", "read_instance", "to_top",
    "Plan", "Result", "Termination", "SolutionStatus", "Status", "VerifiedResult", "VerificationReport",
    "list_methods", "solve", "verify",
    "read_plan", "write_plan", "verify_plan", "PlanCheck",
    "run_suite", "load_results", "gap_tables", "write_report", "plot_plan",
]


def generate(targets: int, views: int, uavs: int, seed: int = 0, preset: str = "paper",
             **overrides: float) -> SARInstance:
    """A random SAR instance: ``targets`` uniform in the 2000 m × 2000 m area, ``views`` per
    target, ``uavs`` UAVs, the ``preset``'s parameters (H, θ, E_F, E_I, E_max) unless overridden
    by keyword (``altitude``, ``pitch_deg``, ``e_fly``, ``e_image``, ``e_max``)."""
    from sarcover.formulations.generate import generate as _generate

    return _generate(targets, views, uavs, seed, preset, **overrides)


def read_instance(source: str | Path) -> TOPInstance:
    """The instance in ``source``, in the TOP form every method solves: a sarcover JSON file, a
    Chao-Golden-Wasil TOP file, or the name of a shipped TOP benchmark (``"p2.3.g"``)."""
    from sarcover.benchmarks.catalog import instance_path
    from sarcover.formulations.io import load_instance

    return load_instance(instance_path(source))


def list_methods() -> list:
    """The methods (name, exact or not, one-line summary, ``params`` dataclass, ``source``): the
    registered ones in the registry's order, then those installed packages register through the
    entry-point group ``sarcover.methods`` (docs/methods.md)."""
    from sarcover.benchmarks.registry import all_methods

    return all_methods()


def solve(instance: SARInstance | TOPInstance, method: str = "greedy", *, seed: int = 0,
          time_limit: float | None = DEFAULT_TIME_LIMIT, params: dict | None = None) -> VerifiedResult:
    """Run a method (registered, a plugin's, a variant such as ``"adpc-pso[iterations=300]"``, or
    a ``"module:function"`` of one's own) with its parameters ``params`` (``{"iterations": 300}``;
    ``sarcover methods NAME`` lists them) and return its result as the independent verifier
    counts it: ``status``, ``termination``, ``solution``, ``objective`` (the verifier's),
    ``bound``, ``plan``, ``runtime_s``; ``info["params"]`` holds the fully resolved parameters.
    Never raises for a failing method (its result is an error with the reason); an unknown
    method, an unknown parameter or a bad value raises, before anything runs.

    The composition a name stands for (``"bp"``: greedy's plan, then branch-and-price with PyVRP
    as its primal heuristic) is one function of :mod:`sarcover.benchmarks.methods`, called by
    :func:`sarcover.benchmarks.registry.run_method`."""
    from sarcover.benchmarks.registry import get_method, run_method

    get_method(method).resolve(params)  # the caller's mistakes raise here
    top = to_top(instance) if isinstance(instance, SARInstance) else instance
    return run_method(method, top, seed=seed, time_limit=time_limit, params=params)


def read_plan(path: str | Path, instance: SARInstance | TOPInstance | None = None) -> Plan:
    """The plan in the plan file at ``path`` (README, "Plan files"); with ``instance``, checked to
    name that instance and only its node ids. Bad input raises a one-line error."""
    from sarcover.formulations.planfile import load_plan

    top = to_top(instance) if isinstance(instance, SARInstance) else instance
    return load_plan(path, top).plan


def write_plan(plan: Plan, path: str | Path, instance: SARInstance | TOPInstance, method: str | None = None) -> None:
    """Write ``plan`` (a :class:`Plan`, or a list of routes of node ids) on ``instance`` as a plan
    file, naming the ``method`` that made it if given."""
    from sarcover.formulations.planfile import save_plan

    save_plan(plan if isinstance(plan, Plan) else Plan.of(plan), path, instance.name, method)


def verify_plan(instance, plan, *, results: str | Path | None = None):
    """Check a plan from outside, as ``sarcover verify`` does: ``instance`` is an instance or
    what :func:`read_instance` reads, ``plan`` a :class:`Plan`, a list of routes of node ids, or
    a plan file. Returns a :class:`PlanCheck`: ``valid``, ``violations``, ``objective``,
    ``coverage``, ``known`` (the proven optimum, infeasibility, best bound or best known value
    sarcover knows, with its source; ``results`` adds the runs of a results folder) and ``gap``.
    Bad input (a missing or malformed file, ids that name no node) raises a one-line error."""
    from sarcover.benchmarks.plancheck import check_plan
    from sarcover.formulations.planfile import load_plan

    if isinstance(instance, SARInstance):
        top = to_top(instance)
    elif isinstance(instance, TOPInstance):
        top = instance
    else:
        top = read_instance(instance)
    if isinstance(plan, (str, Path)):
        plan = load_plan(plan, top).plan
    elif not isinstance(plan, Plan):
        from sarcover.formulations.planfile import plan_from_dict

        plan = plan_from_dict({"format": "sarcover-plan", "version": 1, "instance": top.name,
                               "routes": [list(r) for r in plan]}, top, source="routes").plan
    return check_plan(top, plan, results)


def run_suite(suite, out_dir: str | Path | None = None, *, workers: int | None = None, resume: bool = False,
              scheduler: str | None = None, runs: int | None = None, methods: list[str] | None = None,
              progress: bool = True, security=None) -> dict:
    """Run a benchmark suite (a built-in name such as ``"quick"``, a suite TOML file, or a loaded
    suite) into ``out_dir`` (default ``results/<suite>``), one verified row per job; locally on
    ``workers`` processes, or on the Dask scheduler at ``scheduler`` (``"tcp://host:8786"``, or
    ``"tls://host:8786"`` with ``security``, a :class:`distributed.security.Security`).
    Returns a summary (jobs, runs, counts by status, the results file)."""
    from sarcover.benchmarks.harness import run_suite as _run_suite
    from sarcover.benchmarks.suite import Suite, load_suite

    if not isinstance(suite, Suite):
        suite = load_suite(str(suite), runs=runs, methods=methods)
    out = Path(out_dir) if out_dir is not None else Path("results") / suite.name
    return _run_suite(suite, out, workers=workers, resume=resume, scheduler=scheduler, security=security,
                      progress=progress)


def load_results(results_dir: str | Path):
    """The stored results of ``results_dir`` as a pandas DataFrame, one row per job (fields: see
    :mod:`sarcover.formulations.records`); ``df.attrs["skipped"]`` counts the rows left out."""
    from sarcover.reports.results import load_results as _load

    df, skipped = _load(results_dir)
    df.attrs["skipped"] = skipped
    return df


def gap_tables(results):
    """(per-method table, per-instance table) of a results DataFrame or directory: each method's
    gap to the proven optimum (``gap``) and to the best certified bound (``gap_ub``), and each
    instance's optimum, bound and conflicts."""
    from sarcover.reports.gaps import add_gaps, instance_table, method_table

    df = load_results(results) if isinstance(results, (str, Path)) else results
    inst = instance_table(df)
    return method_table(add_gaps(df, inst)), inst


def write_report(results_dir: str | Path, out_dir: str | Path | None = None) -> str:
    """Write the gap report (Markdown, HTML, PNG plots, CSV tables) of ``results_dir`` into
    ``out_dir`` (default ``results_dir/report``); returns a one-line summary."""
    from sarcover.reports.report import write_report as _write

    out = Path(out_dir) if out_dir is not None else Path(results_dir) / "report"
    return _write(results_dir, out)


def plot_plan(instance: SARInstance | TOPInstance, plan: Plan | None, ax=None, title: str | None = None):
    """Draw a plan as the paper's Fig. 2 (base, targets, covered and missed viewpoints, routes)
    on ``ax`` (a new figure if None); returns the axes, neither shows nor saves."""
    from sarcover.reports.plots import plot_plan as _plot

    top = to_top(instance) if isinstance(instance, SARInstance) else instance
    return _plot(top, plan, ax=ax, title=title)
