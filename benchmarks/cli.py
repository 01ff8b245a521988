"""The `sarcover` command line. Bad input: one line on stderr naming the problem, exit code 2."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from sarcover.formulations.errors import SarcoverError


class CLIError(SarcoverError):
    """A bad command-line argument."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2, no usage dump
        where = self.prog.removeprefix("sarcover").strip()
        raise CLIError(f"{where}: {message}" if where else message)


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text!r}")
    return value


def _int_at_least(minimum: int):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be >= {minimum}, got {value}")
        return value

    return parse


# -- generate -----------------------------------------------------------------------------------
def _add_generate(sub):
    from sarcover.formulations.generate import PRESETS

    p = sub.add_parser("generate", help="draw a random SAR instance (targets uniform in 2000 m × 2000 m)")
    p.add_argument("--targets", "-M", type=_int_at_least(1), required=True, help="number of targets M")
    p.add_argument("--views", "-K", type=_int_at_least(1), required=True, help="views per target K")
    p.add_argument("--uavs", "-N", type=_int_at_least(1), required=True, help="number of UAVs N")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--preset", choices=sorted(PRESETS), default="paper", help="parameter preset")
    p.add_argument("--altitude", type=_positive_float, help="override H (m)")
    p.add_argument("--pitch-deg", type=float, help="override θ (degrees)")
    p.add_argument("--e-fly", type=_positive_float, help="override E_F (energy per metre)")
    p.add_argument("--e-image", type=_positive_float, help="override E_I (energy per viewpoint)")
    p.add_argument("--e-max", type=_positive_float, help="override E_max (energy budget per UAV)")
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
    out = Path(args.output)
    if not out.parent.exists():
        raise CLIError(f"output directory {out.parent} does not exist")
    save_json(sar, out)
    print(f"wrote {out}: {sar.n_targets} targets × {sar.n_views} views, {sar.n_uavs} UAVs, E_max {sar.e_max:g}")
    return 0


# -- methods ------------------------------------------------------------------------------------
def _add_methods(sub):
    p = sub.add_parser("methods", help="list the registered methods")
    p.set_defaults(func=_cmd_methods)


def _cmd_methods(args) -> int:
    from sarcover.benchmarks.registry import METHODS

    width = max(len(n) for n in METHODS)
    for spec in METHODS.values():
        kind = "exact" if spec.exact else "heuristic"
        print(f"{spec.name:<{width}}  {kind:<9}  {spec.summary}")
    return 0


# -- solve --------------------------------------------------------------------------------------
def _add_solve(sub):
    p = sub.add_parser("solve", help="solve one instance (sarcover JSON or TOP benchmark file)")
    p.add_argument("file", help="instance file")
    p.add_argument("--method", default="greedy", help="registered method (see `sarcover methods`)")
    p.add_argument("--time-limit", type=_positive_float, default=60.0, help="seconds (default 60)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", help="write a PNG of the plan (paper's Fig. 2 style)")
    p.set_defaults(func=_cmd_solve)


def _cmd_solve(args) -> int:
    from sarcover.benchmarks.registry import get_method, run_method
    from sarcover.formulations.io import load_instance
    from sarcover.formulations.records import outcome

    spec = get_method(args.method)
    if args.plot and not Path(args.plot).parent.exists():
        raise CLIError(f"--plot: directory {Path(args.plot).parent} does not exist")
    instance = load_instance(args.file)
    if spec.warm_up is not None:  # a pause of ~30 s on a fresh checkout deserves a word
        from sarcover.benchmarks.harness import warm_up_methods

        warm_up_methods([spec.name], sys.stderr)
    run = run_method(spec.name, instance, seed=args.seed, time_limit=args.time_limit)
    record = {**outcome(run, instance), "exact": spec.exact}
    if args.plot:
        _write_plot(instance, run, record, args.plot)
    if args.json:
        print(json.dumps(record))
    else:
        print(_summary(instance, spec, record))
    return 0


def _write_plot(instance, run, record, path):
    import matplotlib.pyplot as plt

    from sarcover.reports.plots import plot_plan

    cov = f"{100 * record['coverage']:.1f}%" if record["coverage"] is not None else "no plan"
    fig, ax = plt.subplots(figsize=(7, 7))
    plot_plan(instance, run.plan if run.valid else None, ax=ax,
              title=f"{instance.name}: {record['method']} ({record['status']}), coverage {cov}")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _summary(instance, spec, rec) -> str:
    what = "viewpoints" if instance.kind == "sar" else "nodes"
    lines = [
        f"instance {instance.name}: {instance.n_nodes} {what}, {len(instance.groups)} groups, "
        f"{instance.n_vehicles} vehicles, budget {instance.budget:g}",
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
            lines.append(f"  vehicle {r + 1}: {len(route)} {what}, energy {e:.6g} / {instance.budget:g}: "
                         + " ".join(map(str, route)))
    return "\n".join(lines)


# -- bench / report -------------------------------------------------------------------------------
def _add_bench(sub):
    p = sub.add_parser("bench", help="run a benchmark suite (built-in name or TOML file) into a results directory")
    from sarcover.benchmarks.suite import builtin_suites

    p.add_argument("suite", nargs="?", default="quick", help=f"built-in suite ({', '.join(builtin_suites())}) "
                   "or a suite TOML file (default quick)")
    p.add_argument("-o", "--output", help="results directory (default results/<suite>)")
    p.add_argument("--workers", type=_int_at_least(1), help="parallel worker processes (default: all cores)")
    p.add_argument("--resume", action="store_true", help="continue a run: skip jobs already stored")
    p.add_argument("--runs", type=_int_at_least(1), help="random instances per setting (replaces the suite's runs)")
    p.add_argument("--methods", type=_method_list, help="run only these of the suite's methods, comma-separated")
    p.add_argument("--scheduler", help="run on a Dask cluster, e.g. tcp://HOST:8786")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_bench)


def _method_list(text: str) -> list[str]:
    names = [n.strip() for n in text.split(",")]
    if not all(names):
        raise argparse.ArgumentTypeError(f"empty method name in {text!r}")
    return names


def _cmd_bench(args) -> int:
    from sarcover.benchmarks.harness import run_suite
    from sarcover.benchmarks.suite import load_suite

    suite = load_suite(args.suite, runs=args.runs, methods=args.methods)
    out = Path(args.output) if args.output else Path("results") / suite.name
    summary = run_suite(suite, out, workers=args.workers, resume=args.resume, scheduler=args.scheduler,
                        progress=not args.quiet)
    counts = ", ".join(f"{n} {k}" for k, n in sorted(summary["counts"].items())) or "nothing to run"
    print(f"{summary['suite']}: ran {summary['ran']} of {summary['jobs']} jobs in {summary['wall_s']:.1f} s "
          f"({counts}) -> {summary['path']}")
    return 0


def _add_report(sub):
    p = sub.add_parser("report", help="gap report (Markdown, HTML, PNG, CSV) from a results directory")
    p.add_argument("results", help="results directory written by `sarcover bench`")
    p.add_argument("-o", "--output", help="report directory (default RESULTS/report)")
    p.set_defaults(func=_cmd_report)


def _cmd_report(args) -> int:
    from sarcover.reports.report import write_report

    out = Path(args.output) if args.output else Path(args.results) / "report"
    summary = write_report(args.results, out)
    print(summary)
    return 0


# -- main ---------------------------------------------------------------------------------------
COMMANDS = [_add_generate, _add_solve, _add_methods, _add_bench, _add_report]


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="sarcover", description="Exact and heuristic benchmarking for multi-view SAR-UAV coverage planning")
    sub = parser.add_subparsers(dest="command", parser_class=_Parser, required=True)
    for add in COMMANDS:
        add(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    try:
        args = build_parser().parse_args(argv)
        return args.func(args)
    except SarcoverError as exc:
        print(f"sarcover: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("sarcover: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
