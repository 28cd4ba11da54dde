"""Planar geometry of segments and profiles: the local frame of a segment (first point at the origin, chord
along ``+x``), chord angles and polyline lengths; planar rotations are :func:`linkwork.geometry.se2.rotation`.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013), Eqs. (1)-(2).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.geometry.se2 import rotation

Array = NDArray[np.float64]

__all__ = ["arc_length", "chord_angle", "rotation", "to_local_frame"]


def arc_length(polyline: ArrayLike) -> float:
    """``C_j``, the arc length of a polyline ``(N, 2)`` (Eqs. 1, 2)."""
    pts = np.asarray(polyline, dtype=float)
    return float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))


def chord_angle(points: ArrayLike) -> Array:
    """Angle ``(...)`` of the chord from the first to the last of ``(..., n, 2)`` points (0 if equal)."""
    pts = np.asarray(points, dtype=float)
    chord = pts[..., -1, :] - pts[..., 0, :]
    return np.arctan2(chord[..., 1], chord[..., 0])


def to_local_frame(points: ArrayLike) -> Array:
    """Points ``(..., n, 2)`` moved so the first is at the origin and the chord lies along ``+x``."""
    pts = np.asarray(points, dtype=float)
    rel = pts - pts[..., :1, :]
    c_s = -chord_angle(pts)
    c, s = np.cos(c_s)[..., None], np.sin(c_s)[..., None]
    return np.stack([c * rel[..., 0] - s * rel[..., 1], s * rel[..., 0] + c * rel[..., 1]], axis=-1)
