"""Every loop in the ground's frame (``kinematics.ground_frame``), against the numpy reference of
``kinematics.closure``: body poses chained along the spanning tree, each loop's own product and logarithm.

A Watt II six-bar held by its crank: one of its two loops (D-E-F-G) does not pass through the crank, so the
tracer takes it from another body, whose frame moves.
"""

from __future__ import annotations

import numpy as np

import linkwork as lw
from linkwork.geometry import adjoint, exp_se3, log_se3
from linkwork.kinematics.closure import body_poses, loop_products, spatial_twists
from linkwork.kinematics.ground_frame import ground_frame_closure, ground_frame_loops, joint_axes, loop_start
from linkwork.kinematics.mechanism import Mechanism

POINTS = dict(A=(0, 0), B=(0.7, 0.6), C=(3.3, 2.4), D=(4.1, -0.1), E=(1.9, 3.6), F=(-1.2, 4.8), G=(-2.3, 0.4))


def watt_held_by_its_crank() -> Mechanism:
    """Ground (A, D, G), crank (A, B), coupler (B, C), rocker (C, D, E), link5 (E, F), link6 (F, G), with the
    crank named ``ground`` and the ground ``crank``."""
    bodies = dict(
        A=("crank", "ground"),
        B=("ground", "coupler"),
        C=("coupler", "rocker"),
        D=("rocker", "crank"),
        E=("rocker", "link5"),
        F=("link5", "link6"),
        G=("link6", "crank"),
    )
    joints = [
        {"name": n, "bodies": bodies[n], "point": p, "direction": (0.0, 0.0, 1.0)} for n, p in POINTS.items()
    ]
    return Mechanism.from_joints("watt", joints, planar=True)


def test_a_loop_that_misses_the_ground_is_taken_from_it() -> None:
    mech = watt_held_by_its_crank()
    starts = [loop_start(mech, loop) for loop in mech.loops]
    assert "ground" in starts and any(s != "ground" for s in starts)
    for loop, taken in zip(mech.loops, ground_frame_loops(mech), strict=True):
        if loop_start(mech, loop) == "ground":
            assert taken == loop
        else:  # the tree path down, the loop, the path back with its signs reversed
            k = len(taken.joints) - len(loop.joints)
            assert k > 0 and k % 2 == 0
            down, back = taken.joints[: k // 2], taken.joints[len(taken.joints) - k // 2 :]
            assert back == down[::-1]
            assert taken.signs[len(taken.signs) - k // 2 :] == tuple(-s for s in taken.signs[: k // 2][::-1])
            assert taken.joints[k // 2 : len(taken.joints) - k // 2] == loop.joints


def test_at_a_closed_configuration_every_column_is_its_joints_axis_in_the_ground_frame() -> None:
    """On the traced path: loop ``k``'s column of joint ``j`` is ``s Ad(g_body) xi_j`` with ``g_body`` the pose of
    the joint's first body chained from the ground (``closure.spatial_twists``), in whichever loop; a joint on a
    loop's tree path only adds nothing. The residual is zero, and ``joint_axes`` reads the same axes."""
    mech = watt_held_by_its_crank()
    trace = lw.trace(mech, until=("A", float(mech.offsets[0]) + np.radians(40.0)), steps=8)
    q = trace.angles - mech.offsets
    residual, jac = ground_frame_closure(mech, q)
    assert np.abs(residual).max() < 1e-11
    axes = joint_axes(mech, jac)
    for i, qi in enumerate(q):
        twists = spatial_twists(mech, qi)
        blocks = jac[i].reshape(len(mech.loops), 6, mech.n_joints)
        for k, loop in enumerate(mech.loops):
            expected = np.zeros((6, mech.n_joints))
            for j, s in zip(loop.joints, loop.signs, strict=True):
                expected[:, j] = s * twists[j]
            np.testing.assert_allclose(blocks[k], expected, atol=1e-11)
        used = sorted({j for loop in mech.loops for j in loop.joints})
        for j in used:  # the axis up to the sign its loop traverses it with
            sign = 1.0 if np.dot(axes[i, j], twists[j]) > 0.0 else -1.0
            np.testing.assert_allclose(axes[i, j], sign * twists[j], atol=1e-11)


def test_off_the_path_the_residual_is_the_loop_turned_to_the_ground_and_the_columns_its_derivative() -> None:
    """At random joint values (no loop closes): loop ``k``'s residual is ``Ad_A log L_k``, ``L_k`` the loop's own
    product and ``A`` the pose of the body it starts from (``closure.body_poses``); its columns are the exact
    right derivative ``dF F^-1`` of ``F = A L_k A^-1`` (central differences of numpy's products, to 1e-8)."""
    mech = watt_held_by_its_crank()
    rng = np.random.default_rng(7)
    for _ in range(5):
        q = rng.uniform(-0.4, 0.4, size=mech.n_joints)
        residual, jac = ground_frame_closure(mech, q[None])
        poses = body_poses(mech, q=q)
        own = loop_products(mech, q)
        for k, loop in enumerate(mech.loops):
            A = poses[loop_start(mech, loop)]
            np.testing.assert_allclose(
                residual[0, 6 * k : 6 * k + 6], adjoint(A) @ log_se3(own[k]), rtol=1e-12, atol=1e-13
            )
            F = A @ own[k] @ np.linalg.inv(A)
            np.testing.assert_allclose(log_se3(F), adjoint(A) @ log_se3(own[k]), atol=1e-12)
        for k, taken in enumerate(ground_frame_loops(mech)):

            def product(x: np.ndarray, taken=taken) -> np.ndarray:
                g = np.eye(4)
                for j, s in zip(taken.joints, taken.signs, strict=True):
                    g = g @ exp_se3(s * mech.twists[j] * x[j])
                return g

            F = product(q)
            for j in range(mech.n_joints):
                h = np.zeros(mech.n_joints)
                h[j] = 1e-6
                dF = (product(q + h) - product(q - h)) / 2e-6 @ np.linalg.inv(F)
                column = np.concatenate([[dF[2, 1], dF[0, 2], dF[1, 0]], dF[:3, 3]])
                np.testing.assert_allclose(jac[0, 6 * k : 6 * k + 6, j], column, atol=1e-8)
