"""The gap decomposition (benchmarks/decomposition.py): exact sums, signs, verified plans, resume."""

from __future__ import annotations

import io
import json

import numpy as np
import pytest

from sarcover.benchmarks.decomposition import (
    METHODS, Case, cases_from_instances, cases_from_results, decompose, plan_clusters, read_decomposition, row_key,
)
from sarcover.formulations.clustered import inside, solve_clustered
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import to_top
from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Status
from sarcover.formulations.verify import verify
from sarcover.heuristics.pipeline import cluster_stage, route_clusters

from brute_force import brute_clustered


@pytest.fixture(scope="module")
def small_rows(tmp_path_factory):
    """Every method (paper and oracle) on three small instances, OPT from milp."""
    instances = [(f"m8k2n3s{s}", to_top(generate(8, 2, 3, seed=s)), {"M": 8, "K": 2, "N": 3, "instance_seed": s})
                 for s in range(3)]
    cases = cases_from_instances(instances, opt_method="milp", time_limit=120, stream=None)
    assert len(cases) == 3 and all(c.opt_proven for c in cases)
    path = tmp_path_factory.mktemp("decomp") / "rows.jsonl"
    return cases, decompose(cases, path, seeds=(0, 1), stream=None), path


def test_losses_sum_to_the_gap_and_have_their_signs(small_rows):
    """Verified plans; clustering + cross-cluster + routing = OPT - objective exactly, each part with its sign."""
    cases, rows, _ = small_rows
    by_name = {c.name: c for c in cases}
    assert len(rows) == 3 * len(METHODS) * 2
    moved = 0
    for r in rows:
        case = by_name[r["instance"]]
        assert r["status"] == "feasible", r
        rep = verify(case.instance, Plan.of(r["routes"]))
        assert rep.valid and rep.prize == r["objective"]
        assert r["opt_c_proven"] and r["opt_cp_proven"]
        total = r["clustering_loss"] + r["cross_cluster"] + r["routing_loss"]
        assert total == r["gap"] == r["opt"] - r["objective"]
        assert r["opt_c"] <= r["opt"] + 1e-9
        assert r["clustering_loss"] >= 0 and r["routing_loss"] >= 0
        if r["n_outside"] == 0:
            assert r["cross_cluster"] == 0 and r["routing_loss"] == r["opt_c"] - r["objective"]
            assert inside(Plan.of(r["routes"]), r["clusters"])
        else:
            moved += 1
            assert inside(Plan.of(r["routes"]), r["clusters_plan"])
        if r["clusterer"] == "oracle":
            assert r["opt_c"] == r["opt"] and r["clustering_loss"] == 0
    assert moved > 0  # the refill does move viewpoints across clusters here: that branch is tested


def test_opt_c_of_the_rows_is_brute_force(small_rows):
    """The rows' OPT|C for the paper clusterings equals brute force on the smallest instance."""
    cases, rows, _ = small_rows
    inst = to_top(generate(3, 2, 2, seed=0, e_max=3500.0))
    for clusterer in ("adpc", "dpc", "kmeans"):
        clusters = cluster_stage(inst, clusterer, seed=0)
        res = solve_clustered(inst, clusters, time_limit=60)
        expected = brute_clustered(inst, clusters)
        if expected is None:
            assert res.status == Status.INFEASIBLE
        else:
            assert res.status == Status.OPTIMAL and verify(inst, res.plan).prize == expected
    clusters = {(r["instance"], r["clusterer"]): r["opt_c"] for r in rows if r["clusterer"] != "oracle"}
    for r in rows:  # one clustering per clusterer (ADPC and DPC are deterministic; KMeans per seed)
        if r["clusterer"] in ("adpc", "dpc"):
            assert r["opt_c"] == clusters[(r["instance"], r["clusterer"])]


def test_plans_inside_their_clusters_lose_nothing_to_cross_moves():
    """A plan made inside its clusters (no refill) never beats OPT|C by brute force: routing loss >= 0."""
    checked = 0
    for s in range(6):
        inst = to_top(generate(3, 2, 2, seed=s, e_max=4000.0))
        for clusterer in ("adpc", "dpc", "kmeans"):
            clusters = cluster_stage(inst, clusterer, seed=s)
            res = route_clusters(inst, clusters, "pso", seed=s, reinsert=False)
            if res.status != Status.FEASIBLE or res.info["n_outside_cluster"]:
                continue
            rep = verify(inst, res.plan)
            assert rep.valid and inside(res.plan, clusters)
            assert rep.prize <= brute_clustered(inst, clusters) + 1e-9
            checked += 1
    assert checked >= 5


def test_plan_clusters_moves_visited_nodes_to_their_route():
    """plan_clusters moves each visited node to its route's cluster and leaves unvisited nodes where they were."""
    clusters = [[0, 1, 2], [3, 4], []]
    plan = Plan.of([[0, 3], [4], [1]])
    assert plan_clusters(clusters, plan) == [[0, 2, 3], [4], [1]]
    assert inside(plan, plan_clusters(clusters, plan))


def test_resume_skips_stored_rows_and_survives_a_torn_line(small_rows, tmp_path):
    """A rerun adds nothing; after a torn last line it completes the missing rows, reusing stored OPT|C values."""
    cases, rows, path = small_rows
    again = decompose(cases, path, seeds=(0, 1), stream=None)
    assert len(again) == len(rows)
    lines = path.read_text().splitlines()
    torn = tmp_path / "torn.jsonl"
    torn.write_text("\n".join(lines[:-2]) + "\n" + lines[-2][: len(lines[-2]) // 2])
    assert len(read_decomposition(torn)) == len(lines) - 2
    err = io.StringIO()
    done = decompose(cases, torn, seeds=(0, 1), stream=err)
    keys = [row_key(r) for r in done]
    assert len(set(keys)) == len(rows) and "2/2" in err.getvalue()
    last = {row_key(r): r for r in rows}
    for r in done[-2:]:
        assert r["opt_c"] == last[row_key(r)]["opt_c"]
    assert len(read_decomposition(torn)) == len(rows)  # the torn line is cut, the rows after it are whole


def test_workers_give_the_rows_of_the_serial_run(small_rows, tmp_path):
    """Two pool workers write the rows of one worker (order aside), with progress; a rerun adds nothing."""
    cases, rows, _ = small_rows
    err = io.StringIO()
    par = decompose(cases, tmp_path / "par.jsonl", seeds=(0, 1), workers=2, stream=err)
    fields = ("objective", "opt_c", "opt_cp", "gap", "clustering_loss", "cross_cluster", "routing_loss", "clusters")
    assert ({row_key(r): [r.get(f) for f in fields] for r in par}
            == {row_key(r): [r.get(f) for f in fields] for r in rows})
    assert len(read_decomposition(tmp_path / "par.jsonl")) == len(rows)
    assert f"{len(rows)}/{len(rows)}" in err.getvalue()
    assert len(decompose(cases, tmp_path / "par.jsonl", seeds=(0, 1), workers=2, stream=None)) == len(rows)
    with pytest.raises(ValueError, match="workers"):
        decompose(cases, tmp_path / "x.jsonl", workers=0, stream=None)


def test_cases_from_a_results_directory(tmp_path):
    """Cases from a harness results folder: OPT from the proven exact row, the oracle's plan verified."""
    from sarcover.benchmarks.harness import run_suite
    from sarcover.benchmarks.suite import load_suite

    suite = tmp_path / "tiny.toml"
    suite.write_text('name = "tiny"\nmethods = ["milp", "adpc-pso"]\ntime_limit = 60\n'
                     '[[instances]]\nM = 5\nK = 2\nN = 2\nruns = 2\n')
    run_suite(load_suite(str(suite)), tmp_path / "res", workers=1, progress=False)
    cases = cases_from_results(tmp_path / "res")
    assert len(cases) == 2
    stored = [json.loads(line) for line in (tmp_path / "res" / "results.jsonl").read_text().splitlines()]
    for case in cases:
        milp = next(r for r in stored if r["instance"] == case.name and r["method"] == "milp")
        assert case.opt_proven and case.opt == milp["objective"] and case.opt_source == "milp"
        assert verify(case.instance, case.opt_plan).prize == case.opt
        assert case.meta["M"] == 5 and case.meta["K"] == 2
    rows = decompose(cases, tmp_path / "d.jsonl", methods=("adpc-pso", "oracle-pso"), stream=None)
    assert all(r["clustering_loss"] + r["cross_cluster"] + r["routing_loss"] == r["gap"] for r in rows)


def test_unproven_opt_is_flagged(tmp_path):
    """With a bound for OPT (not proven) the row says so; the sum still holds."""
    inst = to_top(generate(6, 2, 2, seed=1))
    cases = cases_from_instances([("x", inst, {})], opt_method="milp", time_limit=60, stream=None)
    case = cases[0]
    loose = Case("x", inst, case.opt + 3, False, case.opt_plan, "bound")
    rows = decompose([loose], tmp_path / "rows.jsonl", methods=("adpc-pso",), stream=None)
    r = rows[0]
    assert r["opt_proven"] is False
    assert r["clustering_loss"] + r["cross_cluster"] + r["routing_loss"] == r["gap"]
    assert np.isclose(r["clustering_loss"], case.opt + 3 - r["opt_c"])



def test_a_killed_or_hung_worker_becomes_a_row_and_the_run_goes_on(tmp_path, monkeypatch):
    """A decomposition job whose process dies or hangs becomes an error or time_limit row; the others still run."""
    import os
    import signal
    import time

    import sarcover.benchmarks.decomposition as decomposition

    inst = to_top(generate(5, 2, 2, seed=4))
    cases = cases_from_instances([("a", inst, {}), ("b", inst, {})], opt_method="milp", time_limit=60, stream=None)
    real = decomposition._run_paper_method

    def faulty(method, instance, seed, time_limit):  # forked workers inherit it
        if method == "dpc-pso" and seed == 0:
            os.kill(os.getpid(), signal.SIGKILL)
        if method == "dpc-pso" and seed == 1:
            time.sleep(600)
        return real(method, instance, seed, time_limit)

    monkeypatch.setattr(decomposition, "_run_paper_method", faulty)
    path = tmp_path / "rows.jsonl"
    t0 = time.monotonic()
    rows = decompose(cases, path, methods=("adpc-pso", "dpc-pso"), seeds=(0, 1), time_limit=1.0,
                     clustered_time_limit=1.0, grace=1.0, workers=2, stream=None)
    assert time.monotonic() - t0 < 60
    by = {row_key(r): r for r in rows}
    assert len(rows) == len(by) == 8
    for name in ("a", "b"):
        assert by[f"{name}|dpc-pso|0"]["status"] == "error" and "SIGKILL" in by[f"{name}|dpc-pso|0"]["reason"]
        assert by[f"{name}|dpc-pso|1"]["status"] == "time_limit" and "killed after" in by[f"{name}|dpc-pso|1"]["reason"]
        for s in (0, 1):
            r = by[f"{name}|adpc-pso|{s}"]
            assert r["clustering_loss"] + r["cross_cluster"] + r["routing_loss"] == r["gap"]
    assert len(decompose(cases, path, methods=("adpc-pso", "dpc-pso"), seeds=(0, 1), stream=None)) == 8
