"""The benchmark instances shipped with sarcover: names, files and published values.

The Chao-Golden-Wasil TOP files live in ``instances/top/`` beside this module, with their
published values in ``optimal.csv`` (columns ``instance,value,status,source``; ``status`` is
``optimal`` for a proven value, ``best_known`` for the best published plan) and their
provenance in ``PROVENANCE.md``. ``optimal.csv`` is kept as copied; where this project showed a
copied value wrong for the file as written, ``corrections.csv`` beside it holds the value that
replaces it, the copied one and the evidence (:func:`corrections`), and :func:`published` answers
with the corrected value. A benchmark name (``p2.3.g``) stands for its file wherever an
instance file is read: suites, ``sarcover solve`` and :func:`sarcover.read_instance`.
"""

from __future__ import annotations

import csv
from pathlib import Path

TOP_DIR = Path(__file__).resolve().parent / "instances" / "top"


def is_benchmark_name(text: str) -> bool:
    """True for a bare name like ``p2.3.g`` (no folder, no file ending), which names a shipped file."""
    return "/" not in text and "\\" not in text and not text.endswith((".txt", ".json"))


def _names(path: Path, *, a_file: bool = False) -> bool:
    """``path.exists()`` (``path.is_file()`` if ``a_file``), False where the name cannot name
    anything (too long for the file system: pathlib raises there instead), so that such a name
    reaches the reader's own error."""
    try:
        return path.is_file() if a_file else path.exists()
    except OSError:
        return False


def benchmark_file(name: str) -> Path | None:
    """The shipped TOP file of benchmark ``name``, or None if there is none."""
    path = TOP_DIR / f"{name}.txt"
    return path if is_benchmark_name(name) and _names(path, a_file=True) else None


def instance_path(name_or_path: str | Path) -> Path:
    """A path as given, or the shipped file of a benchmark name (when no such path exists)."""
    path = Path(name_or_path)
    if not _names(path):
        shipped = benchmark_file(str(name_or_path))
        if shipped is not None:
            return shipped
    return path


_TABLES: dict[Path, dict[str, tuple[float, str]]] = {}


def _rows(table: Path) -> list[dict[str, str]]:
    """The rows of a CSV table (none without the file)."""
    if not table.is_file():
        return []
    with table.open() as fh:
        return list(csv.DictReader(fh))


def _read_values(table: Path) -> dict[str, tuple[float, str]]:
    """instance -> (value, status) of a values table (rows it cannot read are skipped)."""
    values = {}
    for row in _rows(table):
        try:
            values[row["instance"]] = (float(row["value"]), row.get("status") or "optimal")
        except (KeyError, TypeError, ValueError):
            continue
    return values


def published(path: str | Path) -> tuple[float, str] | None:
    """(value, status) known for the file at ``path``: the ``optimal.csv`` beside it, with the
    rows of ``corrections.csv`` (if any) in place of the copied ones."""
    path = Path(path)
    table = path.parent / "optimal.csv"
    if table not in _TABLES:
        _TABLES[table] = {**_read_values(table), **_read_values(path.parent / "corrections.csv")}
    return _TABLES[table].get(path.stem)


def corrections(folder: str | Path = TOP_DIR) -> list[dict[str, str]]:
    """The rows of ``corrections.csv`` in ``folder``: ``instance``, the ``value`` and ``status``
    used here, the copied table's ``copied_value`` and ``copied_status``, and the ``evidence``
    (empty without the file)."""
    return _rows(Path(folder) / "corrections.csv")

