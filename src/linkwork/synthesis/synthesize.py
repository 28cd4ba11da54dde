"""Shape-change synthesis from end to end (Shamsudin et al. 2013, Secs. 2-6).

Target profiles -> segment-matrix search for each design vector -> joining -> ranking by the joined error ->
compound segments.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import replace
from typing import Literal

import numpy as np

from linkwork.errors import RequestNotMetError, SpecError
from linkwork.interrupts import requested, stop_text
from linkwork.messages import escape_line
from linkwork.progress import Progress
from linkwork.synthesis.compound import merge_joints
from linkwork.synthesis.problem import Problem
from linkwork.synthesis.result import Compound, DesignScore, SearchStats, SynthesisResult, TargetProfile
from linkwork.synthesis.search import (
    JoinedDesign,
    SegmentedDesign,
    SkippedDesign,
    chain_joints,
    join_design,
    segment_design,
)
from linkwork.synthesis.segment_fit import SegmentFitter
from linkwork.synthesis.segment_matrix import check_design, check_feasible, design_vectors, is_valid
from linkwork.synthesis.targets import target_profiles

SearchMethod = Literal["paper", "refined"]


def _check_initial(problem: Problem, design: str, pieces: list[int]) -> None:
    """The given initial segment matrix fits the design vector and the target profiles.

    That it comes with one design vector (not ``design = "auto"``) is a rule of :class:`Problem`.
    """
    sm = problem.initial_segment_matrix
    if sm is None:
        return
    key = "initial_segment_matrix"
    src = None if problem.source is None else str(problem.source)
    arr = np.asarray(sm)
    if arr.shape != (len(design), len(pieces)):
        raise SpecError(
            f"has shape {arr.shape}; expected one entry per segment ({len(design)}) and profile ({len(pieces)})",
            source=src,
            key=key,
        )
    if not is_valid(arr.astype(np.int64), design, pieces, problem.min_pieces):
        raise SpecError(
            f"is not a valid segment matrix for design {design}: each profile's entries must sum to its "
            f"pieces {pieces}, M-segments must have equal entries on every profile, every entry >= "
            f"min_pieces {problem.min_pieces}",
            source=src,
            key=key,
        )


def _ranked(joined: list[JoinedDesign], problem: Problem) -> list[JoinedDesign]:
    """Joined designs best first: by error, or by joints within ``e_max_tolerance`` (Sec. 5)."""
    by_error = sorted(joined, key=lambda c: c.rank_key)
    if problem.rank_by == "error":
        return by_error
    tol = float(problem.e_max_tolerance or 0.0)
    good = [c for c in by_error if c.joined_e_max <= tol]
    good.sort(key=lambda c: (chain_joints(c.design, problem.kind), c.rank_key))
    return good + [c for c in by_error if c.joined_e_max > tol]


def _join_pruned(
    problem: Problem,
    segmented: list[SegmentedDesign],
    targets: tuple[TargetProfile, ...],
    fitter: SegmentFitter,
    prune: bool,
    tick: Callable[[], None],
) -> tuple[list[JoinedDesign], list[SkippedDesign], list[SegmentedDesign], list[SegmentedDesign]]:
    """Join the designs in the order of their lower bounds; skip those whose bound cannot beat the best.

    A design is left unjoined ("pruned") only when its bound exceeds the best joined ``E_max`` so far and, for
    ``rank_by = "joints"``, also ``e_max_tolerance``: it can then neither rank first nor be acceptable. A signal
    held by the command line (:func:`linkwork.interrupts.requested`) stops the joining once one design is
    joined; the designs left are returned last (``(joined, skipped, pruned, not joined)``).
    """
    joined: list[JoinedDesign] = []
    skipped: list[SkippedDesign] = []
    pruned: list[SegmentedDesign] = []
    left: list[SegmentedDesign] = []
    best = math.inf
    tol = -math.inf if problem.rank_by == "error" else float(problem.e_max_tolerance or 0.0)
    for seg in sorted(segmented, key=lambda d: (d.bound, d.design)):
        if joined and requested():  # stopped: the best joined so far is the result
            left.append(seg)
            continue
        if prune and seg.bound > best and seg.bound > tol:
            pruned.append(seg)
        else:
            outcome = join_design(problem, seg, targets, fitter)
            if isinstance(outcome, SkippedDesign):
                skipped.append(outcome)
            else:
                joined.append(outcome)
                best = min(best, outcome.joined_e_max)
        tick()
    return joined, skipped, pruned, left


def synthesize(
    problem: Problem,
    progress: Progress | None = None,
    *,
    search: SearchMethod = "paper",
    prune: bool = True,
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
    prune
        Join only the design vectors whose lower bound on the joined ``E_max`` (see
        :func:`linkwork.synthesis.search.joined_error_bound`) does not exceed the best joined ``E_max`` found;
        the chosen design is the same as with ``prune=False``, which joins every design vector.

    Returns
    -------
    SynthesisResult
        The design vector ranked first (``problem.rank_by``; by default the lowest ``E_max`` after joining),
        its segments, the joined chain on every profile and, when ``merge_below > 0``, the compound segments.
        A SIGINT or SIGTERM held by the command line (:func:`linkwork.interrupts.held_signals`) stops the search
        after the design vector in hand: the designs searched so far are joined in the order of their bounds
        until one joins, and the result is the best of those joined, ``stats.stopped`` saying why.

    Raises
    ------
    SpecError
        For an invalid problem (unknown design letters, too few pieces for the segments, ...).
    RequestNotMetError
        When no design vector can be joined (each closed or fixed-end chain misses its constraint), or none
        searched before a signal stopped the search; a design that cannot be joined is otherwise skipped and
        listed in ``stats.skipped``.

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
    designs = _designs_to_try(problem, [t.pieces for t in targets])
    fitter = SegmentFitter(targets)
    tick = _ticker(progress, len(designs) * (problem.starts + 1))
    segmented: list[SegmentedDesign] = []
    for design in designs:
        if requested():  # a signal held by the command line: the designs searched so far are kept
            break
        segmented.append(segment_design(problem, design, targets, fitter, search=search, on_start_done=tick))
    joined, skipped, pruned, left = _join_pruned(problem, segmented, targets, fitter, prune, tick)
    signum = requested()
    stopped = stop_text(signum) if signum and (left or len(segmented) < len(designs)) else None
    if not joined:
        if stopped:
            raise RequestNotMetError(
                f"{stopped} before any design vector was joined ({len(segmented)} of {len(designs)} searched)"
            )
        reasons = "; ".join(s.reason for s in skipped[:3]) + ("; ..." if len(skipped) > 3 else "")
        raise RequestNotMetError(f"no design vector of the {len(designs)} tried could be joined: {reasons}")
    ranked = _ranked(joined, problem)
    compound = _compound(problem, targets, ranked[0])
    seconds = time.perf_counter() - t0
    stats = _search_stats(problem, search, segmented, fitter, (ranked, skipped, pruned, left), seconds)
    if stopped:
        stats = replace(stats, stopped=stopped, not_searched=len(designs) - len(segmented))
    return _result(problem, targets, ranked[0], compound, stats)


def _designs_to_try(problem: Problem, pieces: list[int]) -> list[str]:
    """The design vectors to search: the problem's own, or every one of ``segments`` letters (``design =
    "auto"``; the rules of :class:`Problem` ensure ``segments`` then), each checked against the profiles' pieces
    (and the initial segment matrix, which comes only with one design vector)."""
    if problem.auto_design:
        assert problem.segments is not None
        designs = design_vectors(problem.segments, pieces)
    else:
        assert problem.design is not None
        designs = [check_design(problem.design)]
    try:
        for design in designs:
            check_feasible(design, pieces, problem.min_pieces)
        _check_initial(problem, designs[0], pieces)
    except SpecError as exc:  # a rule of the problem as a whole: the line names the problem's file
        if exc.source is not None or problem.source is None:
            raise
        raise SpecError(exc.detail, source=escape_line(str(problem.source)), key=exc.key) from None
    return designs


def _ticker(progress: Progress | None, total: int) -> Callable[[], None]:
    """A function to call once per unit of work done; it reports ``progress(done, total)`` when given."""
    done = 0

    def tick() -> None:
        nonlocal done
        done += 1
        if progress is not None:
            progress(done, total)

    return tick


def _compound(problem: Problem, targets: tuple[TargetProfile, ...], chosen: JoinedDesign) -> Compound | None:
    """The chosen design's compound segments (Sec. 6), or ``None`` when merging is off (``merge_below == 0``)."""
    if problem.merge_below <= 0.0:
        return None
    return merge_joints(
        chosen.design,
        chosen.segmentation.segment_matrix,
        chosen.segments,
        targets,
        chosen.joined,
        problem.merge_below,
        problem.kind,
        merge_on=problem.merge_on,
    )


def _result(
    problem: Problem,
    targets: tuple[TargetProfile, ...],
    chosen: JoinedDesign,
    compound: Compound | None,
    stats: SearchStats,
) -> SynthesisResult:
    """The result for the design ranked first: its segmentation, joined chain and compound segments."""
    opt = chosen.segmentation
    joined_em = np.column_stack([prof.errors for prof in chosen.joined])
    return SynthesisResult(
        problem=problem,
        targets=targets,
        design=chosen.design,
        segment_matrix=opt.segment_matrix,
        error_matrix=opt.error_matrix,
        e_max=float(opt.error_matrix.max()),  # Eq. (22)
        e_mean=float(opt.error_matrix.mean()),  # Eq. (24)
        segments=chosen.segments,
        joined_error_matrix=joined_em,
        joined_e_max=float(joined_em.max()),
        joined=chosen.joined,
        compound=compound,
        stats=stats,
        history=chosen.segmented.history,
    )


def _search_stats(
    problem: Problem,
    search: str,
    segmented: list[SegmentedDesign],
    fitter: SegmentFitter,
    outcomes: tuple[list[JoinedDesign], list[SkippedDesign], list[SegmentedDesign], list[SegmentedDesign]],
    seconds: float,
) -> SearchStats:
    """The search's statistics and its table of design vectors: ``outcomes`` are the joined designs in rank
    order, the skipped and the pruned ones, and those a signal left unjoined."""
    ranked, skipped, pruned, left = outcomes
    scores = [_score(c.segmented, c, problem) for c in ranked]
    scores += [_score(s.segmented, None, problem) for s in skipped]
    scores += [_score(p, None, problem) for p in pruned + left]
    return SearchStats(
        search=search,
        designs=tuple(scores),
        starts=problem.starts,
        iterations=sum(d.iterations for d in segmented),
        evaluations=fitter.evaluations,
        cache_hits=fitter.hits,
        seconds=seconds,
        paper_e_max=ranked[0].segmented.paper_e_max,
        designs_tried=len(segmented),
        skipped=tuple((s.design, s.reason) for s in skipped),
        pruned=len(pruned),
        not_joined=len(left),
        rank_by=problem.rank_by,
        e_max_tolerance=problem.e_max_tolerance,
    )


def _score(seg: SegmentedDesign, joined: JoinedDesign | None, problem: Problem) -> DesignScore:
    """A design's line of the search table: its (best joined, else paper's) matrix, errors and bound."""
    opt = joined.segmentation if joined is not None else seg.options[0]
    return DesignScore(
        seg.design,
        opt.segment_matrix,
        float(opt.error_matrix.max()),
        float(opt.error_matrix.mean()),
        None if joined is None else joined.joined_e_max,
        bound=seg.bound,
        joints=chain_joints(seg.design, problem.kind),
    )
