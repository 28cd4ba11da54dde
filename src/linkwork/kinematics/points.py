"""World positions along a traced motion: every joint's point, the named points a spec declares, and the
transmission angle of the planar four-bar and slider-crank.

A joint's world position is a point on its axis carried by the pose of the body before it: for a revolute joint
the axis' point nearest the origin in the reference configuration (both bodies carry it to the same place while
the loops close); a prismatic joint (a direction only) is placed at the mean of the revolute points of the body
sliding on it (the body after it), and moves with that body. Named points (``mech.meta["points"]``: ``name``, ``body``, ``position`` in the reference configuration)
ride on their body.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.geometry import exp_se3
from linkwork.kinematics.mechanism import Mechanism

Array = NDArray[np.float64]


def reference_joint_points(mech: Mechanism) -> Array:
    """``(n, 3)`` one point on every joint axis in the reference configuration (see the module docstring)."""
    n = mech.n_joints
    points = np.zeros((n, 3))
    prismatic = []
    for j in range(n):
        w, v = mech.twists[j, :3], mech.twists[j, 3:]
        if mech.joint_types[j] == "P" or np.linalg.norm(w) < 1e-12:
            prismatic.append(j)
        else:
            points[j] = np.cross(w, v) / float(w @ w)  # foot of the origin on the axis (v = p x w)
    revolute = [j for j in range(n) if j not in prismatic]
    for j in prismatic:
        after = mech.joint_bodies[j][1]
        near = [k for k in revolute if after in mech.joint_bodies[k]]
        pool = near or revolute
        points[j] = points[pool].mean(axis=0) if pool else 0.0
    return points


def _carrier(mech: Mechanism, j: int) -> str:
    """The body whose pose carries joint ``j``'s point: the one before a revolute joint, the sliding body
    (after) for a prismatic joint."""
    before, after = mech.joint_bodies[j]
    return after if mech.joint_types[j] == "P" else before


def named_points(mech: Mechanism) -> list[Mapping[str, Any]]:
    """The named points declared for ``mech`` (``[[points]]`` in a spec, or set by a built-in)."""
    return list(mech.meta.get("points", ()))


def body_poses_along(mech: Mechanism, angles: ArrayLike) -> dict[str, Array]:
    """Displacement ``(N, 4, 4)`` of every body from the reference at every row of joint values ``(N, n)``
    (radians): :func:`linkwork.kinematics.closure.body_poses` over many rows at once (same spanning tree)."""
    q = mech.q_from_angles(np.atleast_2d(np.asarray(angles, dtype=float)))
    root = "ground" if "ground" in mech.bodies else mech.bodies[0]
    adjacency: dict[str, list[tuple[int, str, int]]] = {b: [] for b in mech.bodies}
    for j, (a, b) in enumerate(mech.joint_bodies):
        adjacency[a].append((j, b, 1))
        adjacency[b].append((j, a, -1))
    poses = {root: np.broadcast_to(np.eye(4), (len(q), 4, 4))}
    queue = deque([root])
    while queue:
        body = queue.popleft()
        for j, other, sign in adjacency[body]:
            if other not in poses:
                poses[other] = poses[body] @ exp_se3(sign * mech.twists[j] * q[:, j, None])
                queue.append(other)
    return poses


def positions(mech: Mechanism, angles: ArrayLike) -> tuple[Array, Array]:
    """World coordinates of the joints ``(N, n, 3)`` and of the named points ``(N, p, 3)`` at joint values.

    Parameters
    ----------
    mech
        The mechanism.
    angles
        ``(N, n)`` reported joint values in radians (rows of ``Trace.angles``), or one row ``(n,)``.
    """
    poses = body_poses_along(mech, angles)
    count = len(next(iter(poses.values())))
    ref = reference_joint_points(mech)
    extra = named_points(mech)
    joints = np.empty((count, mech.n_joints, 3))
    for j in range(mech.n_joints):
        g = poses[_carrier(mech, j)]
        joints[:, j] = g[:, :3, :3] @ ref[j] + g[:, :3, 3]
    points = np.empty((count, len(extra), 3))
    for k, p in enumerate(extra):
        g = poses[str(p["body"])]
        points[:, k] = g[:, :3, :3] @ np.asarray(p["position"], dtype=float) + g[:, :3, 3]
    return joints, points


def transmission_angles(mech: Mechanism, joints: Array) -> Array | None:
    """``(N,)`` transmission angle (radians) at every point of ``joints`` (``(N, n, 3)`` from :func:`positions`),
    or ``None`` when ``mech`` declares none.

    ``mech.meta["transmission"]`` names three joints ``(at, a, b)``: for a four-bar (``kind = "rocker"``) the
    angle at joint ``at`` between the lines to ``a`` and ``b`` (coupler and rocker); for a slider-crank
    (``kind = "slider"``, ``b`` the prismatic joint) the angle between the connecting rod ``a``-``at`` and the
    normal to the slide, ``90 deg - `` the rod's angle to the slide (Norton, Design of Machinery, Sec. 4.10).
    """
    spec = mech.meta.get("transmission")
    if not spec:
        return None
    at, a, b = (mech.index(str(name)) for name in spec["joints"])
    rod = joints[:, a] - joints[:, at]
    rod /= np.linalg.norm(rod, axis=1, keepdims=True)
    if spec.get("kind", "rocker") == "rocker":
        other = joints[:, b] - joints[:, at]
        other /= np.linalg.norm(other, axis=1, keepdims=True)
        return np.arccos(np.clip(np.einsum("ij,ij->i", rod, other), -1.0, 1.0))
    slide = mech.twists[b, 3:] / np.linalg.norm(mech.twists[b, 3:])
    return np.arcsin(np.clip(np.abs(rod @ slide), 0.0, 1.0))


def points_columns(mech: Mechanism) -> Sequence[str]:
    """Names of the positions written to ``points.csv``: joints first, then named points."""
    return [*mech.joint_names, *(str(p["name"]) for p in named_points(mech))]
