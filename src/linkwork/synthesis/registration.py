"""Least-squares planar registration of corresponding point sets: rotation and translation, optionally scale.

The closed form of Umeyama (1991) specialised to the plane: for centred point sets ``x`` (source) and ``y``
(target) the best rotation angle is ``atan2(sum x ^ y, sum x . y)`` (``^`` the planar cross product), which is
always a proper rotation, so no reflection can occur. Works over leading batch axes.

References
----------
S. Umeyama, Least-squares estimation of transformation parameters between two point patterns,
IEEE Trans. Pattern Anal. Mach. Intell. 13 (4) (1991) 376-380.
K. S. Arun, T. S. Huang, S. D. Blostein, Least-squares fitting of two 3-D point sets, IEEE Trans. PAMI
9 (5) (1987) 698-700.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.synthesis.frames import rotation

Array = NDArray[np.float64]


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
