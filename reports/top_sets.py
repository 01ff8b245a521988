"""The larger TOP benchmark sets (Chao, Golden & Wasil sets 4-7, suite ``top-4-7``): bp against the
published values, per set.

Rows carry ``reference`` (the published optimum, where it is proven) and ``best_known`` (a
published best known value, a lower bound on the optimum, where it is not). Per file:

- a bp proof must equal the published optimum; any difference, a plan above it or a bound below
  it is a **conflict** (:func:`sarcover.reports.gaps.instance_table` flags the first and second,
  and a proof or bound below a best known value; the bound below the optimum is checked here);
- a verified plan above a published best known value is **news** (a new best known value;
  ``instance_table``'s ``news``);
- a proof on a file that the shipped table (``optimal.csv``) lists as best known only is new to
  that table, not to the literature: the table marks ``optimal`` only what was checked here, and
  the exact TOP literature reports most of sets 4-7 solved to optimality (``PROVENANCE.md``); the
  section counts these proofs apart from the news;
- an unproven file gets its certified gap (bound − plan)/bound: the true gap of the plan is at
  most that;
- where a correction to the copied table replaces a copied value (``fixes``: the rows of
  ``corrections.csv``, which the caller reads with :func:`sarcover.benchmarks.catalog.corrections`),
  every row of the file is checked against the corrected value, rows stored before the
  correction included, and the section lists the correction with its evidence.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from sarcover.reports.gaps import TOL, instance_table

SUITE = "top-4-7"
PROVER = "bp"


def _set_of(name: pd.Series) -> pd.Series:
    return name.str.extract(r"^p(\d+)\.", expand=False).astype(int)


def corrected(df: pd.DataFrame, fixes: list[dict[str, str]] | None = None) -> pd.DataFrame:
    """``df`` with each corrected file's ``reference`` and ``best_known`` set from its correction
    (``fixes``: rows of ``corrections.csv``; None: none)."""
    out = df.copy()
    for fix in fixes or []:
        at = out["instance"] == fix["instance"]
        value = float(fix["value"])
        out.loc[at, "reference"] = value if fix["status"] == "optimal" else np.nan
        out.loc[at, "best_known"] = value if fix["status"] == "best_known" else np.nan
    return out


def file_table(df: pd.DataFrame, method: str = PROVER, fixes: list[dict[str, str]] | None = None) -> pd.DataFrame:
    """Per file: set, published values (corrected where ``fixes`` say, see :func:`corrected`),
    bp's status, plan and bound, the checks and the gaps."""
    rows = corrected(df[df["method"] == method], fixes)
    inst = instance_table(rows)
    run = rows.drop_duplicates("instance").set_index("instance").reindex(inst.index)
    out = pd.DataFrame(index=inst.index)
    out["set"] = _set_of(pd.Series(inst.index, index=inst.index))
    out["reference"] = run["reference"].astype(float)
    out["best_known"] = inst["best_known"].astype(float)
    out["status"] = run["status"]
    out["objective"] = run["objective"].astype(float)
    out["bound"] = run["bound"].astype(float)
    out["runtime_s"] = run["runtime_s"].astype(float)
    ref, obj, bound = out["reference"], out["objective"], out["bound"]
    out["proven"] = out["status"] == "optimal"
    out["proven_equal"] = out["proven"] & ref.notna() & ((obj - ref).abs() <= TOL * np.maximum(1.0, ref))
    out["proof_of_best_known"] = out["proven"] & ref.isna()  # new to the shipped table only
    below = bound < ref - TOL * np.maximum(1.0, ref)
    conflicts = inst["conflict"].astype(str).where(inst["conflict"].astype(str).str.len() > 0, "")
    extra = pd.Series(np.where(below, "bound " + bound.map("{:g}".format) + " below published optimum "
                               + ref.map("{:g}".format), ""), index=out.index)
    out["conflict"] = [("; ".join(x for x in (a, b) if x)) for a, b in zip(conflicts, extra)]
    out["news"] = inst["news"].astype(str)
    with np.errstate(divide="ignore", invalid="ignore"):
        out["certified_gap"] = np.where(~out["proven"] & (bound > 0) & obj.notna(), (bound - obj) / bound, np.nan)
        target = ref.fillna(out["best_known"])
        out["gap_to_published"] = np.where(obj.notna() & (target > 0), (target - obj) / target, np.nan)
    return out


def set_table(files: pd.DataFrame) -> pd.DataFrame:
    """Per set: files, published optima and best known values, bp proven, proven equal to the
    published optimum, proofs of values the shipped table lists as best known only, conflicts,
    news, and the certified gaps of the unproven files."""
    rows = []
    for st, g in files.groupby("set"):
        open_ = g[~g["proven"]]
        t = g.loc[g["proven"], "runtime_s"]
        rows.append({"set": st, "files": len(g), "published_optima": int(g["reference"].notna().sum()),
                     "best_known_only": int((g["reference"].isna() & g["best_known"].notna()).sum()),
                     "bp_proven": int(g["proven"].sum()), "share_proven": g["proven"].mean(),
                     "proven_equal_published": int(g["proven_equal"].sum()),
                     "proofs_of_best_known": int(g["proof_of_best_known"].sum()),
                     "median_s_proven": t.median() if len(t) else np.nan,
                     "unproven": len(open_), "no_plan": int(open_["objective"].isna().sum()),
                     "certified_gap_mean": open_["certified_gap"].mean() if len(open_) else np.nan,
                     "certified_gap_max": open_["certified_gap"].max() if len(open_) else np.nan,
                     "conflicts": int(g["conflict"].str.len().gt(0).sum()),
                     "news": int(g["news"].str.len().gt(0).sum())})
    return pd.DataFrame(rows)


def _pct(v) -> str:
    return "–" if pd.isna(v) else f"{100 * v:.1f} %"


def _table(st: pd.DataFrame) -> list[str]:
    head = ["set", "files", "published optima (best known only)", "bp proven", "proven = published optimum",
            "proven, table: best known only", "median s (proven)", "unproven", "certified gap mean / max", "conflicts",
            "news"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in st.to_dict("records"):  # per column types (iterrows makes every count a float)
        lines.append(f"| {r['set']} | {r['files']} | {r['published_optima']} ({r['best_known_only']}) | "
                     f"{r['bp_proven']} ({_pct(r['share_proven'])}) | {r['proven_equal_published']} | "
                     f"{r['proofs_of_best_known']} | "
                     + ("–" if pd.isna(r["median_s_proven"]) else f"{r['median_s_proven']:.0f}")
                     + f" | {r['unproven']}" + (f" ({r['no_plan']} without plan)" if r["no_plan"] else "")
                     + f" | {_pct(r['certified_gap_mean'])} / {_pct(r['certified_gap_max'])} | "
                     + (f"**{r['conflicts']}**" if r["conflicts"] else "0") + f" | {r['news']} |")
    return lines


def _open_list(files: pd.DataFrame) -> list[str]:
    """Per set, every unproven file with its certified gap (widest first)."""
    lines = []
    for st, g in files[~files["proven"]].groupby("set"):
        g = g.sort_values("certified_gap", ascending=False, na_position="first")
        items = [f"{name} {_pct(r['certified_gap'])}" if r["objective"] == r["objective"] else f"{name} no plan"
                 for name, r in g.iterrows()]
        lines += [f"- set {st} ({len(g)}): " + ", ".join(items), ""]
    return lines


def _proofs_of_best_known(files: pd.DataFrame) -> list[str]:
    """The proofs of values the shipped table lists as best known only: new to this project's
    table, which marks as optimal only what was checked here, and mostly known to the literature."""
    proofs = files[files["proof_of_best_known"]]
    if proofs.empty:
        return []
    equal = (proofs["objective"] - proofs["best_known"]).abs() <= TOL * np.maximum(1.0, proofs["best_known"])
    lines = [f"Proofs new to this project's table: bp proves the optimum of {len(proofs)} "
             f"file{'s' if len(proofs) != 1 else ''} that the shipped "
             f"table (`optimal.csv`) lists as best known only; {int(equal.sum())} of them equal that value"
             + ("" if equal.all() else f", {int((~equal).sum())} do not (see the news and conflicts above)")
             + ". The table marks as optimal only the values checked here; the exact TOP literature (the "
             "branch-and-price and branch-and-cut papers listed in `PROVENANCE.md`) reports most set 4-7 instances "
             "solved to optimality, so most of these optima are very likely proved there already (the papers' "
             "per-instance tables were not at hand to say which). Per set:", ""]
    for st, g in proofs.groupby("set"):
        lines.append(f"- set {st} ({len(g)}): " + ", ".join(f"{name} {r['objective']:g}" for name, r in g.iterrows()))
    return lines + [""]


def _corrections(files: pd.DataFrame, fixes: list[dict[str, str]] | None) -> list[str]:
    """The corrections to the copied table that concern these files, with their evidence."""
    fixes = [f for f in fixes or [] if f["instance"] in files.index]
    if not fixes:
        return []
    lines = ["Corrections to the copied table (`corrections.csv`; `optimal.csv` stays as copied): these files "
             "are checked against the value below, not the copied one.", ""]
    for f in fixes:
        lines.append(f"- {f['instance']}: {float(f['value']):g} ({f['status']}) in place of the copied "
                     f"{float(f['copied_value']):g} ({f['copied_status']}). {f['evidence']}")
    return lines + [""]


def top_sets_section(df: pd.DataFrame | None, out, *, heading: str = "##",
                     fixes: list[dict[str, str]] | None = None) -> list[str]:
    """The section's Markdown lines; ``top_4_7_sets.csv`` and ``top_4_7_files.csv`` go into ``out``.
    ``fixes``: the corrections to the copied table to apply (rows of ``corrections.csv``)."""
    lines = [f"{heading} bp on the larger TOP sets (Chao, Golden & Wasil sets 4-7, suite `{SUITE}`)", ""]
    if df is None or not (df["method"] == PROVER).any():
        return lines + [f"No bp rows of `{SUITE}` yet.", ""]
    files = file_table(df, fixes=fixes)
    st = set_table(files)
    files.to_csv(out / "top_4_7_files.csv")
    st.to_csv(out / "top_4_7_sets.csv", index=False)
    limits = sorted(df.loc[df["method"] == PROVER, "time_limit"].dropna().unique())
    lines += [f"bp alone, {', '.join(f'{v:g}' for v in limits)} s per file, one thread, on {len(files)} files "
              "(the shipped public part: letters c, h, m, q, v are held out). A proof counts when bp reports "
              "`optimal`; it must equal the published optimum (a difference is a conflict), and no plan may exceed "
              "a published optimum nor any bound fall below one or below a published best known value. For an "
              "unproven file the certified gap (bound − plan)/bound bounds the plan's true gap.", ""]
    conflicts = files[files["conflict"].str.len() > 0]
    if len(conflicts):
        lines += [f"**CONFLICTS ({len(conflicts)} files): a proof, a bound or a published value is wrong.**", ""]
        lines += [f"- **{name}: {r['conflict']}**" for name, r in conflicts.iterrows()] + [""]
    else:
        lines += ["Conflicts with the published values: none.", ""]
    news = files[files["news"].str.len() > 0]
    if len(news):
        lines += ["News: plans above the best known value of the shipped table, new best known values to report "
                  "(the plans' routes are in the suite's result rows):", ""]
        lines += [f"- {name}: {r['news']}" for name, r in news.iterrows()] + [""]
    else:
        lines += ["News: none (no plan above a best known value of the shipped table).", ""]
    lines += _proofs_of_best_known(files)
    lines += _corrections(files, fixes)
    missing = sorted(set(range(4, 8)) - set(st["set"]))
    if missing:
        lines += [f"Sets without rows yet: {', '.join(map(str, missing))}.", ""]
    lines += _table(st) + [""]
    if (~files["proven"]).any():
        lines += ["Unproven files and their certified gaps (bound − plan)/bound:", ""] + _open_list(files)
    lines += ["Tables: `top_4_7_sets.csv`, `top_4_7_files.csv` (every file: published values, bp's plan, bound, "
              "checks, gaps).", ""]
    return lines
