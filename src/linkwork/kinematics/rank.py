"""Numerical rank of a Jacobian from its singular values, with a gap-based tolerance and an absolute floor."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike


@dataclass(frozen=True)
class Tolerances:
    """Every tolerance of the kinematic core in one documented place.

    Attributes
    ----------
    closure
        A configuration is on the loop when the closure residual's 2-norm is below this (Eq. (28) iterations).
    floor
        Singular values below ``floor * sigma_1`` are zero whatever the gap.
    loose
        A singular value above ``loose * sigma_1`` is never zero.
    min_gap
        Between ``floor`` and ``loose`` the spectrum is cut at its largest ratio gap, if that gap is at least this.
    truncate
        The corrector's pseudo-inverse keeps singular values above ``truncate * sigma_1`` (Eq. (28)).
    locate
        Bifurcation points are located to this distance in the unknowns.
    """

    closure: float = 1e-12
    floor: float = 1e-10
    loose: float = 1e-5
    min_gap: float = 1e3
    truncate: float = 1e-10
    locate: float = 1e-10


DEFAULT = Tolerances()


def numerical_rank(sigma: ArrayLike, tol: Tolerances = DEFAULT) -> int:
    """Rank from singular values in descending order.

    Values above ``loose * sigma_1`` count; values below ``floor * sigma_1`` do not; in between, the spectrum is
    cut at its largest ratio gap when that gap exceeds ``min_gap`` (so a value of 1e-8 next to one of 1e-15 is
    non-zero, while 1e-8 below a 1e-1 with nothing smaller is zero).
    """
    s = np.asarray(sigma, dtype=float)
    if s.size == 0 or s[0] <= 0.0:
        return 0
    rel = s / s[0]
    sure = int(np.sum(rel > tol.loose))
    candidates = int(np.sum(rel > tol.floor))
    if candidates == sure:
        return sure
    # Cut among the uncertain values at the largest gap (ratio of consecutive values, zeros as the floor).
    padded = np.maximum(np.append(rel[: candidates + 1], 0.0), tol.floor * 1e-6)
    ratios = padded[sure - 1 : candidates] / padded[sure : candidates + 1]
    best = int(np.argmax(ratios))
    if ratios[best] >= tol.min_gap:
        return sure + best
    return candidates


def numerical_ranks(sigma: ArrayLike, tol: Tolerances = DEFAULT) -> np.ndarray:
    """:func:`numerical_rank` of every row of ``sigma (N, k)``, vectorised over the rows that need no gap test."""
    s = np.atleast_2d(np.asarray(sigma, dtype=float))
    first = np.where(s[:, :1] > 0.0, s[:, :1], 1.0)
    rel = s / first
    sure = np.sum(rel > tol.loose, axis=1)
    candidates = np.sum(rel > tol.floor, axis=1)
    out = np.where(s[:, 0] > 0.0, sure, 0).astype(np.int64)
    for i in np.flatnonzero((candidates != sure) & (s[:, 0] > 0.0)):
        out[i] = numerical_rank(s[i], tol)
    return out
