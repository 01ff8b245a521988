"""Rows of jobs (benchmarks/rows.py): one row per job in the schema's order, never an exception."""

from sarcover.benchmarks.provenance import code_version
from sarcover.benchmarks.registry import get_method
from sarcover.benchmarks.rows import failed_row, run_one
from sarcover.formulations.records import FIELDS

SOURCE = {"type": "generate", "M": 3, "K": 2, "N": 1, "instance_seed": 0, "preset": "paper", "overrides": {},
          "exact": False}


def job(method: str = "greedy", **extra) -> dict:
    return {"key": f"i|{method}|0", "instance": "i", "method": method, "seed": 0, "run": 0, "time_limit": 5.0,
            "grace": 1.0, "source": SOURCE, **extra}


def test_a_row_carries_the_jobs_parameters_and_the_code_version():
    """A row holds the method's resolved parameters (the job's, every default filled in) and the
    commit-labelled code version, in the schema's order."""
    row = run_one(job("adpc-pso", params={"iterations": 3, "population": 5}))
    assert row["status"] in ("feasible", "optimal") and list(row) == list(FIELDS)
    assert row["params"] == get_method("adpc-pso").resolve({"iterations": 3, "population": 5})
    assert row["params"]["iterations"] == 3 and "xi" in row["params"]
    assert row["versions"]["sarcover"] == code_version()
    assert run_one(job())["params"] == {}  # greedy takes none


def test_a_method_name_the_registry_does_not_know_is_an_error_row():
    """An unknown method (also as a variant name) is an error row under the job's name."""
    row = run_one(job("no-such-method[iterations=300]"))
    assert row["status"] == "error" and "unknown method" in row["reason"]
    assert row["method"] == "no-such-method[iterations=300]"


def test_a_killed_jobs_row_says_why_and_how_long():
    """failed_row: the status and reason given, the elapsed time as runtime and wall time, no pid."""
    row = failed_row(job(params={"a": 1}), "time_limit", "killed after 6.0 s", 6.0)
    assert (row["status"], row["termination"], row["solution"]) == ("time_limit", "time_limit", "none")
    assert row["reason"] == "killed after 6.0 s" and row["runtime_s"] == row["wall_s"] == 6.0
    assert row["pid"] is None and row["params"] == {"a": 1} and list(row) == list(FIELDS)
