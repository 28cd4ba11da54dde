"""The chain re-cut so that every C-segment's piece count changes one way through the profiles.

A C-segment's arc slide ``S<e>`` turns by one piece's angle per piece (:mod:`linkwork.mechanization.chain`), so
its value on profile ``j`` follows the segment's piece count ``m_j`` there. The segment-matrix search (Sec. 4)
minimises the joined error profile by profile and may cut a smooth family unevenly: the NACA 2412 ... 7412
camber lines got a first C-segment of 10, 11, 12, **18**, 11, 13 pieces (and 10, 12, 13, **10**, 20, 20 for the
second), which joins each profile to 0.004 but asks the arc slides to go out and back between neighbouring
profiles. A one-DOF mechanism moving one way through the profiles follows that only approximately (0.13 from
profile 4, where the chain was within 0.001).

:func:`monotone_recut` cuts the same design vector with each C-segment's piece count moving one way: the
M-segments keep theirs, and the C-segments share each profile's remaining pieces in proportion between their
counts on the first and on the last profile (largest remainders, the total kept), then the segments are fitted
and joined again by the synthesis (:class:`~linkwork.synthesis.segment_fit.SegmentFitter`,
:func:`~linkwork.synthesis.joining.join_chain`). The camber lines re-cut to 10, 11, 11, 12, 13, 13 and 10, 12,
14, 16, 18, 20 join to the same error, and mechanize within 0.004 of every profile.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from linkwork.errors import LinkworkError
from linkwork.synthesis.joining import join_chain
from linkwork.synthesis.result import SynthesisResult
from linkwork.synthesis.segment_fit import SegmentFitter

IntArray = NDArray[np.int64]


@dataclass(frozen=True)
class Recut:
    """A synthesis result re-cut with monotonic C-segment piece counts.

    Attributes
    ----------
    result
        The result with the new segment matrix, segments and joined chain (the rest as synthesised).
    before
        ``(q, p)`` the synthesised segment matrix.
    joined_before
        ``(p,)`` the synthesised joined chain's ``E_max`` on every profile.
    """

    result: SynthesisResult
    before: IntArray
    joined_before: NDArray[np.float64]

    @property
    def segment_matrix(self) -> IntArray:
        """``(q, p)`` the segment matrix the mechanism follows."""
        return np.asarray(self.result.segment_matrix, dtype=np.int64)

    def describe(self) -> str:
        """One phrase for reports: which C-segments were re-cut, from what to what."""
        parts = []
        for e, (old, new) in enumerate(zip(self.before, self.segment_matrix, strict=True)):
            if not np.array_equal(old, new):
                parts.append(
                    f"segment {e + 1}: {', '.join(map(str, old))} -> {', '.join(map(str, new))} pieces"
                )
        return "; ".join(parts)


def monotonic(counts: IntArray) -> bool:
    """Piece counts that change one way (or not at all) through the profiles."""
    d = np.diff(np.asarray(counts))
    return bool(np.all(d >= 0) or np.all(d <= 0))


def recut_matrix(design: str, segment_matrix: IntArray, min_pieces: int) -> IntArray | None:
    """The segment matrix with every C-segment's piece count changing one way, each profile's total kept;
    ``None`` when the synthesised one already does, or when no such cut exists by this rule (the totals
    themselves go up and down, or a count would fall below ``min_pieces``)."""
    sm = np.asarray(segment_matrix, dtype=np.int64)
    c = [e for e, kind in enumerate(design) if kind == "C"]
    if len(c) < 2 or all(monotonic(sm[e]) for e in c):
        return None
    share = sm[c].sum(axis=0)  # pieces of the C-segments on every profile
    if not monotonic(share) or share[-1] == share[0]:
        return None
    frac = (share - share[0]) / (share[-1] - share[0])
    ideal = sm[c, :1] + np.outer(sm[c, -1] - sm[c, 0], frac)
    new = sm.copy()
    for j in range(sm.shape[1]):
        base = np.floor(ideal[:, j]).astype(np.int64)
        left = int(share[j] - base.sum())
        order = np.argsort(-(ideal[:, j] - base), kind="stable")
        base[order[:left]] += 1
        new[c, j] = base
    if new.min() < min_pieces or not all(monotonic(new[e]) for e in c):
        return None
    return new


def monotone_recut(result: SynthesisResult) -> Recut | None:
    """``result`` re-cut with monotonic C-segment piece counts and joined again, or ``None`` when it already
    has them, no such cut exists by :func:`recut_matrix`'s rule, joints were merged (a compound chain: its
    welds belong to the synthesised cut), or the re-cut chain cannot be joined."""
    if result.compound is not None and result.compound.merged:
        return None
    new = recut_matrix(result.design, np.asarray(result.segment_matrix), int(result.problem.min_pieces))
    if new is None:
        return None
    fitter = SegmentFitter(result.targets)
    segments = fitter.segments(result.design, new)
    try:
        joined = join_chain(segments, result.targets, result.problem.kind)
    except LinkworkError:
        return None
    before = np.array([float(np.max(prof.errors)) for prof in result.joined])
    recut = replace(result, segment_matrix=new, segments=segments, joined=joined, compound=None)
    return Recut(recut, np.asarray(result.segment_matrix, dtype=np.int64), before)
