"""The batched rows of multi-loop planar Jacobians (:func:`linkwork.kinematics.planar_rows.multi_loop_rows`)
against LAPACK (numpy's SVD and determinant): Watt and Stephenson six-bar Jacobians along a turn (from
``closure.jacobian`` at the traced angles), Gaussian ones, adversarial singular values, scaled by 1e-6 and 1e6;
the warm start carried from call to call; the plain-Python twin."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from bookkeeping_reference import stephenson_six_bar
from closed_form_probe import assert_rows_contract

import linkwork as lw
from linkwork.kinematics.bidiagonal_rows import HISTORY, history_size
from linkwork.kinematics.closure import jacobian
from linkwork.kinematics.jit import python_twin
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.planar_rows import multi_loop_rows, multi_loop_state

RNG = np.random.default_rng(20261125)
WATT = Path(__file__).resolve().parents[2] / "examples" / "specs" / "watt-six-bar.toml"
SIGMA_TOL = 1e-13  # every singular value, relative to sigma_1
RESIDUAL_TOL = 1e-14  # |J t| relative to sigma_1
UNIT_TOL = 1e-15  # | |t| - 1 |
TAU_TOL = 1e-12  # raw_tau relative to LAPACK's det([J; t^T]) where sigma_E > 1e-2 sigma_1


def rows(J: np.ndarray, kernel=multi_loop_rows) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:  # type: ignore[no-untyped-def]
    """``(sigma (K, E), tangent (K, m), raw_tau (K,), fall-backs)`` of ``J (K, E, m)``, one call from a fresh
    warm start."""
    K, E, m = J.shape
    jac = np.ascontiguousarray(J.transpose(1, 2, 0))
    sigma, tangent, raw_tau = np.full((E, K), np.nan), np.full((m, K), np.nan), np.full(K, np.nan)
    count = kernel(jac, sigma, tangent, raw_tau, 0, multi_loop_state(E))
    return sigma.T, tangent.T, raw_tau, int(count)


def check_rows(J: np.ndarray, kernel=multi_loop_rows) -> int:  # type: ignore[no-untyped-def]
    """Assert the accuracy contract on every point of ``J (K, E, m)``; returns the number of fall-backs."""
    sigma, t, tau, count = rows(J, kernel)
    assert_rows_contract(J, (sigma, t, tau), (SIGMA_TOL, RESIDUAL_TOL, UNIT_TOL, TAU_TOL))
    return count


def with_singular_values(s: np.ndarray, K: int = 64, rng: np.random.Generator = RNG) -> np.ndarray:
    """``K`` Jacobians ``U diag(s) V^T`` with random orthogonal ``U (E, E)``, ``V (E + 1, E + 1)`` (from ``rng``)."""
    E = len(s)
    U = np.linalg.qr(rng.normal(size=(K, E, E)))[0]
    V = np.linalg.qr(rng.normal(size=(K, E + 1, E + 1)))[0]
    S = np.zeros((K, E, E + 1))
    S[:, range(E), range(E)] = s
    return U @ S @ V.transpose(0, 2, 1)


def turn_jacobians(mech: Mechanism, steps: int = 360) -> np.ndarray:
    """The closure Jacobians of ``mech`` along one turn of joint A, from ``closure.jacobian``."""
    a = mech.index("A")
    trace = lw.trace(mech, until=("A", float(mech.offsets[a] + 2.0 * np.pi)), steps=steps)
    return np.array([jacobian(mech, q) for q in trace.angles - mech.offsets])


@pytest.mark.parametrize("name", ["watt", "stephenson"])
@pytest.mark.parametrize("scale", [1.0, 1e-6, 1e6])
def test_real_jacobians_along_a_turn(name: str, scale: float) -> None:
    """Watt II and Stephenson six-bars (E = 6, m = 7) along one turn of the crank, and those Jacobians scaled:
    the contract at every point, none left to the fall-back (the warm start finishes every lane)."""
    mech = lw.load(str(WATT)) if name == "watt" else stephenson_six_bar(0.3)
    J = turn_jacobians(mech)
    assert J.shape[1:] == (6, 7)
    assert check_rows(scale * J) == 0


@pytest.mark.parametrize("scale", [1.0, 1e-6, 1e6])
def test_random_jacobians(scale: float) -> None:
    """Gaussian 6x7 Jacobians (no warm start helps: each lane's last point is unrelated) and 4x5 ones (any
    size): the contract at every point, whichever lanes the sweeps finish and the fall-back redoes."""
    check_rows(scale * RNG.normal(size=(300, 6, 7)))
    check_rows(scale * RNG.normal(size=(100, 4, 5)))


@pytest.mark.parametrize(
    "values",
    [
        (1.0, 1.0, 0.5, 0.5, 0.2, 0.1),
        (1.0, 0.8, 0.6, 0.4, 0.2, 1e-8),
        (1.0, 1.0, 1.0, 1.0, 1.0, 1.0),
        (1.0, 0.5, 1e-3, 1e-3, 1e-9, 0.0),
    ],
)
def test_adversarial_singular_values(values: tuple[float, ...]) -> None:
    """Equal singular values, a near rank drop, a rank drop of two: the contract (raw_tau relative only where
    sigma_E > 1e-2 sigma_1)."""
    check_rows(with_singular_values(np.array(values)))


def test_zero_jacobian_gives_zeros_not_nan() -> None:
    """A zero Jacobian: zero singular values, a unit tangent, raw_tau 0, no NaN (and no warning)."""
    sigma, t, tau, _ = rows(np.zeros((3, 6, 7)))
    assert np.all(sigma == 0.0) and np.all(tau == 0.0)
    np.testing.assert_allclose(np.linalg.norm(t, axis=1), 1.0, rtol=0.0, atol=UNIT_TOL)


def test_the_warm_start_carries_from_call_to_call() -> None:
    """A path split into calls (each one's column 0 the call before's last point, ``begin = 1``, the state
    carried, as the closed-form path calls it block by block) gives the rows of one call over the whole path."""
    J = turn_jacobians(lw.load(str(WATT)), 720)
    whole = rows(J)
    jac = np.ascontiguousarray(J.transpose(1, 2, 0))
    state = multi_loop_state(6)
    sigma, tangent, tau = np.empty((6, len(J))), np.empty((7, len(J))), np.empty(len(J))
    count = 0
    for first in range(0, len(J) - 1, 100):
        stop = min(first + 101, len(J))
        part = (sigma[:, first:stop], tangent[:, first:stop], tau[first:stop])
        count += multi_loop_rows(
            np.ascontiguousarray(jac[:, :, first:stop]), *part, 0 if first == 0 else 1, state
        )
    assert count == 0
    s1 = whole[0][:, :1]
    assert np.all(np.abs(sigma.T - whole[0]) <= 1e-14 * s1)
    np.testing.assert_allclose(np.abs(tangent.T), np.abs(whole[1]), rtol=0.0, atol=1e-15)
    np.testing.assert_allclose(tau, whole[2], rtol=1e-14)


def test_plain_python_twin_keeps_the_contract() -> None:
    """The plain-Python twin (as ``LINKWORK_JIT=python`` runs kernels) meets the same contract and agrees with
    the compiled kernel, on a stretch of the Watt turn and on Gaussian and rank-deficient Jacobians."""
    twin = python_twin({"multi_loop_rows": multi_loop_rows}).multi_loop_rows
    J = np.concatenate(
        [
            turn_jacobians(lw.load(str(WATT)))[:40],
            RNG.normal(size=(16, 6, 7)),
            with_singular_values(np.array([1.0, 0.8, 0.6, 0.4, 0.2, 1e-8]), 8),
        ]
    )
    check_rows(J, twin)
    plain, compiled = rows(J, twin), rows(J)
    np.testing.assert_allclose(plain[0], compiled[0], rtol=0.0, atol=1e-14 * np.max(compiled[0]))
    np.testing.assert_allclose(plain[1][:56], compiled[1][:56], rtol=0.0, atol=1e-14)
    assert plain[3] == compiled[3]


def test_lanes_not_certified_fall_back_and_are_right() -> None:
    """Cases built to fail the certification: equal singular values (the roots' intervals overlap), a fifth
    singular value 1e-7 sigma_1 (``d sigma = d lambda / sigma`` exceeds the budget): every point falls back to the
    exact routine (counted once, also where a group is padded with repeats of the first point), and the rows keep
    the contract. One double pair among distinct ones: nearly every point falls back; the reduction's rounding
    splits the pair of the ``B`` it computes by a few ulps, and where the split is wider than the roots' bounds
    the lane is certified, rightly (``B``'s roots are distinct; the contract holds), which happens at a point or
    two in one draw of ten (hence no module-wide generator here: the draws would depend on the tests run
    before)."""
    rng = np.random.default_rng(20261127)
    for values, at_least in [
        ((1.0, 1.0, 1.0, 1.0, 1.0, 1.0), 20),
        ((1.0, 0.8, 0.6, 0.4, 1e-7, 1e-8), 20),
        ((1.0, 0.7, 0.5, 0.5, 0.3, 0.1), 17),
    ]:
        J = with_singular_values(np.array(values), 20, rng)  # 2 groups, one padded
        assert at_least <= check_rows(J) <= 20


def test_certified_lanes_are_most_and_right() -> None:
    """Where the certification can hold it does: Gaussian 6x7 Jacobians and ones with a near rank drop
    (sigma_6 = 1e-10 sigma_1, measured as |det B| over the others' product: right to 1e-5 relative, where
    LAPACK's own is right to about 1e-6) are mostly certified, and right (numpy's SVD, the contract)."""
    J = RNG.normal(size=(320, 6, 7))
    assert check_rows(J) < 32
    near = with_singular_values(np.array([1.0, 0.8, 0.6, 0.4, 0.2, 1e-10]), 64)
    assert check_rows(near) == 0
    sigma = rows(near)[0]
    np.testing.assert_allclose(sigma[:, -1], np.linalg.svd(near, compute_uv=False)[:, -1], rtol=1e-5)


def test_a_wrong_warm_start_is_caught() -> None:
    """A state whose previous roots are nonsense (random, or every lane's the same value: Laguerre's steps then
    converge to the wrong roots or to one root twice; the last point's alone, or extrapolated from four) is caught
    by the certification and redone from the bounds: no fall-back, the contract kept."""
    J = turn_jacobians(lw.load(str(WATT)))
    jac = np.ascontiguousarray(J.transpose(1, 2, 0))
    cases = [(RNG.uniform(size=(HISTORY * 5, 16)), 1), (np.full((HISTORY * 5, 16), 0.3), 1)]
    cases += [(RNG.uniform(size=(HISTORY * 5, 16)), HISTORY)]
    for previous, points_set in cases:
        state = multi_loop_state(6)
        state[: HISTORY * 5 * 16] = previous.ravel()
        state[HISTORY * 5 * 16 : history_size(6)] = points_set
        K = len(J)
        sigma, tangent, tau = np.empty((6, K)), np.empty((7, K)), np.empty(K)
        assert multi_loop_rows(jac, sigma, tangent, tau, 0, state) == 0
        assert_rows_contract(J, (sigma.T, tangent.T, tau), (SIGMA_TOL, RESIDUAL_TOL, UNIT_TOL, TAU_TOL))
