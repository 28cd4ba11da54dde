"""The batched rows of one-loop planar Jacobians (:mod:`linkwork.kinematics.planar_rows`) against LAPACK (numpy's
SVD and determinant): random Jacobians, real four-bar and slider-crank Jacobians along a turn, and adversarial
ones (equal singular values, near rank drops, a zero column, scaled by 1e-6 and 1e6)."""

from __future__ import annotations

import platform
import re
from fractions import Fraction

import numba
import numpy as np
import pytest
from closed_form_probe import assert_rows_contract

import linkwork as lw
from linkwork.kinematics import planar_rows
from linkwork.kinematics.closure import jacobian
from linkwork.kinematics.jit import python_twin
from linkwork.kinematics.planar_rows import one_loop_rows

RNG = np.random.default_rng(20261125)
SIGMA_TOL = 1e-13  # every singular value, relative to sigma_1
RESIDUAL_TOL = 1e-14  # |J t| relative to sigma_1
UNIT_TOL = 1e-15  # | |t| - 1 |
TAU_TOL = 1e-13  # raw_tau relative to det([J; t^T]) (see check_rows for nearly rank-deficient J)


def rows(J: np.ndarray, kernel=one_loop_rows) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:  # type: ignore[no-untyped-def]
    """``(sigma (K, 3), tangent (K, 4), raw_tau (K,), fall-backs)`` of ``J (K, 3, 4)``."""
    K = J.shape[0]
    jac = np.ascontiguousarray(J.transpose(1, 2, 0))
    sigma, tangent, raw_tau = np.full((3, K), np.nan), np.full((4, K), np.nan), np.full(K, np.nan)
    count = kernel(jac, sigma, tangent, raw_tau)
    return sigma.T, tangent.T, raw_tau, int(count)


def check_rows(J: np.ndarray, kernel=one_loop_rows) -> int:  # type: ignore[no-untyped-def]
    """Assert the accuracy contract on every point of ``J (K, 3, 4)``; returns the number of fall-backs."""
    sigma, t, tau, count = rows(J, kernel)
    assert_rows_contract(J, (sigma, t, tau), (SIGMA_TOL, RESIDUAL_TOL, UNIT_TOL, TAU_TOL), product_bound=True)
    return count


def with_singular_values(s: np.ndarray, K: int = 400) -> np.ndarray:
    """``K`` Jacobians ``U diag(s) V^T`` with random orthogonal ``U (3, 3)``, ``V (4, 4)``."""
    U = np.linalg.qr(RNG.normal(size=(K, 3, 3)))[0]
    V = np.linalg.qr(RNG.normal(size=(K, 4, 4)))[0]
    S = np.zeros((K, 3, 4))
    S[:, [0, 1, 2], [0, 1, 2]] = s
    return U @ S @ V.transpose(0, 2, 1)


def turn_jacobians(name: str, **params: float) -> np.ndarray:
    """The closure Jacobians of a built-in along one turn of its crank (360 steps), from ``closure.jacobian``."""
    mech = lw.load(name, **params)
    trace = lw.trace(mech, until=("A", float(mech.offsets[0] + 2.0 * np.pi)), steps=360)
    return np.array([jacobian(mech, q) for q in trace.angles - mech.offsets])


def test_random_jacobians() -> None:
    """Gaussian 3x4 Jacobians: the contract on every one; the closed form certifies most of them."""
    J = RNG.normal(size=(4000, 3, 4))
    count = check_rows(J)
    assert count < 0.5 * len(J)


@pytest.mark.parametrize(
    ("name", "params"),
    [
        ("four-bar", {}),
        ("slider-crank", {}),
        ("slider-crank", {"crank": 1.0, "rod": 3.0, "offset": 0.1, "theta": 0.0}),
        # next to the change-point condition: sigma_3 / sigma_1 down to 0.03
        (
            "four-bar",
            {"ground": 2.0, "crank": 1.0, "coupler": 2.01, "rocker": 1.0, "theta": np.radians(60.0)},
        ),
    ],
)
def test_real_jacobians_along_a_turn(name: str, params: dict[str, float]) -> None:
    """Four-bar and slider-crank Jacobians along a turn (the Jacobians the closed-form path hands over): the
    contract at every point, also with lengths in micrometres and in megametres (scale-free)."""
    J = turn_jacobians(name, **params)
    for scale in (1.0, 1e-6, 1e6):
        check_rows(scale * J)


@pytest.mark.parametrize(
    "singular_values",
    [
        (1.0, 1.0, 0.3),  # sigma_1 = sigma_2
        (1.0, 1.0, 1.0),  # all equal
        (1.0, 0.3, 0.3),  # sigma_2 = sigma_3
        (1.0, 0.3, 1e-4),
        (1.0, 0.3, 1e-6),
        (1.0, 0.3, 1e-8),  # a near rank drop
        (1.0, 1e-8, 1e-8),
        (1.0, 1.0 - 1e-9, 1e-8),
        (1.0, 0.3, 0.0),  # rank deficient: any unit null vector, raw_tau ~ 0
    ],
)
def test_adversarial_singular_values(singular_values: tuple[float, float, float]) -> None:
    """Double roots, near rank drops and a rank drop, scaled by 1e-6, 1 and 1e6: the contract holds (through the
    exact fall-back where the closed form cannot certify a point, and those are counted)."""
    J = with_singular_values(np.array(singular_values))
    for scale in (1e-6, 1.0, 1e6):
        count = check_rows(scale * J)
        if singular_values[0] == singular_values[1] or singular_values[2] <= 1e-6:
            assert count > 0.9 * len(J)  # not certifiable in closed form: the fall-back took them


def test_zero_column() -> None:
    """A joint that does not move the loop (a zero column): the tangent is that joint alone."""
    J = RNG.normal(size=(500, 3, 4))
    J[:, :, 2] = 0.0
    check_rows(J)
    _, t, _, _ = rows(J)
    assert np.allclose(np.abs(t[:, 2]), 1.0, rtol=0.0, atol=1e-15)


def test_zero_jacobian_and_rank_one() -> None:
    """Degenerate inputs (all zero; rank one) go through the fall-back without NaN."""
    J = np.zeros((3, 3, 4))
    J[1] = np.outer(RNG.normal(size=3), RNG.normal(size=4))
    J[2, 0, 0] = 1.0
    sigma, t, tau, count = rows(J)
    assert count == 3
    assert np.all(np.isfinite(sigma)) and np.all(np.isfinite(t)) and np.all(np.isfinite(tau))
    assert np.allclose(np.linalg.norm(t, axis=1), 1.0, rtol=0.0, atol=1e-15)
    assert rows(np.zeros((0, 3, 4)))[3] == 0  # no points
    s = np.linalg.svd(J, compute_uv=False)
    assert np.all(np.abs(np.einsum("kec,kc->ke", J, t)) <= RESIDUAL_TOL * np.maximum(s[:, :1], 1e-300))
    assert np.all(np.abs(sigma - s) <= SIGMA_TOL * s[:, :1])


def test_scaling_by_a_power_of_two_is_exact() -> None:
    """Scale-free: scaling J by 2^k scales the singular values by 2^k and raw_tau by 2^3k, exactly, and
    certifies the same points."""
    J = np.concatenate([RNG.normal(size=(300, 3, 4)), with_singular_values(np.array([1.0, 0.99, 0.5]), 100)])
    sigma, t, tau, count = rows(J)
    for k in (-30, 30):
        s2, t2, tau2, count2 = rows(2.0**k * J)
        assert count2 == count
        np.testing.assert_array_equal(s2, 2.0**k * sigma)
        np.testing.assert_array_equal(t2, t)
        np.testing.assert_array_equal(tau2, 2.0 ** (3 * k) * tau)


def test_flipping_the_tangent_flips_raw_tau() -> None:
    """``raw_tau = det([J; t^T])`` for the reported ``t``: the determinant with ``-t`` is ``-raw_tau``."""
    J = RNG.normal(size=(200, 3, 4))
    _, t, tau, _ = rows(J)
    flipped = np.linalg.det(np.concatenate([J, -t[:, None, :]], axis=1))
    np.testing.assert_allclose(flipped, -tau, rtol=1e-13)


def test_plain_python_twin_keeps_the_contract() -> None:
    """The plain-Python twin (numba's py_func, as ``LINKWORK_JIT=python`` runs kernels) meets the same contract
    and agrees with the compiled kernel, on generic, real and degenerate Jacobians (no warning: the test runs
    with warnings as errors)."""
    twin = python_twin({"one_loop_rows": one_loop_rows}).one_loop_rows
    J = np.concatenate(
        [
            RNG.normal(size=(40, 3, 4)),
            with_singular_values(np.array([1.0, 1.0, 0.3]), 5),
            with_singular_values(np.array([1.0, 0.3, 1e-8]), 5),
            np.zeros((1, 3, 4)),
        ]
    )
    check_rows(J[:-1], twin)
    plain = rows(J, twin)
    compiled = rows(J)
    assert all(np.all(np.isfinite(a)) for a in plain[:3])
    np.testing.assert_allclose(plain[0], compiled[0], rtol=0.0, atol=1e-14)
    # the tangents where J is well conditioned (it moves by eps sigma_1 / sigma_3, and J = 0 has any)
    np.testing.assert_allclose(np.abs(plain[1][:45]), np.abs(compiled[1][:45]), rtol=0.0, atol=1e-14)
    assert abs(plain[3] - compiled[3]) <= 1


def test_exact_fall_back_alone() -> None:
    """The fall-back (one-sided Jacobi SVD of J) on every lane of generic and adversarial Jacobians: the same
    contract (the closed form is not involved)."""
    J = np.concatenate([RNG.normal(size=(100, 3, 4)), with_singular_values(np.array([1.0, 0.5, 1e-8]), 50)])
    jac = np.ascontiguousarray(J.transpose(1, 2, 0))
    K = len(J)
    sigma, tangent, tau = np.empty((3, K)), np.empty((4, K)), np.empty(K)
    work = (np.empty((3, 4)), np.empty((4, 4)), np.empty((3, 4)), np.empty(4), np.empty(4, dtype=np.int64))
    twin = python_twin({"exact_lane": planar_rows.exact_lane}).exact_lane
    for k in range(K):
        twin(jac, k, sigma, tangent, tau, work, k % 7 != 0)  # warm-started mostly

    def exact_only(jac, sigma_out, tangent_out, tau_out):  # type: ignore[no-untyped-def]
        sigma_out[:], tangent_out[:], tau_out[:] = sigma, tangent, tau
        return K

    assert check_rows(J, exact_only) == K


def jacobi_calls(J: np.ndarray) -> tuple[int, int]:
    """``(second-pass points, of which by the Jacobi SVD)`` of the plain-Python twin on ``J (K, 3, 4)``."""
    twin = python_twin({"one_loop_rows": one_loop_rows}).one_loop_rows
    exact = twin.__globals__["exact_lane"]
    calls = []

    def counted(*args):  # type: ignore[no-untyped-def]
        calls.append(args[1])
        return exact(*args)

    twin.__globals__["exact_lane"] = counted
    _, _, _, second = rows(J, twin)
    return second, len(calls)


def test_which_pass_computes_what() -> None:
    """Real four-bar and slider-crank turns never reach the Jacobi SVD (the points where sigma_2 nearly equals
    sigma_3 are finished by the 2x2 compression); sigma_2 = sigma_3 goes to the compression too; sigma_1 = sigma_2
    and a near rank drop go to the Jacobi SVD."""
    for name in ("four-bar", "slider-crank"):
        second, jacobi = jacobi_calls(turn_jacobians(name))
        assert jacobi == 0, name
    second, jacobi = jacobi_calls(with_singular_values(np.array([1.0, 0.5, 0.5]), 30))
    assert second == 30 and jacobi == 0
    for values in ((1.0, 1.0, 0.3), (1.0, 0.3, 1e-8)):
        second, jacobi = jacobi_calls(with_singular_values(np.array(values), 30))
        assert second == jacobi == 30


def exact_determinant(rows: list[list[Fraction]]) -> Fraction:
    """The determinant of a small matrix of rationals, by expansion along the first row (exact)."""
    if len(rows) == 1:
        return rows[0][0]
    return sum(
        (
            (-1) ** j * rows[0][j] * exact_determinant([r[:j] + r[j + 1 :] for r in rows[1:]])
            for j in range(len(rows))
        ),
        Fraction(0),
    )


def test_raw_tau_against_exact_rational_determinants() -> None:
    """``raw_tau`` against ``det([J; t^T])`` of the returned ``t`` in exact rational arithmetic (every float is a
    rational): to 1e-14 relative on generic Jacobians, scaled by 1e-6 and with nearly equal singular values (the
    closed form, the 2x2 compression and the Jacobi SVD); next to a rank drop (sigma_3 = 1e-4 sigma_1) to 1e-14
    sigma_1^2 sigma_2, what a rounding error of sigma_1 eps in sigma_3 makes of the determinant sigma_1 sigma_2
    sigma_3 (relative 1e-10 here; double precision gives no better there)."""
    J = np.concatenate(
        [
            RNG.normal(size=(8, 3, 4)),
            1e-6 * RNG.normal(size=(4, 3, 4)),
            with_singular_values(np.array([1.0, 1.0 - 1e-6, 0.2]), 4),
            with_singular_values(np.array([1.0, 0.5, 0.5 - 1e-7]), 4),
            with_singular_values(np.array([1.0, 0.3, 1e-4]), 4),
        ]
    )
    sigma, t, tau, _ = rows(J)
    for k in range(len(J)):
        bordered = [[Fraction(float(x)) for x in row] for row in np.concatenate([J[k], t[k][None]])]
        exact = float(exact_determinant(bordered))
        scale = abs(exact) if k < len(J) - 4 else sigma[k, 0] ** 2 * sigma[k, 1]
        assert abs(tau[k] - exact) <= 1e-14 * scale, k


@pytest.mark.skipif(platform.machine().lower() not in ("x86_64", "amd64"), reason="x86 instruction names")
def test_first_pass_is_vectorised() -> None:
    """The first pass compiles to packed square roots and divisions (several points an instruction): a branch or
    an exception path added to it would make LLVM keep it scalar, five to ten times slower. Compiled afresh here
    (numba does not disassemble cached code)."""
    fresh = numba.njit(error_model="numpy", fastmath={"contract"})(one_loop_rows.py_func)
    K = 16
    fresh(np.ones((3, 4, K)), np.empty((3, K)), np.empty((4, K)), np.empty(K))
    asm = fresh.inspect_asm(fresh.signatures[0])
    assert re.search(r"\bv?sqrtpd\b", asm) and re.search(r"\bv?divpd\b", asm)
