"""Regression table of proven optimal values, confirmed by both exact solvers (`milp`, `cpsat`).

``python -m sarcover.benchmarks.regression [--time-limit S] [--random N]`` re-solves every instance of the
table with both methods and rewrites ``benchmarks/regression/optimal_values.csv``; a row is kept
only if both proved optimality and agree (or both proved infeasibility). Instances are either
generated (``gen:M,K,N,seed,e_max`` with the paper preset) or TOP benchmark files (``top:p2.2.k``).
:func:`random_cases` is also the instance family of the exact cross-check test.
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

ROOT = Path(__file__).resolve().parent
TABLE = ROOT / "regression" / "optimal_values.csv"
TOP_DIR = ROOT / "instances" / "top"
FIELDS = ["spec", "status", "value", "milp_s", "cpsat_s"]

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
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def confirm(spec: str, time_limit: float) -> dict | None:
    """Solve with both exact methods; the row if both proved the same thing, else None."""
    from sarcover.benchmarks.registry import run_method  # the CLI side; formulations never import this

    inst = load_spec(spec)
    out = {}
    for name in ("milp", "cpsat"):
        res = run_method(name, inst, time_limit=time_limit)
        out[name] = res
    a, b = out["milp"], out["cpsat"]
    row = {"spec": spec, "milp_s": f"{a.runtime_s:.3f}", "cpsat_s": f"{b.runtime_s:.3f}"}
    if a.status == b.status == "infeasible":
        return {**row, "status": "infeasible", "value": ""}
    if a.status == b.status == "optimal" and abs(a.objective - b.objective) <= 1e-9:
        return {**row, "status": "optimal", "value": f"{a.objective:g}"}
    print(f"{spec}: not confirmed (milp {a.status} {a.objective}, cpsat {b.status} {b.objective})",
          file=sys.stderr)
    return None


def regenerate(time_limit: float = 60.0, n_random: int = 40, path: Path = TABLE) -> list[dict]:
    """Re-solve the table's instances with both methods and write the confirmed rows."""
    specs = [f"top:{n}" for n in TOP_SPECS] + random_cases(n_random, start=500, max_targets=6, max_views=3)
    rows = [r for r in (confirm(s, time_limit) for s in specs) if r is not None]
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS)
        w.writeheader()
        w.writerows(rows)
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m sarcover.benchmarks.regression", description=__doc__.splitlines()[0])
    ap.add_argument("--time-limit", type=float, default=60.0, help="seconds per solver and instance")
    ap.add_argument("--random", type=int, default=40, help="number of generated SAR instances")
    ap.add_argument("--out", type=Path, default=TABLE)
    args = ap.parse_args(argv)
    rows = regenerate(args.time_limit, args.random, args.out)
    print(f"{len(rows)} confirmed rows written to {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
