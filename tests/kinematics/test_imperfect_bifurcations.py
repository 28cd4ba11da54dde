"""An over-constrained linkage written with rounded numbers keeps its bifurcations.

Guest's frame (and the rectangular frame) has six bifurcation points on its paths. Written with every hinge line
moved by 1e-12 or 1e-11 of its size (what 12 significant digits, or coordinates far from the origin, leave) the
loop is strictly a slightly different linkage whose crossings open into near misses: the path turns sharply at
each, the test function changes sign where it turns, and the Jacobian's rank drops at the nearest approach within
that step, not where the test function vanishes. Before, the located zero had ``sigma_5 / sigma_1`` near 2e-4, the
sign change was counted "without a rank drop" and the bifurcations were lost (two or none of six at 1e-12). The
points found must be the exact frame's (configurations within 1e-4 rad), each a rank drop, and every crossing the
traced path passes must be found (four to six of the six, as each opens).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from bookkeeping_reference import wrapped

import linkwork as lw
from linkwork.kinematics.mechanism import Mechanism


def rounded(mech: Mechanism, size: float, seed: int) -> Mechanism:
    """``mech`` with every hinge line's moment moved by ``size`` (random, seeded): a written imperfection."""
    rng = np.random.default_rng(seed)
    twists = mech.twists.copy()
    twists[:, 3:] += size * rng.normal(size=twists[:, 3:].shape)
    return replace(mech, twists=twists, hinge_points=np.zeros((0, 3)))


@pytest.mark.parametrize("name", ["guest-frame", "rect-frame"])
@pytest.mark.parametrize("size", [1e-12, 1e-11])
@pytest.mark.parametrize("seed", [1, 2])
def test_a_rounded_frame_keeps_every_bifurcation(name: str, size: float, seed: int) -> None:
    exact = lw.trace(lw.load(name), branches=True)
    assert len(exact.bifurcations) == 6
    imperfect = lw.trace(rounded(lw.load(name), size, seed), branches=True)
    # Each crossing opens one way or the other: the nearest approach has two real branch tangents (a bifurcation,
    # branches leave it) or none (the path touches the singular set and turns back: a "fold" point, and the
    # branches beyond it are not on this path).
    assert {b.kind for b in imperfect.bifurcations} <= {"bifurcation", "fold"}
    assert imperfect.stats.sign_changes_without_rank_drop == 0
    for point in imperfect.bifurcations:  # each one of the exact frame's, and a rank drop where reported
        distance = min(float(np.abs(wrapped(point.angles - b.angles)).max()) for b in exact.bifurcations)
        assert distance < 1e-4
        assert point.sigma[point.rank] < 1e-4 * point.sigma[0]
    for b in exact.bifurcations:  # every crossing the traced path passes is located
        passes = np.abs(wrapped(imperfect.angles - b.angles)).max(axis=1).min() < 0.05
        if passes:
            assert (
                min(float(np.abs(wrapped(p.angles - b.angles)).max()) for p in imperfect.bifurcations) < 1e-4
            )
    assert len(imperfect.bifurcations) >= 4


@pytest.mark.parametrize("size", [1e-13, 1e-12])
@pytest.mark.parametrize("seed", [1, 2])
def test_a_rounded_sarrus_linkage_meets_its_components_once(size: float, seed: int) -> None:
    """Sarrus's linkage meets two 2-dimensional components (its two planar four-bar motions) at four points.
    Rounded, the corrected samples around those points no longer all converge; the small sphere around one then
    met the solution set in a curve (34 lines), each line was traced as a branch, and each branch entered the
    component at a point of its own: 138 points and 135 branches at 1e-13. A continuum of lines is a component."""
    exact = lw.trace(lw.load("sarrus"), branches=True)
    imperfect = lw.trace(rounded(lw.load("sarrus"), size, seed), branches=True)
    assert len(imperfect.bifurcations) <= len(exact.bifurcations)
    assert len(imperfect.branches) <= len(exact.branches) + 1
    for point in imperfect.bifurcations:
        distance = min(float(np.abs(wrapped(point.angles - b.angles)).max()) for b in exact.bifurcations)
        assert distance < 1e-3


@pytest.mark.parametrize("name", ["bennett", "goldberg", "hedgepeth"])
@pytest.mark.parametrize("size", [1e-10, 1e-9])
def test_a_loop_rigid_by_a_hair_says_what_play_lets_it_move(name: str, size: float) -> None:
    """Written to ten digits or fewer an over-constrained loop is rigid: its least-squares path's misfit grows
    until the corrector fails. The end says how well the loop closes there and suggests a closure tolerance,
    with which the path closes (checked: the misfit met stays below it)."""
    loop = rounded(lw.load(name), size, 1)
    failed = lw.trace(loop)
    end = failed.branches[0]
    assert end.end_kind == lw.StopReason.FAILED
    assert "rigid by a hair" in end.end_reason
    play = float(end.end_reason.rsplit(" ", 1)[1])
    assert 10.0 * size <= play <= 1e4 * size
    moved = lw.trace(loop, closure_tol=play)
    assert moved.branches[0].end_kind == lw.StopReason.CLOSED
    assert size / 10.0 < moved.stats.max_misfit < play
