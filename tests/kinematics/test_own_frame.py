"""A linkage moved far from the origin, or written in another length unit, is traced as the same linkage.

The tracer's rank decisions read ratios of singular values; on the raw Jacobian those change with placement
and unit (Goldberg in thousandths, 42 units from the origin: ``sigma_4 / sigma_1 = 9.8e-8`` against ``6e-2``, and
five singular points reported where there is none). A linkage far from its own frame is traced in it
(:mod:`linkwork.kinematics.own_frame`). Checked here on every built-in and on generated spatial and spherical loops,
each moved, turned and rescaled: the same rows (joint values, prismatic ones scaled), the same ranks, points and
folds, and at every row the singular values and residual of the *user's* Jacobian, against the independent
reference of ``bookkeeping_reference`` (scipy's matrix exponential and finite differences).
"""

from __future__ import annotations

import re
from dataclasses import replace

import numpy as np
import pytest
from bookkeeping_reference import bennett, fresh_rows, planar_four_bar, rotation, spherical_four_bar, wrapped

import linkwork as lw
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.own_frame import own_frame
from linkwork.linkages.registry import REGISTRY

EXACT_PLACEMENTS = {
    "in thousands": (1e3, np.zeros(3)),
    "in thousands, a few sizes away": (1e3, np.array([1e3, -2e3, 500.0])),
    "in thousandths, near": (1e-3, np.array([0.012, -0.04, 0.007])),
    "tenth of a thousandth": (1e-4, np.array([0.0, 3e-3, 0.0])),
}
"""Placements the file's round-off leaves exact (below 1e-13 of the linkage's size): the same rows, ranks, points."""

FAR_PLACEMENTS = {
    "thousandths, far": (1e-3, np.array([12.0, -40.0, 7.0])),
    "ten thousand away": (1.0, np.array([1e4, 0.0, 0.0])),
}
"""Placements whose coordinates carry round-off of 1e-12 to 1e-11 of the linkage's size (a 1e-16 relative error
of coordinates 1e4 times the size): an over-constrained linkage written so is that much off its exact geometry,
and is traced like the unit linkage with that imperfection: its bifurcations open into near misses, located where
the rank drops (``marcher._on_sign_change``)."""

PLACEMENTS = {**EXACT_PLACEMENTS, **FAR_PLACEMENTS}


def placed(mech: Mechanism, scale: float, shift: np.ndarray) -> Mechanism:
    """``mech`` with every length times ``scale``, turned and then moved by ``shift`` (the same linkage)."""
    R = rotation(np.array([0.0, 0.0, 1.0]) if mech.planar else np.array([0.3, -1.0, 0.5]), 2.1)
    if mech.planar:
        shift = np.array([shift[0], shift[1], 0.0])
    prismatic = np.array([t != "R" for t in mech.joint_types])
    w = mech.twists[:, :3] @ R.T
    v = mech.twists[:, 3:] @ R.T
    v = np.where(prismatic[:, None], v, scale * v + np.cross(shift, w))
    points = mech.hinge_points
    if len(points):
        points = scale * points @ R.T + shift
    return replace(
        mech,
        twists=np.concatenate([w, v], axis=1),
        offsets=np.where(prismatic, scale * mech.offsets, mech.offsets),
        hinge_points=points,
    )


def user_angles(path: lw.Trace, scale: float) -> np.ndarray:
    """The path's joint values with lengths divided by ``scale`` (back to the reference's unit)."""
    prismatic = np.array([t != "R" for t in path.mechanism.joint_types])
    return np.where(prismatic, path.angles / scale, path.angles)


def assert_same_linkage_traced(
    variant: lw.Trace, reference: lw.Trace, scale: float, shift: np.ndarray, exact: bool = True
) -> None:
    """Each row's singular values and residual the user's own, and the same points and folds; ``exact``: the same
    rows and ranks too (an imperfect over-constrained linkage may step differently where its bifurcations open)."""
    mech = variant.mechanism
    closed = 1e-10 * max(1.0, scale, float(np.linalg.norm(shift)))  # a rotation's round-off times the lever
    for k in np.linspace(0, len(variant.angles) - 1, 5).astype(int):
        fresh, misfit = fresh_rows(mech, variant.angles[k])
        np.testing.assert_allclose(variant.sigma[k], fresh, rtol=0, atol=1e-12 * fresh[0])
        assert variant.residual[k] < closed
        assert misfit < closed
    assert variant.max_condition == pytest.approx(reference.max_condition, rel=1e-6)
    if not exact:  # the same points; a component needs the exact geometry (imperfect, it is isolated points)
        assert len(variant.bifurcations) == len(reference.bifurcations)
        if all(b.kind != "component" for b in reference.bifurcations):
            assert [b.kind for b in variant.bifurcations] == [b.kind for b in reference.bifurcations]
        assert len(variant.folds) == len(reference.folds)
        assert [b.end_kind for b in variant.branches] == [b.end_kind for b in reference.branches]
        return
    assert variant.angles.shape == reference.angles.shape
    revolute = np.array([t == "R" for t in reference.mechanism.joint_types])
    mine, theirs = user_angles(variant, scale), reference.angles
    np.testing.assert_allclose(wrapped(mine[:, revolute] - theirs[:, revolute]), 0.0, atol=1e-8)
    np.testing.assert_allclose(mine[:, ~revolute], theirs[:, ~revolute], rtol=0, atol=1e-8)
    np.testing.assert_array_equal(variant.rank, reference.rank)
    assert [b.kind for b in variant.bifurcations] == [b.kind for b in reference.bifurcations]
    assert len(variant.folds) == len(reference.folds)
    for mine_fold, their_fold in zip(variant.folds, reference.folds, strict=True):
        drive = reference.mechanism.index(reference.drive)
        value = mine_fold.value if revolute[drive] else mine_fold.value / scale
        assert value == pytest.approx(their_fold.value, abs=1e-8)
    assert [b.end_kind for b in variant.branches] == [b.end_kind for b in reference.branches]


BUILT_INS = sorted(REGISTRY)


@pytest.mark.parametrize("name", BUILT_INS)
@pytest.mark.parametrize("where", sorted(PLACEMENTS))
def test_every_built_in_moved_and_rescaled_is_traced_as_itself(name: str, where: str) -> None:
    mech = lw.load(name)
    scale, shift = PLACEMENTS[where]
    reference = lw.trace(mech)
    assert not own_frame(mech).used  # every built-in is written near its own frame: traced as it is
    variant = lw.trace(placed(mech, scale, shift))
    assert_same_linkage_traced(variant, reference, scale, shift, exact=where in EXACT_PLACEMENTS)


def test_goldberg_in_thousandths_moved_far_has_no_singular_point() -> None:
    """The audit's case: five points (two with an accuracy of inf) were reported on a path without any."""
    mech = placed(lw.load("goldberg"), *FAR_PLACEMENTS["thousandths, far"])
    ratio = lambda p: p.sigma[:, 3] / p.sigma[:, 0]  # noqa: E731
    path = lw.trace(mech, branches=True)
    assert (
        ratio(path).min() < 1e-6
    )  # the raw ratios that misled the rank decisions are still the ones reported
    assert len(path.bifurcations) == 0
    assert path.branches[0].end_kind == lw.StopReason.CLOSED


def generated_linkage(seed: int) -> Mechanism:
    """A seeded Bennett linkage or planar four-bar (closed forms in ``bookkeeping_reference``)."""
    rng = np.random.default_rng(seed)
    if seed % 2:
        return bennett(*rng.uniform(0.3, 1.3, 2), rng.uniform(0.5, 2.5))
    # a crank-rocker (shortest + longest below the other two: the crank turns fully, any start assembles)
    crank, coupler, rocker = rng.uniform(0.4, 0.8), rng.uniform(1.8, 2.2), rng.uniform(1.5, 2.0)
    return planar_four_bar(2.0, crank, coupler, rocker, rng.uniform(0.3, 2.8))


@pytest.mark.parametrize("seed", [3, 4, 11, 12])
@pytest.mark.parametrize("where", sorted(PLACEMENTS))
def test_generated_linkages_moved_and_rescaled_are_traced_as_themselves(seed: int, where: str) -> None:
    mech = generated_linkage(seed)
    scale, shift = PLACEMENTS[where]
    reference = lw.trace(mech, branches=True)
    variant = lw.trace(placed(mech, scale, shift), branches=True)
    assert_same_linkage_traced(variant, reference, scale, shift, exact=where in EXACT_PLACEMENTS)


@pytest.mark.parametrize("where", sorted(PLACEMENTS))
def test_a_spherical_four_bar_far_from_the_origin_is_traced_as_itself(where: str) -> None:
    """Every hinge line through one point: the linkage's own length is 1 and its centre that point."""
    mech = spherical_four_bar(1.0, 0.5, 1.2, 0.9, 0.7)
    scale, shift = PLACEMENTS[where]
    variant = placed(mech, scale, shift)
    reference = lw.trace(mech, branches=True)
    exact = where in EXACT_PLACEMENTS
    assert_same_linkage_traced(lw.trace(variant, branches=True), reference, scale, shift, exact=exact)


def test_prismatic_targets_limits_and_verdicts_are_in_the_users_unit() -> None:
    """A slider-crank in thousands: a target, a limit and an unmet target's line on the slider, all in its
    unit, as the unit slider-crank's times 1000 (its slider's extremes are ``rod +- crank``)."""
    unit = lw.load("slider-crank", crank=1.0, rod=3.0, offset=0.0, theta=1.0)
    big = placed(unit, 1e3, np.zeros(3))
    assert own_frame(big).used
    start = float(big.offsets[big.index("D")])
    reached = lw.trace(big, drive="D", until=("D", start - 1000.0))
    assert reached.branches[0].end_kind == lw.StopReason.TARGET
    assert reached.angles[-1, big.index("D")] == pytest.approx(start - 1000.0, abs=1e-9)
    folds = sorted(f.value for f in lw.trace(big, drive="D").folds)
    assert folds == pytest.approx([2000.0, 4000.0], abs=1e-8)
    limited = lw.trace(big, drive="D", limits={"D": (start - 500.0, start + 1e6)})
    assert limited.branches[0].end_kind == lw.StopReason.LIMIT
    assert limited.branches[0].end_value == pytest.approx(start - 500.0, abs=1e-9)
    unmet = lw.trace(big, drive="D", until=("D", 5000.0)).stats.unmet
    assert unmet is not None
    numbers = [float(x) for x in re.findall(r"-?\d+\.?\d*", unmet.split("never reaches", 1)[1])]
    assert numbers[0] == pytest.approx(5000.0)
    assert numbers[-2:] == pytest.approx([2000.0, 4000.0], abs=1e-3)


def test_play_in_the_hinges_traces_the_same_in_any_unit_and_placement() -> None:
    """A Bennett linkage 1e-6 off its exact geometry (rigid without play) with play: the same play relative to its
    size gives the same path in thousands, in thousands far away and in thousandths (the twin compares a rotation
    misfit with ``TOL / L``)."""
    mech = lw.load("bennett")
    rng = np.random.default_rng(0)
    twists = mech.twists.copy()
    twists[:, 3:] += 1e-6 * rng.normal(size=(4, 3))
    imperfect = replace(mech, twists=twists, hinge_points=np.zeros((0, 3)))
    with pytest.raises(lw.LinkworkError, match="rigid"):
        lw.trace(imperfect)
    paths = []
    for scale, shift in [
        (1e3, np.zeros(3)),
        (1e3, np.array([5e3, 0.0, 0.0])),
        (1e-3, np.array([0.01, 0.02, 0.0])),
    ]:
        variant = placed(imperfect, scale, shift)
        assert own_frame(variant).used
        path = lw.trace(variant, closure_tol=1e-5 * scale)
        assert path.stats.closure_tol == pytest.approx(1e-5 * scale)
        paths.append(path)
    for path in paths[1:]:
        assert path.angles.shape == paths[0].angles.shape
        np.testing.assert_allclose(wrapped(path.angles - paths[0].angles), 0.0, atol=1e-9)
