"""Hedgepeth's hoops against Gan & Pellegrino (2006): printed matrices, Eq. (10), Eq. (13), Sec. 5."""

from __future__ import annotations

import numpy as np
import pytest

from linkwork.kinematics.chains import rod_transform
from linkwork.kinematics.tracer import trace
from linkwork.linkages.hedgepeth import deployed_angle, hedgepeth, hedgepeth_angles, rod_transforms

S2, S3, S6 = np.sqrt(2.0), np.sqrt(3.0), np.sqrt(6.0)
# The paper's printed T_1 (Sec. 3.1) and the type-2 matrix printed inside Eq. (13).
T1_PRINTED = np.array(
    [
        [-2 / 3, S3 / 3, -S2 / 3, S6 / 3],
        [S3 / 3, 0, -S6 / 3, 0],
        [-S2 / 3, -S6 / 3, -1 / 3, S3 / 3],
        [0, 0, 0, 1],
    ]
)
T2_PRINTED = np.array(
    [
        [-2 / 3, -S3 / 3, -S2 / 3, S6 / 3],
        [-S3 / 3, 0, S6 / 3, 0],
        [-S2 / 3, S6 / 3, -1 / 3, S3 / 3],
        [0, 0, 0, 1],
    ]
)


def test_rod_matrices_match_the_printed_T1_and_T2() -> None:
    T1, T2 = rod_transforms(4)
    np.testing.assert_allclose(T1, T1_PRINTED, atol=1e-15)
    np.testing.assert_allclose(T2, T2_PRINTED, atol=1e-15)


def test_rod_angles_for_the_square_match_section_3_1() -> None:
    g = hedgepeth_angles(4)
    # phi = -30, omega = 90 + atan(1/sqrt(8)) = 109.47, psi = -150 (degrees)
    assert np.degrees(g["phi"]) == pytest.approx(-30.0, abs=1e-12)
    assert np.degrees(g["omega"]) == pytest.approx(90.0 + np.degrees(np.arctan(1 / np.sqrt(8))), abs=1e-12)
    assert np.degrees(g["psi"]) == pytest.approx(-150.0, abs=1e-12)
    np.testing.assert_allclose(
        rod_transform(g["phi"], g["omega"], g["psi"], [S6 / 3, 0, S3 / 3]), T1_PRINTED, atol=1e-15
    )


@pytest.mark.parametrize("n", [4, 6, 8, 10, 12, 20, 50])
def test_the_bundle_closes(n: int) -> None:
    # The hoop is assembled with all hinge angles zero: the loop product (Eq. (12)) is the identity.
    T1, T2 = rod_transforms(n)
    P = np.eye(4)
    for k in range(n):
        P = P @ (T1 if k % 2 == 0 else T2)
    np.testing.assert_allclose(P, np.eye(4), atol=1e-12)
    mech = hedgepeth(n)
    np.testing.assert_allclose(mech.offsets, 0.0, atol=1e-12)


def _eq13(theta_a: np.ndarray) -> np.ndarray:
    """theta_B from theta_A for the symmetric square, Eq. (13)."""
    c, s = np.cos(theta_a), np.sin(theta_a)
    num = 2 * S3 * c**2 - 3 * s * c + 3 * s - 4 * S3 * c + 2 * S3
    den = -(c**2) - 2 * S3 * s * c + 2 * S3 * s - c + 2
    return np.arctan2(num, den)


def test_square_follows_equation_13_over_the_whole_motion() -> None:
    mech = hedgepeth(4)  # no symmetry imposed
    path = trace(mech, until=("A", deployed_angle(4)), steps=200)
    A, B, C, D = path.angles.T
    assert path.branches[0].end_reason == "reached target"
    # Eq. (13) has a removable 0/0 at the bundle; compare away from it.
    away = A > 1e-3
    np.testing.assert_allclose(B[away], _eq13(A[away]), atol=1e-9)
    np.testing.assert_allclose(C, A, atol=1e-10)  # theta_C = theta_A (Sec. 5, Fig. 10)
    np.testing.assert_allclose(D, B, atol=1e-10)
    assert np.all(path.residual < 1e-12)


@pytest.mark.parametrize("n", [4, 6, 8, 10])
def test_trace_from_the_bundle_lands_on_the_deployed_angle_of_equation_10(n: int) -> None:
    path = trace(hedgepeth(n), until=("A", deployed_angle(n)), steps=200)
    assert path.branches[0].end_reason == "reached target"
    assert path.angles[-1, 0] == pytest.approx(deployed_angle(n), abs=1e-14)
    assert np.all(path.mobility == 1)
    assert np.all(path.residual < 1e-12)
    # Equal steps of the drive (paper mode, Sec. 5: 200 steps).
    np.testing.assert_allclose(np.diff(path.angles[:, 0]), deployed_angle(n) / 200, atol=1e-14)


def test_equations_10_and_13_agree_on_the_deployed_square() -> None:
    # Eq. (10) gives theta_A = 120 deg for n = 4; Eq. (13) then gives theta_B = 60 deg; the tracer must end there.
    path = trace(hedgepeth(4), until=("A", deployed_angle(4)), steps=200)
    assert np.degrees(path.angles[-1, 1]) == pytest.approx(
        np.degrees(_eq13(np.array([deployed_angle(4)]))[0]), abs=1e-9
    )
    assert np.degrees(path.angles[-1, 1]) == pytest.approx(60.0, abs=1e-9)


def test_deployed_angles_for_4_and_6_match_the_paper() -> None:
    assert np.degrees(deployed_angle(4)) == pytest.approx(120.0, abs=1e-12)
    assert np.degrees(deployed_angle(6)) == pytest.approx(87.0067, abs=5e-5)  # the value quoted for Fig. 12


def test_hexagon_stays_threefold_symmetric_without_assuming_it() -> None:
    mech = hedgepeth(6)
    assert mech.n_unknowns == 6  # no coupling imposed
    path = trace(mech, until=("A", deployed_angle(6)), steps=200)
    A, B, C, D, E, F = path.angles.T
    for x, y in ((A, C), (A, E), (B, D), (B, F)):
        np.testing.assert_allclose(x, y, atol=1e-10)
    assert np.all(path.mobility == 1)
    assert not path.bifurcations
    assert path.max_condition < 10.0  # "robust" (Sec. 5): the condition ratio stays small


def test_large_hoops_need_and_get_the_paper_symmetry() -> None:
    # n >= 8: mobility n - 5 at the bundle without symmetry (docs/linkages.md); the n/2-fold coupling leaves one.
    free = hedgepeth(8, couple=False)
    from linkwork.kinematics.closure import jacobian
    from linkwork.kinematics.rank import numerical_rank

    s = np.linalg.svd(jacobian(free, np.zeros(8)), compute_uv=False)
    assert 8 - numerical_rank(s) == 8 - 5
    coupled = hedgepeth(8)
    path = trace(coupled, until=("A", deployed_angle(8)), steps=100)
    assert np.all(path.mobility == 1)
