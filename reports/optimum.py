"""The optimum on the paper's figures: suite ``paper-opt`` (M=20; Fig. 3: K=3, N=2..6; Fig. 4: N=5,
K=2..6), every heuristic against bp's proven optimum or, where bp's time limit stops the proof, the
bracket the optimum is known to lie in.

Per instance, with ``best`` the best verified plan of any method and ``bound`` bp's certified
bound (the best bound of the instance, :func:`sarcover.reports.gaps.instance_table`)::

    proven:    optimum = bp's proven value
    unproven:  best <= optimum <= bound      (the bracket [lo, hi])

The mean optimum of a setting is then a value (every instance proven) or a bracket [mean of the
lower ends, mean of the upper ends]; the figures draw the first as a line and the second as a
band. A method's gap (opt − obj)/opt grows with opt, so where the optimum is a bracket the gap
lies between the gap to the best plan (lower end) and the gap to the bound (upper end); both come
from :func:`sarcover.reports.gaps.add_gaps`. Runs without a plan have no gap (as in
:mod:`sarcover.reports.gaps`) and count as coverage 0 in the coverage means (as in the reference
report); the tables say how many runs had a plan.

Tuning against validation: some of bp's settings were chosen on paper-opt's instances (docs/bp.md,
"Where each setting was chosen"), so their proof rates are tuning figures. Suite
``paper-validation`` runs bp with the same limits on fresh instances that chose nothing; the proof
rates of both sit side by side per setting (:func:`validation_table`).

Works on partial results: settings or bp rows that are not there yet are named, not guessed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from sarcover.reports.gaps import add_gaps, instance_table
from sarcover.reports.plots import save_figure, subplots
from sarcover.reports.stats import t_halfwidth
from sarcover.reports.style import PAPER, PEERS, dodge, legend_outside, look

SUITE = "paper-opt"
VALIDATION = "paper-validation"  # the same grid and limits on instances that chose no setting
PROVER = "bp"  # the exact method of the suite: its proofs and bounds make the optimum
METHODS = PAPER + PEERS + [PROVER]  # table and legend order; bp's row is its own plan
OPT_COLOR = "0.35"  # the optimum: a wide translucent grey line/band, unlike any method's look


@dataclass(frozen=True)
class Sweep:
    """One of the paper's figures: coverage against ``x`` with ``fixed`` held at ``value``."""

    name: str  # file stem of the PNG and CSV
    x: str
    fixed: str
    value: int
    xs: tuple[int, ...]
    title: str

    def settings(self) -> list[tuple[int, int]]:
        """The (K, N) settings of the figure."""
        return [(self.value, v) if self.fixed == "K" else (v, self.value) for v in self.xs]


SWEEPS = (Sweep("paper_opt_vs_N", "N", "K", 3, (2, 3, 4, 5, 6),
                "Fig. 3 with the optimum: coverage against N (M=20, K=3)"),
          Sweep("paper_opt_vs_K", "K", "N", 5, (2, 3, 4, 5, 6),
                "Fig. 4 with the optimum: coverage against K (M=20, N=5)"))


def expected_settings() -> list[tuple[int, int]]:
    """Every (K, N) setting of the two figures, once, in figure order."""
    return list(dict.fromkeys(s for sw in SWEEPS for s in sw.settings()))


# What paper-opt's instances of each (K, N) chose among bp's settings (docs/bp.md, "Where each
# setting was chosen"); a setting not named here chose nothing.
TUNED_ON = {
    (2, 5): "second primal call; enumeration from 60 s and its label cap",
    (3, 2): "second primal call; enumeration from 60 s and its label cap",
    (3, 3): "second primal call; enumeration from 60 s and its label cap; sub-buckets (seed 104)",
    (3, 4): "second primal call; enumeration from 60 s and its label cap",
    (3, 5): "second primal call; enumeration from 60 s and its label cap",
    (3, 6): "second primal call; enumeration from 60 s and its label cap; sub-buckets (seed 117)",
    (4, 5): "enumeration's LP stall and MILP route cap (seed 111)",
    (5, 5): "route enumeration settings; 30 s primal calls; node listings (seeds 104, 108)",
    (6, 5): "4 primal calls from 600 s; 30 s primal calls",
}


def proof_target(k: int) -> tuple[float, float]:
    """(bp's time limit in s, the share of instances it should prove) at K views per target."""
    if k <= 3:
        return 60.0, 0.95
    if k <= 5:
        return 300.0, 0.90
    return 600.0, 0.50


def label(k: int, n: int) -> str:
    return f"K={k} N={n}"


# ---------------------------------------------------------------- per instance


def brackets(df: pd.DataFrame) -> pd.DataFrame:
    """Per instance: the optimum's bracket [lo, hi] in viewpoints and in coverage, and its state.

    ``state``: ``proven`` (lo = hi = the proven optimum), ``open`` (bp ran without a proof: lo the
    best verified plan, hi the bound), ``no bound`` (bp ran and left no bound, e.g. an error) or
    ``no bp`` (no bp row yet). Only the first two give the instance an optimum (``known``).
    """
    inst = instance_table(df)
    bp = df[df["method"] == PROVER].drop_duplicates("instance").set_index("instance")
    first = df.drop_duplicates("instance").set_index("instance")
    out = pd.DataFrame(index=inst.index)
    for col in ("M", "K", "N"):
        out[col] = first[col].astype(int)
    out["total"] = out["M"] * out["K"]
    out["bp_status"] = bp["status"].reindex(out.index)
    out["bp_objective"] = bp["objective"].astype(float).reindex(out.index)
    out["bp_bound"] = bp["bound"].astype(float).reindex(out.index)
    out["bp_time_limit"] = bp["time_limit"].astype(float).reindex(out.index)
    out["best_plan"] = inst["best_objective"].astype(float)
    proven = inst["opt"].notna()
    has_bound = inst["best_bound"].notna()
    out["state"] = np.select([proven, out["bp_status"].isna(), has_bound], ["proven", "no bp", "open"], "no bound")
    out["lo"] = np.where(proven, inst["opt"], np.where(out["state"] == "open", out["best_plan"], np.nan))
    out["hi"] = np.where(proven, inst["opt"], np.where(out["state"] == "open", inst["best_bound"], np.nan))
    out["known"] = out["state"].isin(["proven", "open"])
    out["lo_cov"] = out["lo"] / out["total"]
    out["hi_cov"] = out["hi"] / out["total"]
    out["conflict"] = inst["conflict"].astype(str)
    return out


# ---------------------------------------------------------------- per setting


def _target_text(k: int, proven: int, runs: int, instances: int) -> str:
    """The target and whether it is met; while bp has not run on every instance, "met" or "missed"
    only once the instances still to run cannot change it."""
    limit, goal = proof_target(k)
    worst, best = proven / instances, (proven + instances - runs) / instances
    verdict = "met" if worst >= goal else "missed" if best < goal else "open"
    if runs < instances:
        verdict += f" ({runs} of {instances} run)"
    return f"≥{100 * goal:.0f} % at {limit:g} s: {verdict}"


def setting_table(br: pd.DataFrame) -> pd.DataFrame:
    """Per (K, N) setting present: instances, bp runs and proofs against the target, the widest
    open bracket, the mean optimum coverage (a value or a bracket), conflicts."""
    rows = []
    for (k, n), g in br.groupby(["K", "N"]):
        ran = g[g["state"] != "no bp"]
        open_ = g[g["state"] == "open"]
        known = g[g["known"]]
        proven = int((g["state"] == "proven").sum())
        share = proven / len(ran) if len(ran) else np.nan
        limits = sorted(ran["bp_time_limit"].dropna().unique())
        rows.append({
            "setting": label(k, n), "K": k, "N": n, "instances": len(g), "bp_runs": len(ran),
            "bp_time_limit": "/".join(f"{v:g}" for v in limits) if limits else "",
            "proven": proven, "share_proven": share,
            "target_share": proof_target(k)[1],
            "target": _target_text(k, proven, len(ran), len(g)) if len(ran) else "no bp rows yet",
            "open": len(open_), "no_bound": int((g["state"] == "no bound").sum()),
            "max_bound_minus_bp_plan": (open_["bp_bound"] - open_["bp_objective"]).max() if len(open_) else np.nan,
            "max_bound_minus_best_plan": (open_["hi"] - open_["lo"]).max() if len(open_) else np.nan,
            "with_optimum": len(known),
            "opt_cov_lo": known["lo_cov"].mean() if len(known) else np.nan,
            "opt_cov_hi": known["hi_cov"].mean() if len(known) else np.nan,
            "conflicts": int(g["conflict"].str.len().gt(0).sum()),
        })
    return pd.DataFrame(rows)


def interval(lo: float, hi: float, fmt: str = "{:.3f}") -> str:
    """A value where both ends agree, else the bracket [lo, hi]; '–' where unknown."""
    if pd.isna(lo) or pd.isna(hi):
        return "–"
    if abs(hi - lo) <= 1e-12:
        return fmt.format(lo)
    return f"[{fmt.format(lo)}, {fmt.format(hi)}]"


# ---------------------------------------------------------------- per method


GAP_COLUMNS = ["method", "setting", "K", "N", "runs", "instances", "setting_instances", "with_plan", "coverage_mean",
               "gap_lo_mean", "gap_hi_mean", "gap_hi_max"]


def method_gaps(df: pd.DataFrame, br: pd.DataFrame) -> pd.DataFrame:
    """Per method and setting: runs, runs with a plan, mean coverage, and the mean gap to the
    optimum as [lo, hi] over the instances that have one (lo = hi where all are proven)."""
    g = add_gaps(df)
    g = g[g["instance"].map(br["known"]).fillna(False).astype(bool)].copy()
    best = g["instance"].map(br["best_plan"]).astype(float)
    obj = g["objective"].astype(float)
    gap_best = np.maximum((best - obj) / best, 0.0)  # to the best known plan: the gap's lower end
    g["gap_lo"] = g["gap"].fillna(gap_best)
    g["gap_hi"] = g["gap"].fillna(g["gap_ub"])
    rows = []
    for (m, k, n), s in g.groupby(["method", "K", "N"]):
        rows.append({"method": m, "setting": label(k, n), "K": k, "N": n, "runs": len(s),
                     "instances": s["instance"].nunique(),
                     "setting_instances": int(((br["K"] == k) & (br["N"] == n)).sum()),
                     "with_plan": int(s["objective"].notna().sum()),
                     "coverage_mean": s["coverage"].astype(float).fillna(0.0).mean(),
                     "gap_lo_mean": s["gap_lo"].mean(), "gap_hi_mean": s["gap_hi"].mean(),
                     "gap_hi_max": s["gap_hi"].max()})
    return pd.DataFrame(rows, columns=GAP_COLUMNS)


def coverage_table(df: pd.DataFrame, sweep: Sweep) -> pd.DataFrame:
    """Per method and x of the figure: mean coverage (no plan = 0), its 95 % t interval, runs."""
    s = df[(df[sweep.fixed] == sweep.value) & df[sweep.x].isin(sweep.xs)]
    cov0 = s["coverage"].astype(float).fillna(0.0)
    grp = cov0.groupby([s["method"], s[sweep.x]])
    return pd.DataFrame({"mean": grp.mean(), "ci95": grp.apply(t_halfwidth), "runs": grp.size()}).reset_index()


def optimum_curve(br: pd.DataFrame, sweep: Sweep) -> pd.DataFrame:
    """Per x of the figure with bp rows: mean optimum coverage lo/hi over the instances with an
    optimum, how many of the setting's instances that is, and whether every one of them is proven."""
    s = br[(br[sweep.fixed] == sweep.value) & br[sweep.x].isin(sweep.xs)]
    rows = [{sweep.x: x, "lo": g.loc[g["known"], "lo_cov"].mean(), "hi": g.loc[g["known"], "hi_cov"].mean(),
             "instances": int(g["known"].sum()), "setting_instances": len(g),
             "proven": int((g["state"] == "proven").sum())} for x, g in s.groupby(sweep.x) if g["known"].any()]
    out = pd.DataFrame(rows, columns=[sweep.x, "lo", "hi", "instances", "setting_instances", "proven"])
    out["all_proven"] = out["proven"] == out["instances"]
    return out


# ---------------------------------------------------------------- figures


def draw_optimum(ax, curve: pd.DataFrame, x: str, width: float = 0.45) -> list:
    """The mean optimum: a line through the settings where every instance is proven, a band
    [mean lo, mean hi] where some are not (a box of ``width`` at each such x, so that a lone or
    narrow bracket stays visible, joined to its neighbours). Returns the legend entries
    (handle, label) it drew."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    extra = []
    if curve.empty:
        return extra
    xs = curve[x].to_numpy(float)
    open_ = ~curve["all_proven"].to_numpy(bool)
    if open_.any():
        ax.fill_between(xs, curve["lo"], curve["hi"], color=OPT_COLOR, alpha=0.2, lw=0, zorder=0)
        lo, hi = curve["lo"].to_numpy(float)[open_], curve["hi"].to_numpy(float)[open_]
        ax.bar(xs[open_], hi - lo, bottom=lo, width=width, color=OPT_COLOR, alpha=0.25, zorder=0,
               label="optimum bracket")
        ax.hlines(np.r_[lo, hi], np.r_[xs[open_], xs[open_]] - width / 2, np.r_[xs[open_], xs[open_]] + width / 2,
                  color=OPT_COLOR, lw=1.5, alpha=0.6, zorder=1)
        extra.append((Patch(color=OPT_COLOR, alpha=0.25), "mean optimum bracket\n[best plan, bp bound]"))
    if (~open_).any():
        y = np.where(open_, np.nan, curve["lo"])
        ax.plot(xs, y, color=OPT_COLOR, lw=6, alpha=0.45, solid_capstyle="round", marker="_", ms=18,
                zorder=1, label="optimum")
        extra.append((Line2D([], [], color=OPT_COLOR, lw=6, alpha=0.45), "mean optimum (bp proven)"))
    for _, r in curve[curve["instances"] < curve["setting_instances"]].iterrows():  # bp still running there
        ax.annotate(f"optimum on {r['instances']}/{r['setting_instances']}", (r[x], r["hi"]), xytext=(0, 8),
                    textcoords="offset points", ha="center", fontsize=7, color="0.3")
    return extra


def plot_sweep(cov: pd.DataFrame, curve: pd.DataFrame, sweep: Sweep, path) -> list[str]:
    """One figure: each method's mean coverage (95 % CI) in its look, and the mean optimum."""
    fig, ax = subplots(figsize=(8.5, 4.5))
    extra = draw_optimum(ax, curve, sweep.x)
    methods = [m for m in METHODS if m in set(cov["method"])]
    methods += sorted(set(cov["method"]) - set(methods))
    shift = dodge(methods, 0.05)
    for m in methods:
        t = cov[cov["method"] == m]
        ax.errorbar(t[sweep.x] + shift[m], t["mean"], yerr=t["ci95"], capsize=3, label=m, **look(m).line())
    ax.set_xlabel(sweep.x)
    ax.set_xticks(list(sweep.xs))
    ax.set_ylabel("coverage (mean, 95% CI)")
    ax.set_title(sweep.title)
    ax.grid(alpha=0.3)
    runs = cov.groupby("method")["runs"].sum()

    def name(m: str) -> str:  # a method with fewer runs (bp while it runs) says so
        return m + (f" ({runs[m]} runs)" if runs[m] < runs.max() else "")

    legend_outside(ax, methods, label=name, extra=extra)
    save_figure(fig, path)
    return methods


# ---------------------------------------------------------------- the section


def _md_table(head: list[str], rows: list[list]) -> list[str]:
    return (["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
            + ["| " + " | ".join(str(c) for c in r) + " |" for r in rows])


def _fmt(v, fmt: str = "{:g}") -> str:
    return "–" if v is None or (isinstance(v, float) and np.isnan(v)) else fmt.format(v)


def _missing(br: pd.DataFrame) -> list[str]:
    """What is not there yet: settings without rows, settings and instances without bp."""
    present = set(zip(br["K"], br["N"]))
    no_rows = [label(k, n) for k, n in expected_settings() if (k, n) not in present]
    ran = br[br["state"] != "no bp"]
    no_bp = [label(k, n) for k, n in expected_settings() if (k, n) in present
             and not ((ran["K"] == k) & (ran["N"] == n)).any()]
    waiting = int((br["state"] == "no bp").sum())
    out = []
    if no_rows:
        out.append("settings without any rows yet: " + ", ".join(no_rows))
    if no_bp:
        out.append("settings without bp rows yet (no optimum drawn there): " + ", ".join(no_bp))
    if waiting:
        out.append(f"{waiting} of {len(br)} instances have no bp row yet (where a setting is partly run, its "
                   "mean optimum and the gaps are over the instances bp has run on, the methods' coverage "
                   "curves over all)")
    nb = int((br["state"] == "no bound").sum())
    if nb:
        out.append(f"{nb} instances where bp left no bound (not counted in the optimum)")
    return out


def _setting_rows(st: pd.DataFrame) -> list[list]:
    rows = []
    for _, r in st.iterrows():
        share = "–" if pd.isna(r["share_proven"]) else f"{r['proven']}/{r['bp_runs']} ({100 * r['share_proven']:.0f} %)"
        width = (f"{_fmt(r['max_bound_minus_bp_plan'])} / {_fmt(r['max_bound_minus_best_plan'])}"
                 if r["open"] else "–")
        opt = interval(r["opt_cov_lo"], r["opt_cov_hi"])
        if 0 < r["with_optimum"] < r["instances"]:
            opt += f" ({r['with_optimum']} inst.)"
        unproven = ("–" if not r["bp_runs"]
                    else f"{r['open']}" + (f" (+{r['no_bound']} no bound)" if r["no_bound"] else ""))
        rows.append([r["setting"], r["instances"], r["bp_time_limit"] or "–", share, r["target"], unproven, width,
                     opt, r["conflicts"]])
    return rows


def _gap_rows(mg: pd.DataFrame, sweep: Sweep) -> tuple[list[str], list[list]]:
    settings = [label(k, n) for k, n in sweep.settings()]
    s = mg[mg["setting"].isin(settings)]
    have = [c for c in settings if c in set(s["setting"])]
    methods = [m for m in METHODS if m in set(s["method"])] + sorted(set(s["method"]) - set(METHODS))
    rows = []
    for m in methods:
        cells = [m]
        for c in have:
            r = s[(s["method"] == m) & (s["setting"] == c)]
            if r.empty:
                cells.append("–")
                continue
            r = r.iloc[0]
            plan = "" if r["with_plan"] == r["runs"] else f" ({r['with_plan']}/{r['runs']} with plan)"
            if r["instances"] < r["setting_instances"]:  # bp has not run on all of them yet
                plan += f" ({r['instances']} of {r['setting_instances']} inst.)"
            cells.append(interval(r["gap_lo_mean"], r["gap_hi_mean"]) + plan)
        rows.append(cells)
    return ["method"] + [f"{sweep.x}={c.split(sweep.x + '=')[1].split()[0]}" for c in have], rows


# ---------------------------------------------------------------- tuning against validation


def _seeds(df: pd.DataFrame | None) -> str:
    """The instance seeds of ``df`` as a range ("100..119"), from the instance names."""
    if df is None or df.empty:
        return ""
    seeds = df["instance"].str.extract(r"-s(\d+)", expand=False).dropna().astype(int)
    return f"{seeds.min()}..{seeds.max()}" if len(seeds) else ""


def _proofs(df: pd.DataFrame | None) -> pd.DataFrame:
    """Per (K, N) with bp rows: bp's runs, proofs and the widest open bracket (bound − best plan)."""
    cols = ["K", "N", "bp_runs", "proven", "max_bound_minus_best_plan"]
    if df is None or df.empty or not (df["method"] == PROVER).any():
        return pd.DataFrame(columns=cols).set_index(["K", "N"])
    st = setting_table(brackets(df))
    return st[st["bp_runs"] > 0][cols].set_index(["K", "N"])


VALIDATION_COLUMNS = ["setting", "K", "N", "tuned_on", "tuning_bp_runs", "tuning_proven", "tuning_max_open",
                      "validation_bp_runs", "validation_proven", "validation_max_open"]


def validation_table(tuning: pd.DataFrame | None, validation: pd.DataFrame | None) -> pd.DataFrame:
    """Per (K, N) of the figures (and any other setting either suite has): bp's proofs on the
    tuning instances (paper-opt) and on the held-out ones (paper-validation), each with the widest
    open bracket max(bound − best plan) over its unproven instances, and what the tuning instances
    of the setting chose (``TUNED_ON``)."""
    t, v = _proofs(tuning), _proofs(validation)
    keys = list(dict.fromkeys(expected_settings() + sorted(set(t.index) | set(v.index))))
    rows = []
    for k, n in keys:
        row = {"setting": label(k, n), "K": k, "N": n, "tuned_on": TUNED_ON.get((k, n), "")}
        for name, p in (("tuning", t), ("validation", v)):
            have = (k, n) in p.index
            row[f"{name}_bp_runs"] = int(p.loc[(k, n), "bp_runs"]) if have else 0
            row[f"{name}_proven"] = int(p.loc[(k, n), "proven"]) if have else 0
            row[f"{name}_max_open"] = p.loc[(k, n), "max_bound_minus_best_plan"] if have else np.nan
        rows.append(row)
    return pd.DataFrame(rows, columns=VALIDATION_COLUMNS)


def _share(proven: int, runs: int) -> str:
    return f"{proven}/{runs} ({100 * proven / runs:.0f} %)" if runs else "–"


def validation_lines(tuning: pd.DataFrame | None, validation: pd.DataFrame | None, out, *,
                     heading: str = "###") -> list[str]:
    """Markdown lines of bp's proof rates on the tuning and the validation instances side by side;
    the table is written to ``out/paper_validation.csv``."""
    vt = validation_table(tuning, validation)
    vt.to_csv(out / "paper_validation.csv", index=False)
    ran = validation is not None and (validation["method"] == PROVER).any()
    t_seeds, v_seeds = _seeds(tuning), _seeds(validation[validation["method"] == PROVER] if ran else None)
    lines = [f"{heading} bp's proofs on tuning and validation instances", "",
             f"Some of bp's settings were chosen on `{SUITE}`'s instances"
             + (f" (seeds {t_seeds})" if t_seeds else "") + ": per setting the column \"chosen on these\" "
             "names what they chose (docs/bp.md, \"Where each setting was chosen\"), so those proof rates are "
             f"tuning figures. Suite `{VALIDATION}` runs bp with the same limits on fresh instances"
             + (f" (seeds {v_seeds})" if v_seeds else " (seeds 200..219)") + " that chose nothing. max bound − "
             "plan: the widest open bracket over the unproven instances (bp's bound − best plan, viewpoints).", ""]
    if not ran:
        lines += [f"**Validation has not been run yet** (no bp rows of `{VALIDATION}`): the proof rates below are "
                  f"tuning figures only. `sarcover bench {VALIDATION}` runs it (about 1.6 h on 2 cores).", ""]
    rows = []
    for _, r in vt.iterrows():
        val = (_share(r["validation_proven"], r["validation_bp_runs"]) if r["validation_bp_runs"]
               else "not run" if not ran else "no rows yet")
        width = " / ".join(_fmt(r[c]) for c in ("tuning_max_open", "validation_max_open"))
        rows.append([r["setting"], f"{proof_target(r['K'])[0]:g}", _share(r["tuning_proven"], r["tuning_bp_runs"]),
                     r["tuned_on"] or "nothing", val, width])
    lines += _md_table(["setting", "bp limit (s)", "tuning: proven", "chosen on these", "validation: proven",
                        "max bound − plan (tuning / validation)"], rows)
    return lines + ["", "Table: `paper_validation.csv`.", ""]


def optimum_section(df: pd.DataFrame | None, out, *, heading: str = "##",
                    validation: pd.DataFrame | None = None) -> list[str]:
    """The section's Markdown lines; its PNGs and CSVs are written into ``out``. ``validation``:
    the rows of ``paper-validation``, whose bp proofs sit beside paper-opt's (tuning) ones."""
    h = heading
    lines = [f"{h} The optimum on the paper's figures (suite `{SUITE}`)", ""]
    if df is None or df.empty:
        lines += [f"No rows of `{SUITE}` yet.", ""]
        return lines + (validation_lines(df, validation, out, heading=h + "#") if validation is not None else [])
    df = df[df["kind"].fillna("sar") == "sar"] if "kind" in df else df
    br = brackets(df)
    st = setting_table(br)
    mg = method_gaps(df, br)
    br.to_csv(out / "paper_opt_instances.csv")
    st.to_csv(out / "paper_opt_settings.csv", index=False)
    mg.to_csv(out / "paper_opt_gaps.csv", index=False)
    lines += [f"M=20, {df.groupby(['K', 'N'])['instance'].nunique().max()} fresh random instances per setting "
              "(instance seeds 100 on; some of bp's settings were chosen on them, docs/bp.md and the proof "
              "table below); every heuristic against the optimum. Per "
              "instance the optimum is bp's proven value; where bp's time limit stops the proof it lies "
              "between the best verified plan of any method and bp's certified bound. The mean optimum "
              "coverage of a setting is drawn as a line where every instance is proven and as a band [mean "
              "of the lower ends, mean of the upper ends] where some are not. A method's gap (opt − "
              "objective)/opt is then a value, or an interval: against the best known plan its lower end, "
              "against the bound its upper end. Runs without a plan have no gap and count as coverage 0. bp's curve "
              "and row are its own plan.", ""]
    missing = _missing(br)
    if missing:
        lines += ["Partial results: " + "; ".join(missing) + ".", ""]
    conflicts = br[br["conflict"].str.len() > 0]
    for name, r in conflicts.iterrows():
        lines += [f"**CONFLICT on {name}: {r['conflict']}** (a proof or bound is wrong somewhere).", ""]
    for sw in SWEEPS:
        cov, curve = coverage_table(df, sw), optimum_curve(br, sw)
        if cov.empty:
            lines += [f"{sw.title}: no rows yet.", ""]
            continue
        plot_sweep(cov, curve, sw, out / f"{sw.name}.png")
        both = pd.concat([cov, curve.assign(method="optimum").rename(columns={"lo": "mean_lo", "hi": "mean_hi"})],
                         ignore_index=True)
        both.to_csv(out / f"{sw.name}.csv", index=False)
        lines += [f"![{sw.title}]({sw.name}.png)", ""]
    lines += [f"{h}# Proofs and the optimum per setting", "",
              "bp's share of proven instances against its target; the widest open bracket over the unproven "
              "instances (bp bound − bp's own plan / bp bound − best plan of any method, viewpoints); the mean "
              "optimum coverage (a bracket where some instance is unproven).", ""]
    lines += _md_table(["setting", "instances", "bp limit (s)", "proven by bp", "target", "unproven",
                        "max bound − plan (bp / best)", "mean optimum coverage", "conflicts"], _setting_rows(st))
    lines += [""] + validation_lines(df, validation, out, heading=h + "#")
    lines += [f"{h}# Mean gap to the optimum per method", "",
              "Mean (opt − objective)/opt over the runs with a plan on instances with an optimum; [lower, upper] "
              "where some optimum is only bracketed (lower: to the best known plan, upper: to bp's bound). bp's "
              "row is its own plan.", ""]
    for sw in SWEEPS:
        head, rows = _gap_rows(mg, sw)
        if rows:
            lines += [sw.title.split(":")[0] + f" ({sw.fixed}={sw.value}):", ""] + _md_table(head, rows) + [""]
    lines += ["Tables: `paper_opt_settings.csv`, `paper_opt_gaps.csv`, `paper_opt_instances.csv`, "
              + ", ".join(f"`{sw.name}.csv`" for sw in SWEEPS) + ".", ""]
    return lines
