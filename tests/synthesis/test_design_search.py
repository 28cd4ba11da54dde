"""The design search on users' own profiles: it never aborts, skips only what cannot be joined, prunes exactly.

Profiles are NACA 4-digit outlines made from the published formulas (``naca.py``); references are the polygon
inequality (which chains can close), the end-point error bound of the segmentation, the exhaustive search, and
closed forms of the rigid fit.
"""

from __future__ import annotations

import math
import pickle
from typing import Any

import numpy as np
import pytest
from naca import naca4

from linkwork.errors import ConvergenceError, RequestNotMetError
from linkwork.synthesis import Problem, synthesize
from linkwork.synthesis.joining import join_profile, reach_gap
from linkwork.synthesis.search import (
    JoinedDesign,
    SkippedDesign,
    chain_joints,
    evaluate_design,
    rigid_fit_rms,
    segment_design,
)
from linkwork.synthesis.segment_fit import SegmentFitter
from linkwork.synthesis.targets import target_profiles

SETS = {
    "0012-2412-4412": ("0012", "2412", "4412"),
    "2412-4415-6412": ("2412", "4415", "6412"),
}
CHORDS = (1.0, 1.1, 1.25)


def naca_problem(codes: tuple[str, ...], kind: str, **kw: Any) -> Problem:
    profiles = tuple(naca4(c, chord, closed=kind == "closed") for c, chord in zip(codes, CHORDS, strict=True))
    settings: dict[str, Any] = {"piece_length": 0.03, "design": None, "segments": 4, "starts": 2}
    settings.update(kw)
    return Problem(profiles=profiles, kind=kind, **settings)  # type: ignore[arg-type]


def chord_gap(outcome: SkippedDesign | JoinedDesign, problem: Problem, j: int) -> tuple[float, float]:
    """(reach gap of the chain's chords on profile j, 2 x the sum of its segmentation errors there)."""
    opt = outcome.segmented.options[0]
    targets = target_profiles(problem)
    segments = SegmentFitter(targets).segments(outcome.design, opt.segment_matrix)
    lengths = [float(np.linalg.norm(seg.local_points(j)[-1] - seg.local_points(j)[0])) for seg in segments]
    target = targets[j].points
    span = 0.0 if problem.kind == "closed" else float(np.linalg.norm(target[-1] - target[0]))
    return reach_gap(lengths, span), 2.0 * float(opt.error_matrix[:, j].sum())


def test_reach_gap_is_the_polygon_inequality() -> None:
    assert reach_gap([3.0, 4.0, 5.0], 0.0) == 0.0  # a 3-4-5 triangle closes
    assert reach_gap([1.0, 1.0, 3.0], 0.0) == pytest.approx(1.0)  # 3 > 1 + 1 by 1
    assert reach_gap([1.0, 1.0], 2.5) == pytest.approx(0.5)  # fully stretched, 0.5 short
    assert reach_gap([1.0, 2.0], 0.5) == pytest.approx(0.5)  # folded back, ends at least 1 apart
    assert reach_gap([1.0, 2.0], 1.5) == 0.0


@pytest.mark.parametrize("name", sorted(SETS))
@pytest.mark.parametrize("kind", ["closed", "open", "fixed-end"])
def test_auto_search_on_naca_sets_never_aborts(name: str, kind: str) -> None:
    problem = naca_problem(SETS[name], kind)
    result = synthesize(problem)
    stats = result.stats
    assert stats.designs_tried == 2**4 - 1
    assert stats.designs_tried == len(stats.designs)
    # the chosen chain meets its constraint on every profile
    for prof, target in zip(result.joined, result.targets, strict=True):
        if kind == "closed":
            assert np.linalg.norm(prof.joints[-1] - prof.joints[0]) < 1e-9
        if kind == "fixed-end":  # Eq. 32: pinned at this profile's own end points
            assert np.linalg.norm(prof.joints[0] - target.points[0]) < 1e-9
            assert np.linalg.norm(prof.joints[-1] - target.points[-1]) < 1e-9
    assert result.joined_e_max < 0.05 * min(CHORDS)
    # a design is skipped only when its chords cannot close or reach (polygon inequality), and that only
    # happens when its segmentation errors are large: the gap is at most twice their sum on that profile
    for design, reason in stats.skipped:
        assert design in reason and "profile" in reason
        outcome = evaluate_design(problem, design)
        assert isinstance(outcome, SkippedDesign)
        gaps = [chord_gap(outcome, problem, j) for j in range(problem.count)]
        assert any(gap > 0.0 for gap, _ in gaps)
        for gap, bound in gaps:
            assert gap <= bound + 1e-12
    if kind == "closed":  # both closed sets have designs whose chords cannot close
        assert stats.skipped
    listed = result.to_dict()["search"]
    assert listed["designs_tried"] == 15
    assert [s["design"] for s in listed["skipped"]] == [d for d, _ in stats.skipped]


@pytest.mark.parametrize("design", ["CMCM", "MMCC", "CCMM"])
def test_closed_naca_designs_of_the_issue_join(design: str) -> None:
    result = synthesize(naca_problem(SETS["0012-2412-4412"], "closed", design=design, starts=5))
    assert result.joined_e_max < 0.05
    for prof in result.joined:
        assert np.linalg.norm(prof.joints[-1] - prof.joints[0]) < 1e-9


def test_joining_from_a_singular_start_still_closes() -> None:
    # a square of side 1 as four straight M-segments, started with all chords parallel (rank-deficient
    # constraint Jacobian): the damped projection with restarts reaches the square exactly
    side = np.column_stack([np.linspace(0.0, 1.0, 5), np.zeros(5)])
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0]])
    target = np.vstack(
        [
            corners[k] + np.outer(np.linspace(0, 1, 5)[: 4 if k < 3 else 5], corners[k + 1] - corners[k])
            for k in range(4)
        ]
    )
    joined = join_profile([side] * 4, target, [0.0, 0.0], np.zeros(4), closed=True)
    assert np.linalg.norm(joined.joints[-1] - joined.joints[0]) < 1e-12
    assert joined.errors.max() < 1e-9


def test_a_chain_that_cannot_close_names_the_profile() -> None:
    long = np.column_stack([np.linspace(0.0, 3.0, 4), np.zeros(4)])
    short = np.column_stack([np.linspace(0.0, 1.0, 4), np.zeros(4)])
    target = np.vstack([long, short[1:] + np.array([3.0, 0.0])])
    with pytest.raises(ConvergenceError, match="cannot close on itself"):
        join_profile([long, short], target, [0.0, 0.0], np.zeros(2), closed=True)


def test_no_joinable_design_is_request_not_met(monkeypatch: pytest.MonkeyPatch) -> None:
    import linkwork.synthesis.search as search

    def refuse(*args: object, **kw: object) -> None:
        raise ConvergenceError("profile '1': joining: refused for the test")

    monkeypatch.setattr(search, "join_chain", refuse)
    with pytest.raises(RequestNotMetError, match="no design vector of the 15 tried could be joined: design "):
        synthesize(naca_problem(SETS["0012-2412-4412"], "closed", starts=1))


def test_pruned_search_equals_the_exhaustive_one() -> None:
    problem = naca_problem(SETS["2412-4415-6412"], "open", segments=5)
    pruned = synthesize(problem)
    exhaustive = synthesize(problem, prune=False)
    assert pruned.design == exhaustive.design
    assert pruned.joined_e_max == exhaustive.joined_e_max
    np.testing.assert_array_equal(pruned.segment_matrix, exhaustive.segment_matrix)
    assert pruned.stats.pruned > 0 and exhaustive.stats.pruned == 0
    # the bound is a true lower bound on every design's joined E_max
    for score in exhaustive.stats.designs:
        assert score.joined_e_max is not None and score.bound <= score.joined_e_max
    # each design's evaluation is a plain picklable function giving the same numbers
    scores = {s.design: s for s in exhaustive.stats.designs}
    evaluate = pickle.loads(pickle.dumps(evaluate_design))
    for design in ("CCMCC", exhaustive.design):
        outcome = evaluate(problem, design)
        assert isinstance(outcome, JoinedDesign)
        assert outcome.joined_e_max == scores[design].joined_e_max


def test_rigid_fit_rms_closed_forms() -> None:
    rng = np.random.default_rng(3)
    pts = rng.normal(size=(12, 2))
    c, s = math.cos(0.7), math.sin(0.7)
    moved = pts @ np.array([[c, s], [-s, c]]) + [3.0, -1.0]
    assert rigid_fit_rms(pts, moved) < 1e-12
    centred = pts - pts.mean(axis=0)
    expected = 0.25 * math.sqrt(float(np.sum(centred**2)) / len(pts))  # a 1.25x copy: |k - 1| RMS radius
    assert rigid_fit_rms(pts, 1.25 * pts + [1.0, 2.0]) == pytest.approx(expected, rel=1e-12)


def test_rank_by_joints_within_the_tolerance() -> None:
    base = naca_problem(SETS["2412-4415-6412"], "open", segments=3)
    by_error = synthesize(base, prune=False)
    errors = {s.design: s.joined_e_max for s in by_error.stats.designs}
    tolerance = sorted(e for e in errors.values() if e is not None)[-1] * 1.01  # every design acceptable
    loose = synthesize(Problem(**{**base.__dict__, "rank_by": "joints", "e_max_tolerance": tolerance}))
    fewest = min(chain_joints(d, "open") for d in errors)
    assert chain_joints(loose.design, "open") == fewest
    assert loose.joined_e_max == min(e for d, e in errors.items() if chain_joints(d, "open") == fewest)
    tight = synthesize(Problem(**{**base.__dict__, "rank_by": "joints", "e_max_tolerance": 1e-9}))
    assert tight.design == by_error.design  # nothing acceptable: the best error
    # pruning keeps the choice of the joints ranking too (tolerance between the best and the worst error)
    middle = Problem(
        **{**base.__dict__, "rank_by": "joints", "e_max_tolerance": float(np.median(list(errors.values())))}
    )
    assert synthesize(middle).design == synthesize(middle, prune=False).design
    assert chain_joints("MCMC", "open") == 3 + 2 and chain_joints("MCMC", "fixed-end") == 3 + 2 + 2


def test_compiled_search_makes_the_python_search_decisions() -> None:
    problem = naca_problem(SETS["0012-2412-4412"], "closed", segments=6, starts=3, min_pieces=3)
    targets = target_profiles(problem)
    fast, plain = SegmentFitter(targets), SegmentFitter(targets, compiled=False)
    for design in ("CMCMCM", "MMCCMC", "CCCCCC", "MCMMMM"):
        a = segment_design(problem, design, targets, fast)
        b = segment_design(problem, design, targets, plain)
        np.testing.assert_array_equal(a.options[0].segment_matrix, b.options[0].segment_matrix)
        np.testing.assert_array_equal(a.options[0].error_matrix, b.options[0].error_matrix)
        assert a.history == b.history and a.iterations == b.iterations
        # the compiled RMS bound is the RMS of the rigid fits of the segments that are joined
        assert a.bound == pytest.approx(b.bound, rel=1e-12)
