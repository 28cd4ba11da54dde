"""World coordinates of joints and bodies along a trace (``Trace.positions()``, ``Trace.poses()``) and the
``body_poses`` API that cannot be called with the wrong kind of joint value.

References: the planar four-bar's pivots from its closed form (ground pivots fixed, crank pivot on the crank
circle, coupler and rocker lengths kept); Bennett's link lengths ``a = scale * sin(alpha)`` between consecutive
joints; invariance of the world positions under re-referencing the mechanism (which changes every offset).
"""

from __future__ import annotations

import numpy as np
import pytest

import linkwork as lw
from linkwork.kinematics.closure import body_poses
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.positions import joint_points


def four_bar(a: float, b: float, c: float, d: float, theta2: float) -> tuple[Mechanism, float]:
    """Crank ``a`` pivoted at the origin, coupler ``b``, rocker ``c`` pivoted at ``(d, 0)``, crank at ``theta2``."""
    O2, O4 = np.zeros(2), np.array([d, 0.0])
    A = a * np.array([np.cos(theta2), np.sin(theta2)])
    r = np.linalg.norm(O4 - A)
    x = (r * r + b * b - c * c) / (2 * r)  # B on the circles |B - A| = b and |B - O4| = c
    e = (O4 - A) / r
    B = A + x * e + np.sqrt(b * b - x * x) * np.array([-e[1], e[0]])
    pivots = {"O2": O2, "A": A, "B": B, "O4": O4}
    bodies = [("ground", "crank"), ("crank", "coupler"), ("coupler", "rocker"), ("rocker", "ground")]
    joints = [
        {"name": name, "bodies": list(pair), "point": pivots[name], "direction": [0, 0, 1]}
        for name, pair in zip(pivots, bodies, strict=True)
    ]
    return Mechanism.from_joints("four-bar", joints, planar=True), theta2


def test_four_bar_pivots_follow_the_closed_form() -> None:
    a, b, c, d = 1.0, 3.0, 2.5, 3.2
    mech, t2_0 = four_bar(a, b, c, d, 0.3)
    tr = lw.trace(mech, drive="O2", max_steps=300, max_step=np.radians(3.0))
    xyz = tr.positions()
    assert xyz.shape == (len(tr.angles), 4, 3)
    O2, A, B, O4 = (xyz[:, mech.index(n)] for n in ("O2", "A", "B", "O4"))
    np.testing.assert_allclose(O2, 0.0, atol=1e-12)
    np.testing.assert_allclose(O4, np.broadcast_to([d, 0.0, 0.0], O4.shape), atol=1e-12)
    t2 = t2_0 + tr.angles[:, 0]
    np.testing.assert_allclose(A[:, :2], a * np.column_stack([np.cos(t2), np.sin(t2)]), atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(B - A, axis=1), b, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(B - O4, axis=1), c, atol=1e-12)
    np.testing.assert_allclose(xyz[..., 2], 0.0, atol=1e-12)


def test_bennett_joints_are_the_link_lengths_apart() -> None:
    alpha1, alpha2, scale = np.radians(40.0), np.radians(70.0), 1.7
    mech = lw.load("bennett", alpha1=alpha1, alpha2=alpha2, scale=scale)
    tr = lw.trace(mech, until=("A", mech.offsets[0] + 1.2))
    xyz = tr.positions()
    gaps = np.linalg.norm(xyz - np.roll(xyz, -1, axis=1), axis=2)  # A-B, B-C, C-D, D-A
    expected = scale * np.sin([alpha1, alpha2, alpha1, alpha2])
    np.testing.assert_allclose(gaps, np.broadcast_to(expected, gaps.shape), rtol=0, atol=1e-12)


def test_positions_do_not_depend_on_the_reference_configuration() -> None:
    mech = lw.load("bennett")
    tr = lw.trace(mech, until=("A", mech.offsets[0] + 1.0))
    moved = mech.with_reference(mech.q_from_angles(tr.angles[len(tr.angles) // 2]))
    assert np.ptp(moved.offsets - mech.offsets) > 0.1  # the offsets really changed
    again = lw.Trace(**{**tr.__dict__, "mechanism": moved})
    np.testing.assert_allclose(again.positions(), tr.positions(), atol=1e-12)


def test_a_hinge_point_is_on_both_of_its_bodies() -> None:
    mech = lw.load("hedgepeth-rods", n=6)
    tr = lw.trace(mech, until=("A", np.radians(90.0)))
    poses, ref = tr.poses(), joint_points(mech)
    for j, (before, after) in enumerate(mech.joint_bodies):
        p_before = poses[before][:, :3, :3] @ ref[j] + poses[before][:, :3, 3]
        p_after = poses[after][:, :3, :3] @ ref[j] + poses[after][:, :3, 3]
        np.testing.assert_allclose(p_before, p_after, atol=1e-12)
    assert all(p.shape == (len(tr.angles), 4, 4) for p in poses.values())


def test_body_poses_takes_angles_or_displacements_by_name_only() -> None:
    mech = lw.load("bennett")
    angles = mech.offsets + 0.2
    with pytest.raises(TypeError):
        body_poses(mech, angles)  # type: ignore[misc]
    with pytest.raises(TypeError, match="exactly one"):
        body_poses(mech)
    by_angles = body_poses(mech, angles=angles)
    by_q = body_poses(mech, q=mech.q_from_angles(angles))
    for name in mech.bodies:
        np.testing.assert_array_equal(by_angles[name], by_q[name])
