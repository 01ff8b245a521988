"""The decomposition section (reports/decomposition.py): tables, figure, CSVs, verdicts from numbers."""

from __future__ import annotations

import numpy as np
import pandas as pd

from sarcover.reports.decomposition import clustering_verdicts, decomposition_frame, write_decomposition


def synthetic_rows(adpc_shift: float, n: int = 12, K: int = 3) -> list[dict]:
    """Rows of adpc-pso, dpc-pso, kmeans-pso and oracle-pso on n instances; ADPC's OPT|C is
    ``adpc_shift`` viewpoints above the others' (plus noise); every row's parts sum to its gap."""
    rng = np.random.default_rng(0)
    rows = []
    for i in range(n):
        opt = 50.0 + i
        base = opt - 6 - rng.integers(0, 3)
        for method, opt_c in (("adpc-pso", base + adpc_shift + rng.integers(0, 2)), ("dpc-pso", base),
                              ("kmeans-pso", base), ("oracle-pso", opt)):
            cross = -1.0 if method == "dpc-pso" else 0.0
            opt_cp = opt_c - cross
            obj = opt_cp - 2.0
            rows.append({"instance": f"i{i}", "M": 20, "K": K, "N": 5, "method": method, "seed": 0, "opt": opt,
                         "opt_proven": i != 0, "opt_c": opt_c, "opt_c_proven": True, "opt_c_s": 1.0,
                         "opt_cp": opt_cp, "objective": obj, "gap": opt - obj, "clustering_loss": opt - opt_c,
                         "cross_cluster": cross, "routing_loss": opt_cp - obj, "n_outside": int(cross != 0),
                         "clustering_infeasible": False, "clusters": [[0], [1]], "routes": [[0], [1]]})
    return rows


def test_verdicts_follow_the_numbers():
    """ADPC clusterings clearly better -> "less"; no difference -> "no clear difference"."""
    better = clustering_verdicts(decomposition_frame(synthetic_rows(3.0)))
    assert set(better["verdict"]) == {"less"} and (better["diff_pct"] < 0).all()
    same = clustering_verdicts(decomposition_frame(synthetic_rows(0.0) + []))
    # noise of 0 or 1 viewpoint in ADPC's favour, never against: mean difference within [-2, 0] %
    assert (same["diff_pct"] <= 0).all() and (same["diff_pct"] > -2.5).all()
    worse = clustering_verdicts(decomposition_frame(synthetic_rows(-4.0)))
    assert set(worse["verdict"]) == {"more"}


def test_section_files_and_sums(tmp_path):
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
