"""One design vector's evaluation: segment-matrix search (Sec. 4), a lower bound on its joined error, joining (Sec. 5).

The design search of :func:`linkwork.synthesis.synthesize` runs :func:`segment_design` on every design vector,
then joins them in the order of :func:`joined_error_bound` and stops joining once the bound of the next design
exceeds the best joined ``E_max`` found (it cannot win). :func:`evaluate_design` does both steps for one
design vector as a plain function of ``(problem, design)`` so that a scheduler may run designs in other
processes.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013),
Eqs. (11), (21)-(22), (24), (31)-(32).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from linkwork.errors import ConvergenceError
from linkwork.synthesis.compiled_search import MAX_ENTRIES, compiled_rms_bound, compiled_search
from linkwork.synthesis.joining import join_chain
from linkwork.synthesis.problem import Problem
from linkwork.synthesis.refine import refine_segment_matrix
from linkwork.synthesis.result import JoinedProfile, Segment, TargetProfile
from linkwork.synthesis.segment_fit import SegmentFitter
from linkwork.synthesis.segment_matrix import initial_segment_matrices, search_segment_matrix
from linkwork.synthesis.targets import target_profiles

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]


#: The bound is lowered by this relative margin so that rounding differences between the compiled fits and
#: the segments that are joined can never lift it above a joined ``E_max``.
BOUND_MARGIN = 1e-9


@dataclass(frozen=True)
class Segmentation:
    """One segment matrix of a design vector, its errors and the lower bound on its joined ``E_max``."""

    segment_matrix: IntArray
    error_matrix: Array
    bound: float


@dataclass(frozen=True)
class SegmentedDesign:
    """A design vector after the segment-matrix search: the paper's matrix (and the refined one)."""

    design: str
    options: tuple[Segmentation, ...]
    history: tuple[tuple[float, ...], ...]
    iterations: int
    paper_e_max: float

    @property
    def bound(self) -> float:
        """A lower bound on the joined ``E_max`` of every option (see :func:`joined_error_bound`)."""
        return min(opt.bound for opt in self.options)


@dataclass(frozen=True)
class JoinedDesign:
    """A design vector joined (Sec. 5): the option with the lowest joined error."""

    design: str
    segmentation: Segmentation
    segments: tuple[Segment, ...]
    joined: tuple[JoinedProfile, ...]
    joined_e_max: float
    segmented: SegmentedDesign

    @property
    def rank_key(self) -> tuple[float, float, float]:
        """Joined ``E_max``, then ``E_max`` and ``E_bar`` of the segmentation (Eqs. 22, 24)."""
        em = self.segmentation.error_matrix
        return (self.joined_e_max, float(em.max()), float(em.mean()))


@dataclass(frozen=True)
class SkippedDesign:
    """A design vector that could not be joined, and why."""

    design: str
    reason: str
    segmented: SegmentedDesign


def design_seed(seed: int, design: str) -> list[int]:
    """Seed material of one design vector's random starts: independent of the order designs are tried."""
    return [seed, len(design), int(design.replace("M", "0").replace("C", "1"), 2)]


def chain_joints(design: str, kind: str) -> int:
    """Joints of the shape-approximating chain: the revolute joints between segments, one prismatic joint per
    C-segment (an RPR chain, Sec. 3), and the closing joint (closed) or the two ground pins (fixed-end)."""
    ends = {"closed": 1, "fixed-end": 2}.get(kind, 0)
    return len(design) - 1 + design.count("C") + ends


def joined_error_bound(segments: Sequence[Segment], targets: Sequence[TargetProfile]) -> float:
    """A lower bound on the ``E_max`` of any joining of these segments (Sec. 5, Eq. 21 on the joined chain).

    Joining moves each segment's fixed shape rigidly, so on each profile its largest point-to-point distance is
    at least :func:`rigid_fit_bound` of its shape against the target points it spans; the bound is the largest
    over segments and profiles.
    """
    worst = 0.0
    for seg in segments:
        for j, target in enumerate(targets):
            shape = seg.local_points(j)
            start = int(seg.starts[j])
            worst = max(worst, rigid_fit_bound(shape, target.points[start : start + len(shape)]))
    return worst


def rigid_fit_bound(source: Array, target: Array) -> float:
    """A lower bound on the largest distance of any rigid placement of ``source`` against ``target``.

    The largest of: :func:`rigid_fit_rms` of all points, of the first, middle and last points alone (the
    largest distance is at least the RMS of any subset, which is at least that subset's best fit), and half the
    change of their three mutual distances (``d_a + d_b >= | |S_a - S_b| - |T_a - T_b| |``, rigid motions keep
    distances). The compiled search uses the same bound (``compiled.fit_bound``).
    """
    n = len(source)
    idx = [0, n // 2, n - 1]
    s3, t3 = source[idx], target[idx]
    pairs = [(0, 1), (0, 2), (1, 2)]
    half = [
        0.5 * abs(float(np.linalg.norm(s3[a] - s3[b])) - float(np.linalg.norm(t3[a] - t3[b])))
        for a, b in pairs
    ]
    return max(rigid_fit_rms(source, target), rigid_fit_rms(s3, t3), *half)


def rigid_fit_rms(source: Array, target: Array) -> float:
    """Root mean square distance after the best rigid (rotation + translation) fit of ``source`` onto ``target``.

    The closed form of the planar Procrustes problem: centred, the best rotation aligns the summed dot and
    cross products, and the residual is ``|a|^2 + |b|^2 - 2 sqrt(dot^2 + cross^2)``.
    """
    a = source - source.mean(axis=0)
    b = target - target.mean(axis=0)
    dot = float(np.sum(a * b))
    cross = float(np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]))
    ss = float(np.sum(a * a) + np.sum(b * b)) - 2.0 * float(np.hypot(dot, cross))
    return float(np.sqrt(max(ss, 0.0) / len(a)))


def segment_design(
    problem: Problem,
    design: str,
    targets: Sequence[TargetProfile],
    fitter: SegmentFitter,
    *,
    search: str = "paper",
    on_start_done: Callable[[], None] | None = None,
) -> SegmentedDesign:
    """Search the segment matrix of one design vector (Sec. 4) from ``problem.starts`` starts.

    The first start is ``problem.initial_segment_matrix`` when given (Eq. 11), else the even split.
    """
    pieces = [t.pieces for t in targets]
    rng = np.random.default_rng(design_seed(problem.seed, design))
    starts = initial_segment_matrices(design, pieces, problem.min_pieces, problem.starts, rng)
    if problem.initial_segment_matrix is not None:
        starts[0] = np.asarray(problem.initial_segment_matrix, dtype=np.int64)
    if fitter.compiled_tables is not None and len(design) * len(pieces) <= MAX_ENTRIES:
        outcome = compiled_search(design, starts, problem.min_pieces, fitter.compiled_tables)
        fitter.evaluations += outcome.iterations * len(design)  # fits computed, no cache
        for _ in starts:
            if on_start_done is not None:
                on_start_done()
    else:
        outcome = search_segment_matrix(
            design,
            starts,
            lambda sm: fitter.error_matrix(design, sm),
            problem.min_pieces,
            on_start_done=on_start_done,
        )
    matrices = [(outcome.segment_matrix, outcome.error_matrix)]
    if search == "refined":
        matrices.append(refine_segment_matrix(design, outcome.segment_matrix, fitter, problem.min_pieces))
    options = []
    for sm, em in matrices:
        if fitter.compiled_tables is not None:
            bound = compiled_rms_bound(design, sm, fitter.compiled_tables)
        else:
            bound = joined_error_bound(fitter.segments(design, sm), targets)
        options.append(Segmentation(sm, em, bound * (1.0 - BOUND_MARGIN)))
    return SegmentedDesign(
        design, tuple(options), outcome.history, outcome.iterations, float(outcome.error_matrix.max())
    )


def join_design(
    problem: Problem, segmented: SegmentedDesign, targets: Sequence[TargetProfile], fitter: SegmentFitter
) -> JoinedDesign | SkippedDesign:
    """Join every option of a segmented design (Sec. 5); the option with the lower joined error wins.

    A design none of whose options meets the closure (Eq. 31) or end (Eq. 32) constraint is returned as a
    :class:`SkippedDesign` whose reason names the design vector and the profile.
    """
    best: JoinedDesign | None = None
    reason = ""
    for opt in segmented.options:
        segments = fitter.segments(segmented.design, opt.segment_matrix)
        try:
            joined = join_chain(segments, targets, problem.kind)
        except ConvergenceError as exc:
            reason = f"design {segmented.design}: {exc}"
            continue
        e_max = max(float(prof.errors.max()) for prof in joined)
        cand = JoinedDesign(segmented.design, opt, segments, joined, e_max, segmented)
        if best is None or cand.rank_key < best.rank_key:
            best = cand
    if best is None:
        return SkippedDesign(segmented.design, reason, segmented)
    return best


def evaluate_design(problem: Problem, design: str, search: str = "paper") -> JoinedDesign | SkippedDesign:
    """Segment and join one design vector of ``problem``: a plain, picklable function of its arguments.

    Gives the same result as the design search of :func:`linkwork.synthesis.synthesize` for that design
    (the random starts are seeded by the design vector, not by the order designs are tried).
    """
    targets = target_profiles(problem)
    fitter = SegmentFitter(targets)
    segmented = segment_design(problem, design, targets, fitter, search=search)
    return join_design(problem, segmented, targets, fitter)
