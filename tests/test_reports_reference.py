"""The reference report (issue 7) end to end on a tiny run of the paper suites."""

from __future__ import annotations

import pytest

from benchmarks.harness import run_suite
from benchmarks.suite import load_suite
from reports.reference import write_reference


@pytest.fixture(scope="module")
def tiny_root(tmp_path_factory):
    root = tmp_path_factory.mktemp("ref")
    for name in ("paper-n", "paper-k"):
        run_suite(load_suite(name, runs=1), root / name, workers=2, progress=False)
    return root


def test_reference_report_written_with_claims(tiny_root, tmp_path):
    """Figures, tables and every claim section come out of one run of paper-n and paper-k."""
    readme = write_reference(tiny_root, tmp_path / "out")
    text = readme.read_text()
    for heading in ("ADPC-PSO has the best coverage", "Coverage rises with N and falls with K",
                    "ADPC-PSO degrades least", "Runtime ordering", "paper Table I", "Example routes"):
        assert heading in text
    for name in ("coverage_vs_N.png", "coverage_vs_K.png", "table1_runtime.csv", "example_routes.png"):
        assert (tmp_path / "out" / name).stat().st_size > 0


def test_reference_report_counts_runs(tiny_root, tmp_path):
    """The coverage tables hold one row per method and setting with the stored number of runs."""
    import pandas as pd

    write_reference(tiny_root, tmp_path / "out")
    tab = pd.read_csv(tmp_path / "out" / "coverage_vs_N.csv")
    assert set(tab["N"]) == {2, 3, 4, 5, 6}
    assert (tab["runs"] == 1).all() and tab["mean"].between(0, 1).all()
