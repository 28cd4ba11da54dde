"""Planar registration against Umeyama's worked example and exact rigid motions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from linkwork.geometry.fit import register
from linkwork.synthesis.frames import rotation, to_local_frame

# Umeyama (1991), Sec. IV: x = (0,0), (1,0), (0,2) mapped onto y = (0,0), (-1,0), (0,2) (here in the order of
# the brief: reference (0,2), (0,0), (-1,0); sensed (0,2), (0,0), (1,0)).
REFERENCE = np.array([[0.0, 2.0], [0.0, 0.0], [-1.0, 0.0]])
SENSED = np.array([[0.0, 2.0], [0.0, 0.0], [1.0, 0.0]])


def test_umeyama_example_with_scale() -> None:
    t = register(SENSED, REFERENCE, with_scale=True)
    # the paper prints R = [[0.832, 0.555], [-0.555, 0.832]], c = 0.721, t = (-0.8, 0.4)
    assert math.degrees(float(t.angle)) == pytest.approx(-33.6901, abs=1e-4)
    assert float(t.scale) == pytest.approx(0.7211, abs=1e-4)
    np.testing.assert_allclose(t.translation, [-0.8, 0.4], rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        t.matrix, [[0.6, 0.4], [-0.4, 0.6]], rtol=0, atol=1e-12
    )  # c R = [[.6,.4],[-.4,.6]]


def test_rigid_registration_keeps_scale_one_and_never_reflects() -> None:
    t = register(SENSED, REFERENCE)  # the best match is a reflection, which a rigid motion cannot do
    assert float(t.scale) == 1.0
    assert np.linalg.det(t.matrix) == pytest.approx(1.0, abs=1e-14)


@settings(max_examples=50, deadline=None)
@given(
    angle=st.floats(-math.pi, math.pi),
    dx=st.floats(-100, 100),
    dy=st.floats(-100, 100),
    seed=st.integers(0, 2**32 - 1),
)
def test_recovers_an_exact_rigid_motion(angle: float, dx: float, dy: float, seed: int) -> None:
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(7, 2))
    y = x @ rotation(angle).T + [dx, dy]
    t = register(x, y)
    np.testing.assert_allclose(t.apply(x), y, rtol=0, atol=1e-9)
    assert math.remainder(float(t.angle) - angle, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)


def test_batched_registration_matches_one_by_one() -> None:
    rng = np.random.default_rng(3)
    x, y = rng.normal(size=(4, 6, 2)), rng.normal(size=(4, 6, 2))
    batch = register(x, y)
    for k in range(4):
        one = register(x[k], y[k])
        np.testing.assert_allclose(batch.apply(x)[k], one.apply(x[k]), rtol=0, atol=1e-13)


def test_local_frame_puts_the_chord_on_x() -> None:
    loc = to_local_frame([[1.0, 1.0], [2.0, 3.0], [1.0, 4.0]])
    np.testing.assert_allclose(loc[0], [0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(loc[-1], [3.0, 0.0], atol=1e-15)


def test_mismatched_shapes_say_what_was_expected() -> None:
    with pytest.raises(ValueError, match=r"\(\.\.\., n, 2\)"):
        register(np.zeros((3, 2)), np.zeros((4, 2)))
