"""Shape-change synthesis from end to end (Shamsudin et al. 2013, Secs. 2-6).

Target profiles -> segment-matrix search for each design vector -> joining -> ranking by the joined error ->
compound segments.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from linkwork.errors import SpecError
from linkwork.synthesis.compound import merge_joints
from linkwork.synthesis.joining import join_chain
from linkwork.synthesis.problem import Problem
from linkwork.synthesis.refine import refine_segment_matrix
from linkwork.synthesis.result import DesignScore, JoinedProfile, SearchStats, Segment, SynthesisResult
from linkwork.synthesis.segment_fit import SegmentFitter
from linkwork.synthesis.segment_matrix import (
    check_design,
    check_feasible,
    design_vectors,
    initial_segment_matrices,
    search_segment_matrix,
)
from linkwork.synthesis.targets import target_profiles

Progress = Callable[[int, int], None]
SearchMethod = Literal["paper", "refined"]


@dataclass(frozen=True)
class _Candidate:
    design: str
    segment_matrix: NDArray[np.int64]
    error_matrix: NDArray[np.float64]
    segments: tuple[Segment, ...]
    joined: tuple[JoinedProfile, ...]
    joined_e_max: float
    history: tuple[tuple[float, ...], ...]
    paper_e_max: float

    @property
    def rank_key(self) -> tuple[float, float, float]:
        return (self.joined_e_max, float(self.error_matrix.max()), float(self.error_matrix.mean()))


def _design_seed(seed: int, design: str) -> list[int]:
    """Seed material of one design vector's random starts: independent of the order designs are tried."""
    return [seed, len(design), int(design.replace("M", "0").replace("C", "1"), 2)]


def synthesize(
    problem: Problem, progress: Progress | None = None, *, search: SearchMethod = "paper"
) -> SynthesisResult:
    """Synthesise a chain of M- and C-segments that approximates every profile of ``problem``.

    Parameters
    ----------
    problem
        The design profiles and the search settings.
    progress
        Called as ``progress(done, total)`` after each start of the search and each joining.
    search
        ``"paper"``: the adjustment rules of Section 4 from ``problem.starts`` initial segment matrices.
        ``"refined"``: the same, then a local search over the segmentation points from the paper's best matrix
        (never worse: it only accepts improvements).

    Returns
    -------
    SynthesisResult
        The design vector with the lowest ``E_max`` after joining, its segments, the joined chain on every
        profile and, when ``merge_below > 0``, the compound segments.

    Raises
    ------
    SpecError
        For an invalid problem (unknown design letters, too few pieces for the segments, ...).
    ConvergenceError
        When a closed or fixed-end chain cannot be joined.

    References
    ----------
    S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Kinematic synthesis of planar,
    shape-changing, rigid body mechanisms for design profiles with significant differences in arc length,
    Mech. Mach. Theory 70 (2013) 425-440.
    """
    if search not in ("paper", "refined"):
        raise SpecError(f"search must be 'paper' or 'refined', got {search!r}", key="search")
    t0 = time.perf_counter()
    targets = target_profiles(problem)
    pieces = [t.pieces for t in targets]
    if problem.design is not None and problem.design.strip().lower() != "auto":
        designs = [check_design(problem.design)]
    else:
        if problem.segments is None:
            raise SpecError("design 'auto' needs the number of segments", key="segments")
        designs = design_vectors(problem.segments, pieces)
    for design in designs:
        check_feasible(design, pieces, problem.min_pieces)

    fitter = SegmentFitter(targets)
    total = len(designs) * (problem.starts + 1)
    done = 0

    def tick() -> None:
        nonlocal done
        done += 1
        if progress is not None:
            progress(done, total)

    candidates: list[_Candidate] = []
    iterations = 0
    for design in designs:
        rng = np.random.default_rng(_design_seed(problem.seed, design))
        starts = initial_segment_matrices(design, pieces, problem.min_pieces, problem.starts, rng)
        outcome = search_segment_matrix(
            design,
            starts,
            lambda sm, d=design: fitter.error_matrix(d, sm),  # type: ignore[misc]
            problem.min_pieces,
            on_start_done=tick,
        )
        iterations += outcome.iterations
        options = [(outcome.segment_matrix, outcome.error_matrix)]
        if search == "refined":
            options.append(refine_segment_matrix(design, outcome.segment_matrix, fitter, problem.min_pieces))
        best: _Candidate | None = None
        for sm, em in options:
            segments = fitter.segments(design, sm)
            joined = join_chain(segments, targets, problem.kind)
            joined_e_max = max(float(prof.errors.max()) for prof in joined)
            cand = _Candidate(
                design,
                sm,
                em,
                segments,
                joined,
                joined_e_max,
                outcome.history,
                float(outcome.error_matrix.max()),
            )
            if best is None or cand.rank_key < best.rank_key:
                best = cand
        assert best is not None
        candidates.append(best)
        tick()

    candidates.sort(key=lambda c: c.rank_key)
    chosen = candidates[0]
    joined_em = np.column_stack([prof.errors for prof in chosen.joined])
    compound = None
    if problem.merge_below > 0.0:
        compound = merge_joints(
            chosen.design,
            chosen.segment_matrix,
            chosen.segments,
            targets,
            chosen.joined,
            problem.merge_below,
            problem.kind,
        )
    scores = tuple(
        DesignScore(
            c.design,
            c.segment_matrix,
            float(c.error_matrix.max()),
            float(c.error_matrix.mean()),
            c.joined_e_max,
        )
        for c in candidates
    )
    stats = SearchStats(
        search=search,
        designs=scores,
        starts=problem.starts,
        iterations=iterations,
        evaluations=fitter.evaluations,
        cache_hits=fitter.hits,
        seconds=time.perf_counter() - t0,
        paper_e_max=chosen.paper_e_max,
    )
    return SynthesisResult(
        problem=problem,
        targets=targets,
        design=chosen.design,
        segment_matrix=chosen.segment_matrix,
        error_matrix=chosen.error_matrix,
        e_max=float(chosen.error_matrix.max()),  # Eq. (22)
        e_mean=float(chosen.error_matrix.mean()),  # Eq. (24)
        segments=chosen.segments,
        joined_error_matrix=joined_em,
        joined_e_max=float(joined_em.max()),
        joined=chosen.joined,
        compound=compound,
        stats=stats,
        history=chosen.history,
    )
