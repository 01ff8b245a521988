"""Reproduce the paper and write the reference report: ``python -m sarcover.benchmarks.reproduce``.

Runs the built-in suites into ``RESULTS/<suite>`` (default ``results/reference``), resuming whatever
is already stored there, then the gap decomposition, then writes ``reports/reference/README.md``
with its PNGs and CSVs (:func:`sarcover.reports.reference.write_reference`). Wall times on 2 cores
(2 workers; the reference run's, or estimates where marked ~):

================  ========  =========================================================================
step              wall      what
================  ========  =========================================================================
paper-n           5 min     Fig. 3: M=20, K=3, N=2..6; the five paper methods + greedy, ``--runs`` per setting
paper-k           5 min     Fig. 4 / Table I: M=20, N=5, K=2..6; same methods
paper-peers       3.5 min   routing (2 s) and pyvrp (1 s) on the first 20 instances of every setting above
exact-small       10 min    every method on 8-40 viewpoints; milp, cpsat, bp (60 s) prove optima -> gaps
paper-gaps        6 min     M=20, N=5, K=3 and 6 (8 instances each): heuristics against bp's bound (60 s)
paper-gaps-long   8 min     bp at 300 s (subset-row cuts on) on K=3 seed 5 and K=6 seeds 0..3 of paper-gaps
emax-sweep        1.5 min   coverage against E_max = 4000..9000 at M=20, N=5, K=3 (50 instances per budget)
table1            0.5 min   Table I timings: M=20, N=5, K=2..6, 30 instances each, on ONE worker
anytime           ~15 min   every method at 10 s on paper-opt's K=3 and K=6 (N=5) instances: the gap over
                            time against paper-opt's proven optima (docs/anytime.md)
top-chao          32 min    the exact methods (milp, cpsat, bp; 60 s) on TOP sets 1-3 against published optima
paper-opt         1.8 h     the paper's grid (Fig. 3 and 4 settings, 20 instances each): every heuristic
                            against bp's optimum (60 s at K<=3, 300 s at K=4,5, 600 s at K=6; the
                            heuristics and K<=3 11 min, K=4 16 min, K=5 24 min, K=6 56 min on 2 workers)
decomposition     ~12 min   clustering / cross-cluster / routing loss of the paper methods, from
                            paper-opt's optima, at N=5 K=3, N=5 K=6 and K=3 N=2..6 (one instance per
                            worker; 755 of its 960 rows took 9.3 min on 2)
top-4-7           2.0 h     bp alone at 600 s on the 192 shipped files of TOP sets 4-7 (4.1 CPU-hours)
paper-validation  2.3 h     bp alone on the paper grid with paper-opt's limits, 20 held-out instances per
                            setting (seeds 200..219, which chose no setting): its proof rates beside
                            paper-opt's, which are tuning figures (about paper-opt's bp part)
scale             ~7 h      M=20..100 at K=3 and 6 (60-600 viewpoints), 10 instances each: every method
                            against bp (600 s; milp and cpsat only at M<=40); bp's 70 jobs that use
                            their 600 s dominate (about 4 100 s of bp and 620 s of the other methods
                            per instance seed, measured on seed 306: docs/scale.md)
================  ========  =========================================================================

In all about 15 h on 2 cores (``--skip scale --skip paper-validation``: about 6 h).
``--runs R`` sets the random instances per setting of paper-n and paper-k (the paper: 1000, the
default); ``--skip STEP`` leaves a suite or the decomposition out; ``--report-only`` only rewrites
the report. Every step resumes: a stopped run continues where it stopped. The results directory
(raw JSON Lines rows) is not committed; the report's CSVs are. The raw rows of the long steps
(paper-opt, the decomposition, top-4-7) are committed too, in ``reports/reference/rows/<step>/``, so
that a reference run spread over several sittings on fresh machines loses none of them:
``--resume-from reports/reference/rows`` first copies each step's stored rows into the results
root, where the root holds nothing for that step yet (it never merges into rows already there);
each step then runs only the jobs those rows lack (with ``--report-only``, none).
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import time
from pathlib import Path

SUITES = ["paper-n", "paper-k", "paper-peers", "exact-small", "paper-gaps", "paper-gaps-long", "emax-sweep",
          "table1", "anytime", "top-chao", "paper-opt", "top-4-7", "paper-validation", "scale"]
# suites run with only these of their methods (paper-validation's greedy is there for a quick check only)
EXACT_ONLY = {"top-chao": ["milp", "cpsat", "bp"], "top-4-7": ["bp"], "paper-validation": ["bp"]}
DECOMPOSITION = "decomposition"  # the step after paper-opt: RESULTS/decomposition/rows.jsonl
DECOMPOSE_FROM = "paper-opt"
# (K, N) settings of paper-opt to decompose: Fig. 3's K=3 sweep over N and N=5 at K=6
DECOMPOSE_SETTINGS = [(3, 2), (3, 3), (3, 4), (3, 5), (3, 6), (6, 5)]
STEPS = SUITES[:SUITES.index(DECOMPOSE_FROM) + 1] + [DECOMPOSITION] + SUITES[SUITES.index(DECOMPOSE_FROM) + 1:]


def decompose_step(root: Path, *, quiet: bool = False, workers: int | None = None) -> int:
    """Decompose the paper methods' gaps on paper-opt's instances of DECOMPOSE_SETTINGS into
    ``root/decomposition/rows.jsonl`` (resumable: stored rows are skipped), ``workers`` instances
    at a time (default: all cores); returns the rows there."""
    from sarcover.benchmarks.decomposition import cases_from_results, decompose

    source = root / DECOMPOSE_FROM
    if not (source / "results.jsonl").is_file():
        print(f"{DECOMPOSITION}: no {DECOMPOSE_FROM} results in {source}; skipped", file=sys.stderr)
        return 0
    cases = [c for c in cases_from_results(source) if (c.meta.get("K"), c.meta.get("N")) in DECOMPOSE_SETTINGS]
    rows = decompose(cases, root / DECOMPOSITION / "rows.jsonl", workers=workers or os.cpu_count() or 1,
                     stream=None if quiet else sys.stderr)
    return len(rows)


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line naming the problem, exit 2, no usage dump
        self.exit(2, f"{self.prog}: {message}\n")


def seed_step(rows: Path, root: Path, step: str) -> bool:
    """Copy ``rows/<step>/`` (a results folder of that step) to ``root/<step>/`` if the first exists
    and the second does not; returns whether it copied. Rows already in ``root`` are never touched."""
    src, dst = rows / step, root / step
    if not src.is_dir() or dst.exists():
        return False
    root.mkdir(parents=True, exist_ok=True)
    shutil.copytree(src, dst)
    return True


def main(argv: list[str] | None = None) -> int:
    """Run the steps, then write the report. Ctrl-C or SIGTERM stops it with exit code 130 and
    loses nothing (every step resumes); a stored run that does not fit the suite (a changed
    setting) is a one-line error with exit code 2."""
    from sarcover.benchmarks.cli import EXIT_BAD_INPUT, EXIT_INTERRUPTED, _one_line, sigterm_as_interrupt
    from sarcover.formulations.errors import SarcoverError

    prog = "python -m sarcover.benchmarks.reproduce"
    with sigterm_as_interrupt():
        try:
            return _main(argv, prog)
        except SarcoverError as exc:
            print(f"{prog}: error: {_one_line(exc)}", file=sys.stderr)
            return EXIT_BAD_INPUT
        except KeyboardInterrupt:
            print(f"{prog}: interrupted; the rows so far are kept, the same command resumes",
                  file=sys.stderr)
            return EXIT_INTERRUPTED


def _main(argv: list[str] | None, prog: str) -> int:
    ap = _Parser(prog=prog, description=__doc__.splitlines()[0])
    ap.add_argument("--results", default="results/reference", help="results root (default results/reference)")
    ap.add_argument("--out", default="reports/reference", help="report directory (default reports/reference)")
    ap.add_argument("--runs", type=int, default=1000, help="instances per setting of paper-n/paper-k (default 1000)")
    ap.add_argument("--workers", type=int, help="worker processes (default: all cores)")
    ap.add_argument("--skip", action="append", default=[], choices=STEPS,
                    help="leave a suite or the decomposition out (repeatable)")
    ap.add_argument("--resume-from", metavar="ROWS",
                    help="first copy ROWS/<step>/ (stored raw rows, e.g. reports/reference/rows) into the "
                         "results root for every step the root has nothing for")
    ap.add_argument("--report-only", action="store_true", help="do not run; rewrite the report from stored results")
    ap.add_argument("--quiet", action="store_true", help="no progress bars")
    ap.add_argument("--note", action="append", default=[], help="a paragraph to add to the report (repeatable)")
    args = ap.parse_args(argv)

    from sarcover.benchmarks.harness import run_suite
    from sarcover.benchmarks.suite import load_suite
    from sarcover.benchmarks.catalog import corrections
    from sarcover.reports.reference import write_reference

    root = Path(args.results)
    seed = Path(args.resume_from) if args.resume_from else None
    if seed is not None:
        if not seed.is_dir():
            ap.error(f"--resume-from: {seed} is not a directory")
        for name in STEPS:
            if name not in args.skip and seed_step(seed, root, name):
                print(f"{name}: copied the stored rows of {seed / name} into {root / name}", file=sys.stderr)
    if not args.report_only:
        for name in STEPS:
            if name in args.skip:
                continue
            if name == DECOMPOSITION:
                t0 = time.monotonic()
                n = decompose_step(root, quiet=args.quiet, workers=args.workers)
                print(f"{name}: {n} rows in {time.monotonic() - t0:.0f} s", file=sys.stderr)
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
    path = write_reference(root, args.out, suites=SUITES,
                           command=f"python -m sarcover.benchmarks.reproduce --runs {args.runs}", notes=notes,
                           fixes=corrections())
    print(f"wrote {path}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
