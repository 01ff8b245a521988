"""`sarcover report RESULTS_DIR`: Markdown + HTML with PNG plots and CSV tables.

Reads only the results file (and rebuilds one instance through ``formulations`` for the example
routes plot). Sections: per-method gap table, paper views (coverage against N and against K,
Fig. 3 and 4; runtime table, Table I; example routes, Fig. 2), gap distributions, time to
optimality against size for the exact methods, bound and incumbent against time (exact methods
with ``info.history``), consistency checks, skipped rows.
"""

from __future__ import annotations

import html
import json
import os
from pathlib import Path

import numpy as np
import pandas as pd

from sarcover.formulations.records import RESULTS_FILE
from sarcover.reports.gaps import add_gaps, instance_table, method_table
from sarcover.reports.plots import save_figure, subplots
from sarcover.reports.results import load_results
from sarcover.reports.style import dodge, legend_outside, look, ordered

_PCT = ("gap_mean", "gap_median", "gap_max", "share_optimal", "gap_ub_mean", "gap_ub_median",
        "gap_ub_max", "coverage_mean")


class _Doc:
    """Collects sections once and renders them as Markdown and as HTML."""

    def __init__(self, title: str):
        self.title, self.parts = title, []

    def h(self, text):
        self.parts.append(("h", text))

    def p(self, text):
        self.parts.append(("p", text))

    def table(self, df: pd.DataFrame, csv_name: str | None = None):
        self.parts.append(("t", (df, csv_name)))

    def img(self, name, alt):
        self.parts.append(("i", (name, alt)))

    def markdown(self) -> str:
        out = [f"# {self.title}", ""]
        for kind, x in self.parts:
            if kind == "h":
                out += [f"## {x}", ""]
            elif kind == "p":
                out += [x, ""]
            elif kind == "t":
                df, csv_name = x
                out += [_md_table(df), ""]
                if csv_name:
                    out += [f"(CSV: [{csv_name}]({csv_name}))", ""]
            else:
                out += [f"![{x[1]}]({x[0]})", ""]
        return "\n".join(out)

    def html(self) -> str:
        out = ["<!doctype html><html><head><meta charset='utf-8'>", f"<title>{html.escape(self.title)}</title>",
               "<style>body{font-family:sans-serif;max-width:1200px;margin:auto}table{border-collapse:collapse;"
               "font-size:13px}td,th{border:1px solid #bbb;padding:2px 6px;text-align:right}"
               "img{max-width:100%}</style></head><body>", f"<h1>{html.escape(self.title)}</h1>"]
        for kind, x in self.parts:
            if kind == "h":
                out.append(f"<h2>{html.escape(x)}</h2>")
            elif kind == "p":
                out.append(f"<p>{html.escape(x)}</p>")
            elif kind == "t":
                df, csv_name = x
                out.append(_fmt(df).to_html(escape=True))
                if csv_name:
                    out.append(f"<p>CSV: <a href='{csv_name}'>{csv_name}</a></p>")
            else:
                out.append(f"<p><img src='{x[0]}' alt='{html.escape(x[1])}'></p>")
        out.append("</body></html>")
        return "\n".join(out)


def _fmt(df: pd.DataFrame) -> pd.DataFrame:
    """Display copy: percentages for gap/coverage/share columns, 3 significant digits elsewhere."""
    out = df.copy()
    for col in out.columns:
        s = out[col]
        if str(col) in _PCT or str(col).startswith("coverage"):
            out[col] = [("" if pd.isna(v) else f"{100 * v:.2f}%") for v in s]
        elif pd.api.types.is_float_dtype(s):
            out[col] = [("" if pd.isna(v) else f"{v:.3g}") for v in s]
    return out


def _md_table(df: pd.DataFrame) -> str:
    df = _fmt(df)
    index_name = df.index.name or ""
    header = [index_name] + [str(c) for c in df.columns]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for idx, row in df.iterrows():
        cells = [str(idx)] + ["" if (not isinstance(v, str) and pd.isna(v)) else str(v) for v in row]
        lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    return "\n".join(lines)


def _save(fig, out: Path, name: str, layout: bool = True) -> str:
    """Save ``out/name`` (laid out first unless the caller did) and return ``name``."""
    if layout:
        fig.tight_layout()
    save_figure(fig, out / name)
    return name


def _coverage_against(sar: pd.DataFrame, x: str, fixed: tuple[str, str], out: Path, fig_no: int, doc: _Doc):
    """One plot per fixed (a, b) with at least two values of x: mean coverage per method."""
    tables = []
    a, b = fixed
    for (va, vb), g in sar.groupby([a, b]):
        if g[x].nunique() < 2:
            continue
        piv = g.pivot_table(index="method", columns=x, values="coverage", aggfunc="mean")
        runs = g.groupby(x)["instance"].nunique()
        fig, ax = subplots(figsize=(7.5, 4.2))
        xs = list(piv.columns)
        gap = min(np.diff(xs)) if len(xs) > 1 else 1.0
        shift = dodge(piv.index, 0.5 * gap / max(len(piv.index), 1))  # equal values side by side
        for method in ordered(piv.index):
            vals = piv.loc[method]
            ax.plot(vals.index + shift[method], vals.values, ms=6, lw=1.3, label=method, **look(method).line())
        ax.set_xlabel(x)
        ax.set_ylabel("mean coverage")
        ax.set_xticks(xs)
        n_runs = f"{runs.min()}" if runs.min() == runs.max() else f"{runs.min()}–{runs.max()}"
        ax.set_title(f"Coverage against {x} ({a}={va}, {b}={vb}; {n_runs} instances per point)", fontsize=10)
        ax.grid(alpha=0.3)
        legend_outside(ax, piv.index)
        name = _save(fig, out, f"coverage_vs_{x}_{a}{va}_{b}{vb}.png")
        csv = f"coverage_vs_{x}_{a}{va}_{b}{vb}.csv"
        piv.to_csv(out / csv)
        shown = piv.map(lambda v: "" if pd.isna(v) else f"{100 * v:.1f}%")
        planned = g.assign(plan=g["objective"].notna()).pivot_table(index="method", columns=x, values="plan",
                                                                     aggfunc="mean")
        planned.to_csv(out / csv.replace("coverage_vs", "with_plan_vs"))
        for c in piv.columns:  # "91.7% (80%)": coverage, and the share of runs that found a plan
            shown[c] = [f"{a or '-'} ({100 * p:.0f}%)" if p < 1 else a for a, p in zip(shown[c], planned[c])]
        shown.columns = [f"{x}={c}" for c in piv.columns]
        tables.append((va, vb, name, csv, shown))
    if tables:
        doc.h(f"Coverage against {x} (paper Fig. {fig_no})")
        doc.p(f"Mean coverage (covered viewpoints / M·K) over the runs with a plan, {a} and {b} fixed; in "
              f"parentheses the share of runs that found a plan covering every target, where below 100%. "
              f"In the plot each method's points sit slightly apart around each {x}, so that equal values "
              f"stay visible.")
        for va, vb, name, csv, piv in tables:
            doc.img(name, f"coverage against {x}, {a}={va}, {b}={vb}")
            doc.table(piv.rename_axis("method"), csv)


def _runtime_table(sar: pd.DataFrame, out: Path, doc: _Doc):
    g = sar.copy()
    g["setting"] = [f"M{m} N{n} K{k}" for m, n, k in zip(g["M"], g["N"], g["K"])]
    order = (g[["M", "N", "K", "setting"]].drop_duplicates().sort_values(["M", "N", "K"])["setting"]).tolist()
    piv = g.pivot_table(index="method", columns="setting", values="runtime_s", aggfunc="mean")[order]
    piv.to_csv(out / "runtime_by_setting.csv")
    doc.h("Runtime per setting (paper Table I)")
    doc.p("Mean runtime in seconds per run (the method's own clock), per random-instance setting.")
    doc.table(piv.rename_axis("method"), "runtime_by_setting.csv")


def _example_routes(df: pd.DataFrame, out: Path, doc: _Doc):
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top
    from sarcover.formulations.io import load_instance
    from sarcover.formulations.plan import Plan

    from sarcover.reports.plots import plan_legend, plot_plan

    ok = df[df["valid"].astype(bool) & df["routes"].notna()]
    if ok.empty:
        return
    counts = ok.groupby("instance")["method"].nunique()
    sizes = ok.groupby("instance")["n_nodes"].max()
    sar = ok.groupby("instance")["kind"].first() == "sar"  # the paper's Fig. 2 is a SAR plan
    pick = sorted(counts.index, key=lambda i: (-counts[i], not sar[i], -sizes[i], i))[0]
    rows = ok[ok["instance"] == pick].drop_duplicates("method")
    src = rows.iloc[0]["source"]
    try:
        if src["type"] == "generate":
            instance = to_top(generate(src["M"], src["K"], src["N"], src["instance_seed"], src["preset"],
                                       **src["overrides"]))
        else:
            instance = load_instance(src["path"])
    except Exception as exc:  # noqa: BLE001 - a moved file must not kill the report
        doc.h("Example routes (paper Fig. 2)")
        doc.p(f"Could not rebuild instance {pick}: {exc}")
        return
    rows = rows.head(12)
    cols = min(3, len(rows))
    nrows = int(np.ceil(len(rows) / cols))
    rows = rows.set_index("method").loc[ordered(rows["method"])].reset_index()
    fig, axes = subplots(nrows, cols, figsize=(5 * cols, 5 * nrows + 0.6), squeeze=False)
    for ax, (_, r) in zip(axes.flat, rows.iterrows()):
        cov = f"{100 * r['coverage']:.1f}%" if pd.notna(r["coverage"]) else "-"
        plot_plan(instance, Plan.of(r["routes"]), ax=ax, title=f"{r['method']} ({r['status']}): coverage {cov}",
                  legend=False)
    for ax in list(axes.flat)[len(rows):]:
        ax.axis("off")
    fig.tight_layout(rect=(0, 0.6 / (5 * nrows + 0.6), 1, 1))  # the panel titles name the methods; the
    plan_legend(fig, list(axes.flat)[:len(rows)])                # text above names the instance
    name = _save(fig, out, "example_routes.png", layout=False)
    doc.h("Example routes (paper Fig. 2)")
    doc.p(f"Instance {pick}: the plan of each method (seed {int(rows.iloc[0]['seed'])}).")
    doc.img(name, f"routes on {pick}")


def _gap_distributions(gapped: pd.DataFrame, out: Path, doc: _Doc):
    made = []
    for col, label in (("gap", "gap to proven optimum"), ("gap_ub", "gap to best bound (upper bound on true gap)")):
        data = {m: 100 * g[col].dropna().to_numpy() for m, g in gapped.groupby("method", sort=False)}
        data = {m: data[m] for m in ordered(data) if len(data[m])}
        if not data:
            continue
        fig, ax = subplots(figsize=(max(6, 0.8 * len(data) + 2), 4.2))
        box = ax.boxplot(list(data.values()), showmeans=True, patch_artist=True,
                         medianprops={"color": "k"}, flierprops={"markeredgecolor": "0.4"})
        for m, patch, mean in zip(data, box["boxes"], box["means"]):  # each method in its colour
            lk = look(m)
            patch.set(facecolor=lk.color, alpha=0.35, edgecolor=lk.color)
            mean.set(marker=lk.marker, markerfacecolor=lk.color, markeredgecolor="k")
        ax.set_xticks(range(1, len(data) + 1), list(data.keys()), rotation=30, ha="right")
        for tick, m in zip(ax.get_xticklabels(), data):
            tick.set_color(look(m).color)
        groups = [look(m).group for m in data]
        for i in range(1, len(groups)):  # a thin rule between the paper's methods, the peers, the exact ones
            if groups[i] != groups[i - 1]:
                ax.axvline(i + 0.5, color="0.6", lw=0.8, ls=":")
        ax.set_ylabel(f"{label} (%)" if col == "gap" else "gap to best bound (%)")
        ax.set_title(f"{label.capitalize()}, per method (marker: mean)", fontsize=10)
        ax.grid(alpha=0.3, axis="y")
        made.append((_save(fig, out, f"{col}_distribution.png"), label))
    if made:
        doc.h("Gap distributions")
        for name, label in made:
            doc.img(name, label)


def _time_to_optimality(gapped: pd.DataFrame, out: Path, doc: _Doc):
    ex = gapped[gapped["exact"].astype(bool)]
    if ex.empty:
        return
    from matplotlib.lines import Line2D

    fig, ax = subplots(figsize=(7.5, 4.2))
    methods = ordered(ex["method"].unique())
    sizes = sorted(ex["n_nodes"].unique())
    gap = min(np.diff(sizes)) if len(sizes) > 1 else 1.0
    shift = dodge(methods, 0.4 * gap / max(len(methods), 1))
    for m in methods:
        g = ex[ex["method"] == m]
        lk = look(m)
        opt = g[g["status"] == "optimal"]
        rest = g[g["status"] != "optimal"]
        ax.scatter(opt["n_nodes"] + shift[m], opt["runtime_s"], color=lk.color, marker=lk.marker, s=30)
        ax.scatter(rest["n_nodes"] + shift[m], rest["runtime_s"], facecolors="none", edgecolors=lk.color,
                   marker=lk.marker, s=30)
    ax.set_yscale("log")
    ax.set_xlabel("nodes (viewpoints)")
    ax.set_ylabel("runtime (s)")
    ax.grid(alpha=0.3)
    legend_outside(ax, methods, extra=[
        (Line2D([], [], ls="none", marker="o", color="0.3"), "filled: proven optimal"),
        (Line2D([], [], ls="none", marker="o", mfc="none", color="0.3"), "open: not proven")])
    name = _save(fig, out, "time_to_optimality.png")
    tab = ex.groupby(["method", "n_nodes"]).agg(runs=("status", "size"),
                                                 optimal=("status", lambda s: int((s == "optimal").sum())),
                                                 runtime_median_s=("runtime_s", "median"),
                                                 runtime_max_s=("runtime_s", "max"))
    tab.to_csv(out / "time_to_optimality.csv")
    doc.h("Time to optimality against size (exact methods)")
    doc.p("Filled markers: proven optimal; open markers: stopped without proof (time limit, error).")
    doc.img(name, "time to optimality against size")
    tab = tab.reset_index()
    tab.index = [f"{m} n={n}" for m, n in zip(tab.pop("method"), tab.pop("n_nodes"))]
    doc.table(tab.rename_axis("method, size"), "time_to_optimality.csv")


ANYTIME_PANELS = 6


def _anytime_series(row) -> list | None:
    """A row's ``info.history``, closed by its final (runtime, objective, bound) if that is later."""
    info = row.get("info")
    hist = info.get("history") if isinstance(info, dict) else None
    if not hist:
        return None
    pts = [[float(p[0]), p[1], p[2]] for p in hist]
    obj = None if pd.isna(row.get("objective")) else float(row["objective"])
    bnd = None if pd.isna(row.get("bound")) else float(row["bound"])
    if pd.notna(row.get("runtime_s")) and float(row["runtime_s"]) > pts[-1][0]:
        pts.append([float(row["runtime_s"]), obj if obj is not None else pts[-1][1],
                    bnd if bnd is not None else pts[-1][2]])
    return pts


def _anytime(df: pd.DataFrame, inst: pd.DataFrame, out: Path, doc: _Doc):
    """Bound and incumbent against time of the exact methods, one panel per instance."""
    from sarcover.reports.plots import anytime_legend, plot_anytime

    ex = df[df["exact"].astype(bool) & (df["status"] != "error")] if "exact" in df else df.iloc[:0]
    series: dict = {}
    for _, r in ex.sort_values(["instance", "method", "seed"]).iterrows():
        pts = _anytime_series(r)
        if pts is not None:
            series.setdefault(r["instance"], {}).setdefault(r["method"], pts)  # first seed only
    if not series:
        return
    pick = sorted(series, key=lambda i: (-len(series[i]), i))[:ANYTIME_PANELS]
    cols = min(3, len(pick))
    nrows = int(np.ceil(len(pick) / cols))
    methods = ordered({m for i in pick for m in series[i]})
    colors = {m: look(m).color for m in methods}
    fig, axes = subplots(nrows, cols, figsize=(5.2 * cols, 3.8 * nrows), squeeze=False)
    for ax, name in zip(axes.flat, pick):
        ref = inst["opt"].get(name, np.nan) if "opt" in inst else np.nan
        plot_anytime(series[name], ax=ax, title=name, reference=None if pd.isna(ref) else float(ref),
                     colors=colors, legend=False)
    for ax in list(axes.flat)[len(pick):]:
        ax.axis("off")
    handles = anytime_legend(colors, optimum=bool(inst["opt"].reindex(pick).notna().any()))  # one for all panels
    fig.tight_layout(rect=(0, 0.07 if nrows == 1 else 0.04, 1, 1))  # panel titles name the instances
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False)
    name = _save(fig, out, "anytime.png", layout=False)
    flat = [{"instance": i, "method": m, "t_s": p[0], "incumbent": p[1], "bound": p[2]}
            for i in pick for m, pts in series[i].items() for p in pts]
    pd.DataFrame(flat).to_csv(out / "anytime.csv", index=False)
    doc.h("Bound and incumbent against time (exact methods)")
    doc.p(f"Per instance ({len(pick)} of {len(series)} with a recorded history: those with the most exact "
          "methods, then by name), the best verified objective (solid) and the best proven upper bound "
          "(dashed) of each exact method against its own clock (symlog axis, linear below 1 s); "
          "the grey dotted line is the proven or published optimum where known. Each curve ends at "
          "the run's final objective and bound; the first seed of each method is shown.")
    doc.img(name, "bound and incumbent against time")
    doc.p("The plotted points are in anytime.csv.")


def _parquet(df: pd.DataFrame, path: Path) -> bool:
    flat = df.copy()
    for col in ("routes", "energy", "covered", "info", "source", "versions", "params"):
        if col in flat:
            flat[col] = [None if v is None or (isinstance(v, float) and np.isnan(v)) else json.dumps(v)
                         for v in flat[col]]
    try:
        flat.to_parquet(path, index=False)
        return True
    except (ImportError, ValueError, TypeError):
        return False


def _relative(path, start) -> str:
    """``path`` relative to ``start`` (the results folder as seen from the report's folder: ``..``
    for the default RESULTS/report), so that the report names no machine's absolute paths."""
    return Path(os.path.relpath(Path(path).resolve(), Path(start).resolve())).as_posix()


POOLED = "all proven instances"  # the setting name of the opening gap-over-time figure


def _gap_over_time(df: pd.DataFrame, out: Path, doc: _Doc) -> None:
    """Every method's mean gap to the proven optimum against time, over all proven instances
    (figure and table), with the per-setting figures in anytime_report.md; nothing where no run
    of a heuristic recorded a history."""
    if not ({"exact", "info"} <= set(df) and df.loc[~df["exact"].astype(bool), "info"].map(
            lambda i: isinstance(i, dict) and "history" in i).any()):
        return
    from sarcover.reports.convergence import write_convergence

    (out / "anytime_report.md").write_text(write_convergence(df, [], out, heading="#"))
    pooled = out / "anytime_pooled_table.csv"
    pooled.unlink(missing_ok=True)  # written again below only where a run has a proven optimum
    write_convergence(df, [], out, prefix="anytime_pooled", pool=POOLED)
    if not pooled.exists():
        return
    tab = pd.read_csv(pooled).set_index("method")  # the table the pooled section computed and wrote
    cols = {"instances": "instances", "gap_at_0.01s": "gap at 0.01 s", "gap_at_0.1s": "0.1 s",
            "gap_at_1s": "1 s", "gap_at_10s": "10 s", "primal_integral_wall_s": "primal integral (s)",
            "t_gap5_wall_s": "t ≤ 5 % (s)", "t_gap1_wall_s": "t ≤ 1 % (s)", "t_gap0_wall_s": "t ≤ 0 % (s)"}
    shown = tab[[c for c in cols if c in tab]].rename(columns=cols)
    for c in ("gap at 0.01 s", "0.1 s", "1 s", "10 s"):  # n/m: past the method's own limit
        shown[c] = shown[c].map(lambda g: "n/m" if pd.isna(g) else f"{100 * g:.1f} %")
    for c in ("t ≤ 5 % (s)", "t ≤ 1 % (s)", "t ≤ 0 % (s)"):
        shown[c] = shown[c].map(lambda t: "never" if pd.isna(t) else f"{t:.3g}")
    doc.h("Gap over time")
    doc.p("Each method's mean gap to the proven optimum against time (wall clock, log axis) over every instance "
          "with a proven optimum: a run's gap at t is that of the best plan it had by t (100 % before its first). "
          "The primal integral is the integral of that gap over the longest limit, in seconds; \"t ≤ 5 %\": "
          "the first time the mean gap is at most 5 % (never: not within the limit); n/m: past the method's "
          "own limit. Per setting, on the wall and the CPU clock, with "
          "definitions: [anytime_report.md](anytime_report.md).")
    name = f"anytime_pooled_{POOLED.replace(' ', '_')}.png"
    doc.img(name, "mean gap to the optimum against time, every method")
    doc.table(shown, "anytime_pooled_table.csv")


def write_report(results_dir: str | Path, out_dir: str | Path) -> str:
    """Write report.md, report.html, PNGs and CSVs into ``out_dir``; return a one-line summary."""
    df, skipped = load_results(results_dir)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    inst = instance_table(df)
    gapped = add_gaps(df, inst)
    methods = method_table(gapped)
    methods = methods.loc[sorted(methods.index, key=lambda m: (not methods.loc[m, "exact"], m))]
    suites = ", ".join(sorted(str(s) for s in df["suite"].dropna().unique())) or "?"
    doc = _Doc(f"sarcover report: {suites}")
    n_opt = int(inst["opt"].notna().sum())
    doc.p(f"{len(df)} runs: {df['instance'].nunique()} instances × {df['method'].nunique()} methods; "
          f"{n_opt} instances with a proven optimum, {int((inst['opt'].isna() & inst['best_bound'].notna()).sum())} "
          f"with a bound only. Source: `{RESULTS_FILE}` of the results folder `{_relative(results_dir, out)}` "
          f"(paths relative to this report's folder).")
    bad = {k: v for k, v in skipped.items() if v}
    if bad:
        doc.p("Skipped rows: " + ", ".join(f"{v} {k.replace('_', ' ')}" for k, v in bad.items())
              + " (partial = half-written line of a killed run; old schema = written by another version).")
    doc.h("Per method")
    doc.p("gap = (opt − objective) / opt against the proven optimum (gap_* columns, runs with a plan on "
          "instances with a proven optimum); gap_ub = (bound − objective) / bound against the best bound "
          "any method proved, on instances without a proven optimum: an upper bound on the true gap. "
          "share_optimal: share of the runs on proven instances that reached the optimum.")
    methods.to_csv(out / "methods.csv")
    doc.table(methods, "methods.csv")
    if n_opt:
        _gap_over_time(df, out, doc)
    inst.to_csv(out / "instances.csv")
    conflicts = inst[inst["conflict"] != ""]
    doc.h("Consistency checks")
    if len(conflicts):
        doc.p(f"CONFLICTS on {len(conflicts)} instances (a claimed optimum or bound is wrong):")
        doc.table(conflicts[["opt", "opt_source", "best_bound", "best_objective", "conflict"]])
    else:
        doc.p("No conflicts: proven optima agree, no verified objective exceeds a proven optimum or a bound.")
    news = inst[inst["news"] != ""] if "news" in inst else inst.iloc[:0]
    if len(news):
        doc.p(f"NEW BEST KNOWN values on {len(news)} instances (a verified plan above the published best known "
              "value; the plan's routes are in runs.csv):")
        doc.table(news[["best_known", "best_objective", "best_bound", "news"]])
    errors = gapped[gapped["status"] == "error"]
    if len(errors):
        tab = errors.groupby(["method", "reason"]).size().rename("runs").reset_index()
        tab.index = tab.pop("method")
        doc.p(f"{len(errors)} runs ended in error:")
        doc.table(tab.head(30).rename_axis("method"))
    sar = gapped[(gapped["kind"] == "sar") & gapped["M"].notna()].copy()
    if len(sar):
        for c in ("M", "N", "K"):
            sar[c] = sar[c].astype(int)
        _coverage_against(sar, "N", ("M", "K"), out, 3, doc)
        _coverage_against(sar, "K", ("M", "N"), out, 4, doc)
        _runtime_table(sar, out, doc)
    _example_routes(df, out, doc)
    _gap_distributions(gapped, out, doc)
    _time_to_optimality(gapped, out, doc)
    _anytime(df, inst, out, doc)
    dropped = ["routes", "info", "source", "versions", "params", "energy", "covered"]
    gapped.drop(columns=dropped, errors="ignore").to_csv(
        out / "runs.csv", index=False)
    parquet = _parquet(df, out / "results.parquet")
    (out / "report.md").write_text(doc.markdown())
    (out / "report.html").write_text(doc.html())
    n_png = len(list(out.glob("*.png")))
    note = f", skipped {sum(bad.values())} bad rows" if bad else ""
    return (f"report: {len(df)} runs, {len(methods)} methods{note} -> {out / 'report.md'}, report.html, "
            f"{n_png} PNG, CSV tables" + (", results.parquet" if parquet else ""))
