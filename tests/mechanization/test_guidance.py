"""Rigid-body guidance against textbook cases: circles through three positions, Burmester points of a four-bar."""

from __future__ import annotations

import numpy as np
import pytest

from linkwork.errors import LinkworkError
from linkwork.mechanization.guidance import (
    burmester_points,
    centre_point,
    circle_point_curve,
    circle_through,
    compatibility,
    fit_circle_point,
    positions,
)

from .conftest import COUPLER, GROUND_A, GROUND_D


def test_circle_through_three_points_of_a_known_circle() -> None:
    centre, radius = np.array([1.5, -2.0]), 3.25
    angles = np.radians([10.0, 130.0, 250.0])
    pts = centre + radius * np.column_stack([np.cos(angles), np.sin(angles)])
    c, r = circle_through(pts)
    np.testing.assert_allclose(c, centre, rtol=0, atol=1e-12)
    assert abs(r - radius) <= 1e-12


def test_collinear_points_have_no_circle() -> None:
    with pytest.raises(LinkworkError, match="collinear"):
        circle_through(np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]))


def test_three_positions_are_reproduced_exactly_by_any_circle_point() -> None:
    rng = np.random.default_rng(7)
    for _ in range(20):
        poses = np.column_stack([rng.normal(size=(3, 2)), rng.uniform(-1.0, 1.0, 3)])
        m = rng.normal(size=2)
        dyad = centre_point(poses, m)
        w = positions(poses, m)
        # every position of the circle point on the circle about the centre point, and the dyad exact
        np.testing.assert_allclose(
            np.linalg.norm(w - dyad.centre_point, axis=1), dyad.radius, rtol=1e-12, atol=1e-12
        )
        assert dyad.structural_error <= 1e-12 * max(1.0, dyad.radius)


def test_four_positions_pivots_lie_on_the_circle_point_curve(four_bar_poses: np.ndarray) -> None:
    poses = four_bar_poses[:4]
    scale = 10.0**3  # the cubic's size for lengths of order 10
    for m in (np.zeros(2), np.array([COUPLER, 0.0])):
        assert abs(compatibility(poses, m)) <= 1e-12 * scale
    circle, centre = circle_point_curve(poses, rays=720)
    # the sampled curve passes near both moving pivots (rays 0.25 deg apart) and every sample is exact
    for m in (np.zeros(2), np.array([COUPLER, 0.0])):
        assert np.min(np.linalg.norm(circle - m, axis=1)) <= 0.05
    for m, c in zip(circle[::25], centre[::25], strict=True):
        r = np.linalg.norm(positions(poses, m) - c, axis=1)
        assert np.ptp(r) <= 1e-8 * max(1.0, r[0])


def test_five_positions_of_a_four_bar_give_its_pivots_as_burmester_points(four_bar_poses: np.ndarray) -> None:
    dyads = burmester_points(four_bar_poses)
    assert len(dyads) in (2, 4)
    for moving, fixed in ((np.zeros(2), GROUND_A), (np.array([COUPLER, 0.0]), GROUND_D)):
        gaps = [np.linalg.norm(d.circle_point - moving) for d in dyads]
        best = dyads[int(np.argmin(gaps))]
        assert min(gaps) <= 1e-6
        np.testing.assert_allclose(best.centre_point, fixed, rtol=0, atol=1e-6)
    for d in dyads:
        assert d.structural_error <= 1e-8


def test_more_than_five_positions_least_squares_with_structural_error(four_bar_poses: np.ndarray) -> None:
    from .conftest import coupler_pose

    poses = np.array([coupler_pose(p) for p in np.radians(np.linspace(40.0, 120.0, 7))])
    # an exact circle point exists (the coupler pivot C): the fit finds a structural error of ~0 near it
    exact = fit_circle_point(poses, np.array([COUPLER + 0.05, 0.02]))
    assert exact.structural_error <= 1e-8
    # disturb the poses: the error reported is the spread of the length the link would need (longest distance
    # between the pivots over the positions minus the shortest), recomputed here
    noisy = poses + np.column_stack([np.linspace(0.0, 0.03, 7), np.zeros(7), np.zeros(7)])
    dyad = fit_circle_point(noisy, np.array([COUPLER, 0.0]))
    r = np.linalg.norm(positions(noisy, dyad.circle_point) - dyad.centre_point, axis=1)
    assert abs(dyad.structural_error - (r.max() - r.min())) <= 1e-12
    assert 0.0 < dyad.structural_error <= 0.03
