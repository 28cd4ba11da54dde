"""Prismatic binary links (PR sliders): a slider on a straight guide fixed to the frame (or to a body), pivoted
to the moving body, where an RR dyad could go.

A PR slider is the RR dyad whose fixed pivot has gone to infinity: its moving pivot ``m`` must travel on a
straight line of the anchor (McCarthy, *Geometric Design of Linkages*, ch. 4: the *slider points*). For three
positions the slider points along any line ``m = g + t v`` of the body are the roots of the quadratic
``cross(W_2(m) - W_1(m), W_3(m) - W_1(m)) = 0`` (``W_j`` linear in ``t``): exact. For more positions the line
through the positions is fitted (total least squares) and its largest distance is the structural error. The
slider's joint is prismatic, so it can be the drive (the paper's seat, Fig. 14: "actuated via any one of the
five prismatic joints").
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from linkwork.mechanization.guidance import positions

Array = NDArray[np.float64]


def slider_points(poses: Array, origin: Array, direction: Array, reach: float) -> list[Array]:
    """Slider points on the line ``origin + t direction`` (``|t| <= reach``): where the positions of the first,
    middle and last pose are collinear (roots of a quadratic in ``t``)."""
    g = np.asarray(poses, dtype=float)
    pick = [0, len(g) // 2, len(g) - 1] if len(g) > 3 else [0, 1, 2]
    a0 = positions(g[pick], origin)
    a1 = positions(g[pick], origin + direction) - a0  # W_k(origin + t v) = a0_k + t a1_k
    p0, p1 = a0[1] - a0[0], a1[1] - a1[0]
    q0, q1 = a0[2] - a0[0], a1[2] - a1[0]

    def cross(u: Array, w: Array) -> float:
        return float(u[0] * w[1] - u[1] * w[0])

    coeffs = [cross(p1, q1), cross(p0, q1) + cross(p1, q0), cross(p0, q0)]
    if not np.any(coeffs):
        return []
    roots = np.roots(coeffs) if abs(coeffs[0]) > 1e-14 * max(map(abs, coeffs)) else np.roots(coeffs[1:])
    out = []
    for r in roots:
        if abs(r.imag) <= 1e-9 * max(1.0, abs(r)) and abs(r.real) <= reach:
            out.append(origin + float(r.real) * direction)
    return out


def fit_guide(poses: Array, point: Array) -> tuple[Array, Array, Array, float]:
    """The guide of the slider at body point ``point``: ``(start, direction, travel, error)``.

    ``start`` is the point's first position, ``direction`` the unit direction of the line fitted through its
    positions (pointing from the first towards the last), ``travel`` ``(p,)`` the positions' coordinates along
    it (0 first), ``error`` the largest distance of a position from the line (0 for an exact slider point).
    """
    w = positions(poses, point)
    centre = w.mean(axis=0)
    _, _, vt = np.linalg.svd(w - centre)
    u = vt[0]
    if float((w[-1] - w[0]) @ u) < 0:
        u = -u
    start = centre + float((w[0] - centre) @ u) * u
    normal = np.array([-u[1], u[0]])
    error = float(np.max(np.abs((w - centre) @ normal)))
    return start, u, (w - start) @ u, error


def transmission(direction: Array, free: Array) -> Array:
    """Sine of a slider's transmission angle on every profile: the guide reacts along its normal, the pivot is
    free to move along ``free`` ``(p, 2)``; ``direction`` ``(p, 2)`` the guide's direction in the world."""
    normal = np.column_stack([-direction[:, 1], direction[:, 0]])
    return np.asarray(np.sum(normal * free, axis=1))


def monotonic(travel: Array, size: float) -> bool:
    """The slider moves one way along its guide through the profiles, by a visible amount."""
    steps = np.diff(travel)
    return bool(np.all(steps > 1e-6 * size)) and math.isfinite(float(travel[-1]))
