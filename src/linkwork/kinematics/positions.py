"""Where the joints and bodies of a mechanism are in the world, at the joint values users read.

A joint's *point* is a fixed point on its axis: for a revolute joint, the mean of the feet of the common normals
with its neighbours in the loop (for a Denavit-Hartenberg loop with ``d = 0`` both feet coincide at the DH frame
origin, so consecutive points are the link lengths ``a`` apart); where a neighbour's axis is parallel, the foot
of the perpendicular from the origin (the joint's pivot in a planar mechanism drawn in ``z = 0``). A prismatic
joint has a direction only: its point is the mean of the revolute points of the body sliding on it (the body
after it), and moves with that body (a slider's pin); a revolute joint's point moves with the body before it (its
axis is fixed in both of its bodies).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.geometry import exp_se3
from linkwork.kinematics.closure import body_tree
from linkwork.kinematics.mechanism import Mechanism

Array = NDArray[np.float64]

PARALLEL = 1e-10
"""Axes whose directions' cross product is below this (squared norm) count as parallel."""


def _axis(mech: Mechanism, j: int) -> tuple[Array, Array] | None:
    """``(foot of the origin on the axis, unit direction)`` of revolute joint ``j``; ``None`` for prismatic."""
    w, v = mech.twists[j, :3], mech.twists[j, 3:]
    norm = float(np.linalg.norm(w))
    if mech.joint_types[j] == "P" or norm < 1e-12:
        return None
    w = w / norm
    return np.cross(w, v / norm), w  # v = p x w for a unit w: the foot is w x v


def _foot(p1: Array, d1: Array, p2: Array, d2: Array) -> Array:
    """The foot on line 1 of the common normal to lines 1 and 2 (``p1`` when they are parallel)."""
    n = np.cross(d1, d2)
    nn = float(n @ n)
    if nn < PARALLEL:
        return p1
    return p1 + (float(np.cross(p2 - p1, d2) @ n) / nn) * d1


def _neighbours(mech: Mechanism) -> list[list[int]]:
    """For every joint, the joints next to it in the loops it belongs to."""
    out: list[set[int]] = [set() for _ in range(mech.n_joints)]
    for loop in mech.loops:
        joints = [int(j) for j in loop.joints]
        for i, j in enumerate(joints):
            if len(joints) > 1:
                out[j].update((joints[i - 1], joints[(i + 1) % len(joints)]))
    return [sorted(s - {j}) for j, s in enumerate(out)]


def joint_points(mech: Mechanism) -> Array:
    """``(n, 3)`` the point of every joint (see the module's docstring) in the reference configuration."""
    n = mech.n_joints
    axes = [_axis(mech, j) for j in range(n)]
    points = np.zeros((n, 3))
    for j, neighbours in enumerate(_neighbours(mech)):
        axis = axes[j]
        if axis is None:
            continue
        feet = []
        for k in neighbours:
            other = axes[k]
            if other is not None:
                feet.append(_foot(axis[0], axis[1], other[0], other[1]))
        points[j] = np.mean(feet, axis=0) if feet else axis[0]
    for j in range(n):
        if axes[j] is None:
            after = mech.joint_bodies[j][1]
            pool = [k for k in range(n) if axes[k] is not None and after in mech.joint_bodies[k]]
            pool = pool or [k for k in range(n) if axes[k] is not None]
            points[j] = points[pool].mean(axis=0) if pool else 0.0
    return points


def carrier(mech: Mechanism, j: int) -> str:
    """The body whose pose carries joint ``j``'s point: the body before a revolute joint, the sliding body (after)
    for a prismatic one."""
    before, after = mech.joint_bodies[j]
    return after if mech.joint_types[j] == "P" else before


def poses_along(mech: Mechanism, angles: ArrayLike) -> dict[str, Array]:
    """``{body: (N, 4, 4)}`` the world pose of every body at each row of joint values ``angles (N, n)``: what
    :func:`linkwork.kinematics.closure.body_poses` gives row by row (the same spanning tree from the ground or the
    first body), for all rows at once."""
    q = mech.q_from_angles(np.atleast_2d(np.asarray(angles, dtype=float)))
    if not mech.bodies:
        return {}
    root, edges = body_tree(mech)
    poses = {root: np.broadcast_to(np.eye(4), (len(q), 4, 4)).copy()}
    for body, j, other, sign in edges:
        poses[other] = poses[body] @ exp_se3(sign * mech.twists[j] * q[:, j, None])
    return poses


def joint_positions(mech: Mechanism, angles: ArrayLike, poses: dict[str, Array] | None = None) -> Array:
    """``(N, n, 3)`` world coordinates of every joint's point at each row of joint values ``angles (N, n)``."""
    rows = np.atleast_2d(np.asarray(angles, dtype=float))
    poses = poses_along(mech, rows) if poses is None else poses
    ref = joint_points(mech)
    out = np.empty((len(rows), mech.n_joints, 3))
    for j in range(mech.n_joints):
        T = poses[carrier(mech, j)]
        out[:, j] = T[:, :3, :3] @ ref[j] + T[:, :3, 3]
    return out
