"""Planar mechanisms in the general model: a four-bar against Freudenstein's equation, a two-loop six-bar."""

from __future__ import annotations

import numpy as np
import pytest

from linkwork.kinematics.closure import closure_residual, jacobian
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import numerical_rank
from linkwork.kinematics.tracer import trace


def four_bar(a: float, b: float, c: float, d: float, theta2: float) -> tuple[Mechanism, float, float]:
    """Crank a (ground pivot O2 at origin), coupler b, rocker c (pivot O4 at (d, 0)); open assembly."""
    O2, O4 = np.zeros(2), np.array([d, 0.0])
    A = O2 + a * np.array([np.cos(theta2), np.sin(theta2)])
    # B on circles |B - A| = b, |B - O4| = c (the upper intersection).
    r = np.linalg.norm(O4 - A)
    x = (r * r + b * b - c * c) / (2 * r)
    h = np.sqrt(b * b - x * x)
    e = (O4 - A) / r
    B = A + x * e + h * np.array([-e[1], e[0]])
    joints = [
        {"name": "O2", "bodies": ["ground", "crank"], "point": O2, "direction": [0, 0, 1]},
        {"name": "A", "bodies": ["crank", "coupler"], "point": A, "direction": [0, 0, 1]},
        {"name": "B", "bodies": ["coupler", "rocker"], "point": B, "direction": [0, 0, 1]},
        {"name": "O4", "bodies": ["rocker", "ground"], "point": O4, "direction": [0, 0, 1]},
    ]
    mech = Mechanism.from_joints("four-bar", joints, planar=True)
    theta4 = np.arctan2(B[1] - O4[1], B[0] - O4[0])
    return mech, theta2, theta4


def freudenstein(a: float, b: float, c: float, d: float, t2: np.ndarray, t4: np.ndarray) -> np.ndarray:
    """K1 cos t4 - K2 cos t2 + K3 - cos(t2 - t4) = 0 (Freudenstein 1955)."""
    K1, K2, K3 = d / a, d / c, (a * a - b * b + c * c + d * d) / (2 * a * c)
    return K1 * np.cos(t4) - K2 * np.cos(t2) + K3 - np.cos(t2 - t4)


def test_four_bar_path_satisfies_freudenstein() -> None:
    a, b, c, d = 1.0, 3.0, 2.5, 3.2  # Grashof crank-rocker: s + l <= p + q
    mech, t2_0, t4_0 = four_bar(a, b, c, d, 0.3)
    s = np.linalg.svd(jacobian(mech, np.zeros(4)), compute_uv=False)
    assert numerical_rank(s) == 3  # 3 planar equations, 4 joints: mobility 1
    path = trace(mech, drive="O2", max_steps=2000, max_step=np.radians(3.0))
    # The crank goes all the way round: a closed path.
    assert path.branches[0].end_reason == "closed path"
    t2 = t2_0 + path.angles[:, 0]  # crank angle: the ground-crank joint's rotation from the start
    t4 = t4_0 + path.angles[:, 0] + path.angles[:, 1] + path.angles[:, 2]  # rocker = sum along the chain
    assert np.max(np.abs(freudenstein(a, b, c, d, t2, t4))) < 1e-11
    assert np.all(path.residual < 1e-12)
    assert np.ptp(path.angles[:, 0]) == pytest.approx(2 * np.pi, abs=0.1)


def test_two_loop_watt_six_bar_has_mobility_one_and_stays_closed() -> None:
    # Watt I: ternary links ground {O1, O2, O5? } - build from points; two loops sharing the ground-ternary.
    P = {
        "O1": (0.0, 0.0),
        "O2": (4.0, 0.0),
        "A": (0.5, 1.5),
        "B": (3.5, 2.0),
        "C": (1.0, 3.5),
        "D": (3.8, 4.2),
        "E": (2.5, 5.5),
    }
    joints = [
        {"name": "O1", "bodies": ["ground", "l1"], "point": P["O1"]},
        {"name": "A", "bodies": ["l1", "t1"], "point": P["A"]},  # t1: ternary coupler A-B-C
        {"name": "B", "bodies": ["t1", "l2"], "point": P["B"]},
        {"name": "O2", "bodies": ["l2", "ground"], "point": P["O2"]},
        {"name": "C", "bodies": ["t1", "l3"], "point": P["C"]},
        {"name": "E", "bodies": ["l3", "l4"], "point": P["E"]},
        {"name": "D", "bodies": ["l4", "l2"], "point": P["D"]},  # l2: ternary rocker O2-B-D
    ]
    for j in joints:
        j["direction"] = [0, 0, 1]
    mech = Mechanism.from_joints("watt six-bar", joints, planar=True)
    assert len(mech.loops) == 2
    s = np.linalg.svd(jacobian(mech, np.zeros(7)), compute_uv=False)
    assert numerical_rank(s) == 6 and 7 - 6 == 1
    path = trace(mech, drive="O1", until=("O1", np.radians(20.0)))
    assert path.angles[-1, 0] == pytest.approx(np.radians(20.0), abs=1e-14)
    assert np.all(path.mobility == 1)
    # Every point closes both loops (independent numpy reference residual).
    for q in path.angles[:: max(1, len(path.angles) // 10)]:
        assert np.linalg.norm(closure_residual(mech, q)) < 1e-12
    # Link lengths are preserved: distance O1-A and A-B computed by moving the points with the body poses.
    from linkwork.kinematics.closure import body_poses

    poses = body_poses(mech, angles=path.angles[-1])

    def moved(body: str, name: str) -> np.ndarray:
        return (poses[body] @ np.array([*P[name], 0.0, 1.0]))[:2]

    assert np.linalg.norm(moved("t1", "A") - moved("t1", "B")) == pytest.approx(
        np.linalg.norm(np.subtract(P["A"], P["B"])), abs=1e-12
    )
    assert np.linalg.norm(moved("l2", "B") - moved("t1", "B")) == pytest.approx(0.0, abs=1e-12)
    assert np.linalg.norm(moved("l4", "D") - moved("l2", "D")) == pytest.approx(0.0, abs=1e-12)
