"""The reference report's scale section on synthetic rows: bp's proofs and certified gaps per
setting, each method's gap and runtime, and the fitted growth exponent."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from sarcover.benchmarks.reproduce import SUITES
from sarcover.reports import scale
from sarcover.reports.reference import write_reference
from sarcover.reports.scale import fit_exponent, growth_table, method_table, scale_section, setting_table

SETTINGS = [(20, 3, 4), (40, 3, 8), (60, 3, 10), (100, 3, 16)]


def row(instance, method, status, objective, bound=None, *, M, K, N, runtime=1.0) -> dict:
    """One result row of the fields the report reads (formulations/records.py FIELDS)."""
    termination = {"optimal": "optimal", "time_limit": "time_limit"}.get(status, "completed")
    return {"schema": 2, "key": f"{instance}|{method}|0", "suite": "scale", "instance": instance, "method": method,
            "exact": method == "bp", "seed": 0, "kind": "sar", "M": M, "K": K, "N": N, "status": status,
            "termination": termination, "objective": objective, "bound": bound,
            "coverage": None if objective is None else objective / (M * K), "valid": objective is not None,
            "time_limit": 600 if method == "bp" else 10, "runtime_s": runtime, "info": {}, "reference": None,
            "best_known": None}


def scale_rows(settings=SETTINGS, runs=4, open_every=0, exponent=2.0) -> list[dict]:
    """Per setting ``runs`` instances with optimum 0.8·M·K: bp proves it except on every
    ``open_every``-th instance (plan opt − 2, bound opt + 2); greedy finds 0.9·opt; greedy's
    runtime is 1e-4·(M·K)^exponent with noise of ±1 % across instances, bp's 0.01·(M·K)."""
    rng = np.random.default_rng(0)
    rows = []
    for m, k, n in settings:
        vp = m * k
        for i in range(runs):
            name = f"sar-m{m}-k{k}-n{n}-s{300 + i}"
            opt = 0.8 * vp
            noise = 1 + rng.uniform(-0.01, 0.01)
            rows.append(row(name, "greedy", "feasible", float(np.floor(0.9 * opt)), M=m, K=k, N=n,
                            runtime=1e-4 * vp ** exponent * noise))
            if open_every and i % open_every == 0:
                rows.append(row(name, "bp", "time_limit", opt - 2, opt + 2, M=m, K=k, N=n, runtime=600.0))
            else:
                rows.append(row(name, "bp", "optimal", opt, opt, M=m, K=k, N=n, runtime=0.01 * vp))
    return rows


def test_fitted_exponent_of_quadratic_runtime_is_two():
    """A runtime ∝ n² gives a fitted exponent ≈ 2 (and a linear one ≈ 1), per method and per K."""
    rows = scale_rows(SETTINGS + [(20, 6, 5), (40, 6, 10)], exponent=2.0)
    gt = growth_table(method_table(pd.DataFrame(rows))).set_index("method")
    assert gt.loc["greedy", "exponent"] == pytest.approx(2.0, abs=0.02)
    assert gt.loc["greedy", "exponent_K3"] == pytest.approx(2.0, abs=0.02)
    assert gt.loc["bp", "exponent"] == pytest.approx(1.0, abs=1e-9)
    assert gt.loc["greedy", "settings"] == 6 and gt.loc["greedy", "viewpoints"] == "60-300"
    b, a, n = fit_exponent([10, 100, 1000], [3 * 10 ** 1.5, 3 * 100 ** 1.5, 3 * 1000 ** 1.5])
    assert (b, a, n) == (pytest.approx(1.5), pytest.approx(3.0), 3)
    assert np.isnan(fit_exponent([60, 60], [1.0, 2.0])[0])  # one size: no slope


def test_proven_share_and_certified_gap_per_setting():
    """bp's proofs per setting, and the certified gap (bound − best plan)/bound: 0 where proven,
    4/(0.8·M·K + 2) where bp stops at plan opt − 2 under bound opt + 2."""
    waiting = [r for r in scale_rows(settings=[(20, 6, 5)]) if r["method"] != "bp"]  # bp not run there yet
    st = setting_table(pd.DataFrame(scale_rows(open_every=2) + waiting)).set_index("setting")
    assert list(st["viewpoints"]) == [60, 120, 120, 180, 300]
    assert st.loc["M=20 K=6 N=5", "bp_runs"] == 0 and np.isnan(st.loc["M=20 K=6 N=5", "certified_gap_mean"])
    r = st.loc["M=40 K=3 N=8"]
    assert (r["instances"], r["bp_runs"], r["proven"], r["share_proven"]) == (4, 4, 2, 0.5)
    assert r["certified_gap_max"] == pytest.approx(4 / 98)
    assert r["certified_gap_mean"] == pytest.approx(4 / 98 / 2)
    assert r["bp_time_limit"] == "600" and r["conflicts"] == 0


def test_tuning_instances_counted_and_left_out_of_the_held_out_gap():
    """A setting whose open instance chose bp's settings: the certified gap over all instances
    includes it, the held-out one does not; settings without a tuning instance have both equal."""
    rows = scale_rows(settings=[(40, 6, 10), (60, 6, 15)], runs=3, open_every=2)
    assert "sar-m40-k6-n10-s300" in scale.TUNING  # seed 300: the open one (open_every=2)
    st = setting_table(pd.DataFrame(rows)).set_index("setting")
    r = st.loc["M=40 K=6 N=10"]
    assert r["tuning"] == 1 and r["certified_gap_max"] == pytest.approx(4 / 194)
    assert r["held_out_gap_max"] == pytest.approx(4 / 194)  # seed 302 is open too, and held out
    assert r["held_out_gap_mean"] == pytest.approx(4 / 194 / 2)  # seeds 301 (proven) and 302
    assert r["certified_gap_mean"] == pytest.approx(2 * 4 / 194 / 3)
    other = st.loc["M=60 K=6 N=15"]
    assert other["tuning"] == 0 and other["held_out_gap_mean"] == pytest.approx(other["certified_gap_mean"])


def test_gaps_to_optimum_and_to_bound_kept_apart():
    """Greedy's gap is to the optimum on proven instances and to the bound on open ones; the mean
    of both is marked as an upper bound, and its t interval follows stats.t_halfwidth."""
    from sarcover.reports.stats import t_halfwidth

    mt = method_table(pd.DataFrame(scale_rows(open_every=2))).set_index(["method", "setting"])
    r = mt.loc[("greedy", "M=20 K=3 N=4")]  # opt 48, greedy 43; the open ones' bound 50
    assert (r["gap_n"], r["gap_ub_n"]) == (2, 2) and bool(r["gap_is_bound"])
    assert r["gap_mean"] == pytest.approx(5 / 48) and r["gap_ub_mean"] == pytest.approx(7 / 50)
    assert r["gap_any_mean"] == pytest.approx((5 / 48 + 7 / 50) / 2)
    assert r["gap_any_ci95"] == pytest.approx(t_halfwidth([5 / 48, 7 / 50, 5 / 48, 7 / 50]))
    proven = method_table(pd.DataFrame(scale_rows())).set_index(["method", "setting"])
    assert not proven.loc[("greedy", "M=20 K=3 N=4"), "gap_is_bound"]
    assert proven.loc[("greedy", "M=20 K=3 N=4"), "gap_ci95"] == pytest.approx(0.0)


def test_section_text_figure_and_csvs(tmp_path, monkeypatch):
    """The section names every setting (one without bp rows as such), marks bounded gaps with ≤,
    draws one log-log runtime panel with a fitted line per method, and writes its three CSVs."""
    figures = []
    monkeypatch.setattr(scale, "save_figure", lambda fig, path, *a, **k: figures.append((path.name, fig)))
    waiting = [r for r in scale_rows(settings=[(20, 6, 5)]) if r["method"] != "bp"]
    text = "\n".join(scale_section(pd.DataFrame(scale_rows(open_every=2) + waiting), tmp_path))
    assert "| M=20 K=6 N=5 | 120 | 4 | – | no bp rows yet |" in text
    for s in ("M=20 K=3 N=4", "M=100 K=3 N=16"):
        assert s in text
    assert "| M=40 K=3 N=8 | 120 | 4 | 600 | 2/4 (50 %) |" in text
    assert "Tuning instances: " in text and "sar-m40-k6-n10-s300" in text
    assert "| greedy | ≤ " in text and "upper bound" in text
    [(name, fig)] = figures
    ax = fig.axes[0]
    assert name == "scale_growth.png" and (ax.get_xscale(), ax.get_yscale()) == ("log", "log")
    assert any("b = 2.0" in t.get_text() for t in fig.axes[1].get_legend().get_texts())
    for csv in ("scale_settings.csv", "scale_gaps.csv", "scale_growth.csv"):
        assert len(pd.read_csv(tmp_path / csv)) > 0


def test_section_only_with_scale_rows(tmp_path):
    """The reference report has no scale section without scale rows, and has it once they exist."""
    root = tmp_path / "root"
    (root / "table1").mkdir(parents=True)
    other = [dict(r, suite="table1") for r in scale_rows(settings=[(20, 3, 5)])]
    (root / "table1" / "results.jsonl").write_text("".join(json.dumps(r) + "\n" for r in other))
    text = write_reference(root, tmp_path / "out", suites=SUITES).read_text()
    assert "Beyond the paper's size" not in text and not (tmp_path / "out" / "scale_growth.png").exists()
    (root / "scale").mkdir()
    (root / "scale" / "results.jsonl").write_text("".join(json.dumps(r) + "\n" for r in scale_rows()))
    text = write_reference(root, tmp_path / "out", suites=SUITES).read_text()
    assert "## Beyond the paper's size (suite `scale`)" in text
    assert (tmp_path / "out" / "scale_growth.png").stat().st_size > 0
