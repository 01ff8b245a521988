"""The result row: one JSON object per run, the one definition its writer and its readers share.

The benchmark harness writes one row per job to ``RESULTS_DIR/results.jsonl`` (appending and
flushing it to the operating system as each job finishes, so a killed run, even by SIGKILL,
loses only the jobs in flight; ``sarcover bench --resume`` skips the jobs whose ``key`` is
stored). ``sarcover solve --json`` prints the outcome part of a row. The reports read rows
through :func:`read_rows` (pandas reads a clean file natively too:
``pd.read_json(path, lines=True)``).

Row fields (``schema`` 2; :data:`FIELDS` lists them):

- identity: ``key`` (``instance|method|seed``), ``suite``, ``instance``, ``method``, ``params`` (the
  method's resolved parameters; absent from rows written before it was added), ``exact``,
  ``seed`` (method seed), ``run`` (index within the setting and method), ``source`` (how to rebuild
  the instance: generator parameters or file path), ``kind`` (``sar``/``top``), ``M``, ``K``, ``N``,
  ``instance_seed`` (random sets), ``n_nodes``, ``n_groups``, ``n_vehicles``, ``reference``
  (the proven optimum published for a benchmark file, or null), ``best_known`` (the best value
  published for a file whose optimum is not proven, a lower bound on it, or null);
- outcome: ``termination`` (why the run stopped: optimal, infeasible, time_limit, completed,
  error), ``solution`` (what it found: optimal, feasible, none), ``status`` (the one word that
  combines both, see :class:`~sarcover.formulations.result.Status`), ``objective`` (the
  verifier's), ``bound``, ``coverage``, ``covered``, ``routes``, ``energy`` (per route),
  ``energy_used`` (sum), ``e_max``, ``valid`` (verifier verdict), ``reason``, ``info``;
- cost: ``runtime_s`` (the method's), ``wall_s`` (the job's, instance build and verification
  included), ``cpu_s`` (the CPU time of the job's thread over the same span: what a loaded machine
  does not inflate; it misses threads a method starts itself, and is null in rows of a killed job
  and in rows written before it was added), ``time_limit``, ``threads`` (what the method reported
  using, or null), ``workers`` (jobs run in parallel);
- provenance: ``host``, ``platform``, ``cpu_count``, ``versions`` (package versions; ``sarcover``'s
  with its git commit, ``0.1.0+g1a2b3c4d[.dirty]``, when it ran from a checkout), ``pid``,
  ``finished_at`` (UTC ISO time).

Schema 1 rows (written before ``termination`` and ``solution`` existed) are read and upgraded
(:func:`upgrade_row`); rows of any other schema are skipped and counted.
"""

from __future__ import annotations

import json
from pathlib import Path

from sarcover.formulations.errors import SarcoverError
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.result import VerifiedResult, split_status

SCHEMA_VERSION = 2
RESULTS_FILE = "results.jsonl"

IDENTITY = ("schema", "key", "suite", "instance", "method", "params", "exact", "seed", "run", "source", "kind",
            "M", "K",
            "N", "instance_seed", "n_nodes", "n_groups", "n_vehicles", "reference", "best_known")
OUTCOME = ("termination", "solution", "status", "objective", "bound", "coverage", "covered", "routes", "energy",
           "energy_used", "e_max", "valid", "reason", "info")
COST = ("runtime_s", "wall_s", "cpu_s", "time_limit", "threads", "workers")
PROVENANCE = ("host", "platform", "cpu_count", "versions", "pid", "finished_at")
FIELDS = IDENTITY + OUTCOME + COST + PROVENANCE


class ResultsError(SarcoverError):
    """A results directory that cannot be read."""


def outcome(run: VerifiedResult, instance: TOPInstance) -> dict:
    """The outcome part of a row (and the ``solve --json`` object): what the run found, as the
    verifier counted it, plus its runtime."""
    report = run.report
    total = instance.total_prize
    energy = report.energy if report is not None else None
    return {
        "instance": instance.name,
        "method": run.method,
        "termination": str(run.termination),
        "solution": str(run.solution),
        "status": str(run.status),
        "objective": run.objective,
        "bound": run.bound,
        "coverage": (run.objective / total if total > 0 else 0.0) if run.objective is not None else None,
        "covered": report.covered if run.valid else None,
        "routes": [list(r) for r in run.plan.routes] if run.plan is not None else None,
        "energy": energy,
        "energy_used": float(sum(energy)) if energy is not None else None,
        "e_max": instance.budget,
        "runtime_s": run.runtime_s,
        "valid": run.valid,
        "reason": run.reason,
        "info": {k: v for k, v in run.info.items() if k != "traceback"},
    }


def upgrade_row(row: dict) -> dict:
    """A schema 1 row as a schema 2 row: ``termination`` and ``solution`` from its ``status``
    (a ``time_limit`` row has a plan exactly when it has an objective)."""
    termination, solution = split_status(row["status"], row.get("objective") is not None)
    return {**row, "schema": SCHEMA_VERSION, "termination": str(termination), "solution": str(solution)}


def results_path(directory: str | Path) -> Path:
    return Path(directory) / RESULTS_FILE


def read_rows(directory: str | Path) -> tuple[list[dict], dict[str, int]]:
    """Rows of the current schema (schema 1 rows upgraded), plus counts of what was skipped and why.

    Skipped: ``partial`` (a line that is not a JSON object, e.g. the half-written last line of a
    killed run), ``old_schema`` (an unknown schema version), ``duplicate`` (a key seen before;
    the first row wins).
    """
    path = results_path(directory)
    if not Path(directory).is_dir():
        raise ResultsError(f"{directory}: no such results directory")
    if not path.is_file():
        raise ResultsError(f"{directory}: no {RESULTS_FILE} here (run `sarcover bench -o {directory}` first)")
    rows, seen = [], set()
    skipped = {"partial": 0, "old_schema": 0, "duplicate": 0}
    with path.open("rb") as fh:
        for raw in fh:
            if not raw.strip():
                continue
            try:
                row = json.loads(raw)
            except (ValueError, UnicodeDecodeError):
                skipped["partial"] += 1
                continue
            if not isinstance(row, dict) or "key" not in row:
                skipped["partial"] += 1
                continue
            if row.get("schema") == 1 and "status" in row:
                try:
                    row = upgrade_row(row)
                except ValueError:
                    skipped["partial"] += 1
                    continue
            if row.get("schema") != SCHEMA_VERSION:
                skipped["old_schema"] += 1
                continue
            if row["key"] in seen:
                skipped["duplicate"] += 1
                continue
            seen.add(row["key"])
            rows.append(row)
    return rows, skipped


def drop_torn_tail(path: str | Path) -> bool:
    """Cut a half-written last line (a row in flight when its writer was killed) off a JSON Lines
    file, so the next row appended starts a line of its own; True when there was one."""
    path = Path(path)
    if not path.is_file():
        return False
    with path.open("rb+") as fh:
        data = fh.read()
        if not data or data.endswith(b"\n"):
            return False
        fh.truncate(data.rfind(b"\n") + 1)
    return True


def read_decomposition(path: str | Path) -> list[dict]:
    """The rows of a decomposition file (:mod:`sarcover.benchmarks.decomposition` writes one JSON
    object per instance, method and seed; the reports read them); a half-written line is skipped."""
    path = Path(path)
    if not path.is_file():
        return []
    rows = []
    for line in path.read_text().splitlines():
        try:
            row = json.loads(line)
        except ValueError:
            continue
        if isinstance(row, dict) and "instance" in row and "method" in row:
            rows.append(row)
    return rows
