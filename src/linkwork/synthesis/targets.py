"""Target profiles (Sec. 2): design polylines resampled at equal arc-length steps near ``piece_length``.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013), Eqs. (3)-(5), (7).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.errors import SpecError
from linkwork.synthesis.frames import arc_length
from linkwork.synthesis.problem import Problem
from linkwork.synthesis.result import TargetProfile

Array = NDArray[np.float64]

__all__ = ["arc_length", "mean_chord", "mean_piece_length", "resample", "target_profile", "target_profiles"]


def _clean_polyline(polyline: ArrayLike, closed: bool) -> Array:
    pts = np.asarray(polyline, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise SpecError(f"Expected a polyline of shape (N, 2), got {pts.shape}")
    if not np.all(np.isfinite(pts)):
        raise SpecError("a profile has a non-finite coordinate")
    # Repeated points make zero-length pieces, which carry no arc length: drop them.
    keep = np.concatenate([[True], np.any(np.diff(pts, axis=0) != 0.0, axis=1)])
    pts = pts[keep]
    if closed and np.any(pts[-1] != pts[0]):
        pts = np.vstack([pts, pts[:1]])
    if len(pts) < 2:
        raise SpecError("a profile needs at least two distinct points")
    return pts


def resample(polyline: ArrayLike, pieces: int) -> Array:
    """``pieces + 1`` points at equal arc-length increments ``C_j / m_j`` along a polyline (Sec. 2).

    The first and last points are the polyline's own end points.
    """
    pts = np.asarray(polyline, dtype=float)
    station = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    s = np.linspace(0.0, station[-1], pieces + 1)
    out = np.column_stack([np.interp(s, station, pts[:, 0]), np.interp(s, station, pts[:, 1])])
    out[0], out[-1] = pts[0], pts[-1]
    return out


def mean_chord(points: ArrayLike) -> float:
    """``s_bar_j = S_j / m_j``, the mean piece length of a target polyline (Eqs. 4, 5)."""
    pts = np.asarray(points, dtype=float)
    return arc_length(pts) / (len(pts) - 1)


def target_profile(
    polyline: ArrayLike, piece_length: float, *, closed: bool = False, name: str = ""
) -> TargetProfile:
    """The target profile of one design profile (Sec. 2).

    Start from ``m_j = ceil(C_j / s_d)`` pieces (Eq. 3) and remove pieces while the error
    ``|s_d - s_bar_j|`` of the mean chord (Eq. 5) does not grow; the fewest such pieces win.

    Parameters
    ----------
    polyline
        ``(N, 2)`` design profile.
    piece_length
        ``s_d``, the desired piece length.
    closed
        Whether the profile is a closed curve (its target then lists the first point again at the end).
    name
        The profile's name.
    """
    if not piece_length > 0.0 or not math.isfinite(piece_length):
        raise SpecError(f"piece_length must be a positive number, got {piece_length!r}", key="piece_length")
    pts = _clean_polyline(polyline, closed)
    total = arc_length(pts)
    m = max(1, math.ceil(total / piece_length))  # Eq. (3)
    points = resample(pts, m)
    err = abs(piece_length - mean_chord(points))
    while m > 1:
        fewer = resample(pts, m - 1)
        fewer_err = abs(piece_length - mean_chord(fewer))
        if fewer_err > err:
            break
        m, points, err = m - 1, fewer, fewer_err
    return TargetProfile(
        points=points, arc_length=total, pieces=m, target_length=mean_chord(points), name=name
    )


def target_profiles(problem: Problem) -> tuple[TargetProfile, ...]:
    """The target profile of every design profile of ``problem``."""
    names = problem.names or tuple(str(j + 1) for j in range(problem.count))
    return tuple(
        target_profile(prof, problem.piece_length, closed=problem.kind == "closed", name=name)
        for prof, name in zip(problem.profiles, names, strict=False)
    )


def mean_piece_length(targets: tuple[TargetProfile, ...]) -> float:
    """``s_bar_m``, the mean length of all pieces of all target profiles (Eq. 7)."""
    return sum(t.length for t in targets) / sum(t.pieces for t in targets)
