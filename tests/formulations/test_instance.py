"""The instance's derived matrices."""

import numpy as np
import pytest

from sarcover.formulations.instance import TOPInstance


@pytest.mark.parametrize("same_depot", [True, False])
def test_distance_matrix_equals_the_broadcast_formula(same_depot):
    """The cdist distances equal, bit for bit, those of the broadcast formula they replace."""
    rng = np.random.default_rng(5)
    coords = rng.uniform(-2000.0, 2000.0, size=(300, 2))
    start = rng.uniform(-10.0, 10.0, size=2)
    end = start if same_depot else rng.uniform(-10.0, 10.0, size=2)
    inst = TOPInstance(coords=coords, prizes=np.ones(300), start=start, end=end, budget=5000.0, n_vehicles=3)
    pts = np.vstack([start, coords, end])
    diff = pts[:, None, :] - pts[None, :, :]
    np.testing.assert_array_equal(inst.distance_matrix(), np.sqrt((diff**2).sum(axis=-1)))
    assert inst.distance_matrix().shape == (302, 302) and not inst.distance_matrix().flags.writeable
