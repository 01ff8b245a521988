"""The gap decomposition section: tables per setting, a stacked-bar figure, a CSV and verdicts.

Input: the rows :func:`sarcover.benchmarks.decomposition.decompose` writes (one per instance,
method and seed). :func:`write_decomposition` writes ``decomposition.md`` (the section, also
returned as a string), ``decomposition.png`` (per setting, per method: mean clustering loss,
cross-cluster part and routing loss, stacked, in % of OPT), ``decomposition.csv`` (the rows) and
``decomposition_summary.csv`` (the table) into a folder. Every number in the text is computed
from the rows.

Losses are shown in % of OPT per instance, then averaged, so that they add up to the mean gap in
the same units as the report's gaps. The verdicts compare the clusterings alone: for one
instance, clustering loss(ADPC) − clustering loss(DPC) = OPT|C_DPC − OPT|C_ADPC, in which OPT
cancels, so they hold whether OPT is proven or a bound; the paired differences over the
instances of a setting give a mean and a 95 % t interval, and the verdict is "less" or "more"
only when the interval excludes 0.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from sarcover.reports.plots import subplots
from sarcover.reports.stats import t_halfwidth
from sarcover.reports.style import look

PARTS = [("clustering_loss", "clustering loss", "tab:blue"),
         ("cross_cluster", "cross-cluster part (repair/refill moves)", "tab:gray"),
         ("routing_loss", "routing loss", "tab:orange")]
ORDER = ["adpc-pso", "dpc-pso", "kmeans-pso", "adpc-ga", "adpc-aco", "oracle-pso", "oracle-ga", "oracle-aco"]
CLUSTER_METHODS = {"adpc": "adpc-pso", "dpc": "dpc-pso", "kmeans": "kmeans-pso"}  # one row per clusterer


def _rows(rows_or_path) -> list[dict]:
    if isinstance(rows_or_path, (str, Path)):
        from sarcover.formulations.records import read_decomposition

        return read_decomposition(rows_or_path)
    return list(rows_or_path)


def setting_label(row) -> str:
    return f"M={row['M']} K={row['K']} N={row['N']}"


def decomposition_frame(rows) -> pd.DataFrame:
    """The rows as a DataFrame with ``setting`` and each part in % of OPT (``*_pct``)."""
    df = pd.DataFrame.from_records(_rows(rows))
    if df.empty:
        return df
    df["setting"] = df.apply(setting_label, axis=1)
    opt = df["opt"].astype(float)
    for col in ["gap", *(p for p, _, _ in PARTS)]:
        df[f"{col}_pct"] = np.where(opt > 0, 100.0 * df[col].astype(float) / opt, np.nan)
    return df


def _order(methods) -> list[str]:
    return [m for m in ORDER if m in set(methods)] + sorted(set(methods) - set(ORDER))


def summary_table(df: pd.DataFrame) -> pd.DataFrame:
    """Per setting and method: counts, mean OPT, OPT|C, objective, the parts (viewpoints and % of
    OPT), moved viewpoints, and OPT|C solve times."""
    out = []
    for (setting, method), g in df.groupby(["setting", "method"], sort=False):
        ok = g[g["gap"].notna()]
        rec = {"setting": setting, "method": method, "instances": g["instance"].nunique(), "rows": len(g),
               "with_plan": len(ok), "opt_proven": int(g["opt_proven"].astype(bool).sum()),
               "opt_c_unproven": int((~g["opt_c_proven"].astype(bool)).sum()),
               "clustering_infeasible": int(g.get("clustering_infeasible", pd.Series(dtype=bool)).fillna(False)
                                            .astype(bool).sum()),
               "opt": g["opt"].astype(float).mean(), "opt_c": ok["opt_c"].astype(float).mean(),
               "objective": ok["objective"].astype(float).mean(), "gap": ok["gap"].astype(float).mean()}
        for part, _, _ in PARTS:
            rec[part] = ok[part].astype(float).mean()
        for col in ["gap", *(p for p, _, _ in PARTS)]:
            rec[f"{col}_pct"] = ok[f"{col}_pct"].astype(float).mean()
        rec["n_outside"] = ok["n_outside"].astype(float).mean() if "n_outside" in ok else np.nan
        rec["opt_c_s_mean"] = g["opt_c_s"].astype(float).mean()
        rec["opt_c_s_max"] = g["opt_c_s"].astype(float).max()
        out.append(rec)
    tab = pd.DataFrame(out)
    if tab.empty:
        return tab
    tab["order"] = tab["method"].map({m: i for i, m in enumerate(ORDER)}).fillna(len(ORDER))
    first = df.drop_duplicates("setting").set_index("setting")
    tab["skey"] = tab["setting"].map(lambda s: tuple(int(first.loc[s, k]) for k in ("K", "N", "M")))
    return tab.sort_values(["skey", "order"]).drop(columns=["order", "skey"]).reset_index(drop=True)


def clustering_verdicts(df: pd.DataFrame) -> pd.DataFrame:
    """ADPC's clustering loss against DPC's and KMeans', per setting and over all settings.

    Paired per instance (and method seed) on the clustering loss in % of OPT of the rows of
    adpc-pso, dpc-pso and kmeans-pso (each clusterer's clustering, whatever the router).
    ``verdict``: "less" / "more" when the 95 % interval of the mean difference (ADPC − other)
    excludes 0, else "no clear difference".
    """
    rows = []
    cl = df[df["method"].isin(CLUSTER_METHODS.values())]
    wide = cl.pivot_table(index=["setting", "instance", "seed"], columns="method", values="clustering_loss_pct")
    for other in ("dpc", "kmeans"):
        a, b = CLUSTER_METHODS["adpc"], CLUSTER_METHODS[other]
        if a not in wide or b not in wide:
            continue
        pairs = wide[[a, b]].dropna()
        groups = [(s, g) for s, g in pairs.groupby(level="setting")] + [("all settings", pairs)]
        for setting, g in groups:
            d = (g[a] - g[b]).to_numpy()
            n = d.size
            mean = float(d.mean()) if n else np.nan
            half = t_halfwidth(d)
            lo, hi = mean - half, mean + half
            verdict = ("less" if hi < 0 else "more" if lo > 0 else "no clear difference") if n > 1 else "too few"
            rows.append({"setting": setting,
                         "claim": "ADPC's clustering loses less than " + ("DPC's" if other == "dpc" else "KMeans'"),
                         "other": other, "instances": n, "adpc_pct": float(g[a].mean()),
                         "other_pct": float(g[b].mean()), "diff_pct": mean, "ci_lo": lo, "ci_hi": hi,
                         "adpc_better": int((d < 0).sum()), "equal": int((d == 0).sum()),
                         "adpc_worse": int((d > 0).sum()), "verdict": verdict})
    return pd.DataFrame(rows)


def plot_decomposition(tab: pd.DataFrame, path: Path) -> None:
    """Stacked bars per setting: mean clustering loss, cross-cluster part and routing loss (% of
    OPT) per method; a negative cross-cluster part is drawn below zero; the dot is the mean gap."""
    settings = list(dict.fromkeys(tab["setting"]))
    fig, axes = subplots(1, len(settings), figsize=(max(5.5, 3.4 * len(settings)) + 1, 4.6), squeeze=False,
                             sharey=True)
    for ax, setting in zip(axes[0], settings):
        t = tab[tab["setting"] == setting]
        methods = _order(t["method"])
        t = t.set_index("method").loc[methods]
        x = np.arange(len(methods))
        up, down = np.zeros(len(methods)), np.zeros(len(methods))
        for part, label, color in PARTS:
            v = t[f"{part}_pct"].fillna(0.0).to_numpy()
            pos, neg = np.maximum(v, 0), np.minimum(v, 0)
            ax.bar(x, pos, bottom=up, color=color, label=label, width=0.7)
            ax.bar(x, neg, bottom=down, color=color, width=0.7, hatch="//", edgecolor="white")
            up, down = up + pos, down + neg
        ax.plot(x, t["gap_pct"], "k.", label="gap")
        ax.axhline(0, color="k", lw=0.6)
        ax.set_xticks(x, methods, rotation=45, ha="right", fontsize=8)
        for tick in ax.get_xticklabels():  # the bars are coloured by part, so the method names carry its look
            tick.set_color(look(tick.get_text()).color)
        ax.set_title(f"{setting} ({int(t['instances'].max())} inst.)", fontsize=9)
        ax.grid(axis="y", alpha=0.3)
    axes[0][0].set_ylabel("mean loss, % of OPT")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=8, loc="lower center", ncol=len(labels), frameon=False)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.savefig(path, dpi=130)


def _fmt(v, digits=1) -> str:
    if v is None or (isinstance(v, float) and np.isnan(v)):
        return "–"
    return f"{v:.{digits}f}" if isinstance(v, (float, np.floating)) else str(v)


def _markdown(tab: pd.DataFrame, verdicts: pd.DataFrame, df: pd.DataFrame, heading: str) -> str:
    h2 = heading + "#"
    lines = [f"{heading} Where the gap comes from: clustering loss against routing loss", "",
             "For each method's clustering C (one cluster per UAV, before routing), OPT|C is the best "
             "plan any router could make when UAV i may visit only cluster i (solved exactly: "
             "`sarcover.formulations.clustered.solve_clustered`). Per instance, gap = OPT − objective = "
             "**clustering loss** (OPT − OPT|C) + **cross-cluster part** (OPT|C − OPT|C', where C' is the "
             "clustering after the repair/refill moved viewpoints onto another cluster's route; negative "
             "when the moves won coverage back) + **routing loss** (OPT|C' − objective). Oracle rows route "
             "the clustering of the best known plan (unvisited viewpoints assigned to the cheapest route) "
             "with the paper's routers: where that plan is optimal their clustering loss is 0 and their gap "
             "is routing loss alone (where OPT is only a bound, their clustering loss is that bound minus "
             "the plan). Means of % of OPT per instance; "
             "viewpoints in brackets.", ""]
    unproven = df.groupby("setting")["opt_proven"].apply(lambda s: int((~s.astype(bool)).sum()))
    for setting in dict.fromkeys(tab["setting"]):
        t = tab[tab["setting"] == setting]
        n_inst = int(t["instances"].max())
        lines += [f"{h2} {setting}", ""]
        open_rows = int(unproven.get(setting, 0))
        if open_rows:
            lines += [f"OPT is not proven on some instances ({open_rows} of the rows): there the best proven bound "
                      "stands in for it, so gaps and clustering losses are upper bounds.", ""]
        lines += ["| method | runs | gap | clustering loss | cross-cluster | routing loss | OPT | OPT\\|C | objective "
                  "| moved views | OPT\\|C s (mean/max) |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]
        for _, r in t.iterrows():
            lines.append(
                f"| {r['method']} | {r['with_plan']}/{r['rows']} | {_fmt(r['gap_pct'])} % ({_fmt(r['gap'])}) "
                f"| {_fmt(r['clustering_loss_pct'])} % ({_fmt(r['clustering_loss'])}) "
                f"| {_fmt(r['cross_cluster_pct'])} % ({_fmt(r['cross_cluster'])}) "
                f"| {_fmt(r['routing_loss_pct'])} % ({_fmt(r['routing_loss'])}) | {_fmt(r['opt'])} "
                f"| {_fmt(r['opt_c'])} | {_fmt(r['objective'])} | {_fmt(r['n_outside'])} "
                f"| {_fmt(r['opt_c_s_mean'])}/{_fmt(r['opt_c_s_max'])} |")
        notes = []
        if t["opt_c_unproven"].sum():
            notes.append(f"{int(t['opt_c_unproven'].sum())} OPT|C solves stopped at their time limit (their "
                         "bound is used: clustering loss a lower bound there)")
        if t["clustering_infeasible"].sum():
            notes.append(f"{int(t['clustering_infeasible'].sum())} clusterings admit no plan covering every "
                         "target (only the repair's moves made one); their clustering loss is OPT − OPT|C'")
        if n_inst < 20:
            notes.append(f"only {n_inst} instances")
        if notes:
            lines += ["", "Notes: " + "; ".join(notes) + "."]
        lines.append("")
    lines += [f"{h2} Verdict: does ADPC's clustering lose less than DPC's and KMeans'?", "",
              "Paired per instance on the clustering loss alone (the router plays no part; OPT cancels in the "
              "difference, so this holds with bounds too). Difference = ADPC − other, % of OPT, 95 % t interval.", "",
              "| setting | claim | instances | ADPC | other | difference [95 % CI] | ADPC better/equal/worse "
              "| verdict |",
              "|---|---|---|---|---|---|---|---|"]
    for _, v in verdicts.iterrows():
        lines.append(f"| {v['setting']} | {v['claim']} | {v['instances']} | {_fmt(v['adpc_pct'])} % "
                     f"| {_fmt(v['other_pct'])} % | {_fmt(v['diff_pct'], 2)} [{_fmt(v['ci_lo'], 2)}, "
                     f"{_fmt(v['ci_hi'], 2)}] | {v['adpc_better']}/{v['equal']}/{v['adpc_worse']} "
                     f"| **{v['verdict']}** |")
    lines.append("")
    for other in ("dpc", "kmeans"):
        allv = verdicts[(verdicts["setting"] == "all settings") & (verdicts["other"] == other)]
        if len(allv):
            v = allv.iloc[0]
            name, poss = ("DPC", "DPC's") if other == "dpc" else ("KMeans", "KMeans'")
            says = {"less": f"yes: ADPC's clustering loses less than {poss}",
                    "more": f"no: ADPC's clustering loses more than {poss}",
                    "no clear difference": f"not shown: ADPC's and {name}'s clustering losses do not differ "
                                           "beyond noise",
                    "too few": "too few instances to say"}[v["verdict"]]
            lines.append(f"- Over all settings, {says} (mean difference {_fmt(v['diff_pct'], 2)} % of OPT, "
                         f"95 % CI [{_fmt(v['ci_lo'], 2)}, {_fmt(v['ci_hi'], 2)}], {v['instances']} instances).")
    paper = tab[tab["method"].isin(["adpc-pso", "dpc-pso", "kmeans-pso", "adpc-ga", "adpc-aco"])]
    if len(paper):
        cl, rl = paper["clustering_loss_pct"].mean(), paper["routing_loss_pct"].mean()
        cx = paper["cross_cluster_pct"].mean()
        main = "clustering" if cl > rl else "routing"
        lines.append(f"- Over the paper's five methods, averaged over the settings, the mean clustering loss is "
                     f"{_fmt(cl)} % of OPT, the routing loss {_fmt(rl)} % and the cross-cluster part {_fmt(cx)} %: "
                     f"most of the gap is {main} loss.")
    lines += ["", "Figure: `decomposition.png`; rows: `decomposition.csv`; table: `decomposition_summary.csv`.", ""]
    return "\n".join(lines)


def write_decomposition(rows_or_path, out_dir: str | Path, *, heading: str = "##") -> str:
    """Write the section (``decomposition.md``), its figure and CSVs into ``out_dir``; return the
    Markdown. ``rows_or_path``: decomposition rows or the JSONL file holding them."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    df = decomposition_frame(rows_or_path)
    if df.empty:
        text = f"{heading} Where the gap comes from: clustering loss against routing loss\n\nNo decomposition rows.\n"
        (out / "decomposition.md").write_text(text)
        return text
    tab = summary_table(df)
    verdicts = clustering_verdicts(df)
    plot_decomposition(tab, out / "decomposition.png")
    flat = df.copy()
    for col in ("clusters", "clusters_plan", "routes", "cluster_sizes"):
        if col in flat:
            flat[col] = flat[col].apply(lambda v: json.dumps(v) if isinstance(v, list) else v)
    flat.to_csv(out / "decomposition.csv", index=False)
    tab.to_csv(out / "decomposition_summary.csv", index=False)
    verdicts.to_csv(out / "decomposition_verdicts.csv", index=False)
    text = _markdown(tab, verdicts, df, heading)
    (out / "decomposition.md").write_text(text)
    return text
