"""What ``points.csv`` holds along a traced motion: every joint's point (:mod:`linkwork.kinematics.positions`), the
named points a spec declares, and the transmission angle of the planar four-bar and slider-crank. Named points (``mech.meta["points"]``: ``name``, ``body``, ``position`` in the reference configuration)
ride on their body.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.positions import joint_positions, poses_along

Array = NDArray[np.float64]


def named_points(mech: Mechanism) -> list[Mapping[str, Any]]:
    """The named points declared for ``mech`` (``[[points]]`` in a spec, or set by a built-in)."""
    return list(mech.meta.get("points", ()))


def positions(mech: Mechanism, angles: ArrayLike) -> tuple[Array, Array]:
    """World coordinates of the joints ``(N, n, 3)`` (:func:`linkwork.kinematics.positions.joint_positions`) and
    of the named points ``(N, p, 3)`` at joint values ``angles`` (``(N, n)`` radians, or one row ``(n,)``)."""
    poses = poses_along(mech, angles)
    joints = joint_positions(mech, angles, poses)
    extra = named_points(mech)
    points = np.empty((len(joints), len(extra), 3))
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
