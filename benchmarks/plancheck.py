"""Check a plan from outside: the verifier's verdict, and its gap to what sarcover knows.

What sarcover knows about an instance's optimum, looked up by the instance's content (its name
alone does not say E_max, and a file may be edited under a shipped name):

- a proven optimum: of a shipped TOP file (``instances/top/optimal.csv``, status ``optimal``), of
  a row of the regression table (``regression/optimal_values.csv``: shipped files and generated
  instances, each confirmed by two sources), or of the runs in a results folder the caller names
  (an exact method's ``optimal`` row, as the report counts it);
- a proven infeasibility (a regression table row): no valid plan can exist;
- failing those, the best (lowest) bound any run in that results folder proved: the gap to it is
  an upper bound on the true gap;
- failing that, the published best known value of a shipped file whose optimum is not proven (a
  plan's value, so the gap to it is a distance to that plan, not to the optimum).

``sarcover verify`` and :func:`sarcover.verify_plan` print and return this.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan
from sarcover.formulations.verify import VerificationReport, verify

TOL = 1e-6  # relative, as reports.gaps: values within it count as equal


@dataclass(frozen=True)
class Known:
    """What is known of an instance's optimum: ``kind`` is ``optimum`` (proven), ``infeasible``
    (proven: no plan covers every target), ``bound`` (a proven upper bound on the optimum) or
    ``best_known`` (a published plan's value, a lower bound on it); ``source`` says where from."""

    kind: str
    value: float | None
    source: str


@dataclass(frozen=True)
class PlanCheck:
    """A checked plan: the verifier's ``report``, what is ``known`` of the optimum (or None), and
    ``notes`` (say, a results folder without runs on this instance)."""

    instance: str
    kind: str  # the instance's: "sar" (viewpoints) or "top"
    report: VerificationReport
    n_nodes: int
    total_prize: float
    budget: float
    known: Known | None = None
    notes: tuple[str, ...] = field(default=())

    @property
    def valid(self) -> bool:
        return self.report.valid

    @property
    def violations(self) -> list[str]:
        return list(self.report.violations)

    @property
    def objective(self) -> float | None:
        """The verifier's objective (covered viewpoints, or total prize); None for an invalid plan."""
        return self.report.prize if self.valid else None

    @property
    def coverage(self) -> float | None:
        return self.report.coverage if self.valid else None

    @property
    def gap(self) -> float | None:
        """(known − objective) / known, as the reports count it (0 when both are 0): to the proven
        optimum, at most this to the bound, or below the best known value; None without a valid
        plan or a known value. Negative when the plan beats the known value (a wrong optimum or
        bound, or a new best known value)."""
        if not self.valid or self.known is None or self.known.value is None:
            return None
        value, obj = self.known.value, self.objective
        if value > 0:
            return (value - obj) / value
        return 0.0 if obj <= TOL else -math.inf

    def lines(self) -> list[str]:
        """What ``sarcover verify`` prints: each violation on a line of its own, or the objective,
        the coverage and the gap."""
        if not self.valid:
            return self.violations
        obj = self.objective
        if self.kind == "sar":
            covered = f"{self.report.covered} of {self.n_nodes} viewpoints"
        else:
            covered = f"prize {obj:g} of {self.total_prize:g}, {self.report.covered} of {self.n_nodes} nodes"
        most = max(self.report.energy, default=0.0)
        head = (f"valid plan for {self.instance}: objective {obj:g}, coverage {100 * self.coverage:.2f}% "
                f"({covered}), energy per route at most {most:.6g} of {self.budget:g}")
        return [head, self._gap_line(), *self.notes]

    def _gap_line(self) -> str:
        known, gap = self.known, self.gap
        if known is None:
            return "no optimum or bound known for this instance (`--results DIR` adds what a results folder proved)"
        if known.kind == "infeasible":
            return (f"CONFLICT: {known.source} says no plan covers every target, and this one does: "
                    "that proof is wrong")
        pct = f"{100 * gap:.2f}%" if math.isfinite(gap) else "unbounded"
        if known.kind == "optimum":
            line = f"gap {pct} to the proven optimum {known.value:g} ({known.source})"
            if gap < -TOL:
                line += "; CONFLICT: the plan is better than the proven optimum, so that proof is wrong"
            return line
        if known.kind == "bound":
            line = f"gap at most {pct} to the best proven bound {known.value:g} ({known.source}; no optimum proven)"
            if gap < -TOL:
                line += "; CONFLICT: the plan is better than the bound, so that bound is wrong"
            return line
        if gap < -TOL:
            return (f"above the published best known value {known.value:g} by {100 * -gap:.2f}% ({known.source}; "
                    "not proven optimal): a new best known value")
        return f"{pct} below the best known value {known.value:g} ({known.source}; not proven optimal)"

    def to_dict(self) -> dict:
        """The check as one JSON object (``sarcover verify --json``)."""
        gap = self.gap
        return {
            "instance": self.instance, "valid": self.valid, "violations": self.violations,
            "objective": self.objective, "coverage": self.coverage,
            "covered": self.report.covered if self.valid else None,
            "energy": [e if math.isfinite(e) else None for e in self.report.energy],  # NaN is not JSON
            "known": None if self.known is None else {"kind": self.known.kind, "value": self.known.value,
                                                      "source": self.known.source},
            "gap": gap if gap is None or math.isfinite(gap) else None,
            "notes": list(self.notes),
        }


def check_plan(instance: TOPInstance, plan: Plan, results: str | Path | None = None) -> PlanCheck:
    """Verify ``plan`` on ``instance`` and find what is known of its optimum (see the module's
    docstring), including the runs stored in the results folder ``results`` if given."""
    report = verify(instance, plan)
    notes: list[str] = []
    known = known_value(instance, results, notes)
    return PlanCheck(instance=instance.name, kind=instance.kind, report=report, n_nodes=instance.n_nodes,
                     total_prize=instance.total_prize, budget=instance.budget, known=known, notes=tuple(notes))


def known_value(instance: TOPInstance, results: str | Path | None = None,
                notes: list[str] | None = None) -> Known | None:
    """The best thing known of ``instance``'s optimum, in the order of the module's docstring: a
    proven optimum (the results folder's first, then the regression table's, then the published
    one), a proven infeasibility, the results folder's best bound, a published best known value.
    Remarks for the reader (no runs on the instance in ``results``, sources that disagree) are
    appended to ``notes``."""
    notes = [] if notes is None else notes
    from_results = _from_results(instance, results, notes) if results is not None else []
    regression = _from_regression(instance)
    published = _from_published(instance)
    found = from_results + regression + published
    optima = [k for k in found if k.kind == "optimum"]
    if optima and max(k.value for k in optima) - min(k.value for k in optima) > TOL * max(1.0, optima[0].value):
        notes.append("CONFLICT: the proven optima disagree: "
                     + "; ".join(f"{k.value:g} ({k.source})" for k in optima))
    for kind in ("optimum", "infeasible", "bound", "best_known"):
        for k in found:
            if k.kind == kind:
                return k
    return None


def same_instance(a: TOPInstance, b: TOPInstance) -> bool:
    """True when ``a`` and ``b`` pose the same problem (points, prizes, budget, fleet, energies,
    groups), whatever their names."""
    def close(x, y) -> bool:
        return bool(np.allclose(np.asarray(x, dtype=float), np.asarray(y, dtype=float), rtol=1e-12, atol=1e-9))

    return (a.n_nodes == b.n_nodes and a.n_vehicles == b.n_vehicles and a.groups == b.groups
            and close(a.coords, b.coords) and close(a.prizes, b.prizes) and close(a.start, b.start)
            and close(a.end, b.end) and close([a.budget, a.e_fly, a.e_image], [b.budget, b.e_fly, b.e_image]))


def _from_published(instance: TOPInstance) -> list[Known]:
    """The published value of the shipped TOP file this instance is (same name and content)."""
    from sarcover.benchmarks.catalog import benchmark_file, published
    from sarcover.formulations.io import read_top

    if instance.kind != "top":
        return []
    path = benchmark_file(instance.name)
    if path is None or not same_instance(instance, read_top(path)):
        return []
    value = published(path)
    if value is None:
        return []
    kind = "optimum" if value[1] == "optimal" else "best_known"
    return [Known(kind, value[0], "published, benchmarks/instances/top/optimal.csv")]


def _from_regression(instance: TOPInstance) -> list[Known]:
    """The regression table's row of this instance, matched by content: generated instances by
    their parameters (M, K, N, E_max) first, then rebuilt and compared."""
    from sarcover.benchmarks.regression import TABLE, load_spec, read_table

    found = []
    for row in read_table(TABLE):
        kind, _, body = row["spec"].partition(":")
        if kind == "gen" and instance.kind == "sar":
            m, k, n, _seed, e_max = body.split(",")
            if (len(instance.groups), instance.n_nodes, instance.n_vehicles) != (int(m), int(m) * int(k), int(n)):
                continue
            if not math.isclose(float(e_max), instance.budget, rel_tol=1e-12):
                continue
        elif kind == "top" and instance.kind == "top":
            if body != instance.name:
                continue
        else:
            continue
        if not same_instance(instance, load_spec(row["spec"])):
            continue
        source = f"regression table, confirmed by {row['confirmed_by']}"
        if row["status"] == "infeasible":
            found.append(Known("infeasible", None, source))
        elif row["status"] == "optimal":
            found.append(Known("optimum", float(row["value"]), source))
    return found


def _from_results(instance: TOPInstance, results: str | Path, notes: list[str]) -> list[Known]:
    """The proven optimum, or else the best bound, of this instance's runs in a results folder.
    A run is on this instance when its instance name, node count, fleet and E_max are the
    instance's (a generated instance's name does not say its E_max)."""
    import pandas as pd

    from sarcover.reports.gaps import instance_table
    from sarcover.reports.results import load_results

    df, _skipped = load_results(results)
    mine = (df["instance"] == instance.name)
    for col, value in (("n_nodes", instance.n_nodes), ("n_vehicles", instance.n_vehicles)):
        if col in df:
            mine &= df[col].isna() | (pd.to_numeric(df[col], errors="coerce") == value)
    if "e_max" in df:
        e_max = pd.to_numeric(df["e_max"], errors="coerce")
        mine &= e_max.isna() | (np.abs(e_max - instance.budget) <= 1e-9 * max(1.0, abs(instance.budget)))
    runs = df[mine]
    if runs.empty:
        notes.append(f"{results}: none of its {len(df)} runs is on this instance")
        return []
    row = instance_table(runs).iloc[0]
    found = []
    where = f"results {results}"
    if row["conflict"]:
        notes.append(f"CONFLICT in {where}: {row['conflict']}")
    if not np.isnan(row["opt"]):
        found.append(Known("optimum", float(row["opt"]), f"{where}, proven by {row['opt_source']}"))
    elif not np.isnan(row["best_bound"]):
        bound = float(row["best_bound"])
        bounds = pd.to_numeric(runs["bound"], errors="coerce")
        by = sorted({str(m) for m, b in zip(runs["method"], bounds)
                     if not np.isnan(b) and abs(b - bound) <= TOL * max(1.0, abs(bound))})
        found.append(Known("bound", bound, f"{where}, proven by {'+'.join(by)}"))
    return found
