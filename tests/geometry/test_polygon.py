"""Point in polygon (even-odd rule) against matplotlib's path test and a closed form (the unit disc)."""

from __future__ import annotations

import numpy as np
import pytest

from linkwork.geometry.polygon import contains


def test_agrees_with_matplotlib_on_a_concave_polygon() -> None:
    path_module = pytest.importorskip("matplotlib.path")
    rng = np.random.default_rng(7)
    # a concave, star-shaped polygon of 11 points
    angles = np.linspace(0.0, 2 * np.pi, 11, endpoint=False)
    radius = np.where(np.arange(11) % 2 == 0, 1.0, 0.4)
    poly = np.column_stack([radius * np.cos(angles), radius * np.sin(angles)])
    pts = rng.uniform(-1.2, 1.2, size=(4000, 2))
    expected = path_module.Path(poly).contains_points(pts)
    got = contains(poly, pts)
    # points within 1e-9 of an edge may go either way; none of 4000 random points is that close
    assert np.array_equal(got, expected)


def test_inside_a_fine_polygon_of_the_unit_circle_is_the_disc() -> None:
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 2 * np.pi, 2001)
    circle = np.column_stack([np.cos(t), np.sin(t)])  # closed: the last vertex repeats the first
    pts = rng.uniform(-1.5, 1.5, size=(3000, 2))
    r = np.linalg.norm(pts, axis=1)
    far = np.abs(r - 1.0) > 1e-5  # the polygon departs from the circle by at most 1 - cos(pi / 2000) ~ 1.2e-6
    assert np.array_equal(contains(circle, pts[far]), r[far] < 1.0)


def test_shape_errors_say_what_was_expected() -> None:
    with pytest.raises(ValueError, match=r"shape \(k >= 3, 2\)"):
        contains([[0.0, 0.0], [1.0, 0.0]], [[0.5, 0.5]])
