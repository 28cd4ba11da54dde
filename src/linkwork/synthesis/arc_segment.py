"""C-segments (Sec. 3.4): constant-curvature arcs of one curvature and one piece length, and m_j pieces each.

The paper averages the radius of curvature (Eq. 18); we average the signed curvature ``1/r``, which stays
bounded on nearly straight pieces. Eq. (20) lacks its ``1/p``: the mean piece length is a mean over profiles.
An instance with ``m_j`` pieces is the polyline of ``m_j`` equal chords ``s_bar`` inscribed in the circle of
curvature ``kappa``, so its length is ``L_j = m_j s_bar`` (Eq. 19) and it matches a target profile sampled on
a circle exactly.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013), Eqs. (15)-(21).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.geometry.fit import register

Array = NDArray[np.float64]


def discrete_curvature(points: ArrayLike) -> Array:
    """Signed curvature ``1 / r_i`` at the interior points of a polyline ``(n, 2)``, shape ``(n - 2,)``.

    ``r_i`` is the radius of the circle through ``z_{i-1}, z_i, z_{i+1}`` (Eq. 16); the sign is that of
    ``det[P_i P_{i+1}]`` (Eq. 17), positive turning counter-clockwise. Collinear points give 0.
    """
    z = np.asarray(points, dtype=float)
    a = z[1:-1] - z[:-2]  # P_i
    b = z[2:] - z[1:-1]  # P_{i+1}
    c = z[2:] - z[:-2]
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    # 1 / r = 2 sin(theta) / |z_{i+1} - z_{i-1}| = 2 (a x b) / (|a| |b| |c|)
    denom = np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1) * np.linalg.norm(c, axis=1)
    return np.divide(2.0 * cross, denom, out=np.zeros_like(cross), where=denom > 0.0)


def arc_points(curvature: float, piece_length: float, pieces: int) -> Array:
    """``(pieces + 1, 2)`` points of ``pieces`` equal chords ``piece_length`` on a circle of ``curvature``.

    Starts at the origin heading along ``+x``; straight when ``curvature == 0``. A chord longer than the
    diameter is impossible, so ``|curvature|`` is capped at ``2 / piece_length`` (a half turn per piece).
    """
    half = np.clip(0.5 * curvature * piece_length, -1.0, 1.0)
    turn = 2.0 * np.arcsin(half)  # exterior angle between consecutive chords of a regular inscribed polygon
    heading = turn * np.arange(pieces)
    steps = piece_length * np.column_stack([np.cos(heading), np.sin(heading)])
    return np.vstack([np.zeros((1, 2)), np.cumsum(steps, axis=0)])


@dataclass(frozen=True)
class ArcFit:
    """A C-segment fitted to ``p`` pieces.

    Attributes
    ----------
    curvature
        Mean signed curvature over the interior points of every piece.
    piece_length
        ``s_bar^e``, the mean over profiles of each piece's mean chord (Eq. 20 with ``1/p``).
    instances
        Per profile ``(m_j + 1, 2)``: the arc of ``m_j`` chords registered onto that profile's piece (Eq. 15).
    errors
        ``(p,)`` largest point-to-point distance per profile (Eq. 21).
    """

    curvature: float
    piece_length: float
    instances: tuple[Array, ...]
    errors: Array


def fit_arc_segment(pieces: Sequence[ArrayLike]) -> ArcFit:
    """Fit one C-segment to the pieces ``(m_j + 1, 2)`` of the ``p`` target profiles (Sec. 3.4)."""
    zs = [np.asarray(z, dtype=float) for z in pieces]
    kappa = np.concatenate([discrete_curvature(z) for z in zs])
    curvature = float(kappa.mean()) if kappa.size else 0.0  # Eq. (18), averaging 1/r
    chords = [np.linalg.norm(np.diff(z, axis=0), axis=1) for z in zs]
    piece_length = float(np.mean([c.mean() for c in chords]))  # Eq. (20) with its 1/p
    instances = []
    errors = np.empty(len(zs))
    for j, z in enumerate(zs):
        arc = arc_points(curvature, piece_length, len(z) - 1)  # Eq. (19)
        inst = register(arc, z).apply(arc)  # Eq. (15)
        instances.append(inst)
        errors[j] = np.sqrt(np.max(np.sum((inst - z) ** 2, axis=1)))  # Eq. (21)
    return ArcFit(curvature=curvature, piece_length=piece_length, instances=tuple(instances), errors=errors)
