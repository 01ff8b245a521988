"""Gap over time for every method: the mean gap to the proven optimum against time.

Reads result rows whose ``info.history`` is a method's incumbent against time
(:mod:`sarcover.formulations.history`; every registered method records one) and the proven optima
of the same instances (rows with status ``optimal``, from any suite). Per run, the gap at time t is

    gap(t) = (OPT - z(t)) / OPT,

z(t) the best objective the run had recorded by t; before its first point, and for a run that
never finds a plan, the gap is 1 (no plan). After the run ends its gap stays at its final value
until the time limit (a run that stopped early keeps what it returned). This is Berthold's
primal gap function for a maximisation problem with 0 <= z <= OPT, and the **primal integral** of
a run is its integral over [0, limit] (Berthold 2013, "Measuring the impact of primal
heuristics", unnormalised: in seconds; divided by the limit it is the time-averaged gap).

Per setting (M, K, N) and method: the mean gap over the instances with a proven optimum against
time (one figure per setting, time on a log axis), the mean primal integral, the mean gap at
fixed times, and the first time the mean gap reaches 5 %, 1 % and 0 %. Instances without a proven
optimum are left out and listed. Two clocks, both from the method's call: wall time
(``info.history``) and CPU time (``info.history_cpu``, the process's CPU seconds at each point;
on a machine shared with other work the clock that load does not inflate). A row without
``history_cpu`` (bp keeps its own history) gets its wall times scaled by the job's CPU share
``cpu_s / wall_s`` (:func:`cpu_share`), an estimate; the table says how many runs that is. The
time limit is on the wall clock, so on a loaded machine a run cut by it received fewer CPU seconds
than the limit: on the CPU clock a value at time t is given only where every run of the method had
either ended on its own (proof, iteration limit, construction) or received at least t CPU seconds.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from sarcover.formulations.history import stop_reason_of
from sarcover.reports.plots import new_axes, save_figure, subplots
from sarcover.reports.style import look, ordered

THRESHOLDS = (0.05, 0.01, 0.0)  # mean gaps whose first time the table gives
AT_TIMES = (0.01, 0.1, 1.0, 10.0)  # seconds at which the table gives the mean gap
_TOL = 1e-9
_OWN_STOP = {"proof", "iteration_limit", "converged", "completed"}  # ended before the clock cut it


def proven_optima(*frames: pd.DataFrame) -> pd.Series:
    """Instance -> proven optimum, from rows with status ``optimal`` of any of ``frames``.

    Raises ValueError when two proofs of one instance disagree (a bug in a method or a mixed-up
    instance), since every gap would then be wrong."""
    rows = [f[f["status"] == "optimal"][["instance", "objective"]] for f in frames if f is not None and len(f)]
    if not rows:
        return pd.Series(dtype=float)
    opt = pd.concat(rows, ignore_index=True).dropna()
    spread = opt.groupby("instance")["objective"].agg(["min", "max"])
    bad = spread[spread["max"] - spread["min"] > 1e-6 * spread["max"].abs().clip(lower=1.0)]
    if len(bad):
        raise ValueError(f"proven optima disagree on {len(bad)} instance(s), e.g. {bad.index[0]}: "
                         f"{bad.iloc[0]['min']:g} vs {bad.iloc[0]['max']:g}")
    return spread["max"].rename("optimum")


def step_points(row, optimum: float, clock: str = "wall") -> tuple[np.ndarray, np.ndarray]:
    """A run's gap as a right-continuous step function: times ``t`` (starting at 0) and the gap
    from each time on, on the ``"wall"`` or ``"cpu"`` clock (:func:`cpu_times`). Incumbents only
    (a heuristic records no bound); a run without a history (killed, crashed) or a plan has gap 1
    throughout. The run's verified final objective closes it at its runtime if its history ends
    lower (an error row counts as no plan)."""
    info = row.get("info")
    hist = (info.get("history") if isinstance(info, dict) else None) or []
    times = cpu_times(row) if clock == "cpu" else [float(p[0]) for p in hist]
    pts = [(t, float(p[1])) for t, p in zip(times, hist) if p[1] is not None]
    if row.get("status") == "error":
        pts = []
    obj = row.get("objective")
    if obj is not None and not pd.isna(obj) and row.get("status") != "error":
        end = float(row["runtime_s"]) if not pd.isna(row.get("runtime_s")) else (pts[-1][0] if pts else 0.0)
        if clock == "cpu":
            end *= cpu_share(row) if np.isfinite(cpu_share(row)) else 1.0
        if not pts or pts[-1][1] < float(obj) - _TOL:
            pts.append((end if not pts else max(end, pts[-1][0]), float(obj)))
    times, gaps, best = [0.0], [1.0], -np.inf
    for t, z in sorted(pts):
        if z > best + _TOL:
            best = z
            g = max((optimum - z) / optimum, 0.0) if optimum > 0 else (0.0 if z >= optimum else 1.0)
            if t <= times[-1] + _TOL:
                gaps[-1] = g
            else:
                times.append(t)
                gaps.append(g)
    return np.asarray(times), np.asarray(gaps)


def gap_at(times: np.ndarray, gaps: np.ndarray, t) -> np.ndarray:
    """The step function's value at time(s) ``t``."""
    return gaps[np.searchsorted(times, np.asarray(t, dtype=float), side="right") - 1]


def primal_integral(times: np.ndarray, gaps: np.ndarray, limit: float) -> float:
    """Integral of the gap step function over [0, limit] (seconds)."""
    edges = np.append(np.minimum(times, limit), limit)
    return float(np.sum(gaps * np.diff(edges)))


def cpu_share(row) -> float:
    """The run's CPU share: job CPU time over job wall time (1 on a dedicated core; at most 1, as
    every method runs on one thread). NaN when the row has no ``cpu_s``."""
    cpu, wall = row.get("cpu_s"), row.get("wall_s")
    if cpu is None or wall is None or pd.isna(cpu) or pd.isna(wall) or wall <= 0:
        return float("nan")
    return float(min(cpu / wall, 1.0))


def cpu_times(row) -> list[float]:
    """The CPU time of each point of the row's history: ``info.history_cpu`` where the method
    recorded it, else the wall times scaled by the job's CPU share (1 when unknown)."""
    info = row.get("info") if isinstance(row.get("info"), dict) else {}
    hist = info.get("history") or []
    cpu = info.get("history_cpu")
    if cpu is not None and len(cpu) == len(hist):
        return [float(c) for c in cpu]
    share = cpu_share(row)
    return [float(p[0]) * (share if np.isfinite(share) else 1.0) for p in hist]


def runs_table(rows: pd.DataFrame, optima: pd.Series) -> pd.DataFrame:
    """One line per run on an instance with a proven optimum: its step function and CPU share."""
    out = []
    for _, r in rows[rows["instance"].isin(optima.index)].iterrows():
        opt = float(optima[r["instance"]])
        t, g = step_points(r, opt, "wall")
        tc, gc = step_points(r, opt, "cpu")
        info = r["info"] if isinstance(r["info"], dict) else {}
        stop = info.get("stop_reason") or (stop_reason_of(r["termination"]) if r.get("termination") else None)
        # the CPU seconds the run received: its last CPU point, or its runtime times its CPU share
        # (NaN for a killed job, which records neither; filled in below from its method's share)
        share = cpu_share(r)
        known = ([float(r["runtime_s"]) * share] if np.isfinite(share) else []) + (
            [cpu_times(r)[-1]] if info.get("history_cpu") else [])
        cpu_end = max(known + [float(tc[-1])]) if known else np.nan
        out.append({"setting": setting_of(r), "instance": r["instance"], "method": r["method"],
                    "seed": r.get("seed", 0), "limit": float(r["time_limit"]), "times": t, "gaps": g,
                    "times_cpu": tc, "gaps_cpu": gc, "final_gap": float(g[-1]), "cpu_share": cpu_share(r),
                    "cpu_recorded": info.get("history_cpu") is not None, "status": r["status"],
                    "stop_reason": stop, "runtime_s": float(r["runtime_s"]),
                    # CPU seconds up to which the run's CPU curve is measured (inf: it ended on its own)
                    "cpu_covered": np.inf if stop in _OWN_STOP else cpu_end})
    runs = pd.DataFrame(out)
    if len(runs):
        mean_share = runs.groupby(["setting", "method"])["cpu_share"].transform("mean").fillna(1.0)
        runs["cpu_covered"] = runs["cpu_covered"].fillna(runs["runtime_s"] * mean_share)
    return runs


def setting_of(row) -> str:
    """The setting's label: ``M=20 K=3 N=5`` for a generated SAR instance, else the instance kind
    (all TOP files of a suite form one setting)."""
    if all(row.get(c) is not None and not pd.isna(row.get(c)) for c in ("M", "K", "N")):
        return f"M={int(row['M'])} K={int(row['K'])} N={int(row['N'])}"
    return str(row.get("kind") or "files")


def mean_curve(runs: pd.DataFrame, clock: str = "wall") -> tuple[np.ndarray, np.ndarray]:
    """The mean gap over ``runs`` as a step function (times, mean gaps), on the ``"wall"`` or
    ``"cpu"`` clock."""
    scaled = [(r["times_cpu"], r["gaps_cpu"]) if clock == "cpu" else (r["times"], r["gaps"])
              for _, r in runs.iterrows()]
    grid = np.unique(np.concatenate([t for t, _ in scaled]))
    return grid, np.mean([gap_at(t, g, grid) for t, g in scaled], axis=0)


def first_time(times: np.ndarray, gaps: np.ndarray, level: float, limit: float) -> float:
    """The first time the step function is at most ``level`` (NaN if never by ``limit``)."""
    hit = np.flatnonzero(gaps <= level + _TOL)
    return float(times[hit[0]]) if hit.size and times[hit[0]] <= limit else float("nan")


def convergence_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per setting and method: instances, mean primal integral (wall and CPU clock), mean gap at
    :data:`AT_TIMES`, first time of a mean gap of at most each of :data:`THRESHOLDS`, final mean
    gap, optimum reached, mean CPU share."""
    out = []
    for (setting, method), grp in runs.groupby(["setting", "method"], sort=False):
        limit = float(grp["limit"].max())
        line = {"setting": setting, "method": method, "instances": grp["instance"].nunique(), "runs": len(grp)}
        for clock, t_col, g_col in (("wall", "times", "gaps"), ("cpu", "times_cpu", "gaps_cpu")):
            line[f"primal_integral_{clock}_s"] = float(np.mean(
                [primal_integral(r[t_col], r[g_col], limit) for _, r in grp.iterrows()]))
        covered = {"wall": limit, "cpu": float(min(grp["cpu_covered"].min(), limit))}
        line["cpu_covered_s"] = covered["cpu"]
        for clock in ("wall", "cpu"):
            tc, gc = mean_curve(grp, clock)
            suffix = "" if clock == "wall" else "_cpu"
            for at in AT_TIMES:
                measured = at <= covered[clock] + _TOL
                line[f"gap_at_{at:g}s{suffix}"] = float(gap_at(tc, gc, at)) if measured else float("nan")
            for level in THRESHOLDS:
                line[f"t_gap{level * 100:g}_{clock}_s"] = first_time(tc, gc, level, covered[clock])
        line["final_gap"] = float(grp["final_gap"].mean())
        line["optimal_runs"] = int((grp["final_gap"] <= _TOL).sum())
        line["cpu_share"] = float(grp["cpu_share"].mean())
        line["cpu_recorded"] = int(grp["cpu_recorded"].sum())
        out.append(line)
    tab = pd.DataFrame(out)
    rank = {m: i for i, m in enumerate(ordered(tab["method"].unique()))} if len(tab) else {}
    return tab.sort_values(["setting", "method"], key=lambda c: c.map(rank) if c.name == "method" else c,
                           ignore_index=True) if len(tab) else tab


def curves_table(runs: pd.DataFrame) -> pd.DataFrame:
    """The mean gap step functions (wall and CPU clock) as a long table: setting, method, clock,
    t_s, mean_gap (the mean gap from t_s on)."""
    out = []
    for (setting, method), grp in runs.groupby(["setting", "method"], sort=False):
        for clock in ("wall", "cpu"):
            t, g = mean_curve(grp, clock)
            out += [{"setting": setting, "method": method, "clock": clock, "t_s": float(a), "mean_gap": float(b)}
                    for a, b in zip(t, g)]
    return pd.DataFrame(out)


def plot_convergence(runs: pd.DataFrame, clock: str = "wall", ax=None, title: str | None = None,
                     t_min: float = 1e-3):
    """Mean gap to the optimum against time (log axis), one step line per method of ``runs``
    (one setting), ending in the method's marker: at the limit, or on the CPU clock where the CPU
    time of its runs was measured to. Draws on ``ax`` (a new one if None) and returns it; neither
    shows nor saves."""
    if ax is None:
        ax = new_axes((7, 4.5))
    limit = float(runs["limit"].max())
    for method in ordered(runs["method"].unique()):
        grp = runs[runs["method"] == method]
        t, g = mean_curve(grp, clock)
        # on the CPU clock a curve ends where its runs' CPU time does (a run the wall-clock limit cut)
        end = limit if clock == "wall" else float(min(grp["cpu_covered"].min(), limit))
        keep = t <= end
        t, g = t[keep], g[keep]
        t = np.append(np.maximum(t, t_min), max(end, t_min))
        g = np.append(g, g[-1]) * 100
        lk = look(method)
        ax.step(t, g, where="post", color=lk.color, ls=lk.ls, lw=1.6, label=method)
        ax.plot(t[-1:], g[-1:], marker=lk.marker, color=lk.color, ms=6)
    ax.set_xscale("log")
    ax.set_xlim(t_min, limit * 1.05)
    ax.set_ylim(-2, 102)
    ax.set_xlabel("CPU time (s)" if clock == "cpu" else "wall time (s)")
    ax.set_ylabel("mean gap to the optimum (%)")
    ax.grid(alpha=0.3, which="both")
    if title:
        ax.set_title(title, fontsize=10)
    return ax


def _fmt_t(x: float, limit: float) -> str:
    return f"> {limit:.2g}" if pd.isna(x) else (f"{x:.3g}" if x >= 0.001 else "< 0.001")


def _fmt_gap(x: float) -> str:
    return "n/m" if pd.isna(x) else f"{100 * x:.1f} %"


def best_at(tab: pd.DataFrame, setting: str, at: float, clock: str = "wall") -> tuple[list[str], float, list[str]]:
    """The methods with the lowest mean gap at ``at`` seconds in ``setting`` on ``clock``, that gap,
    and the methods not measured that far on that clock (CPU clock: cut by the wall-clock limit)."""
    col = f"gap_at_{at:g}s" + ("_cpu" if clock == "cpu" else "")
    sub = tab[tab["setting"] == setting]
    low = sub[col].min()
    return (list(sub[sub[col] <= low + 1e-12]["method"]), float(low), list(sub[sub[col].isna()]["method"]))


def write_convergence(rows: pd.DataFrame, optimum_rows: list[pd.DataFrame], out: str | Path, *,
                      heading: str = "##", prefix: str = "anytime", pool: str | None = None) -> str:
    """Write the section's figures (``{prefix}_<setting>.png``) and CSVs (``{prefix}_table.csv``,
    ``{prefix}_curves.csv``, ``{prefix}_runs.csv``) into ``out``; return its Markdown.

    ``rows``: the runs (with ``info.history``); ``optimum_rows``: frames whose ``optimal`` rows
    give the proven optima (``rows`` itself is added); ``pool``: one setting of this name for all
    instances (one figure and table) instead of one per setting."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    optima = proven_optima(rows, *optimum_rows)
    insts = rows.drop_duplicates("instance").set_index("instance")
    left_out = sorted(set(insts.index) - set(optima.index))
    runs = runs_table(rows, optima)
    if pool is not None and not runs.empty:
        runs = runs.assign(setting=pool)
    L = [f"{heading} Gap over time for every method", ""]
    if runs.empty:
        return "\n".join(L + ["No run on an instance with a proven optimum.", ""])
    limit = float(runs["limit"].max())
    tab = convergence_table(runs)
    tab.to_csv(out / f"{prefix}_table.csv", index=False)
    curves_table(runs).to_csv(out / f"{prefix}_curves.csv", index=False)
    def joined(a):
        return " ".join(f"{x:.4g}" for x in a)

    runs.assign(**{c: runs[c].map(joined) for c in ("times", "gaps", "times_cpu", "gaps_cpu")}).to_csv(
        out / f"{prefix}_runs.csv", index=False)
    limits = runs.groupby("method")["limit"].agg(["min", "max"])
    if limits["max"].nunique() == 1 and (limits["min"] == limits["max"]).all():
        given = f"Every method with the same time limit ({limit:g} s, one thread) on the same instances"
    else:
        given = ("The methods' time limits differ (" + ", ".join(
            f"{m} {lo:g} s" if lo == hi else f"{m} {lo:g}-{hi:g} s" for m, (lo, hi) in limits.iterrows())
            + f"; one thread each); each run is held at what it returned from its stop up to {limit:g} s")
    L += [f"{given}; the mean gap "
          "to the proven optimum against time, where a run's gap at t is (OPT − z(t))/OPT with z(t) the best "
          "objective it had recorded by t (`info.history`; a gap of 100 % before its first plan, and after it "
          "stops the gap of what it returned). The primal integral is Berthold's: the integral of that gap over "
          f"[0, {limit:g} s], in seconds (divided by {limit:g} it is the time-averaged gap). \"t ≤ 5 %\" is the "
          "first time the mean gap over the instances is at most 5 % (\"> limit\": never). Times are each run's "
          "own clocks from the method's call: wall time, and CPU time (the process's CPU seconds at each point, "
          "`info.history_cpu`), which load from other work on the machine does not inflate; where a method "
          "records no CPU times (bp keeps its own history) its wall times are scaled by the job's CPU share "
          "(cpu_s / wall_s), an estimate. \"CPU share\" is the mean of cpu_s / wall_s over the method's jobs, "
          "\"CPU pts\" how many of its runs recorded CPU times. The limit is on the wall clock, so a run it "
          "cut received fewer CPU seconds than that: on the CPU clock a value is given only up to the CPU time "
          "every run of the method either ended on its own (proof, iteration limit, construction) or reached "
          "(\"CPU measured to\"); beyond it \"n/m\" (not measured), and \"> x\" means not reached by x s. "
          "The CPU-clock primal integral holds a cut run at its final gap up to the limit, which is "
          "pessimistic for the methods the wall clock cut. The gap at the limit counts what a run had by then: "
          "a plan a method returns after its limit (its final point past it) does not count there.", ""]
    if left_out:
        L += [f"Left out (no proven optimum): {', '.join(left_out)}.", ""]
    for setting, grp in runs.groupby("setting", sort=False):
        fig, axes = subplots(1, 2, figsize=(13, 4.6), sharey=True)
        plot_convergence(grp, "wall", ax=axes[0], title=f"{setting}: wall clock")
        plot_convergence(grp, "cpu", ax=axes[1], title=f"{setting}: CPU clock")
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="center right", fontsize=8, frameon=False)
        fig.tight_layout(rect=(0, 0, 0.88, 1))
        name = f"{prefix}_{setting.replace('=', '').replace(' ', '_').lower()}.png"
        save_figure(fig, out / name)
        sub = tab[tab["setting"] == setting]
        n_inst = int(sub["instances"].max())
        L += [f"{heading}# {setting} ({n_inst} instances with a proven optimum)", "",
              f"![mean gap against time, {setting}]({name})", ""]
        head = ("| method | gap at " + " | ".join(f"{a:g} s" for a in AT_TIMES) + " (wall / CPU) | primal integral (s) "
                "wall / CPU | " + " | ".join(f"t ≤ {lv * 100:g} % (s) wall / CPU" for lv in THRESHOLDS)
                + " | optimal | CPU share | CPU measured to (s) | CPU pts |")
        L += [head, "|" + "---|" * (len(AT_TIMES) + len(THRESHOLDS) + 6)]
        for _, r in sub.iterrows():
            cells = [f"{_fmt_gap(r[f'gap_at_{a:g}s'])} / {_fmt_gap(r[f'gap_at_{a:g}s_cpu'])}" for a in AT_TIMES]
            cells.append(f"{r['primal_integral_wall_s']:.2f} / {r['primal_integral_cpu_s']:.2f}")
            cells += [f"{_fmt_t(r[f't_gap{lv * 100:g}_wall_s'], limit)} / "
                      f"{_fmt_t(r[f't_gap{lv * 100:g}_cpu_s'], r['cpu_covered_s'])}" for lv in THRESHOLDS]
            cells += [f"{r['optimal_runs']}/{r['runs']}", f"{r['cpu_share']:.2f}", f"{r['cpu_covered_s']:.2g}",
                      f"{r['cpu_recorded']}/{r['runs']}"]
            L.append(f"| {r['method']} | " + " | ".join(cells) + " |")
        L.append("")
        for clock in ("wall", "cpu"):
            best = []
            for a in AT_TIMES:
                m, g, unmeasured = best_at(tab, setting, a, clock)
                text = f"{a:g} s: {', '.join(m)} ({100 * g:.1f} %)" if m else f"{a:g} s: –"
                if unmeasured:
                    text += f" among the methods measured that far (not: {', '.join(unmeasured)})"
                best.append(text)
            L += [f"Lowest mean gap on the {clock} clock at " + "; ".join(best) + ".", ""]
    L += [f"Data: `{prefix}_table.csv` (this table), `{prefix}_curves.csv` (the mean-gap step functions, both "
          f"clocks), `{prefix}_runs.csv` (each run's gap step function and CPU share).", ""]
    return "\n".join(L)
