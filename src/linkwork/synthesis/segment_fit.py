"""Fit the segments a segment matrix names and tabulate their errors, with a cache of every fit tried.

A segment's errors depend only on its kind, its first point on every profile and its pieces on every profile,
so the search (which revisits the same segments many times) looks them up by that key.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013), Eqs. (8)-(9), (21).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from linkwork.synthesis.arc_segment import fit_arc_segment
from linkwork.synthesis.compiled_search import CompiledTables
from linkwork.synthesis.error_kernels import ProfileTables
from linkwork.synthesis.frames import to_local_frame
from linkwork.synthesis.mean_segment import fit_mean_segment
from linkwork.synthesis.reference import arc_segment_errors, mean_segment_errors
from linkwork.synthesis.result import Segment, SegmentKind, TargetProfile

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]


def segment_starts(segment_matrix: IntArray) -> IntArray:
    """``(q, p)`` 0-based index of each segment's first point on each profile (Eqs. 8, 9)."""
    sm = np.asarray(segment_matrix, dtype=np.int64)
    return np.vstack([np.zeros((1, sm.shape[1]), dtype=np.int64), np.cumsum(sm, axis=0)[:-1]])


class SegmentFitter:
    """Segment fits on fixed target profiles, with their errors cached by ``(kind, starts, pieces)``.

    Parameters
    ----------
    targets
        The target profiles.
    cached
        Keep every error vector computed (on by default).
    vectorised
        Use the numpy fits; ``False`` uses the plain-Python reference (the benchmark's baseline).
    compiled
        Run the segment-matrix search compiled (:mod:`~linkwork.synthesis.compiled_search`, same decisions);
        ``False`` runs it in Python through :meth:`error_matrix` and its cache. Needs ``vectorised``.
    """

    def __init__(
        self,
        targets: Sequence[TargetProfile],
        *,
        cached: bool = True,
        vectorised: bool = True,
        compiled: bool = True,
    ) -> None:
        self.points = [t.points for t in targets]
        self.tables = ProfileTables(self.points)
        self.cached = cached
        self.vectorised = vectorised
        self.cache: dict[tuple[str, tuple[int, ...], tuple[int, ...]], Array] = {}
        self.evaluations = 0
        self.hits = 0
        self.compiled_tables = CompiledTables.from_tables(self.tables) if compiled and vectorised else None

    def pieces(self, starts: Sequence[int], counts: Sequence[int]) -> list[Array]:
        """Each profile's piece: ``counts[j] + 1`` points from ``starts[j]``."""
        return [z[s : s + m + 1] for z, s, m in zip(self.points, starts, counts, strict=True)]

    def errors(self, kind: str, starts: Sequence[int], counts: Sequence[int]) -> Array:
        """``(p,)`` errors ``E_j^e`` (Eq. 21) of a segment of ``kind`` spanning the given pieces."""
        self.evaluations += 1
        key = (kind, tuple(map(int, starts)), tuple(map(int, counts)))
        if self.cached:
            hit = self.cache.get(key)
            if hit is not None:
                self.hits += 1
                return hit
        if self.vectorised:
            err = (
                self.tables.mean_errors(key[1], key[2][0])
                if kind == "M"
                else self.tables.arc_errors(*key[1:])
            )
        else:
            pieces = self.pieces(starts, counts)
            plain = [[(float(x), float(y)) for x, y in z] for z in pieces]
            err = np.array(mean_segment_errors(plain) if kind == "M" else arc_segment_errors(plain))
        if self.cached:
            self.cache[key] = err
        return err

    def error_matrix(self, design: str, segment_matrix: IntArray) -> Array:
        """``(q, p)`` error matrix ``EM`` of a segment matrix (Sec. 4)."""
        rows = np.asarray(segment_matrix).tolist()
        first = [0] * len(rows[0])
        out = []
        for kind, counts in zip(design, rows, strict=True):
            out.append(self.errors(kind, first, counts))
            first = [f + m for f, m in zip(first, counts, strict=True)]
        return np.vstack(out)

    def segment(self, kind: SegmentKind, starts: Sequence[int], counts: Sequence[int]) -> Segment:
        """The full :class:`Segment` (shape, instances, errors) for the given pieces."""
        pieces = self.pieces(starts, counts)
        st = np.asarray(starts, dtype=np.int64)
        ms = np.asarray(counts, dtype=np.int64)
        if kind == "M":
            fit = fit_mean_segment(np.stack(pieces))
            shape = to_local_frame(fit.shape)
            chord = float(np.mean(np.linalg.norm(np.diff(shape, axis=0), axis=1)))
            return Segment("M", ms, st, shape, None, chord, tuple(fit.instances), fit.errors)
        arc = fit_arc_segment(pieces)
        return Segment("C", ms, st, None, arc.curvature, arc.piece_length, arc.instances, arc.errors)

    def segments(self, design: str, segment_matrix: IntArray) -> tuple[Segment, ...]:
        """Every segment of a segment matrix."""
        starts = segment_starts(segment_matrix)
        kinds: list[SegmentKind] = ["M" if k == "M" else "C" for k in design]
        return tuple(self.segment(k, starts[e], segment_matrix[e]) for e, k in enumerate(kinds))
