"""The reference report's new sections on synthetic rows: the optimum on the paper's figures
(paper-opt), the TOP sets 4-7 against published values, and the decomposition section."""

from __future__ import annotations

import json

import matplotlib
import matplotlib.figure
import numpy as np
import pandas as pd
import pytest

from sarcover.benchmarks.reproduce import DECOMPOSE_SETTINGS, DECOMPOSITION, EXACT_ONLY, STEPS, SUITES
from sarcover.reports import optimum
from sarcover.reports.optimum import SWEEPS, brackets, method_gaps, setting_table
from sarcover.reports.reference import write_reference
from sarcover.reports.top_sets import file_table, set_table, top_sets_section


def row(instance, method, status, objective, bound=None, *, K=3, N=2, M=20, **extra) -> dict:
    """One result row of the fields the report reads."""
    total = M * K if M else 1
    return {"schema": 2, "key": f"{instance}|{method}|0", "suite": "paper-opt", "instance": instance,
            "method": method, "exact": method == "bp", "seed": 0, "kind": "sar", "M": M, "K": K, "N": N,
            "status": status, "objective": objective, "bound": bound,
            "coverage": None if objective is None or not M else objective / total, "valid": objective is not None,
            "time_limit": 60 if method == "bp" else 10, "runtime_s": 1.0, "info": {}, "reference": None,
            "best_known": None, **extra}


def setting_rows(K, N, opts, *, open_=(), heuristic=0.8, no_bp=(), seed0=100) -> list[dict]:
    """Rows of one setting: instance i (seed ``seed0 + i``) has optimum opts[i]; bp proves it unless
    i is in ``open_`` (then bp's plan is opt − 2 and its bound opt + 1, and pyvrp finds opt − 1);
    greedy reaches ``heuristic``·opt; instances in ``no_bp`` have no bp row."""
    rows = []
    for i, opt in enumerate(opts):
        name = f"sar-m20-k{K}-n{N}-s{seed0 + i}"
        rows.append(row(name, "greedy", "feasible", float(np.floor(heuristic * opt)), K=K, N=N))
        if i in no_bp:
            continue
        if i in open_:
            rows.append(row(name, "bp", "time_limit", opt - 2.0, opt + 1.0, K=K, N=N))
            rows.append(row(name, "pyvrp", "feasible", opt - 1.0, K=K, N=N))
        else:
            rows.append(row(name, "bp", "optimal", float(opt), float(opt), K=K, N=N))
            rows.append(row(name, "pyvrp", "feasible", float(opt), K=K, N=N))
    return rows


def write_rows(folder, rows):
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "results.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))


def test_brackets_and_setting_counts():
    """Proven instances give a point, open ones [best plan, bound]; the proven share per setting
    and its verdict against the target are counted right, also while bp is still running."""
    rows = (setting_rows(3, 2, [30] * 20, open_={0})                # 19/20 = 95 % at K=3: met
            + setting_rows(3, 3, [40] * 20, open_={0, 1})           # 18/20 = 90 %: missed
            + setting_rows(6, 5, [90] * 20, open_=set(range(11)))   # 9/20 = 45 % at K=6 (target 50 %): missed
            + setting_rows(4, 5, [70] * 20, no_bp=set(range(10))))  # 10 of 20 run, all proven: open
    df = pd.DataFrame(rows)
    br = brackets(df)
    name = "sar-m20-k3-n2-s100"
    assert br.loc[name, "state"] == "open" and (br.loc[name, "lo"], br.loc[name, "hi"]) == (29.0, 31.0)
    assert br.loc["sar-m20-k3-n2-s101", "state"] == "proven" and br.loc["sar-m20-k3-n2-s101", "lo"] == 30.0
    assert (br.loc["sar-m20-k4-n5-s100", "state"], br.loc["sar-m20-k4-n5-s100", "known"]) == ("no bp", False)
    st = setting_table(br).set_index("setting")
    assert st.loc["K=3 N=2", "proven"] == 19 and st.loc["K=3 N=2", "share_proven"] == pytest.approx(0.95)
    assert st.loc["K=3 N=2", "target"].endswith("met")
    assert st.loc["K=3 N=3", "target"].endswith("missed") and st.loc["K=6 N=5", "target"].endswith("missed")
    assert st.loc["K=6 N=5", "share_proven"] == pytest.approx(0.45) and "≥50 % at 600 s" in st.loc["K=6 N=5", "target"]
    assert st.loc["K=4 N=5", "bp_runs"] == 10 and "open (10 of 20 run)" in st.loc["K=4 N=5", "target"]
    # the widest open bracket: bound − bp's plan = 3, bound − best plan (pyvrp) = 2
    assert (st.loc["K=3 N=3", "max_bound_minus_bp_plan"], st.loc["K=3 N=3", "max_bound_minus_best_plan"]) == (3, 2)
    # mean optimum coverage: 19 proven at 30/60, one in [29, 31]/60
    assert st.loc["K=3 N=2", "opt_cov_lo"] == pytest.approx((19 * 30 + 29) / 20 / 60)
    assert st.loc["K=3 N=2", "opt_cov_hi"] == pytest.approx((19 * 30 + 31) / 20 / 60)
    assert st.loc["K=4 N=5", "opt_cov_lo"] == st.loc["K=4 N=5", "opt_cov_hi"] == pytest.approx(70 / 80)


def test_gap_interval_where_unproven():
    """A method's gap is a value on proven instances and [gap to best plan, gap to bound] on open
    ones: greedy 24 of opt 30 (proven) and of [29, 31] (open)."""
    df = pd.DataFrame(setting_rows(3, 2, [30, 30], open_={1}))
    mg = method_gaps(df, brackets(df)).set_index("method")
    g = mg.loc["greedy"]
    assert g["gap_lo_mean"] == pytest.approx(((30 - 24) / 30 + (29 - 24) / 29) / 2)
    assert g["gap_hi_mean"] == pytest.approx(((30 - 24) / 30 + (31 - 24) / 31) / 2)
    assert mg.loc["pyvrp", "gap_lo_mean"] == 0.0 and mg.loc["pyvrp", "gap_hi_mean"] == pytest.approx(2 / 31 / 2)


def test_band_where_unproven_line_where_proven(tmp_path, monkeypatch):
    """Fig. 3: at N=2 every instance is proven (the optimum is a line point), at N=3 one is not
    (a band from the mean best plan to the mean bound, and no line point there)."""
    df = pd.DataFrame(setting_rows(3, 2, [30] * 4) + setting_rows(3, 3, [40] * 4, open_={0}))
    figures = []
    monkeypatch.setattr(optimum, "save_figure", lambda fig, path, *a, **k: figures.append((path.name, fig)))
    text = "\n".join(optimum.optimum_section(df, tmp_path))
    [(name, fig)] = figures  # Fig. 4 has no rows (no N=5): no figure, said in the text
    assert name == "paper_opt_vs_N.png"
    assert "Fig. 4 with the optimum: coverage against K (M=20, N=5): no rows yet" in text
    ax = fig.axes[0]
    [line] = [ln for ln in ax.get_lines() if ln.get_label() == "optimum"]
    assert line.get_ydata()[0] == pytest.approx(0.5) and np.isnan(line.get_ydata()[1])
    # the open instance: bp's plan 38, pyvrp's 39 (the best plan), bp's bound 41
    lo, hi = (3 * 40 + 39) / 4 / 60, (3 * 40 + 41) / 4 / 60
    [box] = ax.patches  # one bracket box, at N=3
    assert box.get_x() + box.get_width() / 2 == pytest.approx(3)
    assert box.get_y() == pytest.approx(lo) and box.get_y() + box.get_height() == pytest.approx(hi)
    curve = pd.read_csv(tmp_path / "paper_opt_vs_N.csv")
    opt = curve[curve["method"] == "optimum"].set_index("N")
    assert opt.loc[2, "all_proven"] and not opt.loc[3, "all_proven"]
    assert opt.loc[3, ["mean_lo", "mean_hi"]].tolist() == pytest.approx([lo, hi])
    # every method's curve carries its look
    from sarcover.reports.style import look

    from matplotlib.container import ErrorbarContainer

    curves = [c for c in ax.containers if isinstance(c, ErrorbarContainer)]
    for c in curves:
        m = c.get_label()
        data = c.lines[0]
        assert (matplotlib.colors.to_hex(data.get_color()), data.get_marker()) == (look(m).color, look(m).marker)
    assert {c.get_label() for c in curves} == {"greedy", "pyvrp", "bp"}


def test_partial_results_are_named_not_crashed(tmp_path):
    """Only two settings, one without any bp row: the reference report names what is missing."""
    root = tmp_path / "root"
    write_rows(root / "paper-opt", setting_rows(3, 2, [30] * 3, open_={2})
               + setting_rows(2, 5, [25] * 3, no_bp={0, 1, 2}))
    text = write_reference(root, tmp_path / "out", suites=SUITES).read_text()
    assert "The optimum on the paper's figures" in text
    assert "settings without any rows yet: K=3 N=3, K=3 N=4, K=3 N=5, K=3 N=6, K=4 N=5, K=5 N=5, K=6 N=5" in text
    assert "settings without bp rows yet (no optimum drawn there): K=2 N=5" in text
    assert "| K=3 N=2 | 3 | 60 | 2/3 (67 %) | ≥95 % at 60 s: missed |" in text
    for name in ("paper_opt_vs_N.png", "paper_opt_vs_K.png", "paper_opt_settings.csv", "paper_opt_gaps.csv",
                 "paper_opt_instances.csv", "paper_opt_vs_N.csv", "paper_opt_vs_K.csv"):
        assert (tmp_path / "out" / name).stat().st_size > 0
    # heuristics only (bp not run at all yet) still gives figures and says so
    write_rows(root / "paper-opt", [r for r in setting_rows(3, 2, [30] * 3) if r["method"] != "bp"])
    text = write_reference(root, tmp_path / "out2", suites=SUITES).read_text()
    assert "3 of 3 instances have no bp row yet" in text and (tmp_path / "out2" / "paper_opt_vs_N.png").exists()


def test_tuning_and_validation_side_by_side():
    """Per setting, bp's proofs on paper-opt's (tuning) and paper-validation's instances, each with
    the widest open bracket; settings neither suite has yet count 0 runs."""
    tuning = pd.DataFrame(setting_rows(3, 2, [30] * 4, open_={0}) + setting_rows(5, 5, [80] * 4, open_={1, 2}))
    held = pd.DataFrame(setting_rows(3, 2, [31] * 5, seed0=200) + setting_rows(5, 5, [82] * 5, open_={0}, seed0=200))
    vt = optimum.validation_table(tuning, held).set_index("setting")
    assert list(vt.index[:9]) == [optimum.label(k, n) for k, n in optimum.expected_settings()]
    assert vt.loc["K=3 N=2", ["tuning_proven", "tuning_bp_runs", "validation_proven", "validation_bp_runs"]].tolist() \
        == [3, 4, 5, 5]
    assert vt.loc["K=5 N=5", ["tuning_proven", "validation_proven", "validation_bp_runs"]].tolist() == [2, 4, 5]
    # bound opt + 1 against pyvrp's opt − 1: 2 viewpoints; nothing open: no bracket
    assert vt.loc["K=5 N=5", "tuning_max_open"] == 2 and vt.loc["K=5 N=5", "validation_max_open"] == 2
    assert np.isnan(vt.loc["K=3 N=2", "validation_max_open"])
    assert vt.loc["K=4 N=5", ["tuning_bp_runs", "validation_bp_runs"]].tolist() == [0, 0]
    assert "route enumeration" in vt.loc["K=5 N=5", "tuned_on"]


def test_proof_table_says_when_validation_has_not_run(tmp_path):
    """Without paper-validation rows the proof table says validation has not been run; with them
    the reference report prints both proof rates per setting, tuning marked with what it chose."""
    root = tmp_path / "root"
    write_rows(root / "paper-opt", setting_rows(5, 5, [80] * 4, open_={1, 2}))
    text = write_reference(root, tmp_path / "out", suites=SUITES).read_text()
    assert "**Validation has not been run yet**" in text
    line = next(x for x in text.splitlines() if x.startswith("| K=5 N=5 | 300 |"))
    assert "| 2/4 (50 %) | route enumeration settings" in line and "| not run |" in line
    write_rows(root / "paper-validation", [dict(r, suite="paper-validation")
                                           for r in setting_rows(5, 5, [82] * 5, open_={0}, seed0=200)])
    text = write_reference(root, tmp_path / "out", suites=SUITES).read_text()
    assert "has not been run" not in text and "(seeds 200..204) that chose nothing" in text
    line = next(x for x in text.splitlines() if x.startswith("| K=5 N=5 | 300 |"))
    assert line.endswith("| 2/4 (50 %) | route enumeration settings; 30 s primal calls; node listings "
                         "(seeds 104, 108) | 4/5 (80 %) | 2 / 2 |")
    assert "| K=4 N=5 | 300 | – | enumeration's LP stall" in text and "no rows yet" in text
    csv = pd.read_csv(tmp_path / "out" / "paper_validation.csv").set_index("setting")
    assert csv.loc["K=5 N=5", "validation_proven"] == 4


def top_rows() -> list[dict]:
    """bp on TOP files: a proof equal to the published optimum, a wrong proof, a bound below the
    published optimum, a plan above a best known value, a proof of a best-known-only file, and an
    honest open file."""
    spec = [  # instance, status, objective, bound, reference, best_known
        ("p4.2.a", "optimal", 200.0, 200.0, 200.0, None),
        ("p4.2.b", "optimal", 190.0, 190.0, 195.0, None),      # wrong "optimal": a conflict
        ("p5.2.a", "time_limit", 300.0, 305.0, 310.0, None),   # bound below the optimum: a conflict
        ("p5.3.a", "time_limit", 410.0, 450.0, None, 400.0),   # plan above best known: news
        ("p6.2.a", "optimal", 500.0, 500.0, None, 500.0),      # proof of a best-known-only value: not news
        ("p7.2.a", "time_limit", 90.0, 100.0, 95.0, None),     # open: certified gap 10 %
    ]
    rows = []
    for name, status, obj, bound, ref, bk in spec:
        r = row(name, "bp", status, obj, bound, K=None, N=None, M=None, reference=ref, best_known=bk)
        rows.append({**r, "kind": "top", "suite": "top-4-7", "time_limit": 600})
    return rows


def test_top_sets_flag_conflicts_and_news(tmp_path):
    """Conflicts are flagged, a plan above a best known value is news, a proof of a best-known-only value apart."""
    files = file_table(pd.DataFrame(top_rows()))
    assert files.loc["p4.2.a", "proven_equal"] and not files.loc["p4.2.b", "proven_equal"]
    assert "disagree" in files.loc["p4.2.b", "conflict"]
    assert "below published optimum" in files.loc["p5.2.a", "conflict"]
    assert files.loc["p4.2.a", "conflict"] == "" and files.loc["p7.2.a", "conflict"] == ""
    assert "new best known 410" in files.loc["p5.3.a", "news"] and files.loc["p6.2.a", "proof_of_best_known"]
    assert files.loc["p6.2.a", "news"] == ""
    assert files.loc["p7.2.a", "certified_gap"] == pytest.approx(0.1)
    st = set_table(files).set_index("set")
    counts = ["files", "published_optima", "bp_proven", "proven_equal_published", "conflicts"]
    assert st.loc[4, counts].tolist() == [2, 2, 2, 1, 1]
    assert st.loc[5, ["best_known_only", "conflicts", "news", "unproven"]].tolist() == [1, 1, 1, 2]
    assert st.loc[6, ["proofs_of_best_known", "news"]].tolist() == [1, 0]
    assert st.loc[7, "certified_gap_max"] == pytest.approx(0.1)
    text = "\n".join(top_sets_section(pd.DataFrame(top_rows()), tmp_path))
    assert "**CONFLICTS (2 files)" in text and "**p4.2.b:" in text and "**p5.2.a:" in text
    news, proofs = text.split("News:")[1].split("Proofs new to this project's table")
    assert "- p5.3.a: new best known 410 (published 400)" in news and "p6.2.a" not in news
    assert "bp proves the optimum of 1 file that" in proofs and "1 of them equal that value" in proofs
    assert "most set 4-7 instances solved to optimality" in proofs and "- set 6 (1): p6.2.a 500" in proofs
    assert "p7.2.a 10.0 %" in text and (tmp_path / "top_4_7_files.csv").exists()
    # counts print as counts, also in a set without an open file (its gap columns are NaN)
    set4 = next(line for line in text.splitlines() if line.startswith("| 4 |"))
    assert set4.startswith("| 4 | 2 | 2 (0) | 2 (100.0 %) | 1 | 0 |")
    assert set4.endswith("| 0 | – / – | **1** | 0 |")


def test_top_sets_in_the_reference_report(tmp_path):
    """The reference report gets the TOP 4-7 section and its CSVs from top-4-7 rows."""
    root = tmp_path / "root"
    write_rows(root / "top-4-7", top_rows())
    text = write_reference(root, tmp_path / "out", suites=SUITES).read_text()
    assert "bp on the larger TOP sets" in text and "CONFLICTS" in text
    assert (tmp_path / "out" / "top_4_7_sets.csv").stat().st_size > 0


def test_decomposition_section_appears_when_its_rows_exist(tmp_path, monkeypatch, synthetic_rows):
    """The decomposition section, its figure and CSVs appear once its rows exist, the methods in their looks."""
    from sarcover.reports.style import look

    ticks = {}
    savefig = matplotlib.figure.Figure.savefig

    def record(fig, path, *args, **kwargs):  # the method names under the bars carry each method's look
        for ax in fig.axes:
            ticks.update({t.get_text(): matplotlib.colors.to_hex(t.get_color()) for t in ax.get_xticklabels()})
        return savefig(fig, path, *args, **kwargs)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", record)

    root = tmp_path / "root"
    text = write_reference(root, tmp_path / "out", suites=SUITES).read_text()
    assert "Where the gap comes from" not in text  # no rows, no section
    rows = root / "decomposition" / "rows.jsonl"
    rows.parent.mkdir(parents=True)
    rows.write_text("".join(json.dumps(r) + "\n" for r in synthetic_rows(3.0)))
    text = write_reference(root, tmp_path / "out", suites=SUITES).read_text()
    assert "## Where the gap comes from: clustering loss against routing loss" in text
    assert "![gap decomposition](decomposition.png)" in text and "upper bounds" in text
    assert "### M=20 K=3 N=5" in text and "ADPC's clustering loses less than DPC's" in text
    for name in ("decomposition.png", "decomposition_summary.csv", "decomposition_verdicts.csv"):
        assert (tmp_path / "out" / name).stat().st_size > 0
    assert set(ticks) == {"adpc-pso", "dpc-pso", "kmeans-pso", "oracle-pso"}
    assert all(color == look(m).color for m, color in ticks.items())


def test_reproduce_runs_paper_opt_then_decomposition_then_top_4_7(tmp_path, monkeypatch):
    """The steps: paper-opt, then the decomposition of its chosen settings, then top-4-7 (bp only),
    paper-validation (bp only) and scale;
    the decomposition step takes only the settings it names, and is skipped without paper-opt."""
    from sarcover.benchmarks import decomposition, reproduce

    assert STEPS.index("paper-opt") + 1 == STEPS.index(DECOMPOSITION) < STEPS.index("top-4-7")
    assert EXACT_ONLY["top-4-7"] == ["bp"] and {"paper-opt", "top-4-7"} <= set(SUITES)
    assert EXACT_ONLY["paper-validation"] == ["bp"] and {"paper-validation", "scale"} <= set(STEPS)
    assert reproduce.decompose_step(tmp_path) == 0  # no paper-opt results: nothing to do

    class Case:
        def __init__(self, k, n):
            self.meta = {"K": k, "N": n}

    seen = {}
    monkeypatch.setattr(decomposition, "cases_from_results",
                        lambda src: [Case(k, n) for k in (2, 3, 6) for n in (2, 5)])
    monkeypatch.setattr(decomposition, "decompose",
                        lambda cases, out, **kw: seen.update(cases=cases, out=out) or [1, 2])
    write_rows(tmp_path / "paper-opt", [])
    assert reproduce.decompose_step(tmp_path, quiet=True) == 2
    assert {(c.meta["K"], c.meta["N"]) for c in seen["cases"]} == {(3, 2), (3, 5), (6, 5)}
    assert set(DECOMPOSE_SETTINGS) >= {(3, 2), (3, 5), (6, 5)}
    assert seen["out"] == tmp_path / "decomposition" / "rows.jsonl"
    assert [s.x for s in SWEEPS] == ["N", "K"]


def test_reproduce_resumes_from_committed_rows(tmp_path, capsys):
    """--resume-from copies each step's stored rows into a results root that has none for it (never
    over rows already there), so the committed top-4-7 rows give the report's TOP 4-7 section."""
    from pathlib import Path

    from sarcover.benchmarks import reproduce

    committed = Path(reproduce.__file__).resolve().parents[1] / "reports" / "reference" / "rows"
    assert (committed / "top-4-7" / "results.jsonl").is_file()
    root, out = tmp_path / "results", tmp_path / "out"
    assert reproduce.main(["--results", str(root), "--out", str(out), "--report-only", "--quiet",
                           "--resume-from", str(committed)]) == 0
    stored = (root / "top-4-7" / "results.jsonl").read_text()
    assert stored == (committed / "top-4-7" / "results.jsonl").read_text() and stored.count("\n") == 192
    assert "## bp on the larger TOP sets" in (out / "README.md").read_text()
    assert not reproduce.seed_step(committed, root, "paper-n")  # nothing stored for it
    # a step the results root already has rows for is left as it is
    other = tmp_path / "other"
    write_rows(other / "top-4-7", [json.loads(line) for line in stored.splitlines()[:10]])
    assert not reproduce.seed_step(committed, other, "top-4-7")
    assert (other / "top-4-7" / "results.jsonl").read_text().count("\n") == 10
    capsys.readouterr()
    with pytest.raises(SystemExit) as exc:
        reproduce.main(["--resume-from", str(tmp_path / "missing"), "--report-only"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--resume-from" in err and "missing" in err


def test_reproduce_stops_on_sigterm_and_names_a_bad_resume(tmp_path, monkeypatch, capsys):
    """SIGTERM (a batch scheduler's stop) ends the reference run like Ctrl-C: exit 130 and one line
    saying the same command resumes; a stored run that does not fit the suite is a one-line error
    (exit 2), not a traceback. The previous SIGTERM handler is back afterwards."""
    import os
    import signal
    import time

    from sarcover.benchmarks import harness, reproduce
    from sarcover.benchmarks.errors import HarnessError

    def terminated(suite, out_dir, **kw):
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(10)  # the handler raises KeyboardInterrupt here
        raise AssertionError("SIGTERM did not stop the run")

    before = signal.getsignal(signal.SIGTERM)
    monkeypatch.setattr(harness, "run_suite", terminated)
    args = ["--results", str(tmp_path / "r"), "--out", str(tmp_path / "o"), "--quiet", "--runs", "1"]
    assert reproduce.main(args) == 130
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "interrupted" in err and "resumes" in err
    assert signal.getsignal(signal.SIGTERM) is before
    assert not (tmp_path / "o" / "README.md").exists()  # no report from a stopped run

    def refused(suite, out_dir, **kw):
        raise HarnessError(f"{out_dir}: stored jobs ran with\nanother time limit")

    monkeypatch.setattr(harness, "run_suite", refused)
    assert reproduce.main(args) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith("python -m sarcover.benchmarks.reproduce: error:")
    assert "another time limit" in err
