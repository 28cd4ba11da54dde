"""The shared math of linkwork.geometry: one wrap, one Kabsch, one planar fit, one naming rule."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from linkwork.geometry.angles import wrap, wrapped_difference
from linkwork.geometry.fit import kabsch, register
from linkwork.geometry.names import default_joint_names
from linkwork.geometry.se2 import apply, pose_matrix, pose_of, relative


@given(st.floats(-1e3, 1e3, allow_nan=False))
def test_wrap_lands_in_the_half_open_interval_and_keeps_the_angle(angle: float) -> None:
    w = float(wrap(angle))
    assert -np.pi <= w < np.pi
    # Same point on the circle (tolerance: float rounding of the modulo at this magnitude).
    assert abs(np.sin(w) - np.sin(angle)) < 1e-9 and abs(np.cos(w) - np.cos(angle)) < 1e-9


def test_wrap_seam_is_minus_pi() -> None:
    assert float(wrap(np.pi)) == -np.pi and float(wrap(-np.pi)) == -np.pi
    difference = float(wrapped_difference(np.radians(179.0), np.radians(-179.0)))
    assert difference == pytest.approx(np.radians(-2.0), abs=1e-12)


def test_default_names_stay_distinct_past_26_joints() -> None:
    names = default_joint_names(200)
    assert names[:3] == ["A", "B", "C"] and names[26] == "A1" and len(set(names)) == 200


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_kabsch_recovers_a_known_rigid_motion(seed: int) -> None:
    rng = np.random.default_rng(seed)
    pts = rng.normal(size=(7, 3))
    rot = Rotation.random(random_state=seed).as_matrix()  # reference rotation from scipy, not from our code
    shift = rng.normal(size=3)
    T = kabsch(pts, pts @ rot.T + shift)
    assert np.allclose(T[:3, :3], rot, atol=1e-10) and np.allclose(T[:3, 3], shift, atol=1e-10)
    assert np.linalg.det(T[:3, :3]) == pytest.approx(1.0, abs=1e-12)


def test_kabsch_never_reflects() -> None:
    pts = np.random.default_rng(1).normal(size=(6, 3))
    mirrored = pts * np.array([1.0, 1.0, -1.0])
    assert np.linalg.det(kabsch(pts, mirrored)[:3, :3]) == pytest.approx(1.0, abs=1e-12)


def test_planar_fit_agrees_with_kabsch_on_points_in_a_plane() -> None:
    rng = np.random.default_rng(2)
    src = rng.normal(size=(9, 2))
    rot = np.array([[0.6, -0.8], [0.8, 0.6]])
    dst = src @ rot.T + [0.3, -1.2] + rng.normal(scale=1e-3, size=(9, 2))
    planar = register(src, dst)
    flat = np.c_[src, np.zeros(9)]
    T = kabsch(flat, np.c_[dst, np.zeros(9)])
    assert np.allclose(planar.apply(src), (flat @ T[:3, :3].T + T[:3, 3])[:, :2], atol=1e-12)


def test_planar_poses_compose_as_matrices() -> None:
    a, b = np.array([0.4, -1.0, 0.7]), np.array([2.0, 0.5, -2.1])
    assert np.allclose(pose_of(pose_matrix(a) @ pose_matrix(b)), [*apply(a, b[:2]), 0.7 - 2.1], atol=1e-12)
    assert np.allclose(relative(a[None], a[None]), 0.0, atol=1e-12)
