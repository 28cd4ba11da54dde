"""The unrolled ``7 x 6`` Householder bidiagonalisation (:mod:`linkwork.kinematics.bidiagonal_7x6`): the checked-in
module is its generator's output, and its bidiagonal, determinant sign and tangent agree with numpy's SVD and QR
(outside references), including at rank-deficient and zero matrices."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from linkwork.kinematics import bidiagonal_7x6
from linkwork.kinematics.bidiagonal_7x6 import CHUNK, reduce_points
from linkwork.kinematics.jit import python_twin

GENERATOR = Path(__file__).resolve().parents[2] / "tools" / "generate_bidiagonal_7x6.py"


def test_the_checked_in_module_is_the_generators_output() -> None:
    spec = importlib.util.spec_from_file_location("generate_bidiagonal_7x6", GENERATOR)
    assert spec is not None and spec.loader is not None
    generator = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(generator)
    assert Path(bidiagonal_7x6.__file__).read_text() == generator.source()


def reduced(J: np.ndarray, plain: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The diagonal ``(n, 6)``, superdiagonal ``(n, 5)``, ``det(U) det(V)`` ``(n,)`` and tangent ``(n, 7)`` of
    the Jacobians ``J (n, 6, 7)`` (compiled, or the plain-Python twin)."""
    n = J.shape[0]
    B = np.zeros(bidiagonal_7x6.ROWS * CHUNK)
    for a in range(7):
        for e in range(6):
            B[(a * 6 + e) * CHUNK : (a * 6 + e) * CHUNK + n] = J[:, e, a]
    run = python_twin({"reduce": reduce_points}).reduce if plain else reduce_points
    run(B, n)
    rows = B.reshape(bidiagonal_7x6.ROWS, CHUNK)[:, :n]
    D, F, DET, T = bidiagonal_7x6.D, bidiagonal_7x6.F, bidiagonal_7x6.DET, bidiagonal_7x6.T
    return rows[D : D + 6].T, rows[F : F + 5].T, rows[DET], rows[T : T + 7].T


@pytest.mark.parametrize("plain", [False, True])
def test_the_bidiagonal_has_the_singular_values_and_the_tangent_spans_the_null_space(plain: bool) -> None:
    rng = np.random.default_rng(7)
    J = rng.normal(size=(40, 6, 7))
    J[1, 5] = J[1, 4]  # rank 5
    J[2] = 0.0  # nothing to reflect: every reflection is the identity
    J[3] *= 1e-100  # small (its squares well above the floor of a reflection)
    d, f, det, t = reduced(J, plain)
    for p in range(J.shape[0]):
        B = np.diag(d[p]) + np.diag(f[p], 1)
        s_ref = np.linalg.svd(J[p], compute_uv=False)
        scale = max(s_ref[0], 1e-300)
        np.testing.assert_allclose(np.linalg.svd(B, compute_uv=False), s_ref, rtol=0, atol=1e-14 * scale)
        if p == 2:
            assert det[p] == 1.0 and np.array_equal(t[p], np.eye(7)[6])
            continue
        assert np.linalg.norm(J[p] @ t[p]) <= 1e-14 * scale
        assert abs(np.linalg.norm(t[p]) - 1.0) <= 1e-15
        if p != 1:  # full rank: det([J; t^T]) = det(U) det(V) prod d_i, against numpy's determinant
            signed = det[p] * np.prod(d[p])
            reference = np.linalg.det(np.vstack([J[p], t[p]]))
            assert abs(signed - reference) <= 1e-12 * abs(reference)
