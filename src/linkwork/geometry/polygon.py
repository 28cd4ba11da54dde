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


def is_simple(polygon: ArrayLike) -> bool:
    """Whether the closed polygon ``(n, 2)`` (n >= 3) is simple: no two of its edges meet but neighbours at their
    shared vertex, and no edge has zero length (a bow tie, whose inside is ambiguous, is not). Exact orientation
    tests on every pair of edges (a ground region has a handful of vertices)."""
    p = np.asarray(polygon, dtype=float)
    n = len(p)
    edges = [(p[i], p[(i + 1) % n]) for i in range(n)]
    if any(np.array_equal(a, b) for a, b in edges):
        return False

    def orient(a: NDArray[np.float64], b: NDArray[np.float64], c: NDArray[np.float64]) -> float:
        return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    def on_segment(a: NDArray[np.float64], b: NDArray[np.float64], c: NDArray[np.float64]) -> bool:
        return bool(min(a[0], b[0]) <= c[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= c[1] <= max(a[1], b[1]))

    def meet(
        a: NDArray[np.float64], b: NDArray[np.float64], c: NDArray[np.float64], d: NDArray[np.float64]
    ) -> bool:
        d1, d2, d3, d4 = orient(c, d, a), orient(c, d, b), orient(a, b, c), orient(a, b, d)
        if ((d1 > 0 > d2) or (d1 < 0 < d2)) and ((d3 > 0 > d4) or (d3 < 0 < d4)):
            return True
        return (
            (d1 == 0 and on_segment(c, d, a))
            or (d2 == 0 and on_segment(c, d, b))
            or (d3 == 0 and on_segment(a, b, c))
            or (d4 == 0 and on_segment(a, b, d))
        )

    for i in range(n):
        for j in range(i + 1, n):
            if j == i + 1 or (i == 0 and j == n - 1):  # neighbours share a vertex
                if n == 3 or not _folds_back(edges[i], edges[j]):
                    continue
                return False
            if meet(*edges[i], *edges[j]):
                return False
    return True


def _folds_back(
    e: tuple[NDArray[np.float64], NDArray[np.float64]], f: tuple[NDArray[np.float64], NDArray[np.float64]]
) -> bool:
    """Whether two neighbouring edges overlap along a line (the polygon doubles back on itself)."""
    shared = next((v for v in e if any(np.array_equal(v, w) for w in f)), None)
    if shared is None:
        return False
    a = next(v for v in e if not np.array_equal(v, shared))
    b = next(v for v in f if not np.array_equal(v, shared))
    cross = (a[0] - shared[0]) * (b[1] - shared[1]) - (a[1] - shared[1]) * (b[0] - shared[0])
    dot = (a[0] - shared[0]) * (b[0] - shared[0]) + (a[1] - shared[1]) * (b[1] - shared[1])
    return bool(cross == 0 and dot > 0)
