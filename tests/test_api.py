"""The public API on `sarcover`: the README's example runs verbatim, and each name does what it says."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

import sarcover

ROOT = Path(__file__).resolve().parents[1]


def readme_example() -> str:
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## Python API"):]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_readme_example_runs_verbatim(tmp_path):
    """The README's Python API example runs as written, in a fresh process and folder."""
    out = subprocess.run([sys.executable, "-c", readme_example()], cwd=tmp_path, capture_output=True,
                         text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    lines = out.stdout.splitlines()
    assert lines[0].startswith("['greedy', 'adpc-pso'")
    assert any(line.startswith("bp ") and " optimal " in line for line in lines)
    assert "optimal optimal True" in lines
    assert (tmp_path / "results" / "api-demo" / "results.jsonl").is_file()
    assert (tmp_path / "results" / "api-demo" / "plan.png").stat().st_size > 0


def test_all_names_exist_and_are_documented():
    """Every name in __all__ is importable from sarcover and has a docstring."""
    for name in sarcover.__all__:
        obj = getattr(sarcover, name)
        assert (obj.__doc__ or "").strip(), name


def test_solve_takes_sar_or_top_and_verifies():
    """solve converts a SAR instance itself; the objective is the verifier's prize of the plan."""
    inst = sarcover.generate(4, 2, 2, seed=1)
    run = sarcover.solve(inst, "greedy")
    report = sarcover.verify(sarcover.to_top(inst), run.plan)
    assert run.valid and report.valid and run.objective == report.prize
    assert sarcover.solve(sarcover.to_top(inst), "greedy").objective == run.objective


def test_unknown_method_and_bad_instance_raise_one_line_errors(tmp_path):
    """Mistakes of the caller raise a SarcoverError naming the problem."""
    from sarcover.formulations.errors import SarcoverError

    with pytest.raises(SarcoverError, match="unknown method 'nope'"):
        sarcover.solve(sarcover.generate(2, 2, 1), "nope")
    with pytest.raises(SarcoverError, match="no such file"):
        sarcover.read_instance(tmp_path / "missing.json")


def test_read_instance_by_benchmark_name_and_path():
    """A shipped benchmark name reads the same instance as its file."""
    from sarcover.benchmarks.catalog import TOP_DIR

    by_name = sarcover.read_instance("p2.3.g")
    by_path = sarcover.read_instance(TOP_DIR / "p2.3.g.txt")
    assert by_name.n_nodes == by_path.n_nodes == 19 and by_name.budget == by_path.budget
