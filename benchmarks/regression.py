"""Regression table of proven optimal values, each confirmed by two independent sources.

A row's ``confirmed_by`` names them: ``milp+cpsat`` (both solvers proved the same value, or both
proved infeasibility), ``bp+milp`` / ``bp+cpsat`` (branch-and-price and a compact model agree, for
instances too large for the other compact model), or ``bp+published`` (bp proved the optimum that
the TOP literature publishes as proven, ``instances/top/optimal.csv``).

``python -m sarcover.benchmarks.regression [--time-limit S] [--random N]`` re-solves the small
instances of the table with milp and cpsat and rewrites its ``milp+cpsat`` rows, keeping the
others; ``--add SPEC ... --by bp+published|bp+milp|bp+cpsat`` confirms further instances and adds
them. Either writes the whole table to ``--out`` (default ``OUT``, under the current directory:
never into the installed package), starting from that file if it exists, else from the shipped
table; to ship the result, copy it over ``benchmarks/regression/optimal_values.csv`` in a
checkout. Instances are either generated (``gen:M,K,N,seed,e_max`` with the paper preset) or TOP
benchmark files (``top:p2.2.k``). :func:`random_cases` is also the instance family of the exact
cross-check test.
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import numpy as np

from sarcover.formulations.generate import generate
from sarcover.formulations.instance import TOPInstance, to_top
from sarcover.formulations.io import read_top

from sarcover.benchmarks.catalog import TOP_DIR, published

ROOT = Path(__file__).resolve().parent
TABLE = ROOT / "regression" / "optimal_values.csv"
OUT = Path("results") / "regression" / "optimal_values.csv"  # the command's output, relative to the current directory
FIELDS = ["spec", "status", "value", "confirmed_by", "milp_s", "cpsat_s", "bp_s"]
SOURCES = ("milp+cpsat", "bp+milp", "bp+cpsat", "bp+published")

# TOP files both solvers prove quickly (sets 1-3, 1 thread).
TOP_SPECS = ["p2.2.a", "p2.2.d", "p2.2.j", "p2.3.g", "p2.4.k", "p1.2.d", "p1.2.f", "p1.3.g",
             "p1.4.e", "p3.2.a", "p3.2.b", "p3.3.d", "p3.4.f"]


def coverage_threshold(n_targets: int, n_views: int, n_uavs: int, seed: int) -> float:
    """Smallest E_max at which every target has a viewpoint some UAV can reach and return from."""
    inst = to_top(generate(n_targets, n_views, n_uavs, seed))
    trip = inst.round_trip_cost()
    return float(max(trip[list(g)].min() for g in inst.groups))


def random_cases(n: int, start: int = 0, max_targets: int = 8, max_views: int = 4) -> list[str]:
    """``n`` small SAR specs: M 3-8, K 2-4, N 1-3 (upper ends adjustable); budgets cycle through below-threshold
    (infeasible on its face), tight (1.0-1.25 × threshold, often infeasible for the fleet),
    medium (1.25-1.6) and loose (2.5-3.5)."""
    specs = []
    for i in range(start, start + n):
        rng = np.random.default_rng([2026, i])
        m, k = int(rng.integers(3, max_targets + 1)), int(rng.integers(2, max_views + 1))
        u = int(rng.integers(1, 4))
        seed = 1000 + i
        lo, hi = [(0.9, 0.99), (1.0, 1.12), (1.12, 1.25), (1.25, 1.6), (2.5, 3.5)][i % 5]
        e_max = round(coverage_threshold(m, k, u, seed) * float(rng.uniform(lo, hi)), 1)
        specs.append(f"gen:{m},{k},{u},{seed},{e_max}")
    return specs


def load_spec(spec: str) -> TOPInstance:
    """Build the instance a spec names (``gen:M,K,N,seed,e_max`` or ``top:NAME``)."""
    kind, _, body = spec.partition(":")
    if kind == "gen":
        m, k, u, seed, e_max = body.split(",")
        return to_top(generate(int(m), int(k), int(u), int(seed), e_max=float(e_max)))
    if kind == "top":
        return read_top(TOP_DIR / f"{body}.txt")
    raise ValueError(f"unknown instance spec {spec!r}")


def read_table(path: Path = TABLE) -> list[dict]:
    """The table's rows; rows written before ``confirmed_by`` existed are ``milp+cpsat`` rows."""
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    for row in rows:
        row["confirmed_by"] = row.get("confirmed_by") or "milp+cpsat"
        row.setdefault("bp_s", "")
    return rows


def write_table(rows: list[dict], path: Path = TABLE) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS, extrasaction="ignore")
        w.writeheader()
        w.writerows({k: row.get(k, "") for k in FIELDS} for row in rows)


def published_optimum(spec: str) -> float | None:
    """The optimum the literature publishes as proven for a ``top:`` spec, else None."""
    kind, _, body = spec.partition(":")
    if kind != "top":
        return None
    value = published(TOP_DIR / f"{body}.txt")
    return value[0] if value is not None and value[1] == "optimal" else None


def confirm(spec: str, time_limit: float, by: str = "milp+cpsat") -> dict | None:
    """Solve ``spec`` with the two sources ``by`` names; the row if both give the same proven
    answer, else None (with the reason on stderr). A bp proof that differs from a published
    optimum is reported as a conflict: that is a bug until shown otherwise."""
    from sarcover.benchmarks.registry import run_method  # the CLI side; formulations never import this

    if by not in SOURCES:
        raise ValueError(f"unknown confirmation {by!r}; expected one of {', '.join(SOURCES)}")
    inst = load_spec(spec)
    methods = [m for m in by.split("+") if m != "published"]
    out = {m: run_method(m, inst, time_limit=time_limit) for m in methods}
    row = {"spec": spec, "confirmed_by": by, **{f"{m}_s": f"{r.runtime_s:.3f}" for m, r in out.items()}}
    answers = [(r.status, r.objective) for r in out.values()]
    if by.endswith("+published"):
        value = published_optimum(spec)
        if value is None:
            print(f"{spec}: no published optimum to confirm against", file=sys.stderr)
            return None
        answers.append(("optimal", value))
    statuses = {a[0] for a in answers}
    if statuses == {"infeasible"}:
        return {**row, "status": "infeasible", "value": ""}
    values = [a[1] for a in answers]
    if statuses == {"optimal"} and max(values) - min(values) <= 1e-9:
        return {**row, "status": "optimal", "value": f"{values[0]:g}"}
    what = ", ".join(f"{m} {r.status} {r.objective}" for m, r in out.items())
    if by.endswith("+published"):
        what += f", published {answers[-1][1]:g}"
        if out["bp"].status == "optimal":
            what = "CONFLICT: " + what
    print(f"{spec}: not confirmed ({what})", file=sys.stderr)
    return None


def _base_rows(path: Path) -> list[dict]:
    """The rows a run starts from: ``path``'s where it exists, else the shipped table's."""
    return read_table(path if path.exists() else TABLE)


def regenerate(time_limit: float = 60.0, n_random: int = 40, path: Path = OUT) -> list[dict]:
    """Re-solve the small instances with milp and cpsat; write their confirmed rows beside the
    table's rows of other sources to ``path``."""
    specs = [f"top:{n}" for n in TOP_SPECS] + random_cases(n_random, start=500, max_targets=6, max_views=3)
    rows = [r for r in (confirm(s, time_limit) for s in specs) if r is not None]
    kept = [r for r in _base_rows(path) if r["confirmed_by"] != "milp+cpsat"]
    write_table(rows + kept, path)
    return rows


def add(specs: list[str], by: str, time_limit: float, path: Path = OUT) -> list[dict]:
    """Confirm ``specs`` by ``by`` and write the table with the confirmed rows added (replacing
    rows of the same spec) to ``path``."""
    rows = [r for r in (confirm(s, time_limit, by) for s in specs) if r is not None]
    new = {r["spec"] for r in rows}
    old = [r for r in _base_rows(path) if r["spec"] not in new]
    write_table(old + rows, path)
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m sarcover.benchmarks.regression", description=__doc__.splitlines()[0])
    ap.add_argument("--time-limit", type=float, default=60.0, help="seconds per solver and instance")
    ap.add_argument("--random", type=int, default=40, help="number of generated SAR instances")
    ap.add_argument("--out", type=Path, default=OUT,
                    help=f"the table to write (default {OUT}; it starts from this file if it exists, else from the "
                         "shipped table)")
    ap.add_argument("--add", nargs="+", metavar="SPEC", help="confirm these specs and add them to the table")
    ap.add_argument("--by", default="bp+published", choices=SOURCES, help="the two sources for --add")
    args = ap.parse_args(argv)
    try:
        if args.add:
            for spec in args.add:
                load_spec(spec)  # a bad spec is a one-line error before anything is solved
            rows = add(args.add, args.by, args.time_limit, args.out)
        else:
            rows = regenerate(args.time_limit, args.random, args.out)
    except (ValueError, OSError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"{len(rows)} confirmed rows written to {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
