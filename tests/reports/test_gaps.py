"""Gap arithmetic and the careful results reader, on hand-made rows."""

import json

import numpy as np
import pandas as pd
import pytest

from sarcover.reports.gaps import add_gaps, instance_table, method_table
from sarcover.reports.report import write_report
from sarcover.reports.results import SCHEMA_VERSION, ResultsError, load_results, read_rows


def row(instance, method, status, objective, bound=None, exact=False, reference=None, **extra):
    base = {"schema": SCHEMA_VERSION, "key": f"{instance}|{method}|0", "suite": "t", "instance": instance,
            "method": method, "exact": exact, "seed": 0, "run": 0, "status": status, "objective": objective,
            "bound": bound, "valid": objective is not None, "reference": reference, "kind": "top",
            "n_nodes": 10, "coverage": None if objective is None else objective / 20, "runtime_s": 1.0,
            "routes": None, "M": None, "K": None, "N": None}
    base.update(extra)
    return base


def frame(*rows):
    return pd.DataFrame.from_records(rows)


def test_nine_of_proven_ten_is_ten_percent_and_bound_gap_is_separate():
    """9 vs proven 10 -> gap 0.10; on an unproven instance 9 vs bound 12 -> gap_ub 0.25, gap NaN."""
    df = frame(
        row("a", "exact", "optimal", 10.0, 10.0, exact=True),
        row("a", "heur", "feasible", 9.0),
        row("b", "exact", "time_limit", 10.0, 12.0, exact=True),
        row("b", "heur", "feasible", 9.0),
        row("c", "heur", "no_plan", None),
    )
    g = add_gaps(df).set_index(["instance", "method"])
    assert g.loc[("a", "heur"), "gap"] == pytest.approx(0.10)
    assert g.loc[("a", "exact"), "gap"] == 0.0
    assert np.isnan(g.loc[("a", "heur"), "gap_ub"])
    assert g.loc[("b", "heur"), "gap_ub"] == pytest.approx(0.25)
    assert g.loc[("b", "exact"), "gap_ub"] == pytest.approx(1 / 6)
    assert np.isnan(g.loc[("b", "heur"), "gap"])
    m = method_table(add_gaps(df))
    assert m.loc["heur", "gap_mean"] == pytest.approx(0.10) and m.loc["heur", "gap_n"] == 1
    assert m.loc["heur", "gap_ub_mean"] == pytest.approx(0.25)
    assert m.loc["heur", "no_plan"] == 1 and m.loc["heur", "share_optimal"] == 0.0
    assert m.loc["exact", "share_optimal"] == 1.0


def test_a_plan_above_a_best_known_value_is_news_not_a_conflict():
    """A best known value is a lower bound: beating it is reported as news; matching it is not."""
    table = instance_table(frame(row("a", "x", "time_limit", 12.0, 14.0, best_known=11.0),
                                 row("b", "x", "time_limit", 11.0, 14.0, best_known=11.0)))
    assert table.loc["a", "news"] == "new best known 12 (published 11)" and table.loc["a", "conflict"] == ""
    assert table.loc["b", "news"] == "" and np.isnan(table.loc["b", "opt"])


def test_published_optimum_counts_as_proven():
    """A benchmark file's published optimum is the reference even when no method proves it."""
    df = frame(row("p", "heur", "feasible", 45.0, reference=50.0))
    g = add_gaps(df)
    assert g["gap"].iloc[0] == pytest.approx(0.10)


@pytest.mark.parametrize("rows, needle", [
    ((row("a", "x", "optimal", 10.0, 10.0), row("a", "y", "optimal", 11.0, 11.0)), "proven optima disagree"),
    ((row("a", "x", "optimal", 10.0, 10.0), row("a", "h", "feasible", 11.0)), "above proven optimum"),
    ((row("a", "x", "time_limit", 8.0, 9.0), row("a", "h", "feasible", 9.5)), "bound 9 below objective 9.5"),
    ((row("a", "x", "time_limit", 8.0, 9.0, best_known=9.5),), "bound 9 below published best known 9.5"),
    ((row("a", "x", "optimal", 9.0, 9.0, best_known=9.5),), "proven optimum 9 below published best known 9.5"),
])
def test_conflicts_are_flagged(rows, needle):
    """A wrong optimum or bound shows up as a conflict on the instance, never silently."""
    assert needle in instance_table(frame(*rows)).loc["a", "conflict"]


def test_reader_skips_torn_and_old_rows_with_counts(tmp_path):
    """A half-written line, an older schema row and a duplicate key are skipped and counted."""
    good = [row("a", "x", "optimal", 10.0, 10.0), row("a", "h", "feasible", 9.0)]
    old = {**row("a", "z", "feasible", 8.0), "schema": 0}
    lines = [json.dumps(r) for r in good] + [json.dumps(old), json.dumps(good[0]), '{"schema": 1, "ke']
    (tmp_path / "results.jsonl").write_text("\n".join(lines))
    rows, skipped = read_rows(tmp_path)
    assert [r["method"] for r in rows] == ["x", "h"]
    assert skipped == {"partial": 1, "old_schema": 1, "duplicate": 1}
    out = tmp_path / "rep"
    summary = write_report(tmp_path, out)
    assert "skipped 3 bad rows" in summary
    assert "1 partial, 1 old schema, 1 duplicate" in (out / "report.md").read_text()


def test_reader_errors_when_nothing_usable(tmp_path):
    """Only old-schema rows: a clear error naming the count, not an empty report."""
    (tmp_path / "results.jsonl").write_text(json.dumps({**row("a", "z", "feasible", 8.0), "schema": 0}) + "\n")
    with pytest.raises(ResultsError, match="1 old schema"):
        load_results(tmp_path)
    with pytest.raises(ResultsError, match="no results.jsonl"):
        load_results(tmp_path / "nope") if (tmp_path / "nope").mkdir() is None else None
