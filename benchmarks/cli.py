"""The `sarcover` command line.

Exit codes (README, "Exit codes"): 0 success (for ``solve``: a verified plan came back); 2 bad
input, with one line on stderr naming the problem; ``solve`` only: 3 no plan (``infeasible``, or
``no_plan`` / ``time_limit`` without a plan), 4 the method failed (``error``); ``verify`` 1 for an
invalid plan; ``bench --strict`` 1 when a job of the suite ended in ``error``; ``report --strict`` 1
when the report lists a conflict; 130 interrupted (Ctrl-C, or SIGTERM as ``kill`` and batch
schedulers send it: a ``bench`` run stops as on Ctrl-C, its stored rows and its runs.jsonl record
kept). Messages go through
``logging.getLogger("sarcover")`` to stderr (:func:`setup_logging`; ``-v``/``-q``).
A reader that closes stdout early (``| head``) ends the output quietly; the exit code stays the
command's.
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import json
import logging
import math
import os
import signal
import sys
import textwrap
import threading
from pathlib import Path

from sarcover.benchmarks.methods import DEFAULT_TIME_LIMIT
from sarcover.formulations.errors import SarcoverError
from sarcover.formulations.limits import shown

EXIT_OK = 0
EXIT_JOBS_FAILED = 1  # bench --strict: a job ended in error
EXIT_BAD_INPUT = 2
EXIT_NO_PLAN = 3
EXIT_METHOD_ERROR = 4
EXIT_INTERRUPTED = 130
MAX_SEED = 2**31 - 1  # CP-SAT and PyVRP take 32-bit seeds

EXIT_CODES = f"""exit codes:
  {EXIT_OK}    a verified plan (status optimal, feasible, or time_limit with a plan)
  {EXIT_BAD_INPUT}    bad input (one line on stderr naming the problem)
  {EXIT_NO_PLAN}    no plan: infeasible (proven), no_plan or time_limit without a plan
  {EXIT_METHOD_ERROR}    the method failed (status error: it raised, or the verifier rejected its plan)"""


class CLIError(SarcoverError):
    """A bad command-line argument."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2, no usage dump
        where = self.prog.removeprefix("sarcover").strip()
        raise CLIError(f"{where}: {message}" if where else message)


def positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text[:40]!r}") from None
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text[:40]!r}")
    return value


def int_at_least(minimum: int, maximum: int | None = None):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not an integer: {text[:40]!r}") from None
        if value < minimum or (maximum is not None and value > maximum):
            bounds = f"an integer in [{minimum}, {maximum}]" if maximum is not None else f">= {minimum}"
            raise argparse.ArgumentTypeError(f"must be {bounds}, got {shown(value)}")
        return value

    return parse


def _plural(count: int, word: str) -> str:
    """``1 UAV``, ``2 UAVs``."""
    return f"{count} {word}" + ("" if count == 1 else "s")


_stdout_gone = False


def _print(text: str) -> None:
    """Print a line on stdout. A reader that has gone (``| head``) ends the output, not the
    command: later output is dropped, and stdout points at /dev/null so that the interpreter's
    final flush does not complain either."""
    global _stdout_gone
    if _stdout_gone:
        return
    try:
        print(text, flush=True)
    except BrokenPipeError:
        _stdout_gone = True
        _silence_stdout()


def _silence_stdout() -> None:
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):  # no file descriptor (captured in a test)
        pass


def _output_file(text: str, flag: str) -> Path:
    """A file the command may write: its folder exists and it is not a folder itself."""
    out = Path(text)
    if "\0" in text:
        raise CLIError(f"{flag}: {text!r} is not a usable file name")
    if out.is_dir():
        raise CLIError(f"{flag}: {out} is a directory; give a file name")
    if not out.parent.is_dir():
        raise CLIError(f"{flag}: directory {out.parent} does not exist")
    return out


# -- generate -----------------------------------------------------------------------------------
def _add_generate(sub):
    from sarcover.formulations.generate import PRESETS

    p = sub.add_parser("generate", help="draw a random SAR instance (targets uniform in 2000 m × 2000 m)")
    p.add_argument("--targets", "-M", type=int_at_least(1), required=True, help="number of targets M")
    p.add_argument("--views", "-K", type=int_at_least(1), required=True, help="views per target K")
    p.add_argument("--uavs", "-N", type=int_at_least(1), required=True, help="number of UAVs N")
    p.add_argument("--seed", type=int_at_least(0, MAX_SEED), default=0, help="random seed (default 0)")
    p.add_argument("--preset", choices=sorted(PRESETS), default="paper", help="parameter preset")
    p.add_argument("--altitude", type=positive_float, help="override H (m)")
    p.add_argument("--pitch-deg", type=float, help="override θ (degrees)")
    p.add_argument("--e-fly", type=positive_float, help="override E_F (energy per metre)")
    p.add_argument("--e-image", type=positive_float, help="override E_I (energy per viewpoint)")
    p.add_argument("--e-max", type=positive_float, help="override E_max (energy budget per UAV)")
    p.add_argument("-o", "--output", required=True, help="output JSON file")
    p.set_defaults(func=_cmd_generate)


def _cmd_generate(args) -> int:
    from sarcover.formulations.generate import generate
    from sarcover.formulations.io import save_json

    sar = generate(
        args.targets, args.views, args.uavs, args.seed, args.preset,
        altitude=args.altitude, pitch_deg=args.pitch_deg, e_fly=args.e_fly,
        e_image=args.e_image, e_max=args.e_max,
    )
    out = _output_file(args.output, "-o")
    try:
        save_json(sar, out)
    except OSError as exc:
        raise CLIError(f"-o: cannot write {out} ({exc.strerror or exc})") from None
    _print(f"wrote {out}: {_plural(sar.n_targets, 'target')} × {_plural(sar.n_views, 'view')}, "
           f"{_plural(sar.n_uavs, 'UAV')}, E_max {sar.e_max:g}")
    return EXIT_OK


# -- methods ------------------------------------------------------------------------------------
def _add_methods(sub):
    p = sub.add_parser("methods", help="list the methods, or one method's parameters",
                       description="Without NAME: every method (built in, or registered by an installed "
                                   "package), exact or heuristic, and where it comes from. With NAME: that "
                                   "method's parameters (name, type, default, meaning).")
    p.add_argument("name", nargs="?", help="a method (or a variant such as 'adpc-pso[iterations=300]')")
    p.set_defaults(func=_cmd_methods)


def _cmd_methods(args) -> int:
    from sarcover.benchmarks.registry import all_methods, get_method

    if args.name is not None:
        _print(_method_card(get_method(args.name)))
        return EXIT_OK
    specs = all_methods()
    width = max(len(spec.name) for spec in specs)
    for spec in specs:
        kind = "exact" if spec.exact else "heuristic"
        where = "" if spec.source == "sarcover" else f"  [{spec.source}]"
        _print(f"{spec.name:<{width}}  {kind:<9}  {spec.summary}{where}")
    return EXIT_OK


def _method_card(spec) -> str:
    """A method's summary and its parameters, one a line: name, type, default (a variant's
    value), meaning."""
    from sarcover.benchmarks.params import accepts_any, fields, literal, type_name

    kind = "exact" if spec.exact else "heuristic"
    lines = [f"{spec.name} ({kind}, {spec.source}): {spec.summary}"]
    if spec.params is None:
        lines.append("parameters: any (passed through as given)" if accepts_any(spec.run) else "parameters: none")
        return "\n".join(lines)
    values = spec.resolve()
    rows = [(n, type_name(t), literal(values[n]), h) for n, t, _, h in fields(spec.params)]
    widths = [max(len(r[i]) for r in rows) for i in range(3)]
    lines.append("parameters (solve --param KEY=VALUE; a suite's [method.NAME.params] or [method.NAME.grid]):")
    lines += [f"  {n:<{widths[0]}}  {t:<{widths[1]}}  {d:<{widths[2]}}  {h}" for n, t, d, h in rows]
    return "\n".join(lines)


# -- solve --------------------------------------------------------------------------------------
DEFAULT_METHOD = "greedy"


def _add_solve(sub):
    p = sub.add_parser(
        "solve", help="solve one instance (sarcover JSON, TOP benchmark file or shipped benchmark name)",
        description=textwrap.fill(
            "Solve one instance with one method and verify the plan. FILE is a sarcover JSON instance "
            "(`sarcover generate`), a Chao-Golden-Wasil TOP text file, or the name of a shipped TOP benchmark "
            f"such as p2.3.g. The default method is {DEFAULT_METHOD}.", 78),
        epilog=EXIT_CODES, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("file", help="instance: sarcover JSON file, TOP text file, or shipped benchmark name (p2.3.g)")
    p.add_argument("--method", default=DEFAULT_METHOD,
                   help=f"method (see `sarcover methods`; default {DEFAULT_METHOD})")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="a parameter of the method (repeatable; VALUE is a TOML literal such as 300, 0.5, "
                        "true or \"text\"; `sarcover methods NAME` lists them)")
    p.add_argument("--time-limit", type=positive_float, default=DEFAULT_TIME_LIMIT,
                   help=f"seconds (default {DEFAULT_TIME_LIMIT:g})")
    p.add_argument("--seed", type=int_at_least(0, MAX_SEED), default=0, help="random seed (default 0)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", help="write a picture of the plan (paper's Fig. 2 style; PNG unless the name says "
                                  "pdf, svg, ...)")
    p.add_argument("--plan-out", metavar="FILE", help="write the plan as a plan file (read by `sarcover verify`)")
    p.set_defaults(func=_cmd_solve)


def solve_exit_code(run) -> int:
    """The exit code of a solved run: a verified plan, no plan, or a failed method."""
    from sarcover.formulations.result import SolutionStatus, Termination

    if run.solution is not SolutionStatus.NONE and run.valid:
        return EXIT_OK
    if run.termination is Termination.ERROR:
        return EXIT_METHOD_ERROR
    return EXIT_NO_PLAN


def _cmd_solve(args) -> int:
    from sarcover.benchmarks.catalog import instance_path
    from sarcover.benchmarks.params import parse_assignment
    from sarcover.benchmarks.registry import check_size, get_method, run_method
    from sarcover.benchmarks.rows import clean
    from sarcover.formulations.io import load_instance
    from sarcover.formulations.records import outcome

    spec = get_method(args.method)
    params = dict(parse_assignment(text) for text in args.param)
    params = spec.resolve(params)  # an unknown parameter or a bad value: one line, exit 2, nothing run
    plot = _plot_file(args.plot) if args.plot else None
    plan_out = _output_file(args.plan_out, "--plan-out") if args.plan_out else None
    instance = load_instance(instance_path(args.file))
    check_size(spec, instance.n_nodes, instance.n_vehicles)  # refused before the method allocates it
    if spec.warm_up is not None:  # a pause of ~30 s on a fresh checkout deserves a word
        from sarcover.benchmarks.harness import warm_up_methods

        warm_up_methods([spec.name], sys.stderr)
    run = run_method(spec.name, instance, seed=args.seed, time_limit=args.time_limit, params=params)
    record = {**outcome(run, instance), "exact": spec.exact, "params": params}
    if plot is not None:
        _write_plot(instance, run, record, plot)
    if plan_out is not None:
        _write_plan(instance, run, plan_out)
    if args.json:
        _print(json.dumps(clean(record)))  # numpy scalars in a method's info, too
    else:
        _print(_summary(instance, spec, record))
    if plot is not None:  # on stderr, so that stdout stays one JSON object with --json
        try:
            print(f"plot written to {plot}", file=sys.stderr, flush=True)
        except OSError:  # nobody reads stderr: the exit code still says how the solve went
            pass
    return solve_exit_code(run)


def _plot_file(text: str) -> Path:
    """The --plot file, checked before solving: a writable place and a format matplotlib writes."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.backend_bases import FigureCanvasBase

    out = _output_file(text, "--plot")
    formats = FigureCanvasBase.get_supported_filetypes()
    suffix = out.suffix.lower().lstrip(".")
    if suffix and suffix not in formats:
        raise CLIError(f"--plot: cannot write a {suffix!r} picture; use one of {', '.join(sorted(formats))}")
    return out


def _write_plot(instance, run, record, path):
    import matplotlib.pyplot as plt
    from sarcover.reports.plots import plot_plan

    cov = f"{100 * record['coverage']:.1f}%" if record["coverage"] is not None else "no plan"
    fig, ax = plt.subplots(figsize=(8.5, 7))
    plot_plan(instance, run.plan if run.valid else None, ax=ax,
              title=f"{instance.name}: {record['method']} ({record['status']}), coverage {cov}")
    fig.tight_layout()
    try:
        fig.savefig(path, dpi=120)
    except OSError as exc:
        raise CLIError(f"--plot: cannot write {path} ({exc.strerror or exc})") from None
    finally:
        plt.close(fig)


def _write_plan(instance, run, path) -> None:
    """Write the run's plan as a plan file (also a plan the verifier rejected, so that `sarcover
    verify` can show why); a run without a plan writes nothing. Says so on stderr."""
    from sarcover.formulations.planfile import save_plan

    if run.plan is None:
        _note(f"no plan: nothing written to {path}")
        return
    try:
        save_plan(run.plan, path, instance.name, run.method)
    except OSError as exc:
        raise CLIError(f"--plan-out: cannot write {path} ({exc.strerror or exc})") from None
    _note(f"plan written to {path}")


def _note(text: str) -> None:
    """A line on stderr, so that stdout stays one JSON object with --json."""
    try:
        print(text, file=sys.stderr, flush=True)
    except OSError:  # nobody reads stderr: the exit code still says how the command went
        pass


def _summary(instance, spec, rec) -> str:
    what = "viewpoint" if instance.kind == "sar" else "node"
    lines = [
        f"instance {instance.name}: {_plural(instance.n_nodes, what)}, {_plural(len(instance.groups), 'group')}, "
        f"{_plural(instance.n_vehicles, 'vehicle')}, budget {instance.budget:g}",
        f"method   {spec.name} ({'exact' if spec.exact else 'heuristic'}): {rec['status']} "
        f"in {rec['runtime_s']:.3f} s" + (f" ({rec['reason']})" if rec["reason"] else ""),
    ]
    if rec["objective"] is not None:
        bound = "none" if rec["bound"] is None else f"{rec['bound']:g}"
        lines.append(
            f"objective {rec['objective']:g} (coverage {100 * rec['coverage']:.2f}%), bound {bound}, "
            f"verified {'yes' if rec['valid'] else 'NO'}"
        )
        for r, (route, e) in enumerate(zip(rec["routes"], rec["energy"])):
            lines.append(f"  vehicle {r + 1}: {_plural(len(route), what)}, energy {e:.6g} / {instance.budget:g}: "
                         + " ".join(map(str, route)))
    return "\n".join(lines)


# -- bench / report -------------------------------------------------------------------------------
def _add_bench(sub):
    p = sub.add_parser("bench", help="run a benchmark suite (built-in name or TOML file) into a results directory")
    from sarcover.benchmarks.suite import builtin_suites

    p.add_argument("suite", nargs="?", default="quick", help=f"built-in suite ({', '.join(builtin_suites())}) "
                   "or a suite TOML file (default quick)")
    p.add_argument("-o", "--output", help="results directory (default results/<suite>)")
    p.add_argument("--workers", type=int_at_least(1), help="parallel worker processes (default: all cores)")
    p.add_argument("--resume", action="store_true", help="continue a run: skip jobs already stored")
    p.add_argument("--runs", type=int_at_least(1), help="random instances per setting (replaces the suite's runs)")
    p.add_argument("--methods", type=method_list, help="run only these of the suite's methods, comma-separated")
    p.add_argument("--scheduler", help="run on a Dask cluster, e.g. tcp://HOST:8786")
    p.add_argument("--tls-ca-file", metavar="PEM", help="with --scheduler tls://...: the CA certificate that "
                   "signed the cluster's certificates")
    p.add_argument("--tls-cert", metavar="PEM", help="this client's certificate (may hold its key too)")
    p.add_argument("--tls-key", metavar="PEM", help="this client's private key, if not in --tls-cert")
    p.add_argument("--strict", action="store_true", help=f"exit {EXIT_JOBS_FAILED} when any job of the suite "
                   "ended in error, in this run or a stored one (a crash, a dead worker, a rejected plan)")
    _add_verbosity(p, quiet_help="no progress bar, warnings only")
    p.set_defaults(func=_cmd_bench)


def method_list(text: str) -> list[str]:
    from sarcover.benchmarks.params import split_top

    names = [n.strip() for n in split_top(text)]  # a variant's own commas stay inside its brackets
    if not all(names):
        raise argparse.ArgumentTypeError(f"empty method name in {text!r}")
    return names


def _tls(args):
    """The Dask ``Security`` of the --tls-* flags (None without them), checked before anything runs."""
    given = {flag: value for flag, value in (("--tls-ca-file", args.tls_ca_file), ("--tls-cert", args.tls_cert),
                                             ("--tls-key", args.tls_key)) if value is not None}
    if not given:
        return None
    if not args.scheduler:
        raise CLIError(f"{next(iter(given))} is for a Dask cluster; give --scheduler tls://HOST:PORT too")
    for flag in ("--tls-ca-file", "--tls-cert"):
        if flag not in given:
            raise CLIError(f"{flag} is missing (TLS needs the CA certificate and this client's certificate)")
    for flag, value in given.items():
        if not Path(value).is_file():
            raise CLIError(f"{flag}: no such file {value}")
    from distributed.security import Security

    return Security(tls_ca_file=args.tls_ca_file, tls_client_cert=args.tls_cert, tls_client_key=args.tls_key,
                    require_encryption=True)


def _cmd_bench(args) -> int:
    from sarcover.benchmarks.harness import run_suite
    from sarcover.benchmarks.suite import load_suite

    suite = load_suite(args.suite, runs=args.runs, methods=args.methods)
    out = Path(args.output) if args.output else Path("results") / suite.name
    security = _tls(args)
    summary = run_suite(suite, out, workers=args.workers, resume=args.resume, scheduler=args.scheduler,
                        security=security, progress=not args.quiet)
    counts = ", ".join(f"{n} {k}" for k, n in sorted(summary["counts"].items())) or "nothing to run"
    _print(f"{summary['suite']}: ran {summary['ran']} of {_plural(summary['jobs'], 'job')} in "
           f"{summary['wall_s']:.1f} s ({counts}) -> {summary['path']}")
    if args.strict and summary["errors"]:  # stored errors count too: --resume does not rerun them
        logging.getLogger("sarcover").error("%s of the suite ended in error (--strict); their reasons are in %s",
                                            _plural(summary["errors"], "job"), summary["path"])
        return EXIT_JOBS_FAILED
    return EXIT_OK


def _add_report(sub):
    p = sub.add_parser("report", help="gap report (Markdown, HTML, PNG, CSV) from a results directory")
    p.add_argument("results", help="results directory written by `sarcover bench`")
    p.add_argument("-o", "--output", help="report directory (default RESULTS/report)")
    p.add_argument("--strict", action="store_true", help="exit 1 when the report lists a conflict (a wrong optimum "
                                                         "or bound), each on a line of stderr")
    p.set_defaults(func=_cmd_report)


def _cmd_report(args) -> int:
    from sarcover.reports.report import write_report

    out = Path(args.output) if args.output else Path(args.results) / "report"
    summary = write_report(args.results, out)
    _print(summary)
    if args.strict:
        return _report_conflicts(args.results)
    return EXIT_OK


EXIT_CONFLICT = 1  # report --strict: the report lists a conflict


def _report_conflicts(results) -> int:
    """``report --strict``: each instance with a conflict (a wrong optimum or bound, as the report's
    consistency checks find them) on a line of stderr, and exit 1; exit 0 without one."""
    from sarcover.reports.gaps import instance_table
    from sarcover.reports.results import load_results

    df, _skipped = load_results(results)
    conflicts = instance_table(df)["conflict"]
    conflicts = conflicts[conflicts != ""]
    for name, what in conflicts.items():
        _note(f"conflict on {name}: {what}")
    if len(conflicts):
        _note(f"report --strict: {_plural(len(conflicts), 'instance')} with a conflict (a wrong optimum or bound)")
        return EXIT_CONFLICT
    return EXIT_OK


# -- verify -------------------------------------------------------------------------------------
EXIT_INVALID_PLAN = 1  # verify: the plan breaks a constraint


def _add_verify(sub):
    p = sub.add_parser(
        "verify", help="check a plan file against an instance: its violations, or its objective and gap",
        description=textwrap.fill(
            "Check a plan file (`sarcover solve --plan-out`, or one's own: README, \"Plan files\") against an "
            "instance (sarcover JSON, TOP text file or shipped benchmark name). A valid plan: its objective, "
            "coverage, and gap to the instance's proven optimum or best bound where sarcover knows one (shipped "
            "TOP values, the regression table, or the runs in --results DIR). An invalid plan: each violation "
            "on a line.", 78),
        epilog=f"""exit codes:
  {EXIT_OK}    a valid plan
  {EXIT_INVALID_PLAN}    an invalid plan (each violation on a line of stdout)
  {EXIT_BAD_INPUT}    bad input (one line on stderr naming the problem)""",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("instance", help="instance: sarcover JSON file, TOP text file, or shipped benchmark name (p2.3.g)")
    p.add_argument("plan", help="plan file (JSON: format sarcover-plan)")
    p.add_argument("--results", metavar="DIR", help="a results folder (`sarcover bench`) whose runs on the "
                                                    "instance give its optimum or best bound")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=_cmd_verify)


def _cmd_verify(args) -> int:
    from sarcover.benchmarks.catalog import instance_path
    from sarcover.benchmarks.plancheck import check_plan
    from sarcover.formulations.io import load_instance
    from sarcover.formulations.planfile import load_plan

    instance = load_instance(instance_path(args.instance))
    plan = load_plan(args.plan, instance)
    check = check_plan(instance, plan.plan, args.results)
    if args.json:
        _print(json.dumps(check.to_dict()))
    else:
        for line in check.lines():
            _print(line)
    return EXIT_OK if check.valid else EXIT_INVALID_PLAN


# -- main ---------------------------------------------------------------------------------------
COMMANDS = [_add_generate, _add_solve, _add_methods, _add_bench, _add_report, _add_verify]


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("sarcover")
    except PackageNotFoundError:  # a checkout that was never installed
        return "unknown"


class _Stderr(logging.StreamHandler):
    """A handler that writes to whatever ``sys.stderr`` is when a record comes (a test swaps it)."""

    @property
    def stream(self):
        return sys.stderr

    @stream.setter
    def stream(self, _):
        pass


class _Format(logging.Formatter):
    """``message`` for information, ``warning: message`` above it, ``[logger] message`` below it."""

    def format(self, record: logging.LogRecord) -> str:
        text = record.getMessage()
        if record.levelno >= logging.WARNING:
            return f"sarcover: {record.levelname.lower()}: {text}"
        if record.levelno < logging.INFO:
            return f"[{record.name}] {text}"
        return text


_HANDLER = _Stderr()
_HANDLER.setFormatter(_Format())


def setup_logging(verbose: int = 0, quiet: bool = False) -> None:
    """The ``sarcover`` loggers on stderr: information by default, debug with ``-v`` (each job's
    row as it is stored, worker replacements), warnings only with ``-q``."""
    logger = logging.getLogger("sarcover")
    logger.setLevel(logging.WARNING if quiet else logging.DEBUG if verbose else logging.INFO)
    if _HANDLER not in logger.handlers:
        logger.addHandler(_HANDLER)


def _add_verbosity(parser, quiet_help: str = "warnings only") -> None:
    """``-v``/``-q`` on ``parser``; on a subcommand they keep what the main parser read."""
    top = parser.prog == "sarcover"
    parser.add_argument("-v", "--verbose", action="count", default=0 if top else argparse.SUPPRESS,
                        help="more messages on stderr (debug: one line per job)")
    parser.add_argument("-q", "--quiet", action="store_true", default=False if top else argparse.SUPPRESS,
                        help=quiet_help)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="sarcover", description="Exact and heuristic benchmarking for multi-view SAR-UAV coverage "
                     "planning", epilog=EXIT_CODES.replace("exit codes:", "exit codes of `sarcover solve`:")
                     + "\nevery other command exits 0 on success and 2 on bad input; `verify` exits 1 for an "
                     "invalid plan,\n`report --strict` 1 when the report lists a conflict,"
                     + f"\n`bench --strict` {EXIT_JOBS_FAILED} when a job of the suite ended in error.",
                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"sarcover {_version()}")
    _add_verbosity(parser)
    sub = parser.add_subparsers(dest="command", parser_class=_Parser, required=True)
    for add in COMMANDS:
        add(sub)
    return parser


def _terminated(signum, frame):
    raise KeyboardInterrupt


@contextlib.contextmanager
def sigterm_as_interrupt():
    """Within the block SIGTERM (``kill``, a batch scheduler's stop) raises KeyboardInterrupt, so
    a command stops as on Ctrl-C (a bench run keeps its rows and records its part). Signals reach
    the main thread only: elsewhere the block changes nothing."""
    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _terminated)
    try:
        yield
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def main(argv: list[str] | None = None) -> int:
    global _stdout_gone
    _stdout_gone = False
    with sigterm_as_interrupt():
        return _main(argv)


def _main(argv: list[str] | None) -> int:
    try:
        args = build_parser().parse_args(argv)
        setup_logging(args.verbose, args.quiet)
        return args.func(args)
    except SarcoverError as exc:
        print(f"sarcover: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as exc:
        if exc.errno != errno.ENAMETOOLONG:
            raise
        # a path argument too long for the file system, whichever command checks it first
        print(f"sarcover: error: {_one_line(exc.filename)}: {exc.strerror}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("sarcover: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # help or version text cut off by `| head`: what was asked for is done
        _silence_stdout()
        return EXIT_OK
    except SystemExit as exc:  # --help and --version end argparse with SystemExit(0)
        return exc.code if isinstance(exc.code, int) else EXIT_OK


def _one_line(exc: object) -> str:
    """The error's message (or a file name) on one line (a name or an argument may hold a line
    break)."""
    return " ".join(str(exc).splitlines())


if __name__ == "__main__":
    sys.exit(main())
