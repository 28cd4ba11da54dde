"""PR sliders: slider points against collinearity (three positions), and a body in pure translation."""

from __future__ import annotations

import numpy as np

from linkwork.mechanization.guidance import positions
from linkwork.mechanization.sliders import fit_guide, slider_points

from .conftest import coupler_pose


def test_slider_points_of_three_positions_travel_on_a_straight_line() -> None:
    poses = np.array([coupler_pose(p) for p in np.radians([40.0, 70.0, 110.0])])
    found = []
    for origin in ([0.0, 0.0], [1.0, 1.0], [-1.0, 2.0]):
        for direction in ([1.0, 0.0], [0.0, 1.0]):
            found += slider_points(poses, np.array(origin), np.array(direction), reach=10.0)
    assert found
    for m in found:
        w = positions(poses, m)
        # collinear: the third position's distance from the line through the first two (closed form)
        d = w[1] - w[0]
        gap = abs(d[0] * (w[2] - w[0])[1] - d[1] * (w[2] - w[0])[0]) / np.linalg.norm(d)
        assert gap <= 1e-9 * max(1.0, float(np.linalg.norm(d)))
        _, _, travel, error = fit_guide(poses, m)
        assert error <= 1e-9 and abs(travel[0]) <= 1e-12


def test_in_pure_translation_every_point_is_a_slider_point_on_the_path_direction() -> None:
    # a body translated along (3, 4) / 5 by 0, 1, 2.5: each point's guide is that direction
    poses = np.array([[0.0, 0.0, 0.0], [0.6, 0.8, 0.0], [1.5, 2.0, 0.0], [2.1, 2.8, 0.0]])
    for m in ([0.0, 0.0], [1.0, -2.0], [5.0, 3.0]):
        start, u, travel, error = fit_guide(poses, np.array(m))
        assert np.allclose(u, [0.6, 0.8], atol=1e-12)
        assert np.allclose(travel, [0.0, 1.0, 2.5, 3.5], atol=1e-12)
        assert error <= 1e-12 and np.allclose(start, m, atol=1e-12)
