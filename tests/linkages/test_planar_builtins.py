"""The planar four-bar and slider-crank built-ins, traced by the kinematic core, against closed-form position
analysis written here independently (loop closure by the law of cosines), and their transmission angles against
triangle geometry."""

from __future__ import annotations

import numpy as np
import pytest

import linkwork as lw
from linkwork.kinematics.points import positions, transmission_angles
from linkwork.linkages.four_bar import four_bar
from linkwork.linkages.slider_crank import slider_crank

TOL = 1e-9  # positions: the tracer's closure tolerance is 1e-12, lengths are O(1)
D, A, B, C = 2.0, 1.0, 2.5, 2.0  # ground, crank, coupler, rocker (Grashof crank-rocker: 1 + 2.5 <= 2 + 2)


def four_bar_closed_form(theta: np.ndarray, along: float, off: float) -> tuple[np.ndarray, ...]:
    """Pivots B, C and coupler point P of the open four-bar, and the transmission angle, by the law of cosines.

    f = |BD|, the angle at D between D->B and D->C is beta with cos(beta) = (c^2 + f^2 - b^2) / (2 c f); the open
    circuit (the built-in's default, C above the ground line) is D->B turned by -beta about D.
    """
    bx, by = A * np.cos(theta), A * np.sin(theta)
    f = np.hypot(D - bx, by)
    beta = np.arccos((C**2 + f**2 - B**2) / (2 * C * f))
    gamma = np.arctan2(by, bx - D)  # direction D -> B
    cx, cy = D + C * np.cos(gamma - beta), C * np.sin(gamma - beta)
    ux, uy = (cx - bx) / B, (cy - by) / B
    px = bx + B * (along * ux - off * uy)
    py = by + B * (along * uy + off * ux)
    mu = np.arccos((B**2 + C**2 - f**2) / (2 * B * C))  # transmission angle: the triangle B C D at C
    return np.stack([bx, by], 1), np.stack([cx, cy], 1), np.stack([px, py], 1), mu


@pytest.fixture(scope="module")
def four_bar_trace() -> lw.Trace:
    mech = four_bar(D, A, B, C, np.radians(60.0), 0.5, 0.8)
    return lw.trace(mech, drive="A", until=("A", np.radians(400.0)))


def test_four_bar_coupler_curve_matches_law_of_cosines(four_bar_trace: lw.Trace) -> None:
    tr = four_bar_trace
    theta = tr.angles[:, 0]
    assert theta.max() > np.radians(399.0)  # a full turn of the crank: a crank-rocker
    joints, named = positions(tr.mechanism, tr.angles)
    b, c, p, _mu = four_bar_closed_form(theta, 0.5, 0.8)
    np.testing.assert_allclose(joints[:, 1, :2], b, atol=TOL)
    np.testing.assert_allclose(joints[:, 2, :2], c, atol=TOL)
    np.testing.assert_allclose(named[:, 0, :2], p, atol=TOL)
    np.testing.assert_allclose(joints[:, :, 2], 0.0, atol=0.0)  # planar
    np.testing.assert_allclose(joints[:, 0], 0.0, atol=TOL)  # ground pivots stay put
    np.testing.assert_allclose(joints[:, 3, :2], [[D, 0.0]] * len(theta), atol=TOL)


def test_four_bar_transmission_angle_from_triangle(four_bar_trace: lw.Trace) -> None:
    tr = four_bar_trace
    joints, _ = positions(tr.mechanism, tr.angles)
    mu = transmission_angles(tr.mechanism, joints)
    assert mu is not None
    np.testing.assert_allclose(mu, four_bar_closed_form(tr.angles[:, 0], 0.5, 0.8)[3], atol=1e-8)
    # extremes of a crank-rocker at crank angles 0 and 180 deg: cos(mu) = (b^2 + c^2 - (d -+ a)^2) / (2 b c)
    lo = np.arccos((B**2 + C**2 - (D - A) ** 2) / (2 * B * C))
    hi = np.arccos((B**2 + C**2 - (D + A) ** 2) / (2 * B * C))
    # the trace passes near, not exactly through, crank angles 0 and 180 deg: 1e-3 rad
    assert lo - 1e-9 <= mu.min() <= lo + 1e-3 and hi - 1e-3 <= mu.max() <= hi + 1e-9


def test_slider_crank_matches_closed_form() -> None:
    r, rod, e = 1.0, 3.0, 0.4
    tr = lw.trace(slider_crank(r, rod, e, np.radians(30.0)), drive="A", until=("A", np.radians(390.0)))
    theta = tr.angles[:, 0]
    assert theta.max() > np.radians(389.0)
    x = r * np.cos(theta) + np.sqrt(rod**2 - (r * np.sin(theta) - e) ** 2)
    np.testing.assert_allclose(tr.angles[:, 3], x, atol=TOL)  # the prismatic joint reads the slider's x
    joints, _ = positions(tr.mechanism, tr.angles)
    np.testing.assert_allclose(joints[:, 2, :2], np.stack([x, np.full_like(x, e)], 1), atol=TOL)
    mu = transmission_angles(tr.mechanism, joints)
    assert mu is not None
    # rod's angle phi to the guide: sin(phi) = (r sin(theta) - e) / l; mu = 90 deg - |phi|
    np.testing.assert_allclose(mu, np.pi / 2 - np.abs(np.arcsin((r * np.sin(theta) - e) / rod)), atol=1e-8)


def test_points_declared_in_a_spec_ride_on_their_body(tmp_path) -> None:
    from linkwork.io.spec import dump_spec, load_spec

    mech = four_bar()
    file = tmp_path / "fb.toml"
    file.write_text(dump_spec(mech))
    back = load_spec(file).mechanism
    assert back.meta["points"] == [dict(p) for p in mech.meta["points"]]
    angles = mech.offsets + np.radians([10.0, 0.0, 0.0, 0.0])  # not closed, but poses are still rigid
    _, p1 = positions(mech, angles)
    _, p2 = positions(back, angles)
    np.testing.assert_allclose(p1, p2, atol=1e-12)
