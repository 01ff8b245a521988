"""Shared helpers of the benchmark tests: suite files written in a test's folder, stored rows."""

from pathlib import Path

from sarcover.formulations.records import read_rows

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent

SMALL = """
name = "small"
methods = ["greedy", "cpsat"]
time_limit = 10
[[instances]]
M = 4
K = 2
N = [2, 3]
runs = 2
[[instances]]
files = ["p2.2.b"]
"""


def write_suite(folder, body: str, name: str = "s.toml") -> Path:
    """``body`` written as the suite file ``folder/name``."""
    path = Path(folder) / name
    path.write_text(body)
    return path


def rows_of(directory) -> list[dict]:
    """The rows stored in ``directory``, checking that none was skipped (torn, old, duplicate)."""
    rows, skipped = read_rows(directory)
    assert not any(skipped.values()), skipped
    return rows
