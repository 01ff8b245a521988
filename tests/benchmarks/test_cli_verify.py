"""`sarcover verify` and `solve --plan-out`: valid plans with their gap, invalid plans line by
line (exit 1), bad input in one line (exit 2)."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from sarcover.benchmarks.cli import main
from sarcover.formulations.generate import generate
from sarcover.formulations.io import load_instance, save_json
from sarcover.formulations.plan import Plan
from sarcover.formulations.planfile import save_plan
from sarcover.formulations.verify import verify


def run(*args):
    """The real console entry point in a subprocess (no traceback may leak)."""
    return subprocess.run([sys.executable, "-m", "sarcover.benchmarks.cli", *args], capture_output=True, text=True)


@pytest.fixture
def inst_file(tmp_path):
    """The regression table's row gen:6,2,2,1501,4159.5 (proven optimum 7) as a JSON instance."""
    path = tmp_path / "i.json"
    save_json(generate(6, 2, 2, 1501, e_max=4159.5), path)
    return path


def test_solve_plan_out_round_trips_through_verify(tmp_path, inst_file, capsys):
    """solve --plan-out writes the plan solve reports; verify finds it valid with the same
    objective and its gap to the regression table's optimum 7."""
    plan = tmp_path / "p.json"
    assert main(["solve", str(inst_file), "--json", "--plan-out", str(plan)]) == 0
    solved = json.loads(capsys.readouterr().out)
    data = json.loads(plan.read_text())
    assert data["routes"] == solved["routes"] and data["method"] == "greedy"
    assert main(["verify", str(inst_file), str(plan), "--json"]) == 0
    check = json.loads(capsys.readouterr().out)
    assert check["valid"] and check["objective"] == solved["objective"]
    assert check["known"]["kind"] == "optimum" and check["known"]["value"] == 7.0
    assert check["gap"] == pytest.approx((7 - solved["objective"]) / 7)
    assert main(["verify", str(inst_file), str(plan)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith(f"valid plan for sar-m6-k2-n2-s1501: objective {solved['objective']:g}, coverage")
    assert lines[1].startswith(f"gap {100 * check['gap']:.2f}% to the proven optimum 7 (regression table")


def test_shipped_top_benchmark_by_name_gets_its_published_optimum(tmp_path, capsys):
    """A plan on p2.3.g (by name) is measured against its proven optimum 145."""
    plan = tmp_path / "p.json"
    assert main(["solve", "p2.3.g", "--plan-out", str(plan)]) == 0
    capsys.readouterr()
    assert main(["verify", "p2.3.g", str(plan), "--json"]) == 0
    check = json.loads(capsys.readouterr().out)
    assert check["known"]["value"] == 145.0 and check["gap"] == pytest.approx((145 - check["objective"]) / 145)


def test_an_instance_nothing_is_known_of_says_so(tmp_path, capsys):
    """An instance outside every table: valid, and the second line says no optimum is known."""
    path = tmp_path / "i.json"
    save_json(generate(5, 2, 2, 77), path)
    save_plan(Plan.of([[0, 2], [4, 6, 8]]), tmp_path / "p.json", "sar-m5-k2-n2-s77")
    assert main(["verify", str(path), str(tmp_path / "p.json")]) == 0
    assert capsys.readouterr().out.splitlines()[1].startswith("no optimum or bound known")


@pytest.fixture
def loose_file(tmp_path):
    """The same targets with E_max 9000, so that any two routes of three targets fit."""
    path = tmp_path / "loose.json"
    save_json(generate(6, 2, 2, 1501, e_max=9000.0), path)
    return path


def plan_on(tmp_path, routes):
    path = tmp_path / "bad.json"
    save_plan(Plan.of(routes), path, "sar-m6-k2-n2-s1501")
    return path


@pytest.mark.parametrize("routes, expected", [
    ([list(range(12))], ["route 0 uses energy"]),                                   # over budget
    ([[0, 2, 4], [6, 8, 10, 0]], ["node 0 visited twice (routes 0 and 1)"]),        # a viewpoint twice
    ([[0, 2, 4], [6, 8]], ["target 5 has no visited viewpoint"]),                   # a target uncovered
    ([[0], [2], [4, 6, 8, 10]], ["3 routes for 2 vehicles"]),                       # a vehicle too many
    ([[0, 0, 2, 4], [6, 8]], ["node 0 visited twice", "target 5 has no visited viewpoint"]),
])
def test_invalid_plans_print_each_violation_on_a_line_and_exit_1(tmp_path, loose_file, capsys, routes, expected):
    """An invalid plan: exit 1, stdout holds exactly the verifier's violations, one per line."""
    plan = plan_on(tmp_path, routes)
    assert main(["verify", str(loose_file), str(plan)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out == verify(load_instance(loose_file), Plan.of(routes)).violations
    assert len(out) == len(expected) and all(line.startswith(e) for line, e in zip(out, expected))


@pytest.mark.parametrize("content, message", [
    (None, "no such file"),
    ("{not json", "not valid JSON"),
    ('{"format": "sarcover-plan", "version": 1, "instance": "sar-m6-k2-n2-s1501", "routes": [[0, 12]]}',
     "field 'routes[0][1]' is 12, not a node id (instance 'sar-m6-k2-n2-s1501' has viewpoints 0..11)"),
    ('{"format": "sarcover-plan", "version": 1, "instance": "sar-m6-k2-n2-s1501", "routes": [[0, -3]]}',
     "field 'routes[0][1]' is -3, not a node id"),
    ('{"format": "sarcover-plan", "version": 1, "instance": "p2.3.g", "routes": [[0]]}',
     "the plan is for instance 'p2.3.g', not 'sar-m6-k2-n2-s1501'"),
])
def test_bad_plan_input_is_one_line_exit_2(tmp_path, inst_file, content, message):
    """A missing or malformed plan file, or ids out of range: one stderr line, exit 2, no output."""
    plan = tmp_path / "p.json"
    if content is not None:
        plan.write_text(content)
    out = run("verify", str(inst_file), str(plan))
    assert out.returncode == 2 and out.stdout == ""
    assert out.stderr.count("\n") == 1 and message in out.stderr and out.stderr.startswith("sarcover: error: ")


def test_bad_instance_and_results_input_is_one_line_exit_2(tmp_path, inst_file):
    """A missing instance file and a --results folder that is not one: one line, exit 2."""
    plan = plan_on(tmp_path, [[0, 2, 4], [6, 8, 10]])
    for args, message in ((["nowhere.json", str(plan)], "nowhere.json: no such file"),
                          ([str(inst_file), str(plan), "--results", str(tmp_path / "none")], "no such results")):
        out = run("verify", *args)
        assert out.returncode == 2 and out.stdout == "" and out.stderr.count("\n") == 1 and message in out.stderr


def test_plan_out_is_checked_before_solving_and_skipped_without_a_plan(tmp_path, capsys):
    """--plan-out into a missing folder is refused before solving; a run without a plan writes none."""
    path = tmp_path / "i.json"
    save_json(generate(4, 2, 2, 1, e_max=100.0), path)  # no viewpoint within reach: infeasible
    assert main(["solve", str(path), "--plan-out", str(tmp_path / "no" / "p.json")]) == 2
    assert "--plan-out: directory" in capsys.readouterr().err
    assert main(["solve", str(path), "--plan-out", str(tmp_path / "p.json")]) == 3
    assert "no plan: nothing written" in capsys.readouterr().err and not (tmp_path / "p.json").exists()


def test_results_folder_gives_the_optimum_a_run_proved(tmp_path, capsys):
    """verify --results DIR: the optimum milp proved in that folder, with the method named."""
    suite = tmp_path / "s.toml"
    suite.write_text('name = "t"\nmethods = ["milp"]\ntime_limit = 20\n\n'
                     '[[instances]]\nM = 4\nK = 2\nN = 2\nruns = 1\nseed = 900\n')
    assert main(["bench", str(suite), "-o", str(tmp_path / "r"), "--workers", "1", "--quiet"]) == 0
    row = json.loads((tmp_path / "r" / "results.jsonl").read_text().splitlines()[0])
    assert row["status"] == "optimal"
    inst = tmp_path / "i.json"
    save_json(generate(4, 2, 2, 900), inst)
    capsys.readouterr()
    save_plan(Plan.of(row["routes"]), tmp_path / "p.json", row["instance"])
    assert main(["verify", str(inst), str(tmp_path / "p.json"), "--results", str(tmp_path / "r"), "--json"]) == 0
    check = json.loads(capsys.readouterr().out)
    assert check["known"] == {"kind": "optimum", "value": row["objective"],
                              "source": f"results {tmp_path / 'r'}, proven by milp"}
    assert check["gap"] == 0.0
    other = tmp_path / "o.json"
    save_json(generate(4, 2, 2, 900, e_max=9000.0), other)  # same name, another E_max: not those runs
    assert main(["verify", str(other), str(tmp_path / "p.json"), "--results", str(tmp_path / "r")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1].startswith("no optimum or bound known")
    assert lines[2].endswith("none of its 1 runs is on this instance")


def test_exit_codes_are_documented_in_help_and_readme(capsys):
    """`verify --help` lists its exit codes 0, 1, 2; the README's exit-code table has the lines of
    `verify` and `report --strict`, and its plan file section the format tag."""
    assert main(["verify", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "0 a valid plan" in text and "1 an invalid plan" in text and "2 bad input" in text
    readme = (Path(__file__).resolve().parents[2] / "README.md").read_text()
    section = readme[readme.index("### Exit codes"):]
    section = section[:section.index("\n## ")]
    assert "| 1 | `verify`: the plan is invalid" in section and "| 1 | `report --strict`: " in section
    assert '"format": "sarcover-plan", "version": 1' in readme
