"""Beyond the paper: a local search over segmentation points, started from the paper's best segment matrix.

The paper's adjustment (Sec. 4) moves every segment at once by one piece, balancing errors against their mean;
it stops in matrices that a single, targeted move could still improve. Here every move that keeps the
constraints is tried: one piece passed between two C-instances on one profile (which also slides any
M-segment between them), one piece passed between an M-segment and a C-segment on every profile, or between
two adjacent M-segments. A move is taken when it lowers the errors in the leximax order (the largest error
first, then the next largest, ...), which makes progress on the plateaus of ``E_max``; the search stops when
no move does. It only accepts improvements, so its ``E_max`` is never above the start's.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from linkwork.synthesis.segment_fit import SegmentFitter

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Largest number of accepted moves.
MAX_MOVES = 500


def _moves(design: str, p: int) -> list[IntArray]:
    q = len(design)
    c_rows = [e for e, k in enumerate(design) if k == "C"]
    m_rows = [e for e, k in enumerate(design) if k == "M"]
    out: list[IntArray] = []
    for a in c_rows:
        for b in c_rows:
            if a < b:
                for j in range(p):
                    for sign in (1, -1):
                        d = np.zeros((q, p), dtype=np.int64)
                        d[a, j], d[b, j] = sign, -sign
                        out.append(d)
    pairs = [(e, c) for e in m_rows for c in c_rows] + [(e, e + 1) for e in m_rows if e + 1 in m_rows]
    for a, b in pairs:
        for sign in (1, -1):
            d = np.zeros((q, p), dtype=np.int64)
            d[a, :], d[b, :] = sign, -sign
            out.append(d)
    return out


def _leximax(em: Array) -> tuple[float, ...]:
    return tuple(np.sort(em.ravel())[::-1].tolist())


def refine_segment_matrix(
    design: str, segment_matrix: IntArray, fitter: SegmentFitter, min_pieces: int
) -> tuple[IntArray, Array]:
    """Improve a valid segment matrix by single moves of segmentation points (see the module notes).

    Returns
    -------
    tuple
        The refined ``(q, p)`` segment matrix and its error matrix; ``E_max`` is at most the start's.
    """
    sm = np.asarray(segment_matrix, dtype=np.int64)
    em = fitter.error_matrix(design, sm)
    score = _leximax(em)
    moves = _moves(design, sm.shape[1])
    for _ in range(MAX_MOVES):
        best = None
        for d in moves:
            trial = sm + d
            if trial.min() < min_pieces:
                continue
            trial_em = fitter.error_matrix(design, trial)
            trial_score = _leximax(trial_em)
            if trial_score < score and (best is None or trial_score < best[0]):
                best = (trial_score, trial, trial_em)
        if best is None:
            break
        score, sm, em = best
    return sm, em
