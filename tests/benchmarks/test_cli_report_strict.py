"""`sarcover report --strict`: exit 1 when the report lists a conflict (a wrong optimum)."""

import json
import shutil

import pytest

from sarcover.benchmarks.cli import main


@pytest.fixture(scope="module")
def clean_results(tmp_path_factory):
    """A real results folder: milp and cpsat both prove the optimum of two small instances."""
    root = tmp_path_factory.mktemp("strict")
    suite = root / "s.toml"
    suite.write_text('name = "t"\nmethods = ["milp", "cpsat"]\ntime_limit = 20\n\n'
                     '[[instances]]\nM = 4\nK = 2\nN = 2\nruns = 2\nseed = 910\n')
    assert main(["bench", str(suite), "-o", str(root / "r"), "--workers", "1", "--quiet"]) == 0
    return root / "r"


def with_wrong_proof(clean, folder):
    """A copy of ``clean`` in which cpsat claims a proven optimum one below milp's on one instance,
    with a plan that really is worth that much (a node dropped): two exact methods disagree."""
    shutil.copytree(clean, folder)
    rows = [json.loads(line) for line in (folder / "results.jsonl").read_text().splitlines()]
    row = next(r for r in rows if r["method"] == "cpsat")
    route = next(r for r in row["routes"] if len(r) > 1)
    route.pop()
    row["objective"] -= 1
    row["bound"] = row["objective"]
    (folder / "results.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    return row["instance"]


def test_clean_results_exit_0_with_strict(clean_results, tmp_path, capsys):
    """Every proof agrees: report --strict writes the report and exits 0, nothing on stderr."""
    rows = [json.loads(line) for line in (clean_results / "results.jsonl").read_text().splitlines()]
    assert len(rows) == 4 and all(r["status"] == "optimal" for r in rows)
    assert main(["report", str(clean_results), "-o", str(tmp_path / "rep"), "--strict"]) == 0
    assert capsys.readouterr().err == "" and (tmp_path / "rep" / "report.md").is_file()


def test_a_wrong_optimum_exits_1_naming_the_instance(clean_results, tmp_path, capsys):
    """Two exact methods proving different optima: the report lists the conflict, --strict exits 1
    with the instance and the conflict on stderr; without --strict the report still exits 0."""
    instance = with_wrong_proof(clean_results, tmp_path / "r")
    assert main(["report", str(tmp_path / "r"), "-o", str(tmp_path / "rep")]) == 0
    assert "CONFLICTS on 1 instances" in (tmp_path / "rep" / "report.md").read_text()
    capsys.readouterr()
    assert main(["report", str(tmp_path / "r"), "-o", str(tmp_path / "rep"), "--strict"]) == 1
    captured = capsys.readouterr()
    assert captured.out.startswith("report: ")
    err = captured.err.splitlines()
    assert err[0].startswith(f"conflict on {instance}: proven optima disagree")
    assert err[1] == "report --strict: 1 instance with a conflict (a wrong optimum or bound)" and len(err) == 2
