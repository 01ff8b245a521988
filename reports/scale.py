"""Beyond the paper's size: suite ``scale`` (M = 20..100 targets at K = 3 and 6, 60 to 600
viewpoints, N chosen for mid-range coverage; docs/scale.md), every method against bp.

Per setting (M, K, N): bp's proven share and its certified gap, each method's gap and runtime.
Per instance, with ``best`` the best verified plan of any method and ``bound`` the best bound of
any exact method (:func:`sarcover.reports.gaps.instance_table`)::

    bp's certified gap = (bp's bound - best) / bp's bound     0 where bp proves the optimum
    a method's gap = (opt - obj) / opt             where the optimum is proven (by any exact method)
                   <= (bound - obj) / bound        where it is not: an upper bound on the true gap

A setting's mean gap is marked "≤" when any of its instances is unproven (it then mixes gaps to
the optimum with upper bounds, and is itself an upper bound on the mean true gap); its 95 % t
interval is over the runs with a plan. How cost grows with size: each method's median runtime
per setting against the viewpoints M·K on log-log axes, and the slope of a least-squares line
through those points, the exponent b of runtime ≈ a·(M·K)^b. A method stopped by its time limit at
the larger sizes has its runtime capped there, so its exponent is then a lower bound on the
growth of the time it would need; the table gives the share of runs that hit the limit.

bp's settings at scale were chosen on two of the suite's instances (``TUNING``, docs/bp.md "Where
each setting was chosen"): the per-setting table counts them and gives bp's certified gap over
the other instances apart, the held-out figure.

Works on partial results: a setting with no bp rows yet has no proven share and its gaps wait.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from sarcover.reports.gaps import add_gaps, instance_table
from sarcover.reports.plots import save_figure, subplots
from sarcover.reports.stats import t_halfwidth
from sarcover.reports.style import legend_outside, look, ordered

SUITE = "scale"
PROVER = "bp"  # its proofs and bounds make the optimum and the certified gap
KEYS = ["M", "K", "N"]
# the instances bp's scale settings (sparse heuristic pricing, the primal heuristic first) were
# chosen on: docs/bp.md "Where each setting was chosen"
TUNING = frozenset({"sar-m40-k6-n10-s300", "sar-m100-k6-n20-s300"})


def label(m: int, k: int, n: int) -> str:
    return f"M={m} K={k} N={n}"


def _settings(df: pd.DataFrame) -> pd.DataFrame:
    """One row per instance: M, K, N, viewpoints (M·K) and the setting's label."""
    first = df.drop_duplicates("instance").set_index("instance")
    out = first[KEYS].astype(int)
    out["viewpoints"] = out["M"] * out["K"]
    out["setting"] = [label(m, k, n) for m, k, n in out[KEYS].itertuples(index=False)]
    return out


def setting_table(df: pd.DataFrame) -> pd.DataFrame:
    """Per setting, in order of viewpoints: instances, bp's runs, proofs and proven share, and bp's
    certified gap (bp's bound − best plan of any method)/bp's bound over the instances bp ran on
    (mean, max), and over those of them that chose no setting (``TUNING``: ``held_out_*``)."""
    inst = instance_table(df)
    where = _settings(df)
    bp = df[df["method"] == PROVER].drop_duplicates("instance").set_index("instance")
    inst = inst.join(where)
    inst["bp_ran"] = inst.index.isin(bp.index)
    inst["bp_proven"] = inst.index.isin(bp.index[bp["status"] == "optimal"])
    bound = bp["bound"].astype(float).reindex(inst.index)  # bp's own certificate
    best = inst["best_objective"].astype(float)
    with np.errstate(divide="ignore", invalid="ignore"):
        inst["certified_gap"] = np.where(bound > 0, np.maximum((bound - best) / bound, 0.0),
                                         np.where(bound.notna() & best.notna(), 0.0, np.nan))
    rows = []
    for (m, k, n), g in inst.groupby(KEYS):
        ran = g[g["bp_ran"]]
        gaps = ran["certified_gap"].dropna()
        held = ran.loc[~ran.index.isin(TUNING), "certified_gap"].dropna()
        limits = sorted(bp.loc[bp.index.isin(g.index), "time_limit"].dropna().astype(float).unique())
        rows.append({"setting": label(m, k, n), "M": m, "K": k, "N": n, "viewpoints": m * k,
                     "instances": len(g), "bp_runs": len(ran),
                     "bp_time_limit": "/".join(f"{v:g}" for v in limits),
                     "proven": int(ran["bp_proven"].sum()),
                     "share_proven": ran["bp_proven"].mean() if len(ran) else np.nan,
                     "certified_gap_n": len(gaps),
                     "certified_gap_mean": gaps.mean() if len(gaps) else np.nan,
                     "certified_gap_max": gaps.max() if len(gaps) else np.nan,
                     "tuning": int(ran.index.isin(TUNING).sum()),
                     "held_out_gap_mean": held.mean() if len(held) else np.nan,
                     "held_out_gap_max": held.max() if len(held) else np.nan,
                     "conflicts": int(g["conflict"].astype(str).str.len().gt(0).sum())})
    return pd.DataFrame(rows).sort_values(["viewpoints", "K", "N"], ignore_index=True)


GAP_COLUMNS = ["method", "setting", "M", "K", "N", "viewpoints", "runs", "with_plan", "at_time_limit",
               "gap_n", "gap_mean", "gap_ci95", "gap_ub_n", "gap_ub_mean", "gap_ub_ci95",
               "gap_any_mean", "gap_any_ci95", "gap_is_bound", "runtime_median_s"]


def method_table(df: pd.DataFrame) -> pd.DataFrame:
    """Per method and setting: runs, runs with a plan, the share stopped by the time limit, the gap
    to the proven optimum (``gap_*``, instances bp proved), to the best bound (``gap_ub_*``, the
    rest: an upper bound on the gap), both together (``gap_any_*``; ``gap_is_bound`` when some of
    it is an upper bound), each a mean with its 95 % t half-width, and the median runtime."""
    g = add_gaps(df)
    g["gap_any"] = g["gap"].fillna(g["gap_ub"])
    rows = []
    for (meth, m, k, n), s in g.groupby(["method"] + KEYS):
        gap, ub, any_ = s["gap"].dropna(), s["gap_ub"].dropna(), s["gap_any"].dropna()
        rows.append({"method": meth, "setting": label(m, k, n), "M": m, "K": k, "N": n, "viewpoints": m * k,
                     "runs": len(s), "with_plan": int(s["objective"].notna().sum()),
                     "at_time_limit": float((s["termination"] == "time_limit").mean())
                     if "termination" in s else np.nan,
                     "gap_n": len(gap), "gap_mean": gap.mean() if len(gap) else np.nan,
                     "gap_ci95": t_halfwidth(gap),
                     "gap_ub_n": len(ub), "gap_ub_mean": ub.mean() if len(ub) else np.nan,
                     "gap_ub_ci95": t_halfwidth(ub),
                     "gap_any_mean": any_.mean() if len(any_) else np.nan, "gap_any_ci95": t_halfwidth(any_),
                     "gap_is_bound": bool(len(ub)),
                     "runtime_median_s": s["runtime_s"].astype(float).median()})
    return pd.DataFrame(rows, columns=GAP_COLUMNS)


def fit_exponent(x, y) -> tuple[float, float, int]:
    """(b, a, points) of the least-squares line log y = log a + b·log x through the points with
    positive x and y: runtime ≈ a·x^b. NaN for b and a below two distinct x."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    if np.unique(x[ok]).size < 2:
        return np.nan, np.nan, int(ok.sum())
    b, log_a = np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)
    return float(b), float(np.exp(log_a)), int(ok.sum())


def growth_table(mt: pd.DataFrame) -> pd.DataFrame:
    """Per method: the exponent of its median runtime against viewpoints over all settings and per
    K, the viewpoints it spans, and the share of its runs stopped by the time limit at its largest
    setting (where that is large the exponent understates the growth)."""
    rows = []
    for meth, s in mt.groupby("method"):
        b, a, pts = fit_exponent(s["viewpoints"], s["runtime_median_s"])
        row = {"method": meth, "exponent": b, "coefficient_s": a, "settings": pts,
               "viewpoints": f"{s['viewpoints'].min()}-{s['viewpoints'].max()}"}
        for k, sk in s.groupby("K"):
            row[f"exponent_K{k}"] = fit_exponent(sk["viewpoints"], sk["runtime_median_s"])[0]
        big = s[s["viewpoints"] == s["viewpoints"].max()]
        row["at_time_limit_largest"] = float((big["at_time_limit"] * big["runs"]).sum() / big["runs"].sum())
        rows.append(row)
    out = pd.DataFrame(rows)
    return out.set_index("method").reindex(ordered(out["method"])).reset_index() if len(out) else out


def plot_growth(mt: pd.DataFrame, gt: pd.DataFrame, path) -> None:
    """Left: median runtime against viewpoints (log-log) per method with its fitted line; right:
    mean gap (to the optimum, or its upper bound to the bound) against viewpoints."""
    fig, (ax, ax_gap) = subplots(1, 2, figsize=(13, 4.6))
    methods = ordered(mt["method"])
    exps = gt.set_index("method")["exponent"] if len(gt) else pd.Series(dtype=float)
    any_gap = False
    for meth in methods:
        own = mt[mt["method"] == meth]  # one point per setting: the points the line is fitted to
        lk = look(meth)
        ax.plot(own["viewpoints"], own["runtime_median_s"], ms=6, lw=0, marker=lk.marker, color=lk.color)
        b = exps.get(meth, np.nan)
        if np.isfinite(b):
            a = float(gt.set_index("method").loc[meth, "coefficient_s"])
            xs = np.array([own["viewpoints"].min(), own["viewpoints"].max()], dtype=float)
            ax.plot(xs, a * xs ** b, color=lk.color, ls=lk.ls, lw=1.3)
        gap = own.groupby("viewpoints")["gap_any_mean"].mean().dropna()  # settings of equal size averaged
        if len(gap):
            any_gap = True
            ax_gap.plot(gap.index, gap.to_numpy(), ms=6, lw=1.3, **lk.line())
    from matplotlib.ticker import NullLocator

    ticks = sorted(int(v) for v in mt["viewpoints"].unique())
    for a_ in (ax, ax_gap):  # the settings' sizes as plain numbers on the log axis
        a_.set_xscale("log")
        a_.set_xticks(ticks, [str(v) for v in ticks])
        a_.xaxis.set_minor_locator(NullLocator())
    ax.set_yscale("log")
    ax.set_xlabel("viewpoints M·K")
    ax.set_ylabel("median runtime (s)")
    ax.set_title("Runtime against size (fitted: runtime ≈ a·(M·K)^b)", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax_gap.set_xlim(ax.get_xlim())
    if not any_gap:
        ax_gap.text(0.5, 0.5, "no gaps yet: no optimum or bound", transform=ax_gap.transAxes, ha="center")
    ax_gap.set_xlabel("viewpoints M·K")
    ax_gap.set_ylabel("mean gap (≤ where unproven)")
    ax_gap.set_title("Gap against size", fontsize=10)
    ax_gap.grid(alpha=0.3)

    def name(m: str) -> str:
        b = exps.get(m, np.nan)
        return f"{m} (b = {b:.2f})" if np.isfinite(b) else m

    legend_outside(ax_gap, methods, label=name)
    save_figure(fig, path)


# ---------------------------------------------------------------- the section


def _pct(mean: float, ci: float) -> str:
    if pd.isna(mean):
        return "–"
    return f"{100 * mean:.1f} %" + ("" if pd.isna(ci) else f" ± {100 * ci:.1f}")


def _md_table(head: list[str], rows: list[list]) -> list[str]:
    return (["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
            + ["| " + " | ".join(str(c) for c in r) + " |" for r in rows])


def scale_section(df: pd.DataFrame | None, out, *, heading: str = "##") -> list[str]:
    """The section's Markdown lines, or none without rows of the suite; its PNG and CSVs go to ``out``."""
    if df is None or df.empty:
        return []
    df = df[df["kind"].fillna("sar") == "sar"] if "kind" in df else df
    if df.empty:
        return []
    h = heading
    st, mt = setting_table(df), method_table(df)
    gt = growth_table(mt)
    st.to_csv(out / "scale_settings.csv", index=False)
    mt.to_csv(out / "scale_gaps.csv", index=False)
    gt.to_csv(out / "scale_growth.csv", index=False)
    plot_growth(mt, gt, out / "scale_growth.png")
    runs = df.groupby(KEYS)["instance"].nunique()
    lines = [f"{h} Beyond the paper's size (suite `{SUITE}`)", "",
             f"M = {', '.join(str(v) for v in sorted(df['M'].unique()))} targets at K = "
             f"{', '.join(str(v) for v in sorted(df['K'].unique()))} ({int(st['viewpoints'].min())} to "
             f"{int(st['viewpoints'].max())} viewpoints), {runs.min()}"
             + (f"-{runs.max()}" if runs.max() > runs.min() else "")
             + (" instances" if runs.max() > 1 else " instance")
             + " per setting, N for mid-range coverage (docs/scale.md). bp's certified gap is "
             "(bp's bound − best plan of any method)/bp's bound, 0 where bp proves the optimum. A method's gap "
             "is to the proven optimum where one is proven and to the best bound where not: there it is an upper "
             "bound on the true gap, and a mean marked ≤ includes such upper bounds. Means with their 95 % t "
             "half-widths over the runs with a plan; runtimes are medians.", ""]
    lines += [f"{h}# bp per setting", "",
              "Tuning instances: those bp's scale settings were chosen on (" + ", ".join(sorted(TUNING))
              + "; docs/bp.md); the held-out gaps leave them out.", ""]
    lines += _md_table(["setting", "viewpoints", "instances", "bp limit (s)", "proven by bp",
                        "certified gap mean", "certified gap max", "tuning instances",
                        "held-out gap mean", "held-out gap max", "conflicts"],
                       [[r["setting"], r["viewpoints"], r["instances"], r["bp_time_limit"] or "–",
                         "no bp rows yet" if not r["bp_runs"] else
                         f"{r['proven']}/{r['bp_runs']} ({100 * r['share_proven']:.0f} %)",
                         _pct(r["certified_gap_mean"], np.nan), _pct(r["certified_gap_max"], np.nan),
                         r["tuning"], _pct(r["held_out_gap_mean"], np.nan), _pct(r["held_out_gap_max"], np.nan),
                         r["conflicts"]]
                        for _, r in st.iterrows()])
    settings = list(st["setting"])
    methods = ordered(mt["method"])
    cell = mt.set_index(["method", "setting"])
    gap_rows, time_rows = [], []
    for meth in methods:
        gr, tr = [meth], [meth]
        for c in settings:
            if (meth, c) not in cell.index:
                gr.append("–")
                tr.append("–")
                continue
            r = cell.loc[(meth, c)]
            text = _pct(r["gap_any_mean"], r["gap_any_ci95"])
            gr.append(("≤ " + text if r["gap_is_bound"] and text != "–" else text)
                      + ("" if r["with_plan"] == r["runs"] else f" ({r['with_plan']}/{r['runs']} with plan)"))
            tr.append(f"{r['runtime_median_s']:.3g}")
        gap_rows.append(gr)
        time_rows.append(tr)
    lines += ["", f"{h}# Gap per method and setting", "",
              "Mean gap ± 95 % t half-width; ≤: some of the setting's instances are unproven and their gaps are to "
              "the best bound (the CSV has the proven and the bounded parts apart).", ""]
    lines += _md_table(["method"] + settings, gap_rows)
    lines += ["", f"{h}# Runtime per method and setting (median, s)", ""]
    lines += _md_table(["method"] + settings, time_rows)
    lines += ["", f"{h}# How runtime and gap grow with the viewpoints", "",
              "![runtime and gap against size](scale_growth.png)", "",
              "The exponent b of median runtime ≈ a·(M·K)^b, least squares on log-log over the settings' "
              "medians (all settings, and per K). Where many runs stop on the time limit at the largest setting "
              "the runtime is capped there and b is a lower bound on the growth.", ""]
    k_cols = [c for c in gt.columns if c.startswith("exponent_K")]
    lines += _md_table(["method", "b (all settings)"] + [f"b at K={c[len('exponent_K'):]}" for c in k_cols]
                       + ["settings", "viewpoints", "at time limit (largest setting)"],
                       [[r["method"], "–" if pd.isna(r["exponent"]) else f"{r['exponent']:.2f}"]
                        + ["–" if pd.isna(r[c]) else f"{r[c]:.2f}" for c in k_cols]
                        + [r["settings"], r["viewpoints"], f"{100 * r['at_time_limit_largest']:.0f} %"]
                        for _, r in gt.iterrows()])
    lines += ["", "Tables: `scale_settings.csv`, `scale_gaps.csv`, `scale_growth.csv`.", ""]
    return lines
