"""M- and C-segments (Secs. 3.3, 3.4) on lines and circles, whose fits are exact."""

from __future__ import annotations

import numpy as np
import pytest

from linkwork.synthesis.arc_segment import arc_points, discrete_curvature, fit_arc_segment
from linkwork.synthesis.error_kernels import ProfileTables
from linkwork.synthesis.frames import rotation
from linkwork.synthesis.mean_segment import fit_mean_segment
from linkwork.synthesis.reference import arc_segment_errors, mean_segment_errors
from linkwork.synthesis.targets import target_profile


def circle_arc(
    radius: float, step: float, count: int, start: float, center: tuple[float, float]
) -> np.ndarray:
    phi = start + step * np.arange(count + 1)
    return np.column_stack([center[0] + radius * np.cos(phi), center[1] + radius * np.sin(phi)])


def test_curvature_of_points_on_a_circle() -> None:
    pts = circle_arc(2.5, 0.1, 20, 0.3, (1.0, -2.0))
    np.testing.assert_allclose(discrete_curvature(pts), 1 / 2.5, rtol=0, atol=1e-12)
    np.testing.assert_allclose(discrete_curvature(pts[::-1]), -1 / 2.5, rtol=0, atol=1e-12)  # clockwise


def test_arc_points_lie_on_the_circle_with_equal_chords() -> None:
    pts = arc_points(0.4, 0.3, 12)
    np.testing.assert_allclose(np.linalg.norm(np.diff(pts, axis=0), axis=1), 0.3, rtol=0, atol=1e-14)
    # the first chord runs from the origin along +x: the centre is on its perpendicular bisector, r away from
    # it
    center = np.array([0.15, np.sqrt(2.5**2 - 0.15**2)])
    np.testing.assert_allclose(np.linalg.norm(pts - center, axis=1), 2.5, rtol=0, atol=1e-12)


def test_concentric_arcs_of_different_length_fit_one_c_segment_exactly() -> None:
    # three arcs of radius 3 about one centre, equal angular step, different lengths (like Fig. 7)
    step, radius = 0.07, 3.0
    s_d = 2 * radius * np.sin(step / 2)  # the chord, so the target points are the arcs' own vertices
    arcs = [circle_arc(radius, step, n, a0, (0.5, 0.25)) for n, a0 in ((20, 0.0), (31, 1.0), (45, -2.0))]
    targets = [target_profile(a, s_d) for a in arcs]
    assert [t.pieces for t in targets] == [20, 31, 45]
    fit = fit_arc_segment([t.points for t in targets])
    assert fit.curvature == pytest.approx(1 / radius, abs=1e-10)
    assert np.max(fit.errors) < 1e-9


@pytest.mark.parametrize("kind", ["M", "C"])
def test_straight_lines_are_matched_exactly(kind: str) -> None:
    rng = np.random.default_rng(11)
    pieces = [10, 10, 10] if kind == "M" else [8, 13, 21]
    lines = []
    for m in pieces:
        direction = rotation(rng.uniform(-np.pi, np.pi)) @ [1.0, 0.0]
        lines.append(rng.normal(size=2) + np.outer(0.2 * np.arange(m + 1), direction))
    errors = fit_mean_segment(np.stack(lines)).errors if kind == "M" else fit_arc_segment(lines).errors
    assert np.max(errors) < 1e-12


def test_m_segment_of_one_shape_moved_rigidly_is_exact() -> None:
    rng = np.random.default_rng(5)
    shape = np.cumsum(rng.normal(size=(9, 2)), axis=0)
    moved = np.stack([shape @ rotation(a).T + rng.normal(size=2) for a in (0.0, 1.0, -2.5, 3.0)])
    fit = fit_mean_segment(moved)
    assert np.max(fit.errors) < 1e-12
    np.testing.assert_allclose(fit.instances, moved, rtol=0, atol=1e-12)


def test_m_segment_fit_is_invariant_to_a_rigid_motion_of_all_pieces() -> None:
    rng = np.random.default_rng(8)
    pieces = np.cumsum(rng.normal(size=(3, 12, 2)), axis=1)
    moved = pieces @ rotation(0.8).T + [3.0, -7.0]
    np.testing.assert_allclose(
        fit_mean_segment(pieces).errors, fit_mean_segment(moved).errors, rtol=0, atol=1e-12
    )


def test_numpy_fits_agree_with_the_plain_reference_and_the_compiled_kernels() -> None:
    rng = np.random.default_rng(21)
    profiles = [np.cumsum(rng.normal(scale=0.3, size=(n, 2)), axis=0) for n in (40, 55, 61)]
    compiled, plain = ProfileTables(profiles), ProfileTables(profiles, compiled=False)
    for _ in range(40):
        m = rng.integers(1, 30, size=3)
        starts = [int(rng.integers(0, len(z) - k)) for z, k in zip(profiles, m, strict=True)]
        pieces = [z[s : s + k + 1] for z, s, k in zip(profiles, starts, m, strict=True)]
        arc = fit_arc_segment(pieces).errors
        as_lists = [p.tolist() for p in pieces]
        np.testing.assert_allclose(arc, arc_segment_errors(as_lists), rtol=0, atol=1e-12)
        np.testing.assert_allclose(arc, compiled.arc_errors(starts, m), rtol=0, atol=1e-12)
        np.testing.assert_allclose(arc, plain.arc_errors(starts, m), rtol=0, atol=1e-12)
        k = int(m[0])
        mstarts = [int(rng.integers(0, len(z) - k)) for z in profiles]
        stack = np.stack([z[s : s + k + 1] for z, s in zip(profiles, mstarts, strict=True)])
        mean = fit_mean_segment(stack).errors
        np.testing.assert_allclose(mean, mean_segment_errors(stack.tolist()), rtol=0, atol=1e-12)
        np.testing.assert_allclose(mean, compiled.mean_errors(mstarts, k), rtol=0, atol=1e-12)
        np.testing.assert_allclose(mean, plain.mean_errors(mstarts, k), rtol=0, atol=1e-12)
