"""Shared fixtures of the report tests: synthetic decomposition rows."""

from __future__ import annotations

import numpy as np
import pytest


def synthetic_rows(adpc_shift: float, n: int = 12, K: int = 3) -> list[dict]:
    """Rows of adpc-pso, dpc-pso, kmeans-pso and oracle-pso on n instances; ADPC's OPT|C is
    ``adpc_shift`` viewpoints above the others' (plus noise); every row's parts sum to its gap."""
    rng = np.random.default_rng(0)
    rows = []
    for i in range(n):
        opt = 50.0 + i
        base = opt - 6 - rng.integers(0, 3)
        for method, opt_c in (("adpc-pso", base + adpc_shift + rng.integers(0, 2)), ("dpc-pso", base),
                              ("kmeans-pso", base), ("oracle-pso", opt)):
            cross = -1.0 if method == "dpc-pso" else 0.0
            opt_cp = opt_c - cross
            obj = opt_cp - 2.0
            rows.append({"instance": f"i{i}", "M": 20, "K": K, "N": 5, "method": method, "seed": 0, "opt": opt,
                         "opt_proven": i != 0, "opt_c": opt_c, "opt_c_proven": True, "opt_c_s": 1.0,
                         "opt_cp": opt_cp, "objective": obj, "gap": opt - obj, "clustering_loss": opt - opt_c,
                         "cross_cluster": cross, "routing_loss": opt_cp - obj, "n_outside": int(cross != 0),
                         "clustering_infeasible": False, "clusters": [[0], [1]], "routes": [[0], [1]]})
    return rows


@pytest.fixture(name="synthetic_rows")
def synthetic_rows_fixture():
    """:func:`synthetic_rows`, for the tests of the decomposition section and of the reference report."""
    return synthetic_rows
