"""Gap over time (reports/convergence.py): step functions, primal integral, times to a mean gap."""

import numpy as np
import pandas as pd
import pytest

from sarcover.reports.convergence import (
    convergence_table,
    first_time,
    primal_integral,
    proven_optima,
    runs_table,
    step_points,
    write_convergence,
)


def row(method, history, objective, *, instance="i1", status="feasible", runtime=None, cpu=None, share=(1.0, 1.0),
        K=3, limit=10.0, stop="time_limit"):
    """A result row as the harness writes it, with only the fields the report reads."""
    info = {"history": history, "stop_reason": stop}
    if cpu is not None:
        info["history_cpu"] = cpu
    return {"instance": instance, "method": method, "seed": 0, "status": status, "objective": objective,
            "runtime_s": runtime if runtime is not None else (history[-1][0] if history else 0.0),
            "time_limit": limit, "cpu_s": share[0], "wall_s": share[1], "info": info, "M": 20, "K": K, "N": 5,
            "exact": method == "bp"}


def test_step_function_by_hand():
    """Incumbents 5 at 1 s and 8 at 3 s against an optimum of 10: gap 1, then 0.5, then 0.2."""
    t, g = step_points(row("x", [[1.0, 5.0, None], [3.0, 8.0, None]], 8.0), 10.0)
    assert t.tolist() == [0.0, 1.0, 3.0] and g.tolist() == pytest.approx([1.0, 0.5, 0.2])


def test_primal_integral_by_hand():
    """Over [0, 10]: 1 s at gap 1, 2 s at 0.5, 7 s at 0.2 make 3.4 s."""
    t, g = step_points(row("x", [[1.0, 5.0, None], [3.0, 8.0, None]], 8.0), 10.0)
    assert primal_integral(t, g, 10.0) == pytest.approx(3.4)
    assert primal_integral(t, g, 2.0) == pytest.approx(1.5)  # the limit cuts the last step


@pytest.mark.parametrize("history, objective, status", [
    ([[0.5, None, None]], None, "no_plan"),  # no plan found
    ([], None, "error"),  # a crashed or killed job
    ([[0.5, 9.0, None]], 9.0, "error"),  # a plan the verifier rejected counts as none
])
def test_without_a_plan_the_gap_is_one_throughout(history, objective, status):
    """No plan (none found, a crash, a rejected plan): gap 100 % over the whole limit."""
    t, g = step_points(row("x", history, objective, status=status), 10.0)
    assert g.tolist() == [1.0] and primal_integral(t, g, 10.0) == pytest.approx(10.0)


def test_final_objective_closes_a_history_that_ends_lower():
    """A row whose history ends below its verified objective gets the objective at its runtime."""
    t, g = step_points(row("x", [[1.0, 5.0, None]], 10.0, runtime=4.0), 10.0)
    assert t.tolist() == [0.0, 1.0, 4.0] and g[-1] == 0.0


def test_cpu_clock_from_history_cpu_or_the_job_share():
    """The CPU clock uses history_cpu where recorded, else wall times scaled by cpu_s / wall_s."""
    rec = row("x", [[2.0, 5.0, None], [4.0, 10.0, None]], 10.0, cpu=[1.0, 1.5])
    assert step_points(rec, 10.0, "cpu")[0].tolist() == [0.0, 1.0, 1.5]
    est = row("bp", [[2.0, 5.0, None], [4.0, 10.0, None]], 10.0, share=(2.5, 10.0))
    assert step_points(est, 10.0, "cpu")[0].tolist() == pytest.approx([0.0, 0.5, 1.0])


def test_first_time_to_a_mean_gap():
    """Two instances reaching the optimum at 2 s and 4 s: the mean gap is 0 from 4 s on, at most
    50 % from 2 s on, and 5 % is never reached by a 3 s limit."""
    rows = pd.DataFrame([row("x", [[2.0, 10.0, None]], 10.0, instance="a"),
                         row("x", [[4.0, 10.0, None]], 10.0, instance="b")])
    tab = convergence_table(runs_table(rows, pd.Series({"a": 10.0, "b": 10.0})))
    r = tab.iloc[0]
    assert r["t_gap0_wall_s"] == 4.0 and r["t_gap5_wall_s"] == 4.0
    assert r["gap_at_1s"] == 1.0 and r["gap_at_10s"] == 0.0
    assert r["primal_integral_wall_s"] == pytest.approx(3.0)  # (2 + 4) / 2
    assert np.isnan(first_time(np.array([0.0, 4.0]), np.array([1.0, 0.0]), 0.05, 3.0))


def test_proven_optima_disagreeing_is_an_error():
    """Two 'optimal' rows with different objectives on one instance make the gaps meaningless."""
    a = pd.DataFrame([{"instance": "i", "status": "optimal", "objective": 10.0},
                      {"instance": "i", "status": "optimal", "objective": 11.0}])
    with pytest.raises(ValueError, match="disagree"):
        proven_optima(a)


def test_write_convergence_end_to_end(tmp_path):
    """Figures per setting, the CSVs, the best method at each time, and the instance without a
    proven optimum named as left out."""
    rows = pd.DataFrame([
        row("greedy", [[0.005, 8.0, None]], 8.0, instance="a"),
        row("pyvrp", [[0.05, 9.0, None], [2.0, 10.0, None]], 10.0, instance="a"),
        row("bp", [[0.2, 9.0, 12.0], [5.0, 10.0, 10.0]], 10.0, instance="a", status="optimal"),
        row("greedy", [[0.005, 7.0, None]], 7.0, instance="open"),
        row("greedy", [[0.005, 20.0, None]], 20.0, instance="c", K=6),
        row("bp", [[1.0, 20.0, 20.0]], 20.0, instance="c", K=6, status="optimal"),
    ])
    text = write_convergence(rows, [], tmp_path)
    for name in ("anytime_m20_k3_n5.png", "anytime_m20_k6_n5.png", "anytime_table.csv", "anytime_curves.csv",
                 "anytime_runs.csv"):
        assert (tmp_path / name).stat().st_size > 0
    assert "Left out (no proven optimum): open." in text
    assert "0.01 s: greedy (20.0 %)" in text and "10 s: pyvrp, bp (0.0 %)" in text
    tab = pd.read_csv(tmp_path / "anytime_table.csv")
    k3 = tab[tab["setting"] == "M=20 K=3 N=5"].set_index("method")
    assert k3.loc["pyvrp", "t_gap0_wall_s"] == 2.0 and k3.loc["bp", "t_gap0_wall_s"] == 5.0


def test_files_without_a_grid_form_one_setting(tmp_path):
    """Rows of TOP files (no M, K, N) are one setting named by their kind."""
    rows = pd.DataFrame([{**row("bp", [[1.0, 5.0, 5.0]], 5.0, status="optimal"), "M": None, "K": None, "N": None,
                          "kind": "top"}])
    text = write_convergence(rows, [], tmp_path)
    assert "### top (1 instances with a proven optimum)" in text and (tmp_path / "anytime_top.png").exists()


def test_cpu_clock_is_not_extrapolated_past_the_cpu_a_cut_run_received():
    """A run the wall-clock limit cut after 1.5 CPU seconds leaves its method's CPU-clock gap at
    10 s unmeasured; a run that ended on its iteration limit counts at every later time."""
    cut = row("x", [[2.0, 9.0, None], [10.0, 9.0, None]], 9.0, cpu=[0.5, 1.5], instance="a", share=(1.5, 10.0))
    own = row("y", [[0.2, 9.0, None]], 9.0, cpu=[0.1], instance="a", stop="iteration_limit")
    tab = convergence_table(runs_table(pd.DataFrame([cut, own]), pd.Series({"a": 10.0}))).set_index("method")
    assert tab.loc["x", "cpu_covered_s"] == 1.5 and np.isnan(tab.loc["x", "gap_at_10s_cpu"])
    assert tab.loc["x", "gap_at_1s_cpu"] == pytest.approx(0.1) and tab.loc["x", "gap_at_10s"] == pytest.approx(0.1)
    assert tab.loc["y", "cpu_covered_s"] == 10.0 and tab.loc["y", "gap_at_10s_cpu"] == pytest.approx(0.1)


def test_a_killed_job_is_measured_to_its_runtime_at_its_methods_cpu_share():
    """A job killed past its limit (no info, no cpu_s) has no plan throughout, and its CPU curve
    counts up to its wall runtime times the CPU share of its method's other jobs."""
    ok = row("x", [[4.0, 10.0, None]], 10.0, cpu=[1.0], instance="a", share=(2.5, 10.0), runtime=10.0)
    killed = {**row("x", [], None, instance="b", status="time_limit", runtime=17.0), "info": {},
              "cpu_s": float("nan"), "termination": "time_limit"}
    runs = runs_table(pd.DataFrame([ok, killed]), pd.Series({"a": 10.0, "b": 10.0}))
    dead = runs.set_index("instance").loc["b"]
    assert dead["gaps"].tolist() == [1.0] and dead["cpu_covered"] == pytest.approx(17.0 * 0.25)


def test_suite_report_gains_the_section_when_heuristics_carry_histories(tmp_path):
    """`sarcover report` on rows whose heuristics record histories writes anytime_report.md and
    links it; rows from before histories (no heuristic history) get no such section."""
    import json

    from sarcover.benchmarks.cli import main

    out = tmp_path / "res"
    suite = tmp_path / "s.toml"
    suite.write_text('methods = ["greedy", "adpc-pso", "milp"]\ntime_limit = 20\n[[instances]]\nM = 4\nK = 2\nN = 2\n'
                     'runs = 2\nseed = 5\n')
    assert main(["bench", str(suite), "-o", str(out), "--workers", "1", "--quiet"]) == 0
    assert main(["report", str(out)]) == 0
    rep = out / "report"
    assert "anytime_report.md" in (rep / "report.md").read_text() and (rep / "anytime_table.csv").exists()
    rows = [json.loads(line) for line in (out / "results.jsonl").read_text().splitlines()]
    for r in rows:
        if not r["exact"]:
            r["info"].pop("history", None)
    (out / "results.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    (rep / "anytime_report.md").unlink()
    assert main(["report", str(out)]) == 0
    assert not (rep / "anytime_report.md").exists()
