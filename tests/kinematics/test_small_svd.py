"""The compiled one-sided Jacobi SVD (:mod:`linkwork.kinematics.small_svd`) and the march's tangent and test
function built on it, against LAPACK (numpy) and the LAPACK-based kernel they replace."""

from __future__ import annotations

import numpy as np
import pytest

from linkwork.kinematics import jit
from linkwork.kinematics import march as kernels
from linkwork.kinematics.small_svd import det_sign_in_place, jacobi_svd

RNG = np.random.default_rng(20261125)
SHAPES = [(6, 6), (6, 7), (12, 6), (3, 4), (6, 4), (6, 12), (1, 2)]


def matrices() -> list[np.ndarray]:
    """Random matrices of full rank, of rank one less, and with repeated singular values (a symmetric loop's
    Jacobian has pairs), and one with a zero column."""
    out = []
    for E, m in SHAPES:
        out.append(RNG.normal(size=(E, m)))
        out.append(RNG.normal(size=(E, m - 1)) @ RNG.normal(size=(m - 1, m)))  # rank-deficient
        k = min(E, m)
        s = np.sort(np.repeat(RNG.uniform(0.5, 2.0, size=(k + 1) // 2), 2)[:k])[::-1]
        U = np.linalg.qr(RNG.normal(size=(E, E)))[0][:, :k]
        V = np.linalg.qr(RNG.normal(size=(m, m)))[0][:, :k]
        out.append(U @ np.diag(s) @ V.T)  # repeated values
    zero = RNG.normal(size=(6, 6))
    zero[:, 2] = 0.0
    out.append(zero)
    return out


def decompose(A: np.ndarray, V: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
    E, m = A.shape
    V = np.eye(m) if V is None else V.copy()
    W, norms, order = np.empty((E, m)), np.empty(m), np.empty(m, dtype=np.int64)
    perm = jacobi_svd(A, V, W, norms, order)
    return V, W, norms, order, perm


@pytest.mark.parametrize("A", matrices(), ids=lambda A: f"{A.shape[0]}x{A.shape[1]}")
def test_jacobi_svd_is_lapacks_svd(A: np.ndarray) -> None:
    """Singular values to 1e-14 of the largest, ``W = A V`` with ``V`` a rotation, ``W``'s columns orthogonal,
    ``order`` sorting them, the permutation's sign as returned."""
    V, W, norms, order, perm = decompose(A)
    reference = np.linalg.svd(A, compute_uv=False)
    k = min(A.shape)
    scale = reference[0]
    np.testing.assert_allclose(norms[:k], reference, rtol=0, atol=1e-14 * scale)
    np.testing.assert_allclose(norms[k:], 0.0, atol=1e-14 * scale)
    assert np.all(np.diff(norms) <= 0.0)
    np.testing.assert_allclose(V.T @ V, np.eye(A.shape[1]), atol=1e-14)
    np.testing.assert_allclose(A @ V, W, atol=1e-14 * scale)
    gram = W.T @ W
    np.testing.assert_allclose(gram - np.diag(np.diag(gram)), 0.0, atol=1e-14 * scale**2)
    np.testing.assert_allclose(np.linalg.norm(W[:, order], axis=0), norms, atol=1e-14 * scale)
    assert perm * np.linalg.det(V[:, order]) == pytest.approx(1.0, abs=1e-12)  # det V = +1, sign of the order


def test_a_warm_start_gives_the_same_decomposition() -> None:
    """Started from the right singular vectors of a nearby matrix (the previous point of a path), the values are
    the same and the null vector is the same line."""
    A = RNG.normal(size=(6, 5)) @ RNG.normal(size=(5, 6))
    V_near, *_ = decompose(A + 1e-2 * RNG.normal(size=A.shape))
    cold = decompose(A)
    warm = decompose(A, V_near)
    np.testing.assert_allclose(warm[2], cold[2], rtol=0, atol=1e-14 * cold[2][0])
    null_cold, null_warm = cold[0][:, cold[3][-1]], warm[0][:, warm[3][-1]]
    assert abs(null_cold @ null_warm) == pytest.approx(1.0, abs=1e-14)
    np.testing.assert_allclose(A @ null_warm, 0.0, atol=1e-14 * cold[2][0])


@pytest.mark.parametrize("n", [1, 2, 3, 5])
def test_det_sign_in_place(n: int) -> None:
    for _ in range(20):
        G = RNG.normal(size=(n + 1, n + 1))
        expected = np.sign(np.linalg.det(G[:n, :n]))
        assert det_sign_in_place(G.copy(), n) == expected
    assert det_sign_in_place(np.zeros((n, n)), n) == 0.0


def path_of_jacobians(E: int, m: int, r: int, points: int = 40) -> list[np.ndarray]:
    """Smoothly varying ``(E, m)`` matrices of rank ``r`` (a path's Jacobians)."""
    A0, A1 = RNG.normal(size=(E, r)), RNG.normal(size=(E, r))
    B0, B1 = RNG.normal(size=(r, m)), RNG.normal(size=(r, m))
    return [(A0 + s * A1) @ (B0 + np.sin(s) * B1) for s in np.linspace(0.0, 1.0, points)]


@pytest.mark.parametrize(("E", "m"), [(6, 6), (6, 7), (3, 4), (12, 6)])
def test_tangent_and_test_agree_with_the_lapack_kernel_along_a_path(E: int, m: int) -> None:
    """Along a path of mobility one, the Jacobi kernel (warm-started from row to row, as the march runs it) and
    the LAPACK kernel it replaces give the same singular values (1e-14 of the largest), tangent (1e-12), range
    (projectors to 1e-10) with the same orientation, and signed test function (1e-12 relative)."""
    r = m - 1
    jacs = path_of_jacobians(E, m, r)
    U, _, Vt = np.linalg.svd(jacs[0])
    basis_a, basis_b = np.ascontiguousarray(U[:, :r]), np.ascontiguousarray(U[:, :r])
    t_a, t_b = Vt[-1].copy(), Vt[-1].copy()
    svd = kernels.svd_work(E, m)
    n_sigma = min(E, m)
    for jac in jacs:
        out_a, out_b = np.empty(m), np.empty(m)
        sig_a, sig_b = np.empty(n_sigma), np.empty(n_sigma)
        tau_a = kernels.tangent_and_test_in(jac, t_a, basis_a, r, out_a, sig_a, svd, np.ones(jac.shape[1]))
        tau_b = kernels.tangent_and_test_lapack(jac, t_b, basis_b, r, out_b, sig_b, np.ones(jac.shape[1]))
        np.testing.assert_allclose(sig_a, sig_b, rtol=0, atol=1e-14 * sig_b[0])
        np.testing.assert_allclose(out_a, out_b, atol=1e-12)
        # the same range, the same orientation (each column's own sign is free: only det(basis) is kept)
        np.testing.assert_allclose(basis_a @ basis_a.T, basis_b @ basis_b.T, atol=1e-10)
        assert np.linalg.det(basis_a.T @ basis_b) == pytest.approx(1.0, abs=1e-10)
        assert tau_a == pytest.approx(tau_b, rel=1e-12) and tau_b != 0.0
        t_a, t_b = out_a, out_b


def test_the_test_function_changes_sign_where_the_rank_drops() -> None:
    """A path through a simple rank drop (sigma_r passes through zero): the test function changes sign there
    and nowhere else, in both kernels."""
    E, m = 6, 7
    Q1 = np.linalg.qr(RNG.normal(size=(E, E)))[0]
    Q2 = np.linalg.qr(RNG.normal(size=(m, m)))[0]
    taus_a, taus_b = [], []
    U, _, Vt = np.linalg.svd(Q1 @ np.diag([3.0, 2.5, 2.0, 1.5, 1.0, -0.5]) @ Q2[:, :E].T)
    basis_a, basis_b = np.ascontiguousarray(U[:, :E]), np.ascontiguousarray(U[:, :E])
    t_a, t_b = Vt[-1].copy(), Vt[-1].copy()
    svd = kernels.svd_work(E, m)
    for s in np.linspace(-0.5, 0.5, 21) + 0.025:
        jac = Q1 @ np.diag([3.0, 2.5, 2.0, 1.5, 1.0, s]) @ Q2[:, :E].T
        out_a, out_b = np.empty(m), np.empty(m)
        taus_a.append(
            kernels.tangent_and_test_in(jac, t_a, basis_a, E, out_a, np.empty(E), svd, np.ones(jac.shape[1]))
        )
        taus_b.append(
            kernels.tangent_and_test_lapack(jac, t_b, basis_b, E, out_b, np.empty(E), np.ones(jac.shape[1]))
        )
        t_a, t_b = out_a, out_b
    assert np.count_nonzero(np.diff(np.sign(taus_a))) == 1
    np.testing.assert_allclose(taus_a, taus_b, rtol=1e-12)


def test_the_python_twin_of_the_tangent_kernel_agrees_with_the_compiled_one() -> None:
    twin, compiled = jit.python_backend(), jit.compiled_backend()
    for jac in path_of_jacobians(6, 6, 5, points=5):
        U, _, Vt = np.linalg.svd(jac)
        outs = []
        for backend in (twin, compiled):
            basis, t, sig = np.ascontiguousarray(U[:, :5]), np.empty(6), np.empty(6)
            tau = backend.tangent_and_test(jac, Vt[-1].copy(), basis, 5, t, sig, np.ones(jac.shape[1]))
            outs.append((tau, t, sig, basis))
        (tau_p, t_p, s_p, b_p), (tau_c, t_c, s_c, b_c) = outs
        assert tau_p == pytest.approx(tau_c, rel=1e-14)
        np.testing.assert_allclose(t_p, t_c, atol=1e-14)
        np.testing.assert_allclose(s_p, s_c, atol=1e-14)
        np.testing.assert_allclose(b_p, b_c, atol=1e-14)
