"""Shared fixtures: tiny instances that can be checked by hand."""

import sys
from pathlib import Path

import numpy as np
import pytest

from sarcover.formulations.instance import TOPInstance

ROOT = Path(__file__).resolve().parents[1]
# the shared helpers (this file, tests/helpers.py) import by name from any test folder
sys.path.insert(0, str(Path(__file__).resolve().parent))
TOP_DIR = ROOT / "benchmarks" / "instances" / "top"


@pytest.fixture
def line_instance() -> TOPInstance:
    """Three nodes on the x-axis at 1, 2, 3; depot at 0; budget 6 fits all on one route."""
    return TOPInstance(
        coords=np.array([[1.0, 0.0], [2.0, 0.0], [3.0, 0.0]]),
        prizes=np.array([1.0, 2.0, 3.0]),
        start=np.zeros(2),
        end=np.zeros(2),
        budget=6.0,
        n_vehicles=1,
    )
