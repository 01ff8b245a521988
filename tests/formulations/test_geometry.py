"""Viewpoint geometry against hand-computed views."""

import numpy as np
import pytest

from sarcover.formulations.errors import InstanceError
from sarcover.formulations.geometry import standoff, viewpoints
from sarcover.formulations.instance import SARInstance, to_top


def test_four_views_of_target_on_x_axis():
    """Target (1000, 0), H·cosθ = 100, K = 4 gives (900,0), (1000,-100), (1100,0), (1000,100)."""
    views = viewpoints(np.array([[1000.0, 0.0]]), 4, altitude=100.0, pitch_deg=0.0)
    expected = np.array([[900.0, 0.0], [1000.0, -100.0], [1100.0, 0.0], [1000.0, 100.0]])
    np.testing.assert_allclose(views, expected, atol=1e-9)


def test_first_view_on_base_target_line_at_standoff():
    """The first view lies on the base–target segment, H·cosθ from the target."""
    rng = np.random.default_rng(3)
    targets = rng.uniform(10, 2000, size=(50, 2))
    h, theta = 200.0, 35.0
    views = viewpoints(targets, 3, h, theta).reshape(50, 3, 2)
    first = views[:, 0]
    r = h * np.cos(np.radians(theta))
    np.testing.assert_allclose(np.linalg.norm(first - targets, axis=1), r)
    np.testing.assert_allclose(np.linalg.norm(first, axis=1), np.linalg.norm(targets, axis=1) - r)
    cross = first[:, 0] * targets[:, 1] - first[:, 1] * targets[:, 0]
    np.testing.assert_allclose(cross, 0.0, atol=1e-6)


def test_views_equally_spaced_on_circle():
    """All K views sit on the circle of radius H·cosθ, spaced 360°/K apart."""
    t = np.array([[700.0, 1300.0]])
    for k in range(1, 7):
        v = viewpoints(t, k, 150.0, 20.0) - t
        np.testing.assert_allclose(np.linalg.norm(v, axis=1), standoff(150.0, 20.0))
        ang = np.unwrap(np.arctan2(v[:, 1], v[:, 0]))
        np.testing.assert_allclose(np.diff(ang), 2 * np.pi / k)


def test_target_at_base_is_a_clear_error():
    """A target at (0, 0) has no defined first view."""
    with pytest.raises(InstanceError, match="target 1 lies at the base"):
        viewpoints(np.array([[5.0, 5.0], [0.0, 0.0]]), 2, 10.0, 0.0)


def test_sar_maps_to_top_with_unit_prizes_and_groups():
    """SAR → TOP: unit prizes, one group of K consecutive views per target, depots at the base."""
    sar = SARInstance(np.array([[500.0, 0.0], [0.0, 800.0]]), 3, 2, 100.0, 0.0, 1.0, 10.0, 5000.0)
    top = to_top(sar)
    assert top.n_nodes == 6 and top.kind == "sar"
    assert top.groups == ((0, 1, 2), (3, 4, 5))
    np.testing.assert_array_equal(top.prizes, np.ones(6))
    np.testing.assert_allclose(top.coords[0], [400.0, 0.0])
    assert top.same_depot and top.budget == 5000.0
    cost = top.cost_matrix()
    assert cost[0, 1] == pytest.approx(400.0 + 10.0)  # flight plus one image
    assert cost[1, 0] == pytest.approx(400.0)  # returning to base images nothing
