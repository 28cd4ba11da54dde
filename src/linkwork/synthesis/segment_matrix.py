"""The segment matrix (Secs. 3.2, 4): design vectors, initial matrices, the adjustment rules and the search.

A segment matrix ``SM`` here has shape ``(q, p)``: ``SM[e, j] = m_j^e``, pieces of segment ``e`` on profile
``j`` (the transpose of the paper's printed layout).
It is valid when column ``j`` sums to ``m_j*``, every M-segment row is constant, and every entry is at least
``alpha`` (``min_pieces``).

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013),
Eqs. (11), (22)-(24), (26).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from linkwork.errors import SpecError

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]
ErrorMatrix = Callable[[IntArray], Array]

#: The search stops when ``E_max`` is at least each of this many previous values (Sec. 4).
PATIENCE = 5
#: A cap on adjustment iterations per start, in case the error sequence never satisfies the stopping rule.
MAX_ITERATIONS = 1000


def check_design(design: str) -> str:
    """Upper-case a design vector such as ``"mcmc"`` and check it has only ``M`` and ``C``."""
    d = design.strip().upper()
    if not d or set(d) - {"M", "C"}:
        raise SpecError(
            f"a design vector is a string of M and C, such as 'MCMC'; got {design!r}", key="design"
        )
    return d


def design_vectors(q: int, pieces: Sequence[int]) -> list[str]:
    """Every design vector of ``q`` segments; all-M only when all profiles have one piece count (Sec. 3.1)."""
    if q < 1:
        raise SpecError(f"the number of segments must be at least 1, got {q}", key="segments")
    out = ["".join(v) for v in itertools.product("MC", repeat=q)]
    if len(set(pieces)) > 1:
        out.remove("M" * q)
    return out


def check_feasible(design: str, pieces: Sequence[int], min_pieces: int) -> None:
    """Raise :class:`SpecError` unless some segment matrix satisfies every constraint."""
    q = len(design)
    if min_pieces < 1:
        raise SpecError(f"min_pieces must be at least 1, got {min_pieces}", key="min_pieces")
    if "C" not in design and len(set(pieces)) > 1:
        raise SpecError(
            f"design {design!r} has no C-segment but the profiles have different piece counts {list(pieces)}",
            key="design",
        )
    if min(pieces) < q * min_pieces:
        raise SpecError(
            f"the shortest target profile has {min(pieces)} pieces, fewer than {q} segments x "
            f"min_pieces {min_pieces}; lower piece_length, min_pieces or the number of segments",
            key="min_pieces",
        )


def is_valid(segment_matrix: IntArray, design: str, pieces: Sequence[int], min_pieces: int) -> bool:
    """Whether ``segment_matrix`` satisfies the column sums, equal M rows and the minimum piece count."""
    sm = np.asarray(segment_matrix)
    if sm.shape != (len(design), len(pieces)):
        return False
    rows_m = [e for e, k in enumerate(design) if k == "M"]
    return bool(
        np.array_equal(sm.sum(axis=0), np.asarray(pieces))
        and np.all(sm >= min_pieces)
        and all(np.all(sm[e] == sm[e, 0]) for e in rows_m)
    )


def _split(total: int, weights: Array) -> IntArray:
    """Integers >= 0 proportional to ``weights`` summing to ``total`` (remainder to the last)."""
    share = np.floor(total * weights / weights.sum()).astype(np.int64)
    share[-1] += total - share.sum()
    return share


def initial_segment_matrix(
    design: str, pieces: Sequence[int], min_pieces: int, weights: Array, jitter: Array | None = None
) -> IntArray:
    """A valid segment matrix with segment sizes in proportion to ``weights`` (``(q,)``, positive).

    M-segments take ``alpha`` plus their share of the shortest profile's spare pieces; on each profile the
    C-segments share what remains (``jitter``, ``(q, p)`` positive factors, varies it per profile), and
    the last C-segment takes the remainder, as in Eq. (11).
    """
    q, p = len(design), len(pieces)
    m = np.asarray(pieces, dtype=np.int64)
    rows_m = np.array([k == "M" for k in design])
    sm = np.full((q, p), min_pieces, dtype=np.int64)
    spare_short = int(m.min()) - q * min_pieces
    if not rows_m.any():
        for j in range(p):
            w = weights * (1.0 if jitter is None else jitter[:, j])
            sm[:, j] += _split(int(m[j]) - q * min_pieces, w)
        return sm
    if rows_m.all():
        sm[:, :] += _split(spare_short, weights)[:, None]
        return sm
    # the M-segments' share of the shortest profile's spare pieces
    m_extra = np.floor(spare_short * weights[rows_m] / weights.sum()).astype(np.int64)
    sm[rows_m] += m_extra[:, None]
    for j in range(p):
        left = int(m[j] - sm[:, j].sum())
        w = weights[~rows_m] * (1.0 if jitter is None else jitter[~rows_m, j])
        sm[~rows_m, j] += _split(left, w)
    return sm


def initial_segment_matrices(
    design: str, pieces: Sequence[int], min_pieces: int, count: int, rng: np.random.Generator
) -> list[IntArray]:
    """``count`` initial segment matrices: the first splits every profile evenly, the rest are random."""
    q, p = len(design), len(pieces)
    out = [initial_segment_matrix(design, pieces, min_pieces, np.ones(q))]
    while len(out) < count:
        weights = rng.dirichlet(np.ones(q))
        jitter = np.exp(rng.normal(0.0, 0.5, size=(q, p)))
        out.append(initial_segment_matrix(design, pieces, min_pieces, weights + 1e-3, jitter))
    return out


def adjust(segment_matrix: IntArray, error_matrix: Array, design: str, min_pieces: int) -> IntArray:
    """One adjustment of the segment matrix by the rules of Section 4.

    A C-instance with ``E_j^e < E_bar`` gains a piece, one with ``E_j^e > E_bar`` loses one; an M-segment
    gains or loses one piece on every profile by ``E_bar^e`` (Eq. 23) against ``E_bar`` (Eq. 24). No entry may
    fall below ``alpha``. The last C-segment (the last segment when all are M) is not judged by its error but
    takes whatever keeps every column sum (Eq. 26); if that would push it below ``alpha``, the gains of that
    profile are withdrawn, largest error first, until it fits.
    """
    sm_arr = np.asarray(segment_matrix, dtype=np.int64)
    em_arr = np.asarray(error_matrix, dtype=float)
    q, p = sm_arr.shape
    # plain Python on these small matrices: this runs once per iteration of every start of every design
    e_bar = float(em_arr.mean())  # Eq. (24)
    row_mean = em_arr.mean(axis=1).tolist()  # Eq. (23)
    sm, em = sm_arr.tolist(), em_arr.tolist()
    absorber = design.rfind("C") if "C" in design else q - 1
    delta = [[0] * p for _ in range(q)]
    for e, kind in enumerate(design):
        if e == absorber:
            continue
        if kind == "M":
            step = 1 if row_mean[e] < e_bar else (-1 if row_mean[e] > e_bar else 0)
            delta[e] = [step] * p
        else:
            delta[e] = [1 if v < e_bar else (-1 if v > e_bar else 0) for v in em[e]]
        delta[e] = [d if m + d >= min_pieces else 0 for m, d in zip(sm[e], delta[e], strict=True)]
    others = [sum(delta[e][j] for e in range(q) if e != absorber) for j in range(p)]
    while True:
        short = [j for j in range(p) if sm[absorber][j] - others[j] < min_pieces]  # Eq. (26)
        if not short:
            delta[absorber] = [-v for v in others]
            return np.asarray(
                [
                    [m + d for m, d in zip(row, drow, strict=True)]
                    for row, drow in zip(sm, delta, strict=True)
                ],
                dtype=np.int64,
            ).reshape(q, p)
        j = short[0]
        gains = [e for e in range(q) if e != absorber and delta[e][j] > 0]
        c_gains = [e for e in gains if design[e] == "C"]
        pick = max(c_gains or gains, key=lambda e: em[e][j])
        if design[pick] == "M":  # an M-segment changes on every profile or on none
            others = [v - d for v, d in zip(others, delta[pick], strict=True)]
            delta[pick] = [0] * p
        else:
            others[j] -= delta[pick][j]
            delta[pick][j] = 0


@dataclass(frozen=True)
class SearchOutcome:
    """The best segment matrix found from several starts and how the search got there.

    Attributes
    ----------
    segment_matrix
        ``(q, p)`` the matrix with the lowest ``E_max`` of the whole history (ties: lower ``E_bar``).
    error_matrix
        ``(q, p)`` its error matrix.
    history
        ``E_max`` after every iteration, one tuple per start.
    iterations
        Total iterations.
    """

    segment_matrix: IntArray
    error_matrix: Array
    history: tuple[tuple[float, ...], ...]
    iterations: int


def search_segment_matrix(
    design: str,
    starts: Sequence[IntArray],
    error_matrix: ErrorMatrix,
    min_pieces: int,
    on_start_done: Callable[[], None] | None = None,
) -> SearchOutcome:
    """Run the error-reducing iterations of Section 4 from every start and keep the best matrix seen.

    From each start: evaluate, adjust, repeat; stop when the current ``E_max`` is greater than or equal to
    each of the previous five values (Sec. 4), or when an adjustment changes nothing.
    """
    best_key = (np.inf, np.inf)
    best_sm: IntArray | None = None
    best_em: Array | None = None
    history: list[tuple[float, ...]] = []
    iterations = 0
    for start in starts:
        sm = np.asarray(start, dtype=np.int64)
        trail: list[float] = []
        for _ in range(MAX_ITERATIONS):
            em = error_matrix(sm)
            iterations += 1
            e_max = float(em.max())  # Eq. (22)
            key = (e_max, float(em.mean()))
            if key < best_key:
                best_key, best_sm, best_em = key, sm, em
            trail.append(e_max)
            if len(trail) > PATIENCE and e_max >= max(trail[-PATIENCE - 1 : -1]):
                break
            nxt = adjust(sm, em, design, min_pieces)
            if np.array_equal(nxt, sm):
                break
            sm = nxt
        history.append(tuple(trail))
        if on_start_done is not None:
            on_start_done()
    assert best_sm is not None and best_em is not None
    return SearchOutcome(best_sm, best_em, tuple(history), iterations)
