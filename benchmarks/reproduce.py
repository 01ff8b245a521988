"""Reproduce the paper and write the reference report: ``python -m sarcover.benchmarks.reproduce``.

Runs the built-in suites into ``RESULTS/<suite>`` (default ``results/reference``), resuming whatever
is already stored there, then writes ``reports/reference/README.md`` with its PNGs and CSVs
(:func:`sarcover.reports.reference.write_reference`):

================  ===================================================================================
paper-n           Fig. 3: M=20, K=3, N=2..6; the five paper methods + greedy, ``--runs`` per setting
paper-k           Fig. 4 / Table I: M=20, N=5, K=2..6; same methods
paper-peers       routing (2 s) and pyvrp (1 s) on the first 20 instances of every setting above
exact-small       every method on 8-40 viewpoints; milp, cpsat, bp (60 s) prove optima -> gaps
paper-gaps        M=20, N=5, K=3 and 6 (8 instances each): heuristics against bp's bound (60 s)
paper-gaps-long   bp at 300 s (subset-row cuts on) on K=3 seed 5 and K=6 seeds 0..3 of paper-gaps
emax-sweep        coverage against E_max = 4000..9000 at M=20, N=5, K=3 (50 instances per budget)
table1            Table I timings: M=20, N=5, K=2..6, 30 instances each, on ONE worker
top-chao          the exact methods (milp, cpsat, bp; 60 s) on TOP sets 1-3 against published optima
================  ===================================================================================

``--runs R`` sets the random instances per setting of paper-n and paper-k (the paper: 1000, the
default); ``--skip SUITE`` leaves a suite out; ``--report-only`` only rewrites the report.
The results directory (raw JSON Lines rows) is not committed; the report's CSVs are.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

SUITES = ["paper-n", "paper-k", "paper-peers", "exact-small", "paper-gaps", "paper-gaps-long", "emax-sweep",
          "table1", "top-chao"]
EXACT_ONLY = {"top-chao": ["milp", "cpsat", "bp"]}  # suites run with only these of their methods


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m sarcover.benchmarks.reproduce", description=__doc__.splitlines()[0])
    ap.add_argument("--results", default="results/reference", help="results root (default results/reference)")
    ap.add_argument("--out", default="reports/reference", help="report directory (default reports/reference)")
    ap.add_argument("--runs", type=int, default=1000, help="instances per setting of paper-n/paper-k (default 1000)")
    ap.add_argument("--workers", type=int, help="worker processes (default: all cores)")
    ap.add_argument("--skip", action="append", default=[], choices=SUITES, help="leave a suite out (repeatable)")
    ap.add_argument("--report-only", action="store_true", help="do not run; rewrite the report from stored results")
    ap.add_argument("--quiet", action="store_true", help="no progress bars")
    ap.add_argument("--note", action="append", default=[], help="a paragraph to add to the report (repeatable)")
    args = ap.parse_args(argv)

    from sarcover.benchmarks.harness import run_suite
    from sarcover.benchmarks.suite import load_suite
    from sarcover.reports.reference import write_reference

    root = Path(args.results)
    if not args.report_only:
        for name in SUITES:
            if name in args.skip:
                continue
            runs = args.runs if name in ("paper-n", "paper-k") else None
            suite = load_suite(name, runs=runs, methods=EXACT_ONLY.get(name))
            t0 = time.monotonic()
            workers = 1 if name == "table1" else args.workers  # one core's timings
            summary = run_suite(suite, root / name, workers=workers, resume=True, progress=not args.quiet)
            print(f"{name}: ran {summary['ran']} of {summary['jobs']} jobs in {time.monotonic() - t0:.0f} s "
                  f"{summary['counts']}", file=sys.stderr)
    notes = ([f"paper-n and paper-k ran with {args.runs} random instances per setting."] if not args.report_only
             else []) + args.note
    path = write_reference(root, args.out, suites=SUITES, command=f"python -m sarcover.benchmarks.reproduce --runs {args.runs}", notes=notes)
    print(f"wrote {path}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
