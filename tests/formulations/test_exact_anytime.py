"""Anytime histories of the exact methods (info["history"]) and the report's anytime plot."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from sarcover.benchmarks.harness import run_suite
from sarcover.benchmarks.registry import run_method
from sarcover.benchmarks.suite import load_suite
from sarcover.formulations.history import History, thin
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.io import read_top
from sarcover.formulations.result import Status
from sarcover.reports.report import write_report
from sarcover.reports.results import SCHEMA_VERSION

from conftest import TOP_DIR

PUBLISHED = {r["instance"]: (float(r["value"]), r["status"]) for r in csv.DictReader(open(TOP_DIR / "optimal.csv"))}
EPS = 1e-6


def check_history(res, optimum: float) -> list:
    """Times non-decreasing from 0; incumbent <= optimum <= bound at every point; ends at the result."""
    h = res.info["history"]
    json.dumps(h, allow_nan=False)  # plain floats and None: it goes into a JSON Lines row
    assert 1 <= len(h) <= 200
    assert all(len(p) == 3 for p in h)
    times = [p[0] for p in h]
    assert times[0] >= 0 and times == sorted(times) and times[-1] <= res.runtime_s + 1e-3  # times are rounded to 0.1 ms
    for _, inc, bnd in h:
        assert inc is None or inc <= optimum + EPS, h
        assert bnd is None or bnd >= optimum - EPS, h
    incs = [p[1] for p in h[:-1] if p[1] is not None]
    bnds = [p[2] for p in h[:-1] if p[2] is not None]
    assert incs == sorted(incs) and bnds == sorted(bnds, reverse=True)
    assert h[-1][1] == pytest.approx(res.objective) if res.objective is not None else h[-1][1] is None
    assert h[-1][2] == pytest.approx(res.bound) if res.bound is not None else h[-1][2] is None
    return h


@pytest.mark.parametrize("method", ["milp", "cpsat"])
def test_history_on_a_proven_top_instance(method):
    """p2.2.b (published optimum 120): proven fast; the history closes at 120 = objective = bound."""
    opt, status = PUBLISHED["p2.2.b"]
    assert status == "optimal"
    res = run_method(method, read_top(TOP_DIR / "p2.2.b.txt"), time_limit=10)
    assert res.status == Status.OPTIMAL and res.objective == opt
    h = check_history(res, opt)
    assert h[-1][1:] == [opt, opt]


@pytest.mark.parametrize("method", ["milp", "cpsat"])
def test_history_under_a_time_limit_brackets_the_optimum(method):
    """p1.3.n (optimum 190) is not proven in 1.5 s: every recorded bound is still >= 190."""
    opt, status = PUBLISHED["p1.3.n"]
    assert status == "optimal"
    res = run_method(method, read_top(TOP_DIR / "p1.3.n.txt"), time_limit=1.5)
    assert res.status != Status.ERROR, res.reason
    h = check_history(res, opt)
    assert any(p[2] is not None for p in h)


@pytest.mark.parametrize("method", ["milp", "cpsat"])
def test_history_in_prize_units_with_decimal_prizes(method):
    """Prizes 0.25, 0.5, 0.125 on a line, budget 4: optimum 0.75 by hand (cpsat scales prizes by 1000)."""
    inst = TOPInstance(coords=np.array([[1.0, 0.0], [2.0, 0.0], [3.0, 0.0]]), prizes=np.array([0.25, 0.5, 0.125]),
                       start=np.zeros(2), end=np.zeros(2), budget=4.0, n_vehicles=1)
    res = run_method(method, inst, time_limit=5)
    assert res.status == Status.OPTIMAL and res.objective == pytest.approx(0.75)
    check_history(res, 0.75)


def test_history_records_improvements_only_and_thins():
    """A point per improvement (incumbent up or bound down); thinning keeps first and last."""
    h = History()
    assert h.update(incumbent=1.0) and not h.update(incumbent=1.0) and not h.update(incumbent=0.5)
    assert h.update(bound=10.0) and not h.update(bound=11.0) and h.update(incumbent=2.0, bound=9.0)
    assert [p[1:] for p in h.points] == [[1.0, None], [1.0, 10.0], [2.0, 9.0]]
    pts = [[float(i), float(i), None] for i in range(1000)]
    out = thin(pts, 200)
    assert len(out) <= 200 and out[0] == pts[0] and out[-1] == pts[-1]


def _row(instance, method, history, objective, bound, status="time_limit"):
    return {"schema": SCHEMA_VERSION, "key": f"{instance}|{method}|0", "suite": "t", "instance": instance,
            "method": method, "exact": True, "seed": 0, "run": 0, "status": status, "objective": objective,
            "bound": bound, "valid": True, "reference": None, "kind": "top", "n_nodes": 30, "coverage": None,
            "runtime_s": 3.0, "routes": None, "M": None, "K": None, "N": None, "info": {"history": history}}


def test_report_draws_anytime_panels_from_rows(tmp_path):
    """Rows with info.history give anytime.png and anytime.csv; bp's history lacking an end point is closed."""
    rows = [
        _row("a", "milp", [[0.1, None, 12.0], [1.0, 8.0, 11.0], [3.0, 8.0, 11.0]], 8.0, 11.0),
        _row("a", "cpsat", [[0.05, 7.0, 14.0], [2.0, 9.0, 10.0], [3.0, 9.0, 10.0]], 9.0, 10.0),
        _row("a", "bp", [[0.2, None, 10.5], [0.5, 9.0, None]], 9.0, 10.0),
        _row("b", "milp", [[0.1, 5.0, 5.0]], 5.0, 5.0, status="optimal"),
    ]
    (tmp_path / "results.jsonl").write_text("\n".join(json.dumps(r) for r in rows) + "\n")
    out = tmp_path / "rep"
    write_report(tmp_path, out)
    assert (out / "anytime.png").read_bytes()[:4] == b"\x89PNG"
    assert "Bound and incumbent against time" in (out / "report.md").read_text()
    pts = list(csv.DictReader(open(out / "anytime.csv")))
    bp = [p for p in pts if p["instance"] == "a" and p["method"] == "bp"]
    assert [float(bp[-1]["t_s"]), float(bp[-1]["incumbent"]), float(bp[-1]["bound"])] == [3.0, 9.0, 10.0]
    assert {p["instance"] for p in pts} == {"a", "b"}


ANYTIME_SUITE = """
name = "anytime-tiny"
methods = ["milp", "cpsat", "greedy"]
time_limit = 5
[[instances]]
files = ["p2.2.b"]
"""


def test_harness_rows_carry_history_and_report_plots_it(tmp_path):
    """Through the harness: exact rows store info.history in the JSON row; the report plots them."""
    path = tmp_path / "s.toml"
    path.write_text(ANYTIME_SUITE)
    out = tmp_path / "res"
    run_suite(load_suite(str(path)), out, workers=1, progress=False)
    rows = [json.loads(line) for line in (out / "results.jsonl").read_text().splitlines()]
    exact = {r["method"]: r for r in rows if r["exact"]}
    assert set(exact) == {"milp", "cpsat"}
    for r in exact.values():
        assert r["info"]["history"][-1][1] == r["objective"] == 120.0
    rep = tmp_path / "rep"
    write_report(out, rep)
    assert (rep / "anytime.png").stat().st_size > 0
