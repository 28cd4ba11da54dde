"""Least-squares rigid fits of corresponding point sets: the one home of Kabsch (3-D) and Umeyama (planar).

:func:`kabsch` is the proper rigid motion (no reflection) that best maps 3-D points onto 3-D points (used to steady
drawings and to place solids); :func:`register` is the planar closed form of Umeyama (1991): for centred point sets
``x`` (source) and ``y`` (target) the best rotation angle is ``atan2(sum x ^ y, sum x . y)`` (``^`` the planar cross
product), always a proper rotation, optionally with a uniform scale. Both work over leading batch axes where noted.

References
----------
W. Kabsch, A solution for the best rotation to relate two sets of vectors, Acta Cryst. A32 (1976) 922-923.
S. Umeyama, Least-squares estimation of transformation parameters between two point patterns,
IEEE Trans. Pattern Anal. Mach. Intell. 13 (4) (1991) 376-380.
K. S. Arun, T. S. Huang, S. D. Blostein, Least-squares fitting of two 3-D point sets, IEEE Trans. PAMI
9 (5) (1987) 698-700.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.geometry.se2 import rotation

Array = NDArray[np.float64]


def kabsch(source: ArrayLike, target: ArrayLike) -> Array:
    """The ``4 x 4`` proper rigid transform ``T`` minimising ``sum_i |T source_i - target_i|^2`` (points ``(n, 3)``).

    The sign correction ``D = diag(1, 1, det(V U^T))`` keeps the rotation proper (Kabsch 1976; Arun et al. 1987).
    """
    src = np.asarray(source, dtype=float)
    dst = np.asarray(target, dtype=float)
    if src.shape != dst.shape or src.ndim != 2 or src.shape[1] != 3:
        raise ValueError(f"Expected two point sets of equal shape (n, 3), got {src.shape} and {dst.shape}")
    cs, cd = src.mean(axis=0), dst.mean(axis=0)
    U, _, Vt = np.linalg.svd((src - cs).T @ (dst - cd))
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T))])
    R = Vt.T @ D @ U.T
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = cd - R @ cs
    return T


@dataclass(frozen=True)
class PlanarTransform:
    """The similarity ``y = scale * R(angle) x + translation``, batched over leading axes.

    Shapes: ``angle (...)``, ``translation (..., 2)``, ``scale (...)``.
    """

    angle: Array
    translation: Array
    scale: Array

    @property
    def matrix(self) -> Array:
        """``(..., 2, 2)`` the linear part ``scale * R(angle)``."""
        return np.asarray(self.scale)[..., None, None] * rotation(self.angle)

    def apply(self, points: ArrayLike) -> Array:
        """Transform points ``(..., n, 2)``."""
        pts = np.asarray(points, dtype=float)
        return np.einsum("...ab,...nb->...na", self.matrix, pts) + np.asarray(self.translation)[..., None, :]


def register(source: ArrayLike, target: ArrayLike, *, with_scale: bool = False) -> PlanarTransform:
    """The transform that best maps ``source`` onto ``target`` in the least-squares sense.

    Parameters
    ----------
    source, target
        Corresponding points, ``(..., n, 2)`` each.
    with_scale
        Also estimate a uniform scale (Umeyama's similarity); by default the scale is 1 (a rigid motion).

    Returns
    -------
    PlanarTransform
        Minimises ``sum_i |target_i - (s R source_i + t)|^2``. Coincident source points give angle 0.
    """
    x = np.asarray(source, dtype=float)
    y = np.asarray(target, dtype=float)
    if x.shape != y.shape or x.shape[-1:] != (2,) or x.ndim < 2:
        raise ValueError(f"Expected two point sets of equal shape (..., n, 2), got {x.shape} and {y.shape}")
    mx, my = x.mean(axis=-2), y.mean(axis=-2)
    xc, yc = x - mx[..., None, :], y - my[..., None, :]
    dot = np.sum(xc[..., 0] * yc[..., 0] + xc[..., 1] * yc[..., 1], axis=-1)
    cross = np.sum(xc[..., 0] * yc[..., 1] - xc[..., 1] * yc[..., 0], axis=-1)
    angle = np.arctan2(cross, dot)
    if with_scale:
        # Umeyama's Eq. (42): c = tr(D S) / sigma_x^2; in the plane tr(D S) = |(dot, cross)| / n.
        var = np.sum(xc * xc, axis=(-2, -1))
        scale = np.divide(np.hypot(dot, cross), var, out=np.ones_like(var), where=var > 0)
    else:
        scale = np.ones_like(angle)
    c, s = np.cos(angle) * scale, np.sin(angle) * scale
    translation = np.stack(
        [my[..., 0] - (c * mx[..., 0] - s * mx[..., 1]), my[..., 1] - (s * mx[..., 0] + c * mx[..., 1])],
        axis=-1,
    )
    return PlanarTransform(angle=np.asarray(angle), translation=translation, scale=np.asarray(scale))
