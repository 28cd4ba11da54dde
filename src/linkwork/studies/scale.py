"""The linkage's own scale for misfits: a centre point ``c`` and a length ``L`` defined by the hinge lines.

A closure misfit is a small twist ``(omega, v)`` (rotation and translation left over when the loop is forced
shut). Its size is measured as ``|(L omega, v + omega x c)|``: the rotation times the linkage's length scale plus
the translation of the point ``c``, so that the number is a length, in the linkage's units, and does not change
when the linkage is moved, turned or relabelled, and scales with it.

``c`` is the point nearest (least squares) to every revolute hinge line, ``L`` the root-mean-square distance of
the hinge lines from ``c`` (for concurrent lines, e.g. a spherical linkage, the RMS distance of their reference
points from ``c``; 1 if that is zero too). This module is the one place to switch to the project's normalised
Jacobian once it exists.
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
    w = mech.twists[:, :3]
    revolute = np.einsum("ij,ij->i", w, w) > 0.5
    if not np.any(revolute):
        centre, length = np.zeros(3), 1.0
    else:
        p0 = line_points(mech)[revolute]
        wr = w[revolute]
        proj = np.eye(3)[None, :, :] - wr[:, :, None] * wr[:, None, :]
        A = proj.sum(axis=0)
        b = np.einsum("kij,kj->i", proj, p0)
        centre = np.linalg.lstsq(A, b, rcond=1e-10)[0]
        pts = line_points(mech, centre)[revolute]
        length = float(np.sqrt(np.mean(np.sum((pts - centre) ** 2, axis=1))))
        if length < 1e-12:
            length = float(np.sqrt(np.mean(np.sum((p0 - centre) ** 2, axis=1)))) or 1.0
    T = np.zeros((6, 6))
    T[:3, :3] = length * np.eye(3)
    T[3:, 3:] = np.eye(3)
    T[3:, :3] = -hat3(centre)  # omega x c = -c x omega
    return MisfitScale(centre=centre, length=length, weight=T)
