"""Regression table: every stored optimal value is proven again by the sources that confirmed it
(a fast subset by default, all rows with -m slow)."""

import pytest

from sarcover.benchmarks import regression
from sarcover.benchmarks.regression import SOURCES, TABLE, load_spec, published_optimum, read_table
from sarcover.benchmarks.registry import METHODS, run_method
from sarcover.formulations.result import Status

ROWS = read_table(TABLE)


def _methods(row: dict) -> list[str]:
    return [m for m in row["confirmed_by"].split("+") if m != "published"]


def _seconds(row: dict, method: str) -> float:
    return float(row.get(f"{method}_s") or "inf")


# Default run: per method, the rows it confirmed fastest (at most 1 s each when the table was made).
FAST = [(r, m) for m in ("milp", "cpsat", "bp")
        for r in [r for r in ROWS if m in _methods(r) and _seconds(r, m) <= 1.0][:6]]


def _reproduce(row: dict, method: str, time_limit: float):
    if method not in METHODS:
        pytest.skip(f"method {method!r} is not registered")
    res = run_method(method, load_spec(row["spec"]), time_limit=time_limit)
    if row["status"] == "infeasible":
        assert res.status == Status.INFEASIBLE, f"{row['spec']}: {res.status} {res.reason}"
    else:
        assert res.status == Status.OPTIMAL, f"{row['spec']}: {res.status} {res.reason}"
        assert res.objective == pytest.approx(float(row["value"]), abs=1e-9)


def test_table_covers_every_source_and_family():
    """Rows from the TOP benchmark (sets 1-3 and 4-7) and from generated instances, confirmed by
    each kind of source."""
    specs = [r["spec"] for r in ROWS]
    assert any(s.startswith("top:p1.") or s.startswith("top:p2.") for s in specs)
    assert any(s.split(".")[0] in ("top:p4", "top:p5", "top:p6", "top:p7") for s in specs)
    assert any(s.startswith("gen:") for s in specs)
    assert {r["confirmed_by"] for r in ROWS} <= set(SOURCES)
    assert {"milp+cpsat", "bp+published"} <= {r["confirmed_by"] for r in ROWS}
    # The paper's view counts K = 4-6 (fewer targets than its M = 20 so a compact model proves
    # them), each confirmed by bp and a compact model.
    views = {int(r["spec"][4:].split(",")[1]) for r in ROWS
             if r["spec"].startswith("gen:") and r["confirmed_by"] in ("bp+milp", "bp+cpsat")}
    assert {4, 5, 6} <= views
    assert len(FAST) >= 10


def test_published_rows_match_the_shipped_optimum():
    """A bp+published row holds exactly the value the literature publishes as proven."""
    rows = [r for r in ROWS if r["confirmed_by"] == "bp+published"]
    assert rows
    for r in rows:
        assert float(r["value"]) == published_optimum(r["spec"]), r["spec"]


def test_every_row_is_unique_and_well_formed():
    """One row per spec; an optimal row has a value, an infeasible one none; each source has a time."""
    specs = [r["spec"] for r in ROWS]
    assert len(specs) == len(set(specs))
    for r in ROWS:
        assert r["status"] in ("optimal", "infeasible")
        assert (r["value"] == "") == (r["status"] == "infeasible")
        for m in _methods(r):
            assert _seconds(r, m) < float("inf"), (r["spec"], m)


def test_confirm_refuses_what_the_sources_do_not_agree_on(monkeypatch, capsys):
    """confirm keeps a row only when both sources give the same proof, and calls a bp proof that
    differs from a published optimum a conflict."""
    from sarcover.formulations.plan import Plan
    from sarcover.formulations.result import Result, Termination, verified_result
    row = next(r for r in ROWS if r["confirmed_by"] == "bp+published")
    inst = load_spec(row["spec"])
    true = run_method("bp", inst, time_limit=30.0)
    assert true.status == Status.OPTIMAL

    def lying_bp(name, instance, **kw):
        res = Result(name, Termination.OPTIMAL, Plan.of([]), bound=0.0)  # the empty plan "proven"
        return verified_result(instance, res, method=name)

    monkeypatch.setattr("sarcover.benchmarks.registry.run_method", lying_bp)
    assert regression.confirm(row["spec"], 5.0, "bp+published") is None
    assert "CONFLICT" in capsys.readouterr().err
    with pytest.raises(ValueError, match="unknown confirmation"):
        regression.confirm(row["spec"], 5.0, "greedy+milp")


def test_add_replaces_rows_of_the_same_spec(tmp_path, monkeypatch):
    """--add keeps one row per spec: the new confirmation replaces the old."""
    path = tmp_path / "t.csv"
    regression.write_table(ROWS[:3], path)
    spec = ROWS[0]["spec"]
    monkeypatch.setattr(regression, "confirm", lambda s, t, by: {
        "spec": s, "status": "optimal", "value": "7", "confirmed_by": by, "bp_s": "0.1"})
    regression.add([spec], "bp+milp", 1.0, path)
    rows = read_table(path)
    assert [r["spec"] for r in rows].count(spec) == 1 and len(rows) == 3
    assert next(r for r in rows if r["spec"] == spec)["confirmed_by"] == "bp+milp"


def test_cli_default_output_is_under_the_current_directory_not_the_package(tmp_path, monkeypatch, capsys):
    """Without --out the shipped table plus the new row go to ./results/regression/, the package's table untouched."""
    shipped = TABLE.read_bytes()
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(regression, "confirm", lambda s, t, by: {
        "spec": s, "status": "optimal", "value": "7", "confirmed_by": by, "bp_s": "0.1"})
    assert regression.main(["--add", "top:p2.2.a", "--by", "bp+milp"]) == 0
    out = tmp_path / "results" / "regression" / "optimal_values.csv"
    assert f"written to {regression.OUT}" in capsys.readouterr().out
    rows = read_table(out)
    assert TABLE.read_bytes() == shipped
    assert {r["spec"] for r in rows} == {r["spec"] for r in ROWS} | {"top:p2.2.a"}
    assert next(r for r in rows if r["spec"] == "top:p2.2.a")["value"] == "7"


def test_cli_bad_spec_is_one_line(capsys):
    """A bad spec is one line on stderr and exit code 2."""
    assert regression.main(["--add", "nonsense:1", "--out", "/dev/null"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nonsense:1" in err[0]


@pytest.mark.parametrize("row,method", FAST, ids=[f"{r['spec']}-{m}" for r, m in FAST])
def test_fast_rows_reproduced(row, method):
    """A fast row: the method proves the stored optimum (or infeasibility) again."""
    _reproduce(row, method, 30.0)


SLOW = [(r, m) for r in ROWS for m in _methods(r)]


@pytest.mark.slow
@pytest.mark.parametrize("row,method", SLOW, ids=[f"{r['spec']}-{m}" for r, m in SLOW])
def test_all_rows_reproduced(row, method):
    """Every row of the table, each of its methods, with twice its recorded time (at least 120 s)."""
    _reproduce(row, method, max(120.0, 2 * _seconds(row, method)))
