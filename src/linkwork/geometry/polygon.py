"""Plane polygons: which points lie inside (the even-odd rule), for regions a designer allows pivots in."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


def contains(polygon: ArrayLike, points: ArrayLike) -> NDArray[np.bool_]:
    """``(n,)`` True where ``points`` ``(n, 2)`` lie strictly inside the closed ``polygon`` ``(k, 2)``.

    The even-odd (crossing-number) rule: a horizontal ray from the point crosses the boundary an odd number of
    times. The polygon is closed from its last vertex back to its first; a repeated closing vertex is harmless.
    Points on the boundary may go either way.

    Examples
    --------
    >>> contains([[0, 0], [1, 0], [1, 1], [0, 1]], [[0.5, 0.5], [1.5, 0.5]]).tolist()
    [True, False]
    """
    poly = np.asarray(polygon, dtype=float)
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    if poly.ndim != 2 or poly.shape[1] != 2 or len(poly) < 3:
        raise ValueError(f"Expected a polygon of shape (k >= 3, 2), got {poly.shape}")
    if pts.shape[1] != 2:
        raise ValueError(f"Expected points of shape (n, 2), got {pts.shape}")
    a = poly[:, None, :]
    b = np.roll(poly, -1, axis=0)[:, None, :]
    x, y = pts[None, :, 0], pts[None, :, 1]
    straddles = (a[..., 1] > y) != (b[..., 1] > y)
    dy = np.where(straddles, b[..., 1] - a[..., 1], 1.0)
    x_cross = a[..., 0] + (y - a[..., 1]) * (b[..., 0] - a[..., 0]) / dy
    crossings = np.sum(straddles & (x < x_cross), axis=0)
    return np.asarray(crossings % 2 == 1)
