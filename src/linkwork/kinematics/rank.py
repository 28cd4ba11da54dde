"""Numerical rank of a Jacobian from its singular values, with a gap-based tolerance and an absolute floor.

References
----------
W. W. Gan, S. Pellegrino, Proc. IMechE Part C 220 (2006), Eq. (28).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike

from linkwork.kinematics import kernels


@dataclass(frozen=True)
class Tolerances:
    """Every tolerance and threshold of the kinematic core in one documented place.

    Attributes
    ----------
    closure
        A configuration is on the loop when the closure residual's 2-norm is below this (Eq. (28) iterations).
        Raised above ``exact`` (``--closure-tol``, play in the hinges), the corrector accepts a least-squares
        closure: Gauss-Newton iterated until its step stops reducing the residual, with a residual below this.
    exact
        A residual below this is closed whatever ``closure`` says (the round-off level of one loop of unit size;
        the tracer scales it by the linkage's own length ``L`` when ``L < 1``, since the residual's translation
        part is a length).
    roundoff
        A residual that stalls (falls by less than half in an iteration) below ``roundoff * max(closure, exact)``
        is accepted: the round-off floor of very long loops.
    max_iter
        Corrector iterations before it gives up (it also gives up when the residual grows after the second).
    start_slack
        The start must close to ``start_slack * closure``; a larger residual asks for assembly first.
    floor
        Singular values below ``floor * sigma_1`` are zero whatever the gap.
    loose
        A singular value above ``loose * sigma_1`` is never zero.
    min_gap
        Between ``floor`` and ``loose`` the spectrum is cut at its largest ratio gap, if that gap is at least this.
    truncate
        The corrector's pseudo-inverse keeps singular values above ``truncate * sigma_1`` (Eq. (28)).
    locate
        Bifurcation points and folds are located to this distance in the unknowns.
    local_min
        A local minimum of ``sigma_r / sigma_1`` below this (without a sign change of the test function) is
        refined by golden section as a possible bifurcation point.
    same_branch
        At a bifurcation, a branch tangent whose ``|cos|`` with the incoming tangent exceeds this is the incoming
        branch itself (not queued as a new branch).
    same_point
        Two located points closer than ``same_point * max(1, |u|)`` (angles modulo a full turn) are the same.
    polish_gap
        A simple bifurcation point is replaced by the intersection of its two fitted branches when they pass
        within this of each other.
    advance
        An adaptive step is rejected (and halved) when the corrected point advanced less than ``advance * h``
        along the tangent: the corrector pulled it back (no progress).
    stall_steps, stall_length
        A branch whose last ``stall_steps`` accepted steps together advanced less than
        ``stall_length * max_step`` in arclength has stalled: it ends with the reason ``no progress``.
    component_points
        A branch on which the mobility is 2 or more at this many consecutive points lies on a
        higher-dimensional component of the configuration space: it ends there, reported once as such.
    """

    closure: float = 1e-12
    exact: float = 1e-12
    roundoff: float = 100.0
    max_iter: int = 25
    start_slack: float = 1e3
    floor: float = 1e-10
    loose: float = 1e-5
    min_gap: float = 1e3
    truncate: float = 1e-10
    locate: float = 1e-10
    local_min: float = 1e-2
    same_branch: float = 0.99
    same_point: float = 1e-6
    polish_gap: float = 1e-8
    advance: float = 0.5
    stall_steps: int = 25
    stall_length: float = 1e-3
    component_points: int = 3

    def at_length(self, length: float) -> Tolerances:
        """These tolerances with the corrector's round-off levels scaled to a linkage's own length ``L``: ``exact
        * L`` when ``L < 1``, ``roundoff * L`` when ``L > 1`` (unchanged for ``L = 1`` or one that is not a
        positive finite number). Why: ``linkwork.kinematics.tracer`` (the trace's tolerances at scale); the
        located turning points of ``linkwork.kinematics.extremes`` use the same."""
        if not (0.0 < length and np.isfinite(length)) or length == 1.0:
            return self
        if length > 1.0:  # the round-off floor grows with the size: a stall there is accepted as closed
            return replace(self, roundoff=self.roundoff * length)
        return replace(self, exact=self.exact * length)

    def with_closure(self, closure: float) -> Tolerances:
        """These tolerances accepting a least-squares closure within ``closure`` (``--closure-tol``).

        Singular values at the scale of an accepted misfit carry no information, so ``floor`` (and ``loose``)
        and the corrector's ``truncate`` are raised to at least ``closure``: a loop whose parameters are off by
        that much is read as the mobile loop it was meant to be, and Gauss-Newton does not chase the misfit
        along the direction it would have been mobile in. A tolerance below ``exact`` tightens ``exact`` too.

        The rank test's levels are ratios to ``sigma_1`` and stop at :data:`MAX_FLOOR` and :data:`MAX_LOOSE`:
        a larger play (``--closure-tol 0.5`` on a loop of unit size) still leaves ``sigma_1`` a sure non-zero
        value (with ``loose`` at 1 or above no value was sure, and the rank test failed).
        """
        if not closure > 0.0:
            raise ValueError(f"closure tolerance {closure!r}: expected a positive number")
        floor = min(max(self.floor, closure), max(self.floor, MAX_FLOOR))
        return replace(
            self,
            closure=closure,
            exact=min(self.exact, closure),
            floor=floor,
            loose=max(self.loose, min(10.0 * floor, MAX_LOOSE)),
            truncate=max(self.truncate, floor),
        )


DEFAULT = Tolerances()

MAX_FLOOR = 1e-3
"""The highest ``floor`` a closure tolerance raises (:meth:`Tolerances.with_closure`): singular values below a
thousandth of ``sigma_1`` are zero at most, whatever play is accepted."""
MAX_LOOSE = 1e-2
"""The highest ``loose`` a closure tolerance raises: a value above a hundredth of ``sigma_1`` is always non-zero."""


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
    sure = int((rel > tol.loose).sum())
    candidates = int((rel > tol.floor).sum())
    if candidates == sure:
        return sure
    # Cut among the uncertain values at the largest gap (ratio of consecutive values, zeros as the floor).
    padded = np.maximum(np.append(rel[: candidates + 1], 0.0), tol.floor * 1e-6)
    ratios = padded[sure - 1 : candidates] / padded[sure : candidates + 1]
    best = int(np.argmax(ratios))
    if ratios[best] >= tol.min_gap:
        return sure + best
    return candidates


def numerical_ranks(sigma: ArrayLike, tol: Tolerances = DEFAULT, compiled: bool = False) -> np.ndarray:
    """:func:`numerical_rank` of every row of ``sigma (N, k)``, vectorised over the rows that need no gap test
    (``compiled``: the counts by a compiled pass, :func:`linkwork.kinematics.kernels.rank_counts`)."""
    s = np.atleast_2d(np.asarray(sigma, dtype=float))
    if compiled and s.shape[1] > 0:
        sure = np.empty(len(s), dtype=np.int64)
        candidates = np.empty(len(s), dtype=np.int64)
        kernels.rank_counts(np.ascontiguousarray(s), tol.loose, tol.floor, sure, candidates)
        for i in (candidates != sure).nonzero()[0]:
            sure[i] = numerical_rank(s[i], tol)
        return sure
    if all_full_rank(s, tol):
        return np.full(len(s), s.shape[1], dtype=np.int64)
    positive = s[:, 0] > 0.0
    rel = s / np.where(positive, s[:, 0], 1.0)[:, None]
    ones = np.ones(
        s.shape[1]
    )  # counts by a product: numpy's boolean sum along short rows is several times slower
    sure = ((rel > tol.loose) @ ones).astype(np.int64)
    candidates = ((rel > tol.floor) @ ones).astype(np.int64)
    out = np.where(positive, sure, 0)
    for i in ((candidates != sure) & positive).nonzero()[0]:
        out[i] = numerical_rank(s[i], tol)
    return out


#: Columns up to which :func:`all_full_rank` takes the smallest value a column at a time (numpy's reduction along a
#: short last axis is many times slower than a few column operations).
FEW_COLUMNS = 8


def all_full_rank(s: np.ndarray, tol: Tolerances = DEFAULT) -> bool:
    """Whether every row of ``s (N, k)`` has ``s_1 > 0`` and every value above ``loose * s_1``: then (with
    ``floor <= loose``) every row's rank by :func:`numerical_rank` is ``k``; where not, some rows may still have
    rank ``k`` by the gap test, and :func:`numerical_ranks` decides row by row. The smallest value of a row over
    its first is the smallest of the row's ratios (division by a positive number is monotone, also once
    rounded), so the test is the one :func:`numerical_rank` makes, exactly; NaN and infinite values fail it."""
    if s.shape[1] == 0 or len(s) == 0 or not tol.floor <= tol.loose:
        return False
    first = s[:, 0]
    if s.shape[1] <= FEW_COLUMNS:
        low = first
        for j in range(1, s.shape[1]):
            low = np.minimum(low, s[:, j])
    else:
        low = np.min(s, axis=1)
    return bool(np.all(first > 0.0) and np.all(low / first > tol.loose))
