"""How far a link leaves a shape, against matplotlib's point-in-polygon and distances worked by hand."""

from __future__ import annotations

import numpy as np
import pytest

from linkwork.mechanization.inside import leaving, link_outside_by, outside_by

# a U: the notch x in (1, 2), y in (1, 3) is outside
U = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 3.0], [2.0, 3.0], [2.0, 1.0], [1.0, 1.0], [1.0, 3.0], [0.0, 3.0]])


def test_points_outside_by_their_distance_to_the_outline() -> None:
    mpath = pytest.importorskip("matplotlib.path")
    rng = np.random.default_rng(7)
    pts = rng.uniform(-1.0, 4.0, (400, 2))
    by = outside_by(U, pts)
    inside = mpath.Path(np.vstack([U, U[:1]]), closed=True).contains_points(pts)
    assert np.array_equal(by == 0.0, inside)
    # by hand: in the notch 0.2 from its wall x = 1; right of the U 0.5 away; below a corner sqrt(0.5)
    np.testing.assert_allclose(
        outside_by(U, [[1.2, 2.5], [3.5, 1.5], [3.5, -0.5]]), [0.2, 0.5, np.sqrt(0.5)], rtol=0, atol=1e-15
    )


def test_a_link_between_two_inside_pivots_can_still_leave() -> None:
    # both ends inside the U's arms: the link at y = 2.5 crosses the notch, whose middle (x = 1.5) is 0.5 from
    # either wall (the samples, 1/16 apart, find it to a sample's spacing)
    assert link_outside_by(U, [0.5, 2.5], [2.5, 2.5]) == pytest.approx(0.5, abs=1.0 / 32)
    assert link_outside_by(U, [0.5, 0.5], [2.5, 0.5]) == 0.0  # along the bottom, inside
    assert link_outside_by(U, [0.5, 0.5], [0.5, 2.5]) == 0.0  # up one arm


def test_a_link_that_slips_out_between_samples_is_not_inside() -> None:
    # a spike of the outline 1e-3 wide that the link crosses between two of its samples
    shape = np.array(
        [[0.0, 0.0], [10.0, 0.0], [10.0, 1.0], [5.0005, 1.0], [5.0, 0.4], [4.9995, 1.0], [0.0, 1.0]]
    )
    assert link_outside_by(shape, [0.1, 0.5], [9.9, 0.5]) > 0.0


def test_leaving_names_the_worst_part_and_profile() -> None:
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    targets = (square, square + np.array([0.5, 0.0]))  # the second profile shifted right
    anchor = np.array([[0.2, 0.5], [0.2, 0.5]])  # a fixed pivot: inside the first, 0.3 outside the second
    moving = np.array([[0.8, 0.5], [1.3, 0.5]])
    worst = leaving(targets, anchor, moving)
    assert (worst.part, worst.profile) == ("anchor pivot", 1)
    assert worst.by == pytest.approx(0.3, abs=1e-15)
    assert "anchor pivot of D1 leaves profile 2 by 0.3" in worst.describe("D1")
    assert leaving(targets, anchor + np.array([0.4, 0.0]), moving - np.array([0.1, 0.0])).by == 0.0
