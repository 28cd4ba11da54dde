"""numba-compiled segment errors (Eq. 21) for the search's inner loop.

The same arithmetic as :mod:`~linkwork.synthesis.error_kernels` (the numpy reference), point by point. All
profiles' target points are stacked in one ``(N, 2)`` array; profile ``j`` starts at row ``offsets[j]``.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013),
Eqs. (12)-(15), (19), (21).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from linkwork.kernel_cache import kernel

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]


@kernel(inline="always")
def _centroid(points: Array) -> tuple[float, float]:  # pragma: no cover - compiled
    """Mean of ``points (n, 2)``, summed in order."""
    n = points.shape[0]
    mx = my = 0.0
    for i in range(n):
        mx += points[i, 0]
        my += points[i, 1]
    return mx / n, my / n


@kernel(inline="always")
def _best_turn(
    src: Array, tgt: Array, ms: tuple[float, float], mt: tuple[float, float]
) -> tuple[float, float]:  # pragma: no cover - compiled
    """``(cos, sin)`` of the rotation that best maps ``src`` onto ``tgt``, centred at ``ms`` and ``mt``.

    The planar closed form of the rigid registration (Umeyama 1991; :func:`linkwork.geometry.fit.register`): the
    angle of ``(sum a . b, sum a ^ b)``; coincident points give the identity.
    """
    dot = cross = 0.0
    for i in range(src.shape[0]):
        ax, ay = src[i, 0] - ms[0], src[i, 1] - ms[1]
        bx, by = tgt[i, 0] - mt[0], tgt[i, 1] - mt[1]
        dot += ax * bx + ay * by
        cross += ax * by - ay * bx
    h = math.hypot(dot, cross)
    return (dot / h, cross / h) if h > 0.0 else (1.0, 0.0)


@kernel(inline="always")
def _aligned_distance(src: Array, tgt: Array, rms: bool) -> float:  # pragma: no cover - compiled
    """Largest (or with ``rms`` the root mean square) distance after the best rigid registration of
    ``src (n, 2)`` onto ``tgt (n, 2)``: the one kernel behind both the error (Eq. 21) and :func:`fit_bound`.

    Inlined where it is called (as are :func:`_fit` and its own steps), so that numba compiles each caller with
    ``rms`` known and the loop holds only the branch taken: one source, no cost over two separate kernels.
    """
    ms, mt = _centroid(src), _centroid(tgt)
    c, s = _best_turn(src, tgt, ms, mt)
    acc = 0.0
    for i in range(src.shape[0]):
        ax, ay = src[i, 0] - ms[0], src[i, 1] - ms[1]
        rx = c * ax - s * ay - (tgt[i, 0] - mt[0])
        ry = s * ax + c * ay - (tgt[i, 1] - mt[1])
        d2 = rx * rx + ry * ry
        if rms:
            acc += d2
        else:
            acc = max(acc, d2)
    return math.sqrt(acc / src.shape[0]) if rms else math.sqrt(acc)


@kernel()
def fit_bound(src: Array, tgt: Array) -> float:  # pragma: no cover - compiled
    """A lower bound on the largest distance of ANY rigid placement of ``src (n, 2)`` against ``tgt (n, 2)``.

    The largest of: the RMS of the best rigid fit of all points, the RMS of the best fit of the first, middle
    and last points alone (a placement's largest distance is at least the RMS of any subset, which is at least
    that subset's best fit), and half the change of each of their three mutual distances (a rigid motion keeps
    distances, so ``d_a + d_b >= | |S_a - S_b| - |T_a - T_b| |``).
    """
    n = src.shape[0]
    best = _aligned_distance(src, tgt, True)
    idx = np.array([0, n // 2, n - 1])
    s3 = np.empty((3, 2))
    t3 = np.empty((3, 2))
    for k in range(3):
        s3[k] = src[idx[k]]
        t3[k] = tgt[idx[k]]
    best = max(best, _aligned_distance(s3, t3, True))
    for a in range(3):
        for b in range(a + 1, 3):
            ds = math.hypot(s3[a, 0] - s3[b, 0], s3[a, 1] - s3[b, 1])
            dt = math.hypot(t3[a, 0] - t3[b, 0], t3[a, 1] - t3[b, 1])
            best = max(best, 0.5 * abs(ds - dt))
    return best


@kernel(inline="always")
def _fit(src: Array, tgt: Array, bound: bool) -> float:  # pragma: no cover - compiled
    """The error of ``src`` registered onto ``tgt`` (Eq. 21), or with ``bound`` its :func:`fit_bound`."""
    return fit_bound(src, tgt) if bound else _aligned_distance(src, tgt, False)


@kernel()
def _mean_shape(points: Array, offsets: IntArray, starts: IntArray, pieces: int) -> tuple[Array, Array]:
    """``(z, mean)``: the pieces ``(p, n, 2)`` and their mean shape in profile 1's frame (Eqs. 12-14)."""
    p = starts.shape[0]
    n = pieces + 1
    z = np.empty((p, n, 2))
    for j in range(p):
        z[j] = points[offsets[j] + starts[j] : offsets[j] + starts[j] + n]
    mean = np.zeros((n, 2))
    mr = _centroid(z[0])
    for j in range(p):
        m = _centroid(z[j])
        c, s = (1.0, 0.0) if j == 0 else _best_turn(z[j], z[0], m, mr)
        for i in range(n):
            ax, ay = z[j, i, 0] - m[0], z[j, i, 1] - m[1]
            mean[i, 0] += (c * ax - s * ay + mr[0]) / p
            mean[i, 1] += (s * ax + c * ay + mr[1]) / p
    return z, mean


@kernel()
def mean_fits(
    points: Array, offsets: IntArray, starts: IntArray, pieces: int, bound: bool
) -> Array:  # pragma: no cover - compiled
    """``(p,)`` errors of an M-segment (Eqs. 12-15, 21), or with ``bound`` the :func:`fit_bound` of its shape
    on each profile."""
    z, mean = _mean_shape(points, offsets, starts, pieces)
    out = np.empty(starts.shape[0])
    for j in range(starts.shape[0]):
        out[j] = _fit(mean, z[j], bound)
    return out


@kernel()
def _arc(pieces: IntArray, curvature: float, piece_length: float) -> Array:  # pragma: no cover - compiled
    """The arc of the longest instance: equal chords ``piece_length``, each turning by the same angle."""
    longest = 0
    for j in range(pieces.shape[0]):
        longest = max(longest, pieces[j])
    half = min(1.0, max(-1.0, 0.5 * curvature * piece_length))
    turn = 2.0 * math.asin(half)
    arc = np.zeros((longest + 1, 2))
    for i in range(longest):
        arc[i + 1, 0] = arc[i, 0] + piece_length * math.cos(turn * i)
        arc[i + 1, 1] = arc[i, 1] + piece_length * math.sin(turn * i)
    return arc


@kernel()
def arc_fits(
    points: Array,
    offsets: IntArray,
    starts: IntArray,
    pieces: IntArray,
    curvature: float,
    piece_length: float,
    bound: bool,
) -> Array:  # pragma: no cover - compiled
    """``(p,)`` errors of the C-segment of ``curvature`` and ``piece_length`` (Eqs. 19, 21), or with ``bound``
    the :func:`fit_bound` of its instance on each profile."""
    arc = _arc(pieces, curvature, piece_length)
    out = np.empty(starts.shape[0])
    for j in range(starts.shape[0]):
        lo = offsets[j] + starts[j]
        out[j] = _fit(arc[: pieces[j] + 1], points[lo : lo + pieces[j] + 1], bound)
    return out
