"""Error-only kernels of the segment fits (Eq. 21), lean enough for the inner loop of the search.

They compute exactly what :func:`~linkwork.synthesis.mean_segment.fit_mean_segment` and
:func:`~linkwork.synthesis.arc_segment.fit_arc_segment` compute, without building the fitted shapes: curvature
and chord sums come from per-profile prefix sums, every C-instance is a prefix of one arc, and registration
error is evaluated in centred coordinates (the translation cancels).

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013), Eqs. (12)-(21).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from linkwork.synthesis import compiled
from linkwork.synthesis.arc_segment import arc_points, discrete_curvature

Array = NDArray[np.float64]


def _best_turn(dot: Array, cross: Array) -> tuple[Array, Array]:
    """``(cos, sin)``, each ``(p, 1)``, of the best rotation of centred point sets whose summed dot and cross
    products are ``dot``, ``cross`` ``(p,)`` (the planar rigid registration); coincident points give the
    identity."""
    h = np.hypot(dot, cross)
    safe = np.where(h > 0.0, h, 1.0)
    c = np.where(h > 0.0, dot / safe, 1.0)[:, None]
    s = np.where(h > 0.0, cross / safe, 0.0)[:, None]
    return c, s


def _aligned_errors(src: Array, tgt: Array) -> Array:
    """``(p,)`` largest distance after the best rigid registration of ``src (p, n, 2)`` onto ``tgt``."""
    a = src - src.mean(axis=1, keepdims=True)
    b = tgt - tgt.mean(axis=1, keepdims=True)
    ax, ay, bx, by = a[..., 0], a[..., 1], b[..., 0], b[..., 1]
    dot = np.einsum("pn,pn->p", ax, bx) + np.einsum("pn,pn->p", ay, by)
    cross = np.einsum("pn,pn->p", ax, by) - np.einsum("pn,pn->p", ay, bx)
    c, s = _best_turn(dot, cross)
    rx = c * ax - s * ay - bx
    ry = s * ax + c * ay - by
    return np.sqrt(np.max(rx * rx + ry * ry, axis=1))


class ProfileTables:
    """Prefix sums of chord lengths and interior curvatures of the target profiles.

    Parameters
    ----------
    points
        The target profiles' points.
    compiled
        Use the numba kernels of :mod:`~linkwork.synthesis.compiled` (default); ``False`` uses numpy.
    """

    def __init__(self, points: Sequence[Array], *, compiled: bool = True) -> None:
        self.points = [np.asarray(z, dtype=float) for z in points]
        self.compiled = compiled
        self.stacked = np.ascontiguousarray(np.vstack(self.points))
        self.offsets = np.concatenate([[0], np.cumsum([len(z) for z in self.points])[:-1]]).astype(np.int64)
        self.chord_sum = [
            np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(z, axis=0), axis=1))])
            for z in self.points
        ]
        # curvature_sum[j][i] = sum of the curvatures of points 1 .. i - 1 of profile j
        self.curvature_sum = [
            np.concatenate([[0.0, 0.0], np.cumsum(discrete_curvature(z))]) for z in self.points
        ]

    def mean_errors(self, starts: Sequence[int], pieces: int) -> Array:
        """``(p,)`` errors of an M-segment of ``pieces`` pieces from ``starts`` (Eqs. 12-15, 21)."""
        if self.compiled:
            return compiled.mean_fits(
                self.stacked, self.offsets, np.asarray(starts, dtype=np.int64), int(pieces), False
            )
        z = np.stack([pts[s : s + pieces + 1] for pts, s in zip(self.points, starts, strict=True)])
        first = np.broadcast_to(z[0], z.shape)
        a = z - z.mean(axis=1, keepdims=True)
        b = first - first.mean(axis=1, keepdims=True)
        dot = np.einsum("pni,pni->p", a, b)
        cross = np.einsum("pn,pn->p", a[..., 0], b[..., 1]) - np.einsum("pn,pn->p", a[..., 1], b[..., 0])
        c, s = _best_turn(dot, cross)
        # Eqs. (12)-(14): every piece moved onto profile 1 (centred there), then averaged
        shifted_x = c * a[..., 0] - s * a[..., 1]
        shifted_y = s * a[..., 0] + c * a[..., 1]
        mean = np.stack([shifted_x.mean(axis=0), shifted_y.mean(axis=0)], axis=-1)
        return _aligned_errors(np.broadcast_to(mean, z.shape), z)  # Eqs. (15), (21)

    def arc_errors(self, starts: Sequence[int], pieces: Sequence[int]) -> Array:
        """``(p,)`` errors of a C-segment with ``pieces[j]`` pieces from ``starts[j]`` (Eqs. 16-21)."""
        kappa_total = 0.0
        interior = 0
        s_bar = 0.0
        for cs, ks, s, m in zip(self.chord_sum, self.curvature_sum, starts, pieces, strict=True):
            s_bar += (cs[s + m] - cs[s]) / m
            if m > 1:
                kappa_total += ks[s + m] - ks[s + 1]
                interior += m - 1
        s_bar /= len(pieces)  # Eq. (20) with its 1/p
        kappa = kappa_total / interior if interior else 0.0  # Eq. (18), averaging 1/r
        if self.compiled:
            return compiled.arc_fits(
                self.stacked,
                self.offsets,
                np.asarray(starts, dtype=np.int64),
                np.asarray(pieces, dtype=np.int64),
                kappa,
                s_bar,
                False,
            )
        arc = arc_points(kappa, s_bar, int(max(pieces)))
        out = np.empty(len(pieces))
        for j, (pts, s, m) in enumerate(zip(self.points, starts, pieces, strict=True)):
            out[j] = _aligned_errors(arc[None, : m + 1], pts[None, s : s + m + 1])[0]
        return out
