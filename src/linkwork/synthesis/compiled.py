"""numba-compiled segment errors (Eq. 21) for the search's inner loop.

The same arithmetic as :mod:`~linkwork.synthesis.error_kernels` (the numpy reference), point by point. All
profiles' target points are stacked in one ``(N, 2)`` array; profile ``j`` starts at row ``offsets[j]``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]


@njit(cache=True)
def _aligned_error(src: Array, tgt: Array) -> float:  # pragma: no cover - compiled
    """Largest distance after the best rigid registration of ``src (n, 2)`` onto ``tgt (n, 2)``."""
    n = src.shape[0]
    msx = msy = mtx = mty = 0.0
    for i in range(n):
        msx += src[i, 0]
        msy += src[i, 1]
        mtx += tgt[i, 0]
        mty += tgt[i, 1]
    msx /= n
    msy /= n
    mtx /= n
    mty /= n
    dot = cross = 0.0
    for i in range(n):
        ax, ay = src[i, 0] - msx, src[i, 1] - msy
        bx, by = tgt[i, 0] - mtx, tgt[i, 1] - mty
        dot += ax * bx + ay * by
        cross += ax * by - ay * bx
    h = math.hypot(dot, cross)
    c, s = (dot / h, cross / h) if h > 0.0 else (1.0, 0.0)
    worst = 0.0
    for i in range(n):
        ax, ay = src[i, 0] - msx, src[i, 1] - msy
        rx = c * ax - s * ay - (tgt[i, 0] - mtx)
        ry = s * ax + c * ay - (tgt[i, 1] - mty)
        worst = max(worst, rx * rx + ry * ry)
    return math.sqrt(worst)


@njit(cache=True)
def _aligned_rms(src: Array, tgt: Array) -> float:  # pragma: no cover - compiled
    """Root mean square distance after the best rigid registration of ``src (n, 2)`` onto ``tgt (n, 2)``."""
    n = src.shape[0]
    msx = msy = mtx = mty = 0.0
    for i in range(n):
        msx += src[i, 0]
        msy += src[i, 1]
        mtx += tgt[i, 0]
        mty += tgt[i, 1]
    msx /= n
    msy /= n
    mtx /= n
    mty /= n
    dot = cross = total = 0.0
    for i in range(n):
        ax, ay = src[i, 0] - msx, src[i, 1] - msy
        bx, by = tgt[i, 0] - mtx, tgt[i, 1] - mty
        dot += ax * bx + ay * by
        cross += ax * by - ay * bx
    h = math.hypot(dot, cross)
    c, s = (dot / h, cross / h) if h > 0.0 else (1.0, 0.0)
    for i in range(n):
        ax, ay = src[i, 0] - msx, src[i, 1] - msy
        rx = c * ax - s * ay - (tgt[i, 0] - mtx)
        ry = s * ax + c * ay - (tgt[i, 1] - mty)
        total += rx * rx + ry * ry
    return math.sqrt(total / n)


@njit(cache=True)
def fit_bound(src: Array, tgt: Array) -> float:  # pragma: no cover - compiled
    """A lower bound on the largest distance of ANY rigid placement of ``src (n, 2)`` against ``tgt (n, 2)``.

    The largest of: the RMS of the best rigid fit of all points, the RMS of the best fit of the first, middle
    and last points alone (a placement's largest distance is at least the RMS of any subset, which is at least
    that subset's best fit), and half the change of each of their three mutual distances (a rigid motion keeps
    distances, so ``d_a + d_b >= | |S_a - S_b| - |T_a - T_b| |``).
    """
    n = src.shape[0]
    best = _aligned_rms(src, tgt)
    idx = np.array([0, n // 2, n - 1])
    s3 = np.empty((3, 2))
    t3 = np.empty((3, 2))
    for k in range(3):
        s3[k] = src[idx[k]]
        t3[k] = tgt[idx[k]]
    best = max(best, _aligned_rms(s3, t3))
    for a in range(3):
        for b in range(a + 1, 3):
            ds = math.hypot(s3[a, 0] - s3[b, 0], s3[a, 1] - s3[b, 1])
            dt = math.hypot(t3[a, 0] - t3[b, 0], t3[a, 1] - t3[b, 1])
            best = max(best, 0.5 * abs(ds - dt))
    return best


@njit(cache=True)
def _mean_shape(points: Array, offsets: IntArray, starts: IntArray, pieces: int) -> tuple[Array, Array]:
    """``(z, mean)``: the pieces ``(p, n, 2)`` and their mean shape in profile 1's frame (Eqs. 12-14)."""
    p = starts.shape[0]
    n = pieces + 1
    z = np.empty((p, n, 2))
    for j in range(p):
        z[j] = points[offsets[j] + starts[j] : offsets[j] + starts[j] + n]
    mean = np.zeros((n, 2))
    ref = z[0]
    mrx = mry = 0.0
    for i in range(n):
        mrx += ref[i, 0]
        mry += ref[i, 1]
    mrx /= n
    mry /= n
    for j in range(p):
        mx = my = 0.0
        for i in range(n):
            mx += z[j, i, 0]
            my += z[j, i, 1]
        mx /= n
        my /= n
        dot = cross = 0.0
        for i in range(n):
            ax, ay = z[j, i, 0] - mx, z[j, i, 1] - my
            bx, by = ref[i, 0] - mrx, ref[i, 1] - mry
            dot += ax * bx + ay * by
            cross += ax * by - ay * bx
        h = math.hypot(dot, cross)
        c, s = (dot / h, cross / h) if h > 0.0 else (1.0, 0.0)
        if j == 0:
            c, s = 1.0, 0.0
        for i in range(n):
            ax, ay = z[j, i, 0] - mx, z[j, i, 1] - my
            mean[i, 0] += (c * ax - s * ay + mrx) / p
            mean[i, 1] += (s * ax + c * ay + mry) / p
    return z, mean


@njit(cache=True)
def mean_errors(points: Array, offsets: IntArray, starts: IntArray, pieces: int) -> Array:  # pragma: no cover
    """``(p,)`` errors of an M-segment (Eqs. 12-15, 21)."""
    z, mean = _mean_shape(points, offsets, starts, pieces)
    out = np.empty(starts.shape[0])
    for j in range(starts.shape[0]):
        out[j] = _aligned_error(mean, z[j])
    return out


@njit(cache=True)
def mean_bound(points: Array, offsets: IntArray, starts: IntArray, pieces: int) -> Array:  # pragma: no cover
    """``(p,)`` :func:`fit_bound` of the M-segment's shape on each profile."""
    z, mean = _mean_shape(points, offsets, starts, pieces)
    out = np.empty(starts.shape[0])
    for j in range(starts.shape[0]):
        out[j] = fit_bound(mean, z[j])
    return out


@njit(cache=True)
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


@njit(cache=True)
def arc_errors(
    points: Array,
    offsets: IntArray,
    starts: IntArray,
    pieces: IntArray,
    curvature: float,
    piece_length: float,
) -> Array:  # pragma: no cover - compiled
    """``(p,)`` errors of the C-segment of ``curvature`` and ``piece_length`` (Eqs. 19, 21)."""
    arc = _arc(pieces, curvature, piece_length)
    out = np.empty(starts.shape[0])
    for j in range(starts.shape[0]):
        lo = offsets[j] + starts[j]
        out[j] = _aligned_error(arc[: pieces[j] + 1], points[lo : lo + pieces[j] + 1])
    return out


@njit(cache=True)
def arc_bound(
    points: Array,
    offsets: IntArray,
    starts: IntArray,
    pieces: IntArray,
    curvature: float,
    piece_length: float,
) -> Array:  # pragma: no cover - compiled
    """``(p,)`` :func:`fit_bound` of the C-segment's instance on each profile."""
    arc = _arc(pieces, curvature, piece_length)
    out = np.empty(starts.shape[0])
    for j in range(starts.shape[0]):
        lo = offsets[j] + starts[j]
        out[j] = fit_bound(arc[: pieces[j] + 1], points[lo : lo + pieces[j] + 1])
    return out


def warm_up() -> None:
    """Compile these kernels into numba's cache (run by the background compile of a first run, see
    :mod:`linkwork.kinematics.jit`), with the argument types the search uses."""
    from linkwork.synthesis.compiled_search import CompiledTables, compiled_rms_bound, compiled_search
    from linkwork.synthesis.error_kernels import ProfileTables

    t = np.linspace(0.0, 1.0, 9)
    curve = np.column_stack([t, 0.1 * np.sin(3.0 * t)])
    tables = ProfileTables([curve, 1.1 * curve], compiled=True)
    tables.mean_errors([0, 1], 4)
    tables.arc_errors([0, 1], [4, 5])
    compiled = CompiledTables.from_tables(tables)  # the segment-matrix search: 8 pieces on both profiles
    start = np.array([[4, 4], [4, 4]], dtype=np.int64)
    compiled_search("MC", [start], 2, compiled)
    compiled_rms_bound("MC", start, compiled)
