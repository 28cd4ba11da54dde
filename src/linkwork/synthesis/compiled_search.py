"""The segment-matrix search of Section 4 compiled with numba: error matrix, adjustment and stopping rule.

It makes the same decisions as :func:`~linkwork.synthesis.segment_matrix.search_segment_matrix` driven by
:class:`~linkwork.synthesis.segment_fit.SegmentFitter` (same error kernels, same arithmetic order, numpy's
pairwise summation for ``E_bar``), without the Python overhead of each iteration; it is what makes the
exhaustive design search over ``2^q - 1`` design vectors affordable. The tests check that both agree.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013),
Eqs. (18), (20)-(24), (26).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from linkwork.kernel_cache import kernel
from linkwork.synthesis.compiled import arc_fits, mean_fits
from linkwork.synthesis.error_kernels import ProfileTables
from linkwork.synthesis.segment_matrix import MAX_ITERATIONS, PATIENCE, SearchOutcome

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Largest ``q * p`` of a segment matrix searched compiled (numpy's pairwise sums are reproduced up to this size).
MAX_ENTRIES = 128


@kernel()
def _pairwise_sum(a: Array, lo: int, n: int) -> float:  # pragma: no cover - compiled
    """numpy's pairwise summation of ``a[lo : lo + n]``, ``n <= 128`` (the order ``ndarray.mean`` uses).

    Longer sums split in halves in numpy; :func:`compiled_search` leaves matrices of more than
    :data:`MAX_ENTRIES` entries to the Python search.
    """
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[lo + i]
        return res
    if n <= MAX_ENTRIES:
        r = np.empty(8)
        for k in range(8):
            r[k] = a[lo + k]
        i = 8
        while i < n - (n % 8):
            for k in range(8):
                r[k] += a[lo + i + k]
            i += 8
        res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
        while i < n:
            res += a[lo + i]
            i += 1
        return res
    return np.nan


@kernel()
def _arc_parameters(
    tables: tuple[Array, IntArray, Array, Array], first: IntArray, pieces: IntArray
) -> tuple[float, float]:  # pragma: no cover - compiled
    """``(curvature, piece_length)`` of a C-segment of ``pieces[j]`` pieces from ``first[j]`` on profile ``j``:
    the mean interior curvature (Eq. 18, averaging ``1/r``) and mean chord (Eq. 20 with its ``1/p``), from the
    prefix sums of ``tables`` (:attr:`CompiledTables.arrays`) as ``ProfileTables.arc_errors`` takes them."""
    _, offsets, chord_sum, curvature_sum = tables
    p = pieces.shape[0]
    kappa_total = 0.0
    interior = 0
    s_bar = 0.0
    for j in range(p):
        s, m, o = first[j], pieces[j], offsets[j]
        s_bar += (chord_sum[o + s + m] - chord_sum[o + s]) / m
        if m > 1:
            kappa_total += curvature_sum[o + s + m] - curvature_sum[o + s + 1]
            interior += m - 1
    s_bar /= p
    kappa = kappa_total / interior if interior else 0.0
    return kappa, s_bar


@kernel()
def _segment_matrix_table(
    sm: IntArray, is_m: NDArray[np.bool_], tables: tuple[Array, IntArray, Array, Array], rms: bool
) -> Array:  # pragma: no cover - compiled
    """``(q, p)`` errors (Eq. 21) of a segment matrix, or with ``rms`` the lower bounds of ``compiled.fit_bound``.

    The arithmetic of ``ProfileTables.mean_errors/arc_errors`` (curvature and chord from prefix sums);
    ``tables`` is :attr:`CompiledTables.arrays`.
    """
    points, offsets = tables[0], tables[1]
    q, p = sm.shape
    em = np.empty((q, p))
    first = np.zeros(p, dtype=np.int64)
    for e in range(q):
        if is_m[e]:
            em[e] = mean_fits(points, offsets, first, sm[e, 0], rms)
        else:
            kappa, s_bar = _arc_parameters(tables, first, sm[e])
            em[e] = arc_fits(points, offsets, first, sm[e].copy(), kappa, s_bar, rms)
        for j in range(p):
            first[j] += sm[e, j]
    return em


@kernel()
def _adjust(sm: IntArray, em: Array, is_m: NDArray[np.bool_], absorber: int, alpha: int) -> IntArray:
    """The adjustment rules of Sec. 4, decision for decision as ``segment_matrix.adjust``."""  # pragma: no cover
    q, p = sm.shape
    flat = em.ravel()
    e_bar = _pairwise_sum(flat, 0, q * p) / (q * p)  # Eq. (24)
    delta = np.zeros((q, p), dtype=np.int64)
    for e in range(q):
        if e == absorber:
            continue
        if is_m[e]:
            row = _pairwise_sum(flat, e * p, p) / p  # Eq. (23)
            step = 1 if row < e_bar else (-1 if row > e_bar else 0)
            for j in range(p):
                delta[e, j] = step
        else:
            for j in range(p):
                v = em[e, j]
                delta[e, j] = 1 if v < e_bar else (-1 if v > e_bar else 0)
        for j in range(p):
            if sm[e, j] + delta[e, j] < alpha:
                delta[e, j] = 0
    others = np.zeros(p, dtype=np.int64)
    for j in range(p):
        for e in range(q):
            if e != absorber:
                others[j] += delta[e, j]
    while True:
        short = -1
        for j in range(p):
            if sm[absorber, j] - others[j] < alpha:
                short = j
                break
        if short < 0:
            break
        j = short
        pick = -1
        for c_only in (True, False):  # the C-segments' gains are withdrawn first, the largest error first
            for e in range(q):
                if e == absorber or delta[e, j] <= 0 or (c_only and is_m[e]):
                    continue
                if pick < 0 or em[e, j] > em[pick, j]:
                    pick = e
            if pick >= 0:
                break
        if pick < 0:
            break
        if is_m[pick]:  # an M-segment changes on every profile or on none
            for jj in range(p):
                others[jj] -= delta[pick, jj]
                delta[pick, jj] = 0
        else:
            others[j] -= delta[pick, j]
            delta[pick, j] = 0
    out = sm + delta
    for j in range(p):
        out[absorber, j] = sm[absorber, j] - others[j]  # Eq. (26)
    return out


@kernel()
def _search(
    starts: IntArray,
    is_m: NDArray[np.bool_],
    absorber: int,
    alpha: int,
    tables: tuple[Array, IntArray, Array, Array],
    patience: int,
    max_iterations: int,
) -> tuple[IntArray, Array, Array, IntArray]:  # pragma: no cover - compiled
    """Every start's iterations; the best ``(E_max, E_bar)`` matrix of the whole history."""
    n_starts, q, p = starts.shape
    history = np.full((n_starts, max_iterations), np.nan)
    lengths = np.zeros(n_starts, dtype=np.int64)
    best_sm = starts[0].copy()
    best_em = np.full((q, p), np.inf)
    best_max, best_mean = np.inf, np.inf
    for k in range(n_starts):
        sm = starts[k].copy()
        for it in range(max_iterations):
            em = _segment_matrix_table(sm, is_m, tables, False)
            e_max = em.max()  # Eq. (22)
            e_mean = _pairwise_sum(em.ravel(), 0, q * p) / (q * p)
            if e_max < best_max or (e_max == best_max and e_mean < best_mean):
                best_max, best_mean, best_sm, best_em = e_max, e_mean, sm.copy(), em
            history[k, it] = e_max
            lengths[k] = it + 1
            if it >= patience:
                previous = history[k, it - patience : it].max()
                if e_max >= previous:
                    break
            nxt = _adjust(sm, em, is_m, absorber, alpha)
            if (nxt == sm).all():
                break
            sm = nxt
    return best_sm, best_em, history, lengths


@dataclass(frozen=True)
class CompiledTables:
    """The target profiles stacked for the compiled search (points, chord and curvature prefix sums)."""

    points: Array
    offsets: IntArray
    chord_sum: Array
    curvature_sum: Array

    @property
    def arrays(self) -> tuple[Array, IntArray, Array, Array]:
        """The tuple the compiled kernels take: ``(points, offsets, chord_sum, curvature_sum)``."""
        return self.points, self.offsets, self.chord_sum, self.curvature_sum

    @classmethod
    def from_tables(cls, tables: ProfileTables) -> CompiledTables:
        """Stack the prefix sums of :class:`ProfileTables` (each as long as its profile's points)."""
        return cls(
            tables.stacked,
            tables.offsets,
            np.ascontiguousarray(np.concatenate(tables.chord_sum)),
            np.ascontiguousarray(np.concatenate(tables.curvature_sum)),
        )


def compiled_search(
    design: str, starts: Sequence[IntArray], min_pieces: int, tables: CompiledTables
) -> SearchOutcome:
    """Run the search of Sec. 4 from every start (compiled); same result as ``search_segment_matrix``."""
    stacked = np.ascontiguousarray(np.stack([np.asarray(s, dtype=np.int64) for s in starts]))
    is_m = np.array([k == "M" for k in design])
    absorber = design.rfind("C") if "C" in design else len(design) - 1
    sm, em, history, lengths = _search(
        stacked,
        is_m,
        absorber,
        int(min_pieces),
        tables.arrays,
        PATIENCE,
        MAX_ITERATIONS,
    )
    trails = tuple(tuple(float(v) for v in history[k, : lengths[k]]) for k in range(len(starts)))
    return SearchOutcome(sm, em, trails, int(lengths.sum()))


def compiled_rms_bound(design: str, segment_matrix: IntArray, tables: CompiledTables) -> float:
    """A lower bound on the ``E_max`` of any joining of a segment matrix's segments: the largest
    :func:`~linkwork.synthesis.compiled.fit_bound` of a segment on a profile (joining only moves each segment
    rigidly; see :func:`linkwork.synthesis.search.joined_error_bound`)."""
    is_m = np.array([k == "M" for k in design])
    sm = np.ascontiguousarray(np.asarray(segment_matrix, dtype=np.int64))
    table = _segment_matrix_table(sm, is_m, tables.arrays, True)
    return float(table.max())
