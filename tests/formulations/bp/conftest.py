"""The bp tests' shared cases (:mod:`bp_cases`) import by name from this folder."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
