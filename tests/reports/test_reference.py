"""The reference report end to end on a tiny run of the paper suites."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from sarcover.benchmarks.harness import run_suite
from sarcover.benchmarks.reproduce import SUITES
from sarcover.benchmarks.suite import load_suite
from sarcover.reports.reference import write_reference


@pytest.fixture(scope="module")
def tiny_root(tmp_path_factory):
    root = tmp_path_factory.mktemp("ref")
    for name in ("paper-n", "paper-k"):
        run_suite(load_suite(name, runs=1), root / name, workers=2, progress=False)
    return root


def test_reference_report_written_with_claims(tiny_root, tmp_path):
    """Figures, tables and every claim section come out of one run of paper-n and paper-k."""
    readme = write_reference(tiny_root, tmp_path / "out", suites=SUITES)
    text = readme.read_text()
    for heading in ("ADPC-PSO has the best coverage", "Coverage rises with N and falls with K",
                    "ADPC-PSO degrades least", "Runtime ordering", "paper Table I", "Example routes"):
        assert heading in text
    for name in ("coverage_vs_N.png", "coverage_vs_K.png", "table1_runtime.csv", "example_routes.png"):
        assert (tmp_path / "out" / name).stat().st_size > 0


def test_reference_report_counts_runs(tiny_root, tmp_path):
    """The coverage tables hold one row per method and setting with the stored number of runs."""
    import pandas as pd

    write_reference(tiny_root, tmp_path / "out", suites=SUITES)
    tab = pd.read_csv(tmp_path / "out" / "coverage_vs_N.csv")
    assert set(tab["N"]) == {2, 3, 4, 5, 6}
    assert (tab["runs"] == 1).all() and tab["mean"].between(0, 1).all()


def test_top_table_checks_against_published_optima():
    """Per set and method: proven only when optimal AND equal to the published value; wrong optima,
    bounds below and plans above the published optimum are counted, never hidden."""
    import pandas as pd

    from sarcover.reports.reference import top_table

    rows = [  # instance, method, status, objective, bound, reference, runtime
        ("p1.2.a", "milp", "optimal", 10.0, 10.0, 10.0, 1.0),
        ("p1.2.b", "milp", "optimal", 15.0, 15.0, 20.0, 2.0),      # wrong "optimal"
        ("p1.3.c", "milp", "time_limit", 30.0, 35.0, 40.0, 60.0),  # bound below the optimum (so is 15 < 20)
        ("p2.2.a", "milp", "time_limit", 50.0, 55.0, 50.0, 60.0),  # honest open instance
        ("p2.2.b", "greedy", "feasible", 40.0, None, 50.0, 0.01),  # heuristics are left out
    ]
    df = pd.DataFrame(rows, columns=["instance", "method", "status", "objective", "bound", "reference", "runtime_s"])
    df["exact"] = df["method"] != "greedy"
    t = top_table(df).set_index("set")
    assert list(t["method"]) == ["milp", "milp"]
    assert t.loc[1, "files"] == 3 and t.loc[1, "proven"] == 1 and t.loc[1, "wrong_optimal"] == 1
    assert t.loc[1, "bound_below_optimum"] == 2 and t.loc[1, "median_s_proven"] == 1.0
    assert t.loc[2, "proven"] == 0 and abs(t.loc[2, "bound_gap_unproven"] - 0.1) < 1e-12


def test_long_bp_rows_join_the_paper_scale_gaps(tmp_path):
    """paper-gaps-long's bp rows (other time limit, same instance ids) join paper-gaps as their
    own method row, and their bounds count for the instances' gaps."""
    import pandas as pd

    root = tmp_path / "root"
    common = 'methods = {m}\ntime_limit = 5\n[[instances]]\nM = 5\nK = 2\nN = 2\nruns = 2\n'
    for name, methods in (("paper-gaps", '["greedy", "bp"]'), ("paper-gaps-long", '["bp"]')):
        f = tmp_path / f"{name}.toml"
        f.write_text(f'name = "{name}"\n' + common.format(m=methods))
        run_suite(load_suite(str(f)), root / name, workers=1, progress=False)
    text = write_reference(root, tmp_path / "out", suites=SUITES).read_text()
    assert "paper-gaps-long" in text and "bp-300s" in text
    runs = pd.read_csv(tmp_path / "out" / "runs_paper_gaps.csv")
    assert set(runs["method"]) == {"greedy", "bp", "bp-300s"}
    assert len(runs) == 6 and runs["instance"].nunique() == 2
    long = runs[runs["method"] == "bp-300s"].set_index("instance")
    best = runs.groupby("instance")["best_bound"].first()
    assert (best <= long["bound"] + 1e-9).all()  # the best bound includes the long rows' bounds


def test_claims_count_wilcoxon_comparisons_holm_corrected():
    """Of 8 comparisons, a clear advantage is significant, a weak one (p < 0.05 alone) not after Holm, none not."""
    # the weak one: adpc-pso ahead on 6 of 30 instances, tied on the rest; its t interval excludes 0
    import pandas as pd

    from sarcover.reports.reference import PAPER, _paired_best, _significance

    rows = []
    for n in (2, 3):
        for i in range(30):
            for m in PAPER:
                cov = 0.5
                if m == "adpc-pso":
                    cov += 1 / 60 if n == 2 else 0.0
                elif m == "kmeans-pso" and n == 3:
                    cov -= 1 / 60 if i < 6 else 0.0
                else:
                    cov += 1 / 60 if n == 2 and m != "dpc-pso" else 0.0
                rows.append({"instance": f"i{n}-{i}", "method": m, "N": n, "cov0": cov})
    paired = _significance(_paired_best(pd.DataFrame(rows), "N")).set_index(["N", "vs"])
    assert len(paired) == 8 and paired["significant"].sum() == 1
    assert paired.loc[(2, "dpc-pso"), "significant"] and paired.loc[(2, "dpc-pso"), "diff"] > 0
    weak = paired.loc[(3, "kmeans-pso")]
    assert weak["p_wilcoxon"] < 0.05 < weak["p_holm"] and weak["diff"] - weak["ci95"] > 0
    assert (paired.drop([(2, "dpc-pso"), (3, "kmeans-pso")])["p_wilcoxon"] == 1.0).all()


ROWS = Path(__file__).resolve().parents[2] / "reports" / "reference" / "rows"  # the committed raw rows


def _empty_sections(text: str) -> list[str]:
    """Headings with nothing under them before the next heading of the same or a higher level."""
    lines = [ln for ln in text.splitlines() if ln.strip()]
    empty = []
    for i, line in enumerate(lines):
        if line.startswith("#"):
            level = len(line) - len(line.lstrip("#"))
            nxt = lines[i + 1] if i + 1 < len(lines) else "#"
            if nxt.startswith("#") and len(nxt) - len(nxt.lstrip("#")) <= level:
                empty.append(line)
    return empty


def test_reference_of_top_rows_only_has_no_paper_sections(tmp_path):
    """From top-4-7 rows alone: the TOP section and run log, no paper section, no heading without content."""
    shutil.copytree(ROWS / "top-4-7", tmp_path / "root" / "top-4-7")
    text = write_reference(tmp_path / "root", tmp_path / "out", suites=SUITES).read_text()
    assert text.startswith("# Reference report: exact solvers on the TOP benchmark")
    assert "## bp on the larger TOP sets" in text and "## How it was run" in text
    for absent in ("paper preset", "The paper's claims", "Optimality gaps", "Coverage = ", "Example routes"):
        assert absent not in text
    assert _empty_sections(text) == []


def test_reference_of_sar_rows_only_has_no_top_sections(tmp_path):
    """From exact-small rows alone: preset and gaps, no claims or TOP sections, no heading without content."""
    shutil.copytree(ROWS / "exact-small", tmp_path / "root" / "exact-small")
    text = write_reference(tmp_path / "root", tmp_path / "out", suites=SUITES).read_text()
    assert text.startswith("# Reference report: the paper reproduced")
    assert "## The paper preset" in text and "### exact-small: gap to the proven optimum" in text
    for absent in ("The paper's claims", "TOP benchmark", "TOP sets", "Paper scale"):
        assert absent not in text
    assert _empty_sections(text) == []


@pytest.mark.parametrize("step, present, absent", [
    ("top-4-7", ["## Per method", "## Time to optimality against size"], ["Coverage against", "Runtime per setting"]),
    ("exact-small", ["## Coverage against K", "## Runtime per setting"], ["NEW BEST KNOWN"]),
])
def test_gap_report_writes_the_sections_its_rows_fill(tmp_path, step, present, absent):
    """sarcover report has SAR coverage and runtime sections only on SAR rows, and no heading without content."""
    from sarcover.reports.report import write_report

    shutil.copytree(ROWS / step, tmp_path / "res")
    write_report(tmp_path / "res", tmp_path / "out")
    text = (tmp_path / "out" / "report.md").read_text()
    assert all(p in text for p in present) and not any(a in text for a in absent)
    assert _empty_sections(text) == []
