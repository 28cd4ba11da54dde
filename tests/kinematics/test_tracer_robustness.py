"""The tracer on linkages a user brings: unreachable targets, full turns, limits, play in the hinges, stalls,
degenerate singular sets, and the branch graph of every built-in.

Outside references: the crank-rocker's rocker range from triangle geometry (law of cosines at the two positions
where crank and coupler are collinear); Bennett's closed form ``tan(t1/2) tan(t2/2) = k`` (Bennett 1903); the
Sarrus loop closed with an independent product of rotations about its hinge lines (Rodrigues), whose
finite-difference Jacobian gives the mobility of its flat-folded configurations.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import linkwork as lw
from linkwork.kinematics.rank import Tolerances, numerical_rank
from linkwork.kinematics.stops import StopReason
from linkwork.kinematics.tracer import trace
from linkwork.kinematics.workspace import Workspace
from linkwork.linkages import REGISTRY
from linkwork.linkages.sarrus import sarrus_hinges

DEG = np.pi / 180.0
FOUR_BAR = Path(__file__).resolve().parents[2] / "examples" / "specs" / "four-bar.toml"
#: The crank-rocker of examples/specs/four-bar.toml: ground pivots A, D; crank A-B, coupler B-C, rocker C-D.
A0, B0, C0, D0 = (np.array(p, dtype=float) for p in ([0, 0], [1, 1], [3.5, 3], [4, 0]))


def rocker_range_deg() -> tuple[float, float]:
    """The rocker joint's range (degrees, from its start), from the triangle A-C-D at the two positions where
    crank and coupler are collinear (|AC| = coupler -/+ crank), by the law of cosines."""
    crank, coupler = np.linalg.norm(B0 - A0), np.linalg.norm(C0 - B0)
    rocker, ground = np.linalg.norm(D0 - C0), np.linalg.norm(D0 - A0)

    def angle_at_d(ac: float) -> float:  # angle between D->A and D->C
        return float(np.degrees(np.arccos((ground**2 + rocker**2 - ac**2) / (2 * ground * rocker))))

    start = angle_at_d(float(np.linalg.norm(C0 - A0)))
    extremes = [angle_at_d(coupler - crank) - start, angle_at_d(coupler + crank) - start]
    return min(extremes), max(extremes)


@pytest.fixture(scope="module")
def four_bar() -> lw.Mechanism:
    return lw.load(str(FOUR_BAR))


def test_rocker_range_and_folds_match_the_triangle_geometry(four_bar: lw.Mechanism) -> None:
    tr = trace(four_bar, drive="D")
    lo, hi = rocker_range_deg()
    d = four_bar.index("D")
    folds = sorted(np.degrees(f.value) for f in tr.folds)
    # Joint D turns with the angle at D in the triangle: its range is [lo, hi] from the start.
    np.testing.assert_allclose(folds, [lo, hi], atol=1e-7)  # located folds: to Tolerances.locate
    sampled = np.degrees(tr.angles[:, d])
    assert lo - 1e-9 < sampled.min() < lo + 0.01 and hi - 0.01 < sampled.max() < hi + 1e-9


def test_unreachable_target_ends_when_the_path_closes_with_its_range(four_bar: lw.Mechanism) -> None:
    tr = trace(four_bar, until=("D", -95 * DEG))
    lo, hi = rocker_range_deg()
    assert tr.branches[0].end_reason == "closed path"
    # the crank went round once (not 19 times): exactly 360 deg, the last row snapped onto the start
    assert np.ptp(tr.angles[:, four_bar.index("A")]) == pytest.approx(2 * np.pi, abs=1e-9)
    assert tr.stats.unmet == f"D never reaches -95.00 deg on this path: its range is [{lo:.2f}, {hi:.2f}] deg"


def test_a_crank_target_beyond_one_turn_is_reached_by_turning_on(four_bar: lw.Mechanism) -> None:
    tr = trace(four_bar, until=("A", 1000 * DEG))
    assert tr.branches[0].end_reason == "reached target"
    assert np.degrees(tr.angles[-1, four_bar.index("A")]) == pytest.approx(1000.0, abs=1e-9)
    assert tr.stats.unmet is None


def test_a_limit_ends_the_branch_exactly_on_it(four_bar: lw.Mechanism) -> None:
    tr = trace(four_bar, limits={"D": (-5 * DEG, 30 * DEG)})
    assert tr.branches[0].end_reason == "limit D"
    assert np.degrees(tr.angles[-1, four_bar.index("D")]) == pytest.approx(-5.0, abs=1e-9)
    assert tr.residual[-1] < 1e-12
    assert np.all(np.degrees(tr.angles[:, four_bar.index("D")]) >= -5.0 - 1e-9)


def bennett(a1: float, a2: float, t1: float) -> lw.Mechanism:
    """Bennett linkage in DH form (a_i = sin alpha_i, theta3 = -theta1, theta4 = -theta2)."""
    from linkwork.kinematics.chains import from_dh

    k = np.sin((a2 + a1) / 2) / np.sin((a2 - a1) / 2)
    t2 = 2 * np.arctan(k / np.tan(t1 / 2))
    rows = [
        {"theta": t1, "a": np.sin(a1), "alpha": a1},
        {"theta": t2, "a": np.sin(a2), "alpha": a2},
        {"theta": -t1, "a": np.sin(a1), "alpha": a1},
        {"theta": -t2, "a": np.sin(a2), "alpha": a2},
    ]
    return from_dh("bennett", rows)[0]


def test_play_in_a_hinge_is_traced_within_the_closure_tolerance() -> None:
    a1, a2 = 45 * DEG, 75 * DEG
    exact = bennett(a1, a2, 90 * DEG)
    twists = np.array(exact.twists, copy=True)
    twists[1, 3:] += [0.0, 0.0, 1e-8]  # hinge B's line moved by about 1e-8: the loop is no longer mobile
    bent = dataclasses.replace(exact, twists=twists)
    tol = 1e-6
    tr = trace(bent, closure_tol=tol)
    assert tr.branches[0].end_reason == "closed path"
    assert tr.stats.closure_tol == tol
    assert 1e-12 < tr.stats.max_misfit <= tol  # a real misfit, within what was allowed
    th = tr.angles
    k = np.sin((a2 + a1) / 2) / np.sin((a2 - a1) / 2)
    rel = np.sin(th[:, 0] / 2) * np.sin(th[:, 1] / 2) - k * np.cos(th[:, 0] / 2) * np.cos(th[:, 1] / 2)
    assert np.max(np.abs(rel)) < 1e-5  # Bennett's closed form, to the order of the play
    # the exact default refuses to pretend: the loop is rigid to its corrector and ends with a reason
    strict = trace(bent)
    assert strict.branches[0].end_reason != "closed path"


@pytest.mark.parametrize("play", [0.1, 0.5, 1.0, 1e3, 1e12])
def test_a_large_play_keeps_the_rank_test_meaningful(four_bar: lw.Mechanism, play: float) -> None:
    """``--closure-tol`` from 0.1 to its bound 1e12 on the exact crank-rocker: the rank test's levels stop at a
    hundredth and a thousandth of ``sigma_1`` (:data:`~linkwork.kinematics.rank.MAX_LOOSE`, ``MAX_FLOOR``), so the
    start has rank 3 (a four-bar's three planar equations, independent off its singular points), the rocker swings
    over the triangles' range and the crank turns once. (From 0.1 the rank test failed with a ValueError: no
    singular value was sure; from 1, every one was below the floor and the start was 'mobility 4'.)"""
    tol = Tolerances().with_closure(play)
    assert tol.floor <= tol.loose < 1.0 and numerical_rank([2.0, 1.0, 0.5], tol) == 3
    tr = trace(four_bar, closure_tol=play)
    assert tr.stats.start_rank == 3 and tr.branches[0].end_reason == "closed path"
    assert np.ptp(tr.angles[:, four_bar.index("A")]) == pytest.approx(2 * np.pi, abs=1e-9)
    lo, hi = rocker_range_deg()
    swing = np.degrees(np.ptp(tr.angles[:, four_bar.index("D")]))
    assert hi - lo - 0.01 < swing <= hi - lo + 1e-9


def test_the_corrector_cannot_pull_a_step_back() -> None:
    """Near A = 123 deg a minimum-norm corrector pulled every step of the trihedral Bricard loop back (5000 steps of
    1e-9 that advanced nothing, caught by the advance test); the hyperplane corrector keeps each step's advance
    along the tangent, so even with the advance test off every step advances."""
    mech = lw.load("bricard-trihedral")
    for tol in (Tolerances(), Tolerances(advance=-np.inf)):
        path = trace(mech, tol=tol, max_steps=5000)
        assert path.branches[0].end_reason == "closed path"
        assert np.min(np.diff(path.arclength)) > 1e-4  # every step advanced


def sarrus_closure(
    q: np.ndarray, link: float = 1.0, height: float = 1.2, beta: float = np.pi / 2
) -> np.ndarray:
    """The Sarrus loop product minus the identity (12 numbers), built from its hinge lines by Rodrigues' formula."""
    points, directions = sarrus_hinges(link, height, beta)
    total = np.eye(4)
    for p, d, angle in zip(points, directions, q, strict=True):
        d = d / np.linalg.norm(d)
        K = np.array([[0, -d[2], d[1]], [d[2], 0, -d[0]], [-d[1], d[0], 0]])
        R = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
        g = np.eye(4)
        g[:3, :3], g[:3, 3] = R, p - R @ p
        total = total @ g
    return (total - np.eye(4))[:3].ravel()


def fd_mobility(q: np.ndarray, h: float = 1e-6) -> int:
    """Six joints minus the rank of the central-difference Jacobian of :func:`sarrus_closure`."""
    J = np.column_stack(
        [(sarrus_closure(q + h * e) - sarrus_closure(q - h * e)) / (2 * h) for e in np.eye(6)]
    )
    s = np.linalg.svd(J, compute_uv=False)
    return 6 - int(np.sum(s > 1e-6 * s[0]))


def test_sarrus_reports_its_two_dimensional_sheet_once_per_meeting_and_no_chain_of_points() -> None:
    mech = lw.load("sarrus")
    tr = trace(mech, branches=True)
    assert np.max(np.abs([sarrus_closure(q) for q in tr.angles])) < 1e-9  # the independent closure agrees
    components = [b for b in tr.bifurcations if b.kind == "component"]
    points = [b for b in tr.bifurcations if b.kind == "bifurcation"]
    assert components and len(tr.bifurcations) <= 8  # was 738 "bifurcation points"
    for b in components:
        assert b.dimension == 2
        assert fd_mobility(b.angles) == mech.n_unknowns - b.rank  # where the path meets the sheet
        # steps along the null space stay on the loop with mobility 2: a sheet, not an isolated point. Where the
        # path meets the sheet the null space has three dimensions (the sheet's two and the path's), and which
        # basis numpy returns for it depends on round-off in the point: step along the sums and differences of
        # pairs of its vectors; those not along the path land on the sheet (an isolated point has none).
        J = np.column_stack([(sarrus_closure(b.angles + 1e-6 * e) - sarrus_closure(b.angles - 1e-6 * e)) / 2e-6
                             for e in np.eye(6)])  # fmt: skip
        null = np.linalg.svd(J)[2][-3:]
        on_sheet = 0
        for i, j, sign in [(0, 1, 1), (0, 1, -1), (0, 2, 1), (0, 2, -1), (1, 2, 1), (1, 2, -1)]:
            step = null[i] + sign * null[j]
            fixed = _newton_onto(b.angles + 0.05 * step / np.linalg.norm(step))
            assert np.linalg.norm(sarrus_closure(fixed)) < 1e-10
            on_sheet += fd_mobility(fixed) == 2
        assert on_sheet >= 1
    for b in points:
        assert len(b.tangents) >= 2 and b.rank < int(tr.stats.start_rank)
    for br in tr.branches:
        assert br.mobility == 1 and br.steps > 0
        assert br.end_reason in ("closed path",) or br.end_reason.startswith("reached bifurcation")


def _newton_onto(q: np.ndarray) -> np.ndarray:
    """Minimum-norm Gauss-Newton onto the Sarrus loop with central differences (independent of linkwork)."""
    q = q.copy()
    for _ in range(50):
        r = sarrus_closure(q)
        J = np.column_stack(
            [(sarrus_closure(q + 1e-7 * e) - sarrus_closure(q - 1e-7 * e)) / 2e-7 for e in np.eye(6)]
        )
        q -= np.linalg.lstsq(J, r, rcond=1e-8)[0]
    return q


#: The branch graph a kinematician draws for each built-in with its default parameters: (isolated bifurcation
#: points, meetings with a higher-dimensional component). Single loops of mobility one close without branching;
#: the threefold Bricard loop crosses its second motion mode once (all joints at 180 deg); Guest's frame has its
#: six published bifurcation points; the Sarrus linkage branches where a limb is straight (two points) and meets
#: its flat-folded sheet of mobility 2.
EXPECTED = {
    "bennett": (0, 0),
    "bricard-line": (0, 0),
    "bricard-plane": (0, 0),
    "bricard-threefold": (1, 0),
    "bricard-trihedral": (0, 0),
    "four-bar": (0, 0),  # a Grashof crank-rocker: the crank turns round, no change point
    "goldberg": (0, 0),
    "guest-frame": (6, 0),
    "hedgepeth": (0, 0),
    "hedgepeth-rods": (0, 0),
    "rect-frame": (6, 0),  # its defaults are Guest's frame
    "sarrus": (2, 4),
    "slider-crank": (0, 0),  # the rod longer than crank + offset: no dead point
}


@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_every_builtin_gives_a_clean_branch_graph(name: str) -> None:
    assert name in EXPECTED, f"new built-in {name}: add its expected branch graph"
    mech = lw.load(name)
    tr = trace(mech, branches=True)
    kinds = [b.kind for b in tr.bifurcations]
    assert (kinds.count("bifurcation"), kinds.count("component")) == EXPECTED[name]
    assert len(kinds) == sum(EXPECTED[name])  # and no point labelled a fold
    assert tr.stats.sign_changes_without_rank_drop == 0
    for b in tr.bifurcations:
        if b.kind == "bifurcation":
            assert len(b.tangents) >= 2 and numerical_rank(b.sigma) < mech.n_unknowns - 1
    for br in tr.branches:
        assert br.steps > 0
        assert not br.end_reason.startswith(("step budget", "corrector failed", "no progress", "could not"))


def test_branch_tangents_over_the_unknowns_are_a_field_that_replace_keeps() -> None:
    mech = lw.load("guest-frame")
    bif = trace(mech).bifurcations[0]
    copy = dataclasses.replace(bif, step=0)
    assert copy.tangents_u.shape == (2, mech.n_unknowns)
    C = mech.coupling_matrix()
    over_joints = np.array([C @ t / np.linalg.norm(C @ t) for t in copy.tangents_u])
    np.testing.assert_allclose(over_joints, bif.tangents, atol=1e-15)
    _, _, jac = Workspace.of(mech).evaluate(bif.u)
    for t in copy.tangents_u:  # each is a null vector of the Jacobian there (to the located point's accuracy)
        assert np.linalg.norm(jac @ t) < 1e-6


def test_a_branch_that_runs_on_the_sarrus_sheet_ends_once_as_a_component() -> None:
    from linkwork.kinematics.marcher import BranchMarcher, MarchSettings

    mech = lw.load("sarrus")
    meeting = next(b for b in trace(mech).bifurcations if b.kind == "component")
    # a point of the sheet next to the meeting point (independent Newton), then march from it inside the sheet
    J = np.column_stack([(sarrus_closure(meeting.angles + 1e-6 * e) - sarrus_closure(meeting.angles - 1e-6 * e)) / 2e-6
                         for e in np.eye(6)])  # fmt: skip
    null = np.linalg.svd(J)[2][-3:]  # the sheet's two directions and the path's, in a basis round-off chooses
    candidates = (_newton_onto(meeting.angles + 0.05 * step) for step in (*null, *(-null)))
    on_sheet = next((q for q in candidates if fd_mobility(q) == 2), None)
    assert on_sheet is not None
    u0 = mech.u_from_q(mech.q_from_angles(on_sheet))
    ws = Workspace.of(mech)
    _, _, jac = ws.evaluate(u0)
    U, _, Vt = np.linalg.svd(jac)
    n = mech.n_unknowns
    settings = MarchSettings(
        drive=0, target=None, min_step=1e-9, max_step=2 * DEG, cos_turn=float(np.cos(10 * DEG)), r_path=5,
        n_sigma=6, periodic=np.ones(n, dtype=bool), lo=np.full(n, -np.inf), hi=np.full(n, np.inf), tol=Tolerances(),
    )  # fmt: skip
    marcher = BranchMarcher(mech, settings, 5000, switch_branches=True)
    steps, end = marcher.run_branch(
        0, u0, Vt[-1], np.ascontiguousarray(U[:, :5]), paper=False, h0=0.5 * DEG, stop_at_known=True
    )
    assert end.text.startswith("entered a 2-dimensional component (mobility 2) at point")
    assert end.kind == StopReason.COMPONENT and end.text.endswith(f"at point {end.point}")
    assert steps <= Tolerances().component_points
    assert 1 <= len(marcher.found) <= 2 and not marcher.queue  # no chain of points, no branch switching
    assert all(p.kind == "component" and p.dimension == 2 for p in marcher.found)


def _wrapped_distances(x: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Distances (angles compared modulo a full turn) from ``x`` to every row of ``points``."""
    diff = (x - points + np.pi) % (2.0 * np.pi) - np.pi
    return np.linalg.norm(diff, axis=1)


@pytest.mark.parametrize("name", ["guest-frame", "sarrus", "bricard-threefold"])
def test_every_arc_of_the_branch_graph_is_traced_once(name: str) -> None:
    """A branch never runs back along an arc already traced (the other way round): apart from the points it
    starts and ends at, no point of a branch lies on another branch, and each point where the motion branches is
    left along every one of its tangents by some traced point next to it."""
    mech = lw.load(name)
    tr = trace(mech, branches=True)
    for br in tr.branches:
        mine = tr.angles[tr.of_branch(br.id)]
        others = tr.angles[~tr.of_branch(br.id)]
        if len(others) == 0:
            continue
        near = np.array([_wrapped_distances(x, others).min() for x in mine]) < 1e-2
        assert near[2:-2].mean() < 0.02, (br.id, near.mean())  # only the ends are shared
    for bif in tr.bifurcations:
        if bif.kind != "bifurcation":
            continue
        for t in bif.tangents_u:
            for sign in (1.0, -1.0):  # both ways along each tangent there is a traced point
                probe = mech.angles_from_q(mech.q_from_u(bif.u + sign * 0.05 * t))
                away = _wrapped_distances(probe, bif.angles[None, :])[
                    0
                ]  # how far the probe is from the point
                assert _wrapped_distances(probe, tr.angles).min() < 0.5 * away, (bif.id, sign)
    assert tr.stats.branches_not_retraced >= 0


def test_the_threefold_bricard_loop_is_one_branch_through_its_point_twice() -> None:
    """Both motion modes of the threefold Bricard loop cross at all joints = 180 deg, and one closed path runs
    through that point twice (its joints turn twice round): the branch graph is that one branch."""
    tr = trace(lw.load("bricard-threefold"), branches=True)
    assert [b.kind for b in tr.bifurcations] == ["bifurcation"]
    assert len(tr.branches) == 1 and tr.branches[0].end_reason == "closed path"
    a = np.degrees(tr.angles[:, 0])
    assert a.max() - a.min() > 700.0  # joint A turns twice: once along each mode
    assert tr.stats.branches_not_retraced == 2


@pytest.mark.parametrize(
    "links", [(2.0, 1.0, 2.5, 1.5), (2.5, 1.0, 2.0, 1.5)], ids=["crank-shortest", "crank-and-ground-long"]
)
def test_a_change_point_four_bar_has_its_bifurcation_where_the_links_are_collinear(links) -> None:
    """Grashof's change point (s + l = p + q): the two circuits cross where all four pivots lie on one line. The
    located point must be that configuration (checked on the pivots' positions, not on the tracer's numbers), with
    two branch tangents; the path crosses it on both circuits, so no other branch is left to trace."""
    ground, crank, coupler, rocker = links
    assert min(links) + max(links) == pytest.approx(sum(links) - min(links) - max(links))  # a change point
    mech = lw.load("four-bar", ground=ground, crank=crank, coupler=coupler, rocker=rocker)
    tr = trace(mech, branches=True)
    assert [b.kind for b in tr.bifurcations] == ["bifurcation"]
    bif = tr.bifurcations[0]
    assert len(bif.tangents) == 2 and bif.sigma[-1] < 1e-10 * bif.sigma[0]
    from linkwork.kinematics.positions import joint_positions

    pivots = joint_positions(mech, bif.angles[None, :])[0, :, :2]
    d = pivots[1:] - pivots[0]
    cross = d[:, 0] * d[0, 1] - d[:, 1] * d[0, 0]
    assert np.max(np.abs(cross)) < 1e-9  # every pivot on the line through the first two
    assert tr.stats.sign_changes_without_rank_drop == 0
    assert len(tr.branches) == 1 and tr.branches[0].end_reason == "closed path"
