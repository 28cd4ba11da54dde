"""Which route :func:`linkwork.kinematics.planar_rows.multi_loop_rows` takes by size: three loops (``9 x 10``
Jacobians) take the Jacobi lanes (the bidiagonal route's reduction bound is wider than its budget there), with
their own state, and keep the contract against LAPACK (numpy's SVD and determinant) with no fall-back along a
three-loop eight-bar's turn."""

from __future__ import annotations

import numpy as np
import pytest
from bookkeeping_reference import planar_four_bar
from closed_form_probe import assert_rows_contract

import linkwork as lw
from linkwork.kinematics import bidiagonal_7x6
from linkwork.kinematics.bidiagonal_7x6 import CHUNK
from linkwork.kinematics.bidiagonal_rows import (
    HISTORY,
    LANES,
    bidiagonal_rows,
    bidiagonal_state,
    certifiable,
    history_size,
    takes_bidiagonal,
    work_rows,
)
from linkwork.kinematics.closure import jacobian
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.planar_rows import jacobi_loop_state, multi_loop_rows, multi_loop_state

TOLS = (
    1e-13,
    1e-14,
    1e-15,
    1e-12,
)  # sigma / sigma_1, |J t| / sigma_1, | |t| - 1 |, raw_tau (as for two loops)


def dyad(E: np.ndarray, G: np.ndarray, link: float) -> np.ndarray:
    """The middle joint of a dyad of two equal links ``link`` from ``E`` to ``G`` (left of ``E -> G``)."""
    half = 0.5 * float(np.linalg.norm(E - G))
    normal = np.array([-(E - G)[1], (E - G)[0]]) / (2.0 * half)
    return 0.5 * (E + G) + np.sqrt(link**2 - half**2) * normal


def eight_bar(theta: float) -> Mechanism:
    """Three loops: a crank-rocker four-bar (ground 2, crank 0.6, coupler 2.2, rocker 2) whose coupler carries
    two more pivots, each joined to a ground pivot by a dyad of equal links longer than half the largest distance
    between its ends over the turn (so it assembles all the way round): 8 bodies, 10 hinges, ``9 x 10``
    closure Jacobians."""
    four = planar_four_bar(2.0, 0.6, 2.2, 2.0, theta)
    pts = {four.joint_names[j]: np.cross(four.twists[j, :3], four.twists[j, 3:]) for j in range(4)}
    B, C = pts["B"][:2], pts["C"][:2]
    along = (C - B) / np.linalg.norm(C - B)
    left = np.array([-along[1], along[0]])
    E1, G1 = B + 0.5 * (C - B) + 0.8 * left, np.array([1.0, -2.5])
    E2, G2 = B + 0.3 * (C - B) - 0.6 * left, np.array([-1.5, 3.0])
    joints = [
        {"name": "A", "bodies": ["ground", "crank"], "point": pts["A"][:2], "value": theta},
        {"name": "B", "bodies": ["crank", "coupler"], "point": B},
        {"name": "C", "bodies": ["coupler", "rocker"], "point": C},
        {"name": "D", "bodies": ["rocker", "ground"], "point": pts["D"][:2]},
        {"name": "E", "bodies": ["coupler", "link5"], "point": E1},
        {"name": "F", "bodies": ["link5", "link6"], "point": dyad(E1, G1, 4.0)},
        {"name": "G", "bodies": ["link6", "ground"], "point": G1},
        {"name": "H", "bodies": ["coupler", "link7"], "point": E2},
        {"name": "I", "bodies": ["link7", "link8"], "point": dyad(E2, G2, 5.0)},
        {"name": "K", "bodies": ["link8", "ground"], "point": G2},
    ]
    for j in joints:
        j["direction"] = [0.0, 0.0, 1.0]
    return Mechanism.from_joints("eight-bar", joints, planar=True)


def test_routes_by_size() -> None:
    """The bidiagonal route for two loops (the one multi-loop size it can certify), the Jacobi lanes (and their
    state) for three and four; the bidiagonal kernel refuses any other size instead of running it."""
    assert certifiable(4, 3) and certifiable(7, 6)
    assert not certifiable(10, 9) and not certifiable(13, 12)
    assert takes_bidiagonal(7, 6) and not takes_bidiagonal(4, 3) and not takes_bidiagonal(10, 9)
    jac = np.zeros((9, 10, 20))
    with pytest.raises(ValueError, match="6 x 7"):
        bidiagonal_rows(jac, np.zeros((9, 20)), np.zeros((10, 20)), np.zeros(20), 0, bidiagonal_state(9))
    # the roots at four points and how many are set, then the lanes' work rows and the chunk of the reduction
    work = work_rows(7, 6)[-1] * LANES + bidiagonal_7x6.ROWS * CHUNK
    assert history_size(6) == (HISTORY * 5 + 1) * 16
    assert multi_loop_state(6).shape == (history_size(6) + work,)
    assert not multi_loop_state(6).any()
    for E in (9, 12):
        np.testing.assert_array_equal(multi_loop_state(E), jacobi_loop_state(E))


def test_three_loops_along_a_turn() -> None:
    """An eight-bar (``9 x 10``) along one turn of its crank: the contract at every point, no fall-back, in one
    call and in blocks with the state carried (as the closed-form path calls it)."""
    mech = eight_bar(0.3)
    a = mech.index("A")
    trace = lw.trace(mech, until=("A", float(mech.offsets[a] + 2.0 * np.pi)), steps=360)
    J = np.array([jacobian(mech, q) for q in trace.angles - mech.offsets])
    K, E, m = J.shape
    assert (E, m) == (9, 10)
    jac = np.ascontiguousarray(J.transpose(1, 2, 0))
    sigma, tangent, tau = np.full((E, K), np.nan), np.full((m, K), np.nan), np.full(K, np.nan)
    assert multi_loop_rows(jac, sigma, tangent, tau, 0, multi_loop_state(E)) == 0
    assert_rows_contract(J, (sigma.T, tangent.T, tau), TOLS)
    state, count = multi_loop_state(E), 0
    for first in range(0, K - 1, 100):
        stop = min(first + 101, K)
        part = (sigma[:, first:stop], tangent[:, first:stop], tau[first:stop])
        count += multi_loop_rows(
            np.ascontiguousarray(jac[:, :, first:stop]), *part, 0 if first == 0 else 1, state
        )
    assert count == 0
    assert_rows_contract(J, (sigma.T, tangent.T, tau), TOLS)
