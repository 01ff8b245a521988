"""The decomposition section (reports/decomposition.py): tables, figure, CSVs, verdicts from numbers."""

from __future__ import annotations

import numpy as np
import pandas as pd

from sarcover.reports.decomposition import clustering_verdicts, decomposition_frame, write_decomposition


def test_verdicts_follow_the_numbers(synthetic_rows):
    """ADPC clusterings clearly better -> "less"; no difference -> "no clear difference"."""
    better = clustering_verdicts(decomposition_frame(synthetic_rows(3.0)))
    assert set(better["verdict"]) == {"less"} and (better["diff_pct"] < 0).all()
    same = clustering_verdicts(decomposition_frame(synthetic_rows(0.0) + []))
    # noise of 0 or 1 viewpoint in ADPC's favour, never against: mean difference within [-2, 0] %
    assert (same["diff_pct"] <= 0).all() and (same["diff_pct"] > -2.5).all()
    worse = clustering_verdicts(decomposition_frame(synthetic_rows(-4.0)))
    assert set(worse["verdict"]) == {"more"}


def test_section_files_and_sums(tmp_path, synthetic_rows):
    """The section, figure and CSVs are written; per method the mean parts add up to the mean gap;
    the unproven OPT is flagged in the text; the verdict line is there."""
    rows = synthetic_rows(3.0) + synthetic_rows(0.0, K=6)
    text = write_decomposition(rows, tmp_path)
    for name in ("decomposition.md", "decomposition.png", "decomposition.csv", "decomposition_summary.csv",
                 "decomposition_verdicts.csv"):
        assert (tmp_path / name).stat().st_size > 0
    tab = pd.read_csv(tmp_path / "decomposition_summary.csv")
    parts = tab["clustering_loss"] + tab["cross_cluster"] + tab["routing_loss"]
    assert np.allclose(parts, tab["gap"])
    assert np.allclose(tab["clustering_loss_pct"] + tab["cross_cluster_pct"] + tab["routing_loss_pct"], tab["gap_pct"])
    assert "M=20 K=3 N=5" in text and "M=20 K=6 N=5" in text and "upper bounds" in text
    assert "ADPC's clustering loses less than DPC's" in text and "Over all settings" in text
    assert "only 12 instances" in text
