"""Stop conditions, step control and bifurcations of the tracer, against closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from linkwork.errors import LinkworkError, SpecError
from linkwork.kinematics.chains import from_dh
from linkwork.kinematics.closure import jacobian
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import DEFAULT as DEFAULT_TOL
from linkwork.kinematics.tracer import trace

DEG = np.pi / 180.0


def bennett(a1: float, a2: float, t1: float) -> Mechanism:
    """Bennett linkage in DH form: a_i = sin(alpha_i), theta3 = -theta1, theta4 = -theta2 (Bennett 1903)."""
    k = np.sin((a2 + a1) / 2) / np.sin((a2 - a1) / 2)
    t2 = 2 * np.arctan(k / np.tan(t1 / 2))
    params = [
        {"theta": t1, "a": np.sin(a1), "alpha": a1},
        {"theta": t2, "a": np.sin(a2), "alpha": a2},
        {"theta": -t1, "a": np.sin(a1), "alpha": a1},
        {"theta": -t2, "a": np.sin(a2), "alpha": a2},
    ]
    return from_dh("bennett", params)[0]


def parallelogram(theta: float) -> Mechanism:
    """A planar parallelogram four-bar (crank 1, coupler 2, ground 2): its change points are bifurcations."""
    O2, O4 = np.array([0.0, 0.0]), np.array([2.0, 0.0])
    A = O2 + np.array([np.cos(theta), np.sin(theta)])
    B = A + np.array([2.0, 0.0])
    joints = [
        {"name": "O2", "bodies": ["ground", "crank"], "point": O2, "direction": [0, 0, 1]},
        {"name": "A", "bodies": ["crank", "coupler"], "point": A, "direction": [0, 0, 1]},
        {"name": "B", "bodies": ["coupler", "rocker"], "point": B, "direction": [0, 0, 1]},
        {"name": "O4", "bodies": ["rocker", "ground"], "point": O4, "direction": [0, 0, 1]},
    ]
    return Mechanism.from_joints("parallelogram", joints, planar=True)


def test_bennett_path_keeps_the_closed_form_relation_and_closes_after_a_full_turn() -> None:
    a1, a2, t1 = 45 * DEG, 75 * DEG, 90 * DEG
    mech = bennett(a1, a2, t1)
    path = trace(mech, max_steps=3000)
    assert path.branches[0].end_reason == "closed path"
    th = path.angles
    k = np.sin((a2 + a1) / 2) / np.sin((a2 - a1) / 2)
    # tan(t1/2) tan(t2/2) = k, written without poles: sin(t1/2) sin(t2/2) - k cos(t1/2) cos(t2/2) = 0
    rel = np.sin(th[:, 0] / 2) * np.sin(th[:, 1] / 2) - k * np.cos(th[:, 0] / 2) * np.cos(th[:, 1] / 2)
    assert np.max(np.abs(rel)) < 1e-10
    np.testing.assert_allclose(np.sin(th[:, 2] + th[:, 0]), 0.0, atol=1e-10)  # theta3 = -theta1 (mod 2 pi)
    # the drive (joint A) goes once round
    assert np.ptp(th[:, 0]) == pytest.approx(2 * np.pi, abs=0.05)


def test_landing_on_until_is_exact_in_adaptive_mode() -> None:
    mech = bennett(30 * DEG, 80 * DEG, 60 * DEG)
    target = 60 * DEG + 1.2345
    path = trace(mech, until=("A", target), max_step=3 * DEG)
    assert path.branches[0].end_reason == "reached target"
    assert path.angles[-1, 0] == target  # exactly, not approximately
    steps = np.linalg.norm(np.diff(path.angles, axis=0), axis=1)
    # The predictor step never exceeds max_step; the chord adds the corrector's small normal move (< 1 %).
    assert steps.max() <= 3 * DEG * 1.01


@pytest.mark.parametrize("target_deg", [20.0, -20.0])
def test_paper_mode_steps_towards_a_target_on_either_side_of_the_start(target_deg: float) -> None:
    # Regression: equal drive steps towards a target below the start once marched the wrong way until the budget.
    a1, a2, t1 = 30 * DEG, 80 * DEG, 60 * DEG
    mech = bennett(a1, a2, t1)
    path = trace(mech, until=("A", t1 + target_deg * DEG), steps=10)
    assert path.branches[0].end_reason == "reached target"
    np.testing.assert_allclose(np.diff(path.angles[:, 0]), target_deg * DEG / 10, atol=1e-14)
    k = np.sin((a2 + a1) / 2) / np.sin((a2 - a1) / 2)
    th = path.angles
    rel = np.sin(th[:, 0] / 2) * np.sin(th[:, 1] / 2) - k * np.cos(th[:, 0] / 2) * np.cos(th[:, 1] / 2)
    assert np.max(np.abs(rel)) < 1e-10


def test_step_budget_is_reported() -> None:
    mech = bennett(30 * DEG, 80 * DEG, 60 * DEG)
    path = trace(mech, max_steps=7)
    assert path.branches[0].end_reason == "step budget"
    assert len(path.angles) == 8


def test_paper_mode_reports_a_drive_turning_point_instead_of_failing_silently() -> None:
    # A crank-rocker four-bar: the rocker's angle has a maximum; equal steps of the rocker cannot pass it.
    from test_planar_mechanisms import four_bar

    mech, _, _ = four_bar(1.0, 3.0, 2.5, 3.2, 0.3)
    for steps in (100, 2, 1):  # the rocker cannot swing 2 rad, in short steps or in one long one
        path = trace(mech, until=("O4", 2.0), steps=steps)
        assert path.branches[0].end_reason == "drive turning point"
        assert path.angles[-1, 3] < 2.0


def test_mobility_two_is_refused_with_advice() -> None:
    from linkwork.linkages.hedgepeth import hedgepeth

    with pytest.raises(LinkworkError, match="mobility 3"):
        trace(hedgepeth(8, couple=False))


def test_paper_mode_needs_a_target() -> None:
    with pytest.raises(SpecError, match="until"):
        trace(bennett(30 * DEG, 80 * DEG, 60 * DEG), steps=10)


def test_parallelogram_change_point_is_located_and_both_branches_traced() -> None:
    mech = parallelogram(60 * DEG)
    path = trace(mech, drive="O2", branches=True, max_steps=4000, max_step=4 * DEG)
    assert path.bifurcations, "the change points of a parallelogram linkage are bifurcations"
    for b in path.bifurcations:
        # At a change point every link is collinear: the crank is at 0 or 180 degrees from the ground line.
        crank = 60 * DEG + b.angles[0]
        assert abs(np.sin(crank)) < 1e-9
        assert b.rank == 2  # 3 planar equations lose one rank
        s = b.sigma
        assert s[2] / s[0] < 1e-9
        # Two branches: the parallelogram (coupler keeps its direction: A + B = 0) and the anti-parallelogram.
        assert len(b.tangents) == 2
        J = jacobian(mech, b.angles - mech.offsets)
        for t in b.tangents:
            assert np.linalg.norm(J @ t) < 1e-8
        coupler_turn = [abs(t[0] + t[1]) for t in b.tangents]
        assert min(coupler_turn) < 1e-8  # one branch keeps the coupler parallel to the ground
    assert any(br.parent is not None for br in path.branches)
    for br in path.branches:
        assert br.end_reason != "corrector failed"


def test_guest_frame_bifurcation_and_both_branches() -> None:
    """Sec. 6: the rank drops from 5 to 4 on the symmetric path; a symmetry-breaking branch leaves there."""
    from linkwork.kinematics.closure import hessian, reduce
    from linkwork.linkages.guest import guest_frame

    mech = guest_frame()
    path = trace(mech, branches=True, max_steps=3000)
    assert path.stats.start_rank == 5
    first = path.bifurcations[0]
    assert first.rank == 4
    assert first.sigma[4] / first.sigma[0] < 1e-11  # located to round-off
    # Independent reference: a plain continuation in A with Gauss-Newton (tests/linkages) puts the drop at
    # A = D = 38.942 deg, B = C = E = F = 18.463 deg for the default proportions (to 1e-3 deg).
    deg = np.degrees(first.angles)
    wrapped = (deg + 180.0) % 360.0 - 180.0
    np.testing.assert_allclose(wrapped, [38.942, 18.463, 18.463, 38.942, 18.463, 18.463], atol=2e-3)
    # Two branch tangents: both in the kernel of J, both solving the quadratic branching equation.
    q = mech.q_from_angles(first.angles)
    J = jacobian(mech, q)
    U = np.linalg.svd(J)[0]
    left = U[:, 4:]
    H = reduce(mech, hessian(mech, q))
    assert len(first.tangents) == 2
    for t in first.tangents:
        assert np.linalg.norm(J @ t) < 1e-9
        assert np.abs(np.einsum("el,eij,i,j->l", left, H, t, t)).max() < 1e-8
    symmetric = [t for t in first.tangents if abs(t[1] - t[2]) < 1e-9]
    breaking = [t for t in first.tangents if abs(t[1] - t[2]) > 0.1]
    assert len(symmetric) == 1 and len(breaking) == 1
    # The symmetric branch keeps A = D and B = C = E = F all along (no symmetry imposed).
    main = path.angles[path.branch == 0]
    np.testing.assert_allclose(main[:, 0], main[:, 3], atol=1e-9)
    for k in (2, 4, 5):
        np.testing.assert_allclose(main[:, 1], main[:, k], atol=1e-9)
    # Branches leave the first bifurcation in both directions and break the symmetry B = C.
    children = [br for br in path.branches if br.bifurcation == first.id]
    assert {br.direction for br in children} == {1, -1}
    for br in children:
        pts = path.angles[path.branch == br.id]
        assert np.max(np.abs(pts[:, 1] - pts[:, 2])) > 0.1
        assert np.all(path.residual[path.branch == br.id] < 1e-12)


def test_minimum_of_the_smallest_singular_value_finds_a_change_point_on_its_own() -> None:
    """The second detector (sigma_r minima) locates the parallelogram's change point without the test function."""
    from linkwork.kinematics.bifurcation import Workspace, locate_minimum

    mech = parallelogram(60 * DEG)
    path = trace(mech, drive="O2", until=("O2", np.radians(150.0)), max_step=4 * DEG)
    crank = 60 * DEG + path.angles[:, 0]
    k = int(np.argmin(np.abs(crank - np.pi)))  # the path point nearest the change point (crank at 180 deg)
    ws = Workspace.of(mech)
    u = mech.u_from_q(mech.q_from_angles(path.angles))
    tangents = []
    for i in (k - 1, k + 1):
        jac = ws.evaluate(u[i])[2]
        t = np.linalg.svd(jac)[2][-1]
        tangents.append(t if t @ (u[k + 1] - u[k - 1]) > 0 else -t)
    u_min, ratio = locate_minimum(ws, u[k - 1], tangents[0], u[k + 1], tangents[1], 3, DEFAULT_TOL)
    assert ratio < 1e-8  # sigma_3 / sigma_1 vanishes there
    assert abs(np.sin(60 * DEG + mech.q_from_u(u_min)[0])) < 1e-8  # crank collinear with the ground
