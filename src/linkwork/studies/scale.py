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
    T = np.zeros((6, 6))
    T[:3, :3] = length * np.eye(3)
    T[3:, 3:] = np.eye(3)
    T[3:, :3] = -hat3(centre)  # omega x c = -c x omega
    return MisfitScale(centre=centre, length=length, weight=T)


def centre_and_length(mech: Mechanism) -> tuple[Array, float]:
    """The linkage's centre ``c`` and length ``L`` at its reference: those of the project's normalised Jacobian
    (:func:`linkwork.kinematics.normalization.hinge_centre`), so that the misfit and the normalised Sec. 5 ratio
    share one scale."""
    from linkwork.kinematics.normalization import hinge_centre

    centre, length = hinge_centre(mech.twists, mech.joint_types)
    return np.asarray(centre, dtype=float), float(length)
