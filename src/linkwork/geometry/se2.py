"""Planar rigid motions SE(2): rotation matrices and poses ``(x, y, angle)`` as 3x3 homogeneous matrices.

Convention: a pose ``g = (x, y, angle)`` maps body coordinates into the frame it is expressed in,
``p_world = R(angle) p_body + (x, y)``; so ``g_A_C = g_A_B g_B_C`` and :func:`relative` gives ``g_before^-1 g_after``.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013), Eq. (13).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]


def rotation(angle: ArrayLike) -> Array:
    """Rotation matrices ``(..., 2, 2)`` of angles ``(...)`` (radians, counter-clockwise), Eq. (13)."""
    angle = np.asarray(angle, dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([np.stack([c, -s], axis=-1), np.stack([s, c], axis=-1)], axis=-2)


def pose_matrix(pose: ArrayLike) -> Array:
    """``3 x 3`` homogeneous matrix of a planar pose ``(x, y, angle)``."""
    x, y, a = np.asarray(pose, dtype=float)
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, x], [s, c, y], [0.0, 0.0, 1.0]])


def pose_of(matrix: ArrayLike) -> Array:
    """``(x, y, angle)`` of a ``3 x 3`` (or the planar part of a ``4 x 4``) homogeneous matrix."""
    m = np.asarray(matrix, dtype=float)
    t = m[:2, -1]
    return np.array([t[0], t[1], math.atan2(m[1, 0], m[0, 0])])


def apply(pose: ArrayLike, points: ArrayLike) -> Array:
    """Points ``(n, 2)`` (or ``(2,)``) moved by the displacement ``pose``."""
    x, y, a = np.asarray(pose, dtype=float)
    pts = np.asarray(points, dtype=float)
    c, s = math.cos(a), math.sin(a)
    rot = np.array([[c, -s], [s, c]])
    return pts @ rot.T + np.array([x, y])


def relative(before: ArrayLike, after: ArrayLike) -> Array:
    """``(p, 3)`` displacements of ``after`` seen from ``before``: ``g_before^-1 g_after`` per profile."""
    b, a = np.asarray(before, dtype=float), np.asarray(after, dtype=float)
    return np.array(
        [pose_of(np.linalg.inv(pose_matrix(u)) @ pose_matrix(v)) for u, v in zip(b, a, strict=True)]
    )
