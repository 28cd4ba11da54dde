"""The linkage's own scale for misfits: a centre point ``c`` and a length ``L`` defined by the hinge lines.

A closure misfit is a small twist ``(omega, v)`` (rotation and translation left over when the loop is forced
shut). Its size is measured as ``|(L omega, v + omega x c)|``: the rotation times the linkage's length scale plus
the translation of the point ``c``, so that the number is a length, in the linkage's units, and does not change
when the linkage is moved or turned, and scales with it.

``c`` is the point nearest (least squares) to every revolute hinge line, ``L`` the root-mean-square distance of
the hinge lines from ``c`` (1 for concurrent lines, e.g. a spherical linkage): the centre and scale of the project's
normalised Jacobian (:mod:`linkwork.kinematics.normalization`), taken at the reference configuration.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from linkwork.geometry import hat3
from linkwork.kinematics.mechanism import Mechanism

Array = NDArray[np.float64]


@dataclass(frozen=True)
class MisfitScale:
    """The centre ``c`` (3,), length ``L`` and the 6x6 map ``T`` with ``T (omega, v) = (L omega, v + omega x c)``."""

    centre: Array
    length: float
    weight: Array


def weight(centre: Array, length: float) -> Array:
    """The 6x6 map ``T (omega, v) = (L omega, v + omega x c)`` of centre ``c`` and length ``L``."""
    T = np.zeros((6, 6))
    T[:3, :3] = length * np.eye(3)
    T[3:, 3:] = np.eye(3)
    T[3:, :3] = -hat3(np.asarray(centre, dtype=float))  # omega x c = -c x omega
    return T


def weights_along(mech: Mechanism, angles: Array, length: float) -> Array:
    """``(K, 6, 6)`` the weight at every row of joint values ``angles (K, n)``: moments about the centre of the
    hinge lines in that configuration, in the ground's frame where the misfit takes every loop
    (:func:`linkwork.kinematics.normalization.hinge_centres_along`; a point that moves with the linkage, so the
    measure does not depend on which body is held still as the ground), lengths in the linkage's scale ``length``
    (from the start)."""
    from linkwork.kinematics.normalization import hinge_centres_along

    centres, _ = hinge_centres_along(mech, angles)
    return np.ascontiguousarray(np.array([weight(c, length) for c in centres]).reshape(len(centres), 6, 6))


def line_points(mech: Mechanism, centre: Array | None = None) -> Array:
    """``(n, 3)`` one point per hinge line: the point nearest ``centre`` (the origin if not given); prismatic
    joints give ``centre`` itself (their line has no position)."""
    c = np.zeros(3) if centre is None else np.asarray(centre, dtype=float)
    w = mech.twists[:, :3]
    v = mech.twists[:, 3:]
    p0 = np.cross(w, v)  # nearest point to the origin of a unit-twist line (v = p x w)
    along = np.einsum("ij,ij->i", c[None, :] - p0, w)
    pts = p0 + along[:, None] * w
    prismatic = np.einsum("ij,ij->i", w, w) < 0.5
    pts[prismatic] = c
    return pts


def misfit_scale(mech: Mechanism) -> MisfitScale:
    """The centre, length scale and weight map of ``mech`` (see the module docstring)."""
    centre, length = centre_and_length(mech)
    return MisfitScale(centre=centre, length=length, weight=weight(centre, length))


def hinge_pivots(mech: Mechanism) -> Array:
    """``(n, 3)`` where each hinge physically is, on its line in the reference configuration: the point written
    for the joint (``mech.hinge_points``) when it lies on the line, else the joint's point as linkwork draws and
    exports it (:func:`linkwork.kinematics.positions.joint_points`: the feet of the common normals with its
    neighbours). A prismatic joint's line has no position: its entry is that point too, and is not used."""
    from linkwork.kinematics.positions import joint_points

    pivots = joint_points(mech)
    written = np.asarray(mech.hinge_points, dtype=float)
    if len(written) != mech.n_joints:
        return pivots
    w = mech.twists[:, :3]
    revolute = np.einsum("ij,ij->i", w, w) > 0.5
    foot = np.cross(w, mech.twists[:, 3:])  # the line's point nearest the origin (v = p x w, |w| = 1)
    along = np.einsum("ij,ij->i", written - foot, w)
    off = np.linalg.norm(written - foot - along[:, None] * w, axis=1)
    size = 1.0 + float(np.abs(written).max(initial=0.0)) + float(np.abs(foot).max(initial=0.0))
    on_line = revolute & (off <= 1e-9 * size)
    return np.where(on_line[:, None], foot + along[:, None] * w, pivots)


def centre_and_length(mech: Mechanism) -> tuple[Array, float]:
    """The linkage's centre ``c`` and length ``L`` at its reference: those of the project's normalised Jacobian
    (:func:`linkwork.kinematics.normalization.hinge_centre`), so that the misfit and the normalised Sec. 5 ratio
    share one scale; except where every hinge line passes through ``c`` (a spherical linkage), whose lines have no
    size: there ``L`` is the root-mean-square distance of the hinges themselves (:func:`hinge_pivots`) from ``c``,
    so that the misfit is proportional to the linkage's size (1 only when every hinge sits at ``c``)."""
    from linkwork.kinematics.normalization import hinge_centre

    centre, length = hinge_centre(mech.twists, mech.joint_types)
    centre = np.asarray(centre, dtype=float)
    w = mech.twists[:, :3]
    revolute = np.einsum("ij,ij->i", w, w) > 0.5
    if not np.any(revolute):
        return centre, float(length)
    foot = np.cross(w[revolute], mech.twists[revolute, 3:])
    to_line = centre - foot
    to_line -= np.einsum("ij,ij->i", to_line, w[revolute])[:, None] * w[revolute]
    spread = 1.0 + float(np.abs(foot).max(initial=0.0))
    if float(np.sqrt(np.mean(np.sum(to_line**2, axis=1)))) > 1e-12 * spread:
        return centre, float(length)
    size = float(np.sqrt(np.mean(np.sum((hinge_pivots(mech)[revolute] - centre) ** 2, axis=1))))
    return centre, size if size > 1e-12 * spread else 1.0


def loop_weights(mech: Mechanism) -> Array:
    """``(loops, loops)`` the weights that combine the loops' residuals before their size is taken:
    ``sqrt(n / l) (Z Z^T)^(-1/2)`` for the signed loop-joint incidence ``Z`` (``l`` loops over ``n`` joints in some
    loop; :func:`linkwork.kinematics.normalization.cycle_metric`), the loops made orthonormal over the cycle space.

    Another body held as the ground gives the body graph another cycle basis ``Z' = M Z`` (a six-bar's two loops,
    or one of them and their sum), whose residuals are combined by ``M`` to first order; these weights give the
    stacked residual the same size in every basis, so the misfit does not depend on the ground. The factor makes
    them 1 for a single loop (its misfit is its own residual, as before).
    """
    from linkwork.kinematics.normalization import cycle_metric

    in_loops = {j for loop in mech.loops for j in loop.joints}
    return np.ascontiguousarray(np.sqrt(len(in_loops) / len(mech.loops)) * cycle_metric(mech))
