"""Optimality gaps from a results table (one row per job; see :mod:`sarcover.reports.results`).

Gap of a run with objective ``obj`` on an instance with proven optimum ``opt``::

    gap = (opt - obj) / opt          # 9 of an optimal 10 -> 0.10; 0 when opt == obj == 0

The proven optimum of an instance is the best objective of any run whose status is ``optimal``
(an exact method that proved it), or the published optimum of a benchmark file (``reference``).
Where none is proven, the gap to the best (lowest) bound any method proved, ``(bound - obj) /
bound``, is an *upper bound* on the true gap; it is reported in its own columns, never mixed with
proven gaps. Runs without a plan (``no_plan``, ``infeasible``, ``time_limit`` without incumbent,
``error``) have no gap; they are counted in their own columns.

Consistency checks (a wrong "optimal" is the worst bug): two different proven optima on one
instance, a verified objective above the proven optimum, a bound below a verified objective, or a
proven optimum or bound below a published best known value (``best_known``, a lower bound) are
listed as conflicts. A verified plan above a published best known value is news: it is listed in
the ``news`` column (a new best known value, to be reported with its routes).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

TOL = 1e-6


def _rel(a: float) -> float:
    return TOL * max(1.0, abs(a))


def instance_table(df: pd.DataFrame) -> pd.DataFrame:
    """Per instance: proven optimum (and where from), best bound, best objective, conflicts."""
    out = []
    for inst, g in df.groupby("instance", sort=True):
        obj = g["objective"].astype(float)
        proven = obj[(g["status"] == "optimal") & g["valid"].astype(bool)].dropna()
        sources = [f"{m}" for m in g.loc[proven.index, "method"].unique()]
        candidates = list(proven)
        ref = g["reference"].dropna() if "reference" in g else pd.Series(dtype=float)
        if len(ref):
            candidates.append(float(ref.iloc[0]))
            sources.append("published")
        opt = max(candidates) if candidates else np.nan
        bounds = g["bound"].astype(float).dropna()
        best_bound = float(bounds.min()) if len(bounds) else np.nan
        best_obj = float(obj.max()) if obj.notna().any() else np.nan
        conflicts = []
        if candidates and max(candidates) - min(candidates) > _rel(opt):
            conflicts.append(f"proven optima disagree: {sorted(set(round(c, 9) for c in candidates))}")
        if not np.isnan(opt) and not np.isnan(best_obj) and best_obj > opt + _rel(opt):
            conflicts.append(f"objective {best_obj:g} above proven optimum {opt:g}")
        if not np.isnan(best_bound) and not np.isnan(best_obj) and best_bound < best_obj - _rel(best_obj):
            conflicts.append(f"bound {best_bound:g} below objective {best_obj:g}")
        bk_values = g["best_known"].dropna() if "best_known" in g else pd.Series(dtype=float)
        best_known = float(bk_values.iloc[0]) if len(bk_values) else np.nan
        news = ""
        if not np.isnan(best_known):
            if not np.isnan(opt) and opt < best_known - _rel(best_known):
                conflicts.append(f"proven optimum {opt:g} below published best known {best_known:g}")
            if not np.isnan(best_bound) and best_bound < best_known - _rel(best_known):
                conflicts.append(f"bound {best_bound:g} below published best known {best_known:g}")
            if not np.isnan(best_obj) and best_obj > best_known + _rel(best_known):
                news = f"new best known {best_obj:g} (published {best_known:g})"
        first = g.iloc[0]
        out.append({
            "instance": inst, "kind": first.get("kind"), "n_nodes": first.get("n_nodes"),
            "opt": opt, "opt_source": "+".join(sources) if candidates else "",
            "best_bound": best_bound, "best_objective": best_obj, "best_known": best_known,
            "conflict": "; ".join(conflicts), "news": news,
        })
    return pd.DataFrame(out).set_index("instance")


def add_gaps(df: pd.DataFrame, inst: pd.DataFrame | None = None) -> pd.DataFrame:
    """Copy of ``df`` with ``opt``, ``gap`` (to the proven optimum), ``gap_ub`` (to the best
    bound, where no optimum is proven) and ``at_opt`` (objective equals the proven optimum)."""
    inst = instance_table(df) if inst is None else inst
    out = df.copy()
    out["opt"] = out["instance"].map(inst["opt"]).astype(float)
    out["best_bound"] = out["instance"].map(inst["best_bound"]).astype(float)
    obj = out["objective"].astype(float)
    opt, bb = out["opt"], out["best_bound"]
    with np.errstate(divide="ignore", invalid="ignore"):
        gap = np.where(opt > 0, (opt - obj) / opt, np.where(obj.notna(), 0.0, np.nan))
        gap_ub = np.where(bb > 0, (bb - obj) / bb, np.where(obj.notna() & bb.notna(), 0.0, np.nan))
    out["gap"] = np.where(opt.notna() & obj.notna(), np.maximum(gap, 0.0), np.nan)
    out["gap_ub"] = np.where(opt.isna() & bb.notna() & obj.notna(), np.maximum(gap_ub, 0.0), np.nan)
    out["at_opt"] = np.where(opt.notna(), obj.notna() & (np.abs(opt - obj) <= TOL * np.maximum(1.0, opt)), np.nan)
    return out


def method_table(gapped: pd.DataFrame) -> pd.DataFrame:
    """Per method: run counts by status, gap statistics, share optimal, coverage, runtime."""
    rows = []
    for method, g in gapped.groupby("method", sort=False):
        status = g["status"]
        has_plan = g["objective"].notna()
        gap, gap_ub = g["gap"].dropna(), g["gap_ub"].dropna()
        on_opt = g[g["opt"].notna()]
        rows.append({
            "method": method,
            "exact": bool(g["exact"].iloc[0]) if g["exact"].notna().any() else False,
            "runs": len(g),
            "with_plan": int(has_plan.sum()),
            "optimal": int((status == "optimal").sum()),
            "time_limit": int((status == "time_limit").sum()),
            "no_plan": int(status.isin(["no_plan", "infeasible"]).sum()),
            "error": int((status == "error").sum()),
            "gap_n": len(gap),
            "gap_mean": gap.mean() if len(gap) else np.nan,
            "gap_median": gap.median() if len(gap) else np.nan,
            "gap_max": gap.max() if len(gap) else np.nan,
            "share_optimal": float(on_opt["at_opt"].astype(float).mean()) if len(on_opt) else np.nan,
            "gap_ub_n": len(gap_ub),
            "gap_ub_mean": gap_ub.mean() if len(gap_ub) else np.nan,
            "gap_ub_median": gap_ub.median() if len(gap_ub) else np.nan,
            "gap_ub_max": gap_ub.max() if len(gap_ub) else np.nan,
            "coverage_mean": g["coverage"].astype(float).mean(),
            "runtime_mean_s": g["runtime_s"].astype(float).mean(),
            "runtime_median_s": g["runtime_s"].astype(float).median(),
            "runtime_max_s": g["runtime_s"].astype(float).max(),
        })
    return pd.DataFrame(rows).set_index("method")
