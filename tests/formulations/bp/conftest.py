"""The bp tests' shared cases (:mod:`bp_cases`) import by name from this folder (appended to the
path, so that ``conftest`` still names tests/conftest.py for the tests that import it)."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent))
