"""The results store: one JSON object per line in ``RESULTS_DIR/results.jsonl``, one line per job.

The harness appends a row (and flushes it to the operating system) as each job finishes, so a
killed run, even by SIGKILL, loses only the jobs in flight; ``sarcover bench --resume`` skips the
jobs whose ``key`` is already stored. pandas reads a clean file natively
(``pd.read_json(path, lines=True)``); :func:`load_results` is the careful reader: it skips a
half-written line and rows of another ``schema`` version and counts them, never guessing.

Row fields (``schema`` 1):

- identity: ``key`` (``instance|method|seed``), ``suite``, ``instance``, ``method``, ``exact``,
  ``seed`` (method seed), ``run`` (index within the setting and method), ``source`` (how to rebuild
  the instance: generator parameters or file path), ``kind`` (``sar``/``top``), ``M``, ``K``, ``N``,
  ``instance_seed`` (random sets), ``n_nodes``, ``n_groups``, ``n_vehicles``, ``reference``
  (published optimum of a benchmark file, or null);
- outcome: ``status``, ``objective`` (the verifier's), ``bound``, ``coverage``, ``covered``,
  ``routes``, ``energy`` (per route), ``energy_used`` (sum), ``e_max``, ``valid`` (verifier
  verdict), ``reason``, ``info``;
- cost: ``runtime_s`` (the method's), ``wall_s`` (the job's, instance build and verification
  included), ``cpu_s`` (the CPU time of the job's thread over the same span: what a loaded machine
  does not inflate; it misses threads a method starts itself, and is null in rows of a killed job
  and in rows written before it was added), ``time_limit``, ``threads`` (what the method reported
  using, or null), ``workers`` (jobs run in parallel);
- provenance: ``host``, ``platform``, ``cpu_count``, ``versions`` (package versions), ``pid``,
  ``finished_at`` (UTC ISO time).
"""

from __future__ import annotations

import json
from pathlib import Path

from sarcover.formulations.errors import SarcoverError

SCHEMA_VERSION = 1
RESULTS_FILE = "results.jsonl"


class ResultsError(SarcoverError):
    """A results directory that cannot be read."""


def results_path(directory: str | Path) -> Path:
    return Path(directory) / RESULTS_FILE


def read_rows(directory: str | Path) -> tuple[list[dict], dict[str, int]]:
    """Rows of the current schema, plus counts of what was skipped and why.

    Skipped: ``partial`` (a line that is not a JSON object, e.g. the half-written last line of a
    killed run), ``old_schema`` (another schema version), ``duplicate`` (a key seen before; the
    first row wins).
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
            if row.get("schema") != SCHEMA_VERSION:
                skipped["old_schema"] += 1
                continue
            if row["key"] in seen:
                skipped["duplicate"] += 1
                continue
            seen.add(row["key"])
            rows.append(row)
    return rows, skipped


def load_results(directory: str | Path):
    """The results as a pandas DataFrame (one row per job) and the skipped-row counts.

    Raises ResultsError when nothing usable is left, naming what was skipped.
    """
    import pandas as pd

    rows, skipped = read_rows(directory)
    if not rows:
        what = ", ".join(f"{n} {k.replace('_', ' ')}" for k, n in skipped.items() if n) or "the file is empty"
        raise ResultsError(f"{results_path(directory)}: no usable rows of schema {SCHEMA_VERSION} ({what})")
    return pd.DataFrame.from_records(rows), skipped
