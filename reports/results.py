"""Stored results as a pandas DataFrame (the row format is :mod:`sarcover.formulations.records`)."""

from __future__ import annotations

from pathlib import Path

from sarcover.formulations.records import SCHEMA_VERSION, ResultsError, read_rows, results_path


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
