"""The tracer's bookkeeping, proven as properties over every built-in linkage and over generated loops.

Each property is checked against something outside the code under test (:mod:`bookkeeping_reference`: loop
products by ``scipy.linalg.expm``, the Jacobian by central finite differences of them, and linkages built from
their closed forms):

* a closed path's last row is its first again: every joint modulo a full turn, every singular value, the residual;
* every row's singular values are numpy's SVD of the finite-difference Jacobian at that row's angles;
* every target inside the range a trace reports is reached, including exactly one turn and just below it;
* a fold of the drive is reported only where the drive turns back;
* a point of the path that lands exactly on a bifurcation point is recognised as one;
* the values the Python API reports are joint values, as in report.json.
"""

from __future__ import annotations

from dataclasses import replace
from functools import cache

import numpy as np
import pytest
from bookkeeping_reference import (
    bennett,
    hat,
    jacobian,
    planar_four_bar,
    singular_values,
    spherical_four_bar,
    stephenson_six_bar,
    wrapped,
)
from bookkeeping_reference import residual as reference_residual
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.linalg import expm

import linkwork as lw
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.trace_result import Trace
from linkwork.linkages.registry import REGISTRY

DEG = np.pi / 180.0
#: Seeded, no deadline, few examples: the generated cases run in seconds.
PROPERTY = settings(deadline=None, max_examples=6, derandomize=True)
#: A closed path's last row against its first: angles (rad, modulo a turn), singular values, residual.
CLOSED_TOL = 1e-9
#: Singular values against numpy's SVD of the finite-difference Jacobian, relative to sigma_1 (the central
#: difference's truncation and round-off at step 1e-6 are below 1e-9).
SIGMA_TOL = 1e-7

BUILT_INS = sorted(REGISTRY)


@cache
def built_in_trace(name: str, branches: bool) -> Trace:
    """The default trace of a built-in (every branch with ``branches``)."""
    return lw.trace(lw.load(name), branches=branches)


def rows_to_check(tr: Trace, most: int = 12) -> np.ndarray:
    """Every branch's first and last rows and up to ``most`` rows spread along the path."""
    starts = np.flatnonzero(np.diff(tr.branch, prepend=-1) != 0)
    ends = np.append(starts[1:] - 1, len(tr.branch) - 1)
    spread = np.linspace(0, len(tr.branch) - 1, most).astype(int)
    return np.unique(np.concatenate([starts, ends, spread]))


def assert_closed_rows_match(tr: Trace) -> int:
    """Every branch that ended on a closed path ends on its first row; returns how many did."""
    closed = 0
    for br in tr.branches:
        if br.end_reason != "closed path":
            continue
        rows = np.flatnonzero(tr.branch == br.id)
        first, last = rows[0], rows[-1]
        np.testing.assert_allclose(wrapped(tr.angles[last] - tr.angles[first]), 0.0, atol=CLOSED_TOL)
        np.testing.assert_allclose(tr.sigma[last], tr.sigma[first], rtol=0.0, atol=CLOSED_TOL)
        assert abs(tr.residual[last] - tr.residual[first]) <= CLOSED_TOL
        closed += 1
    return closed


def assert_sigma_is_fresh_svd(tr: Trace, rows: np.ndarray) -> None:
    """Each checked row's singular values are numpy's SVD of the independent Jacobian at its angles; its residual
    is the independent closure's (both to the stated tolerances)."""
    mech = tr.mechanism
    for k in rows:
        reference = singular_values(mech, tr.angles[k])
        k_sig = min(len(reference), tr.sigma.shape[1])
        np.testing.assert_allclose(
            tr.sigma[k, :k_sig], reference[:k_sig], rtol=0.0, atol=SIGMA_TOL * reference[0],
            err_msg=f"{mech.name}: row {k} (branch {tr.branch[k]}, step {tr.step[k]})",
        )  # fmt: skip
        assert reference_residual(mech, tr.angles[k]) < 1e-9


# ------------------------------------------------------------------------------------ closed paths
@pytest.mark.parametrize("name", BUILT_INS)
def test_every_built_in_closed_path_ends_on_its_first_row(name: str) -> None:
    """And report.json's ``condition_at_end`` (the normalised ratio at the last point) is the start's again."""
    from linkwork.io.results import report_dict

    tr = built_in_trace(name, False)
    assert assert_closed_rows_match(tr) >= (1 if tr.branches[0].end_reason == "closed path" else 0)
    if tr.branches[-1].end_reason == "closed path":
        assert report_dict(tr)["condition_at_end"] == pytest.approx(tr.condition()[0], rel=1e-9)
        assert tr.rank[-1] == tr.rank[0]


@pytest.mark.parametrize("name", ["guest-frame", "bricard-threefold", "four-bar"])
def test_closed_path_rows_match_when_the_march_runs_in_chunks(name: str) -> None:
    """The command line marches 100 steps at a time (its progress bar): the last row is still the first."""
    tr = lw.trace(lw.load(name), progress=lambda done, total: None)
    assert tr.branches[0].end_reason == "closed path"
    assert assert_closed_rows_match(tr) >= 1


@pytest.mark.parametrize("name", ["guest-frame", "bricard-threefold", "sarrus"])
def test_closed_branches_from_bifurcation_points_end_on_their_first_row(name: str) -> None:
    assert_closed_rows_match(built_in_trace(name, True))


# ------------------------------------------------------------------------------------ singular values
@pytest.mark.parametrize("name", BUILT_INS)
def test_every_built_in_row_has_the_singular_values_of_its_angles(name: str) -> None:
    for branches in (False, True):
        tr = built_in_trace(name, branches)
        assert_sigma_is_fresh_svd(tr, rows_to_check(tr))


# ------------------------------------------------------------------------------------ generated loops
bennett_params = st.tuples(
    st.floats(15.0, 70.0),  # alpha1 (deg)
    st.floats(20.0, 80.0),  # alpha2 - alpha1 (deg)
    st.floats(30.0, 150.0),  # theta1 at the start (deg)
)


def generated_bennett(params: tuple[float, float, float]) -> Mechanism:
    a1, da, t1 = params
    return bennett(a1 * DEG, (a1 + da) * DEG, t1 * DEG)


@PROPERTY
@given(bennett_params)
def test_generated_bennett_closed_path_and_singular_values(params: tuple[float, float, float]) -> None:
    tr = lw.trace(generated_bennett(params), progress=lambda done, total: None)
    assert tr.branches[0].end_reason == "closed path"
    assert assert_closed_rows_match(tr) == 1
    assert_sigma_is_fresh_svd(tr, rows_to_check(tr, 6))


grashof_crank = st.tuples(
    st.floats(1.5, 3.0),  # ground
    st.floats(0.3, 1.0),  # crank (shortest: a crank-rocker when ground + crank < coupler + rocker)
    st.floats(0.0, 1.0),  # coupler, as a fraction of its Grashof range
    st.floats(20.0, 160.0),  # crank angle at the start (deg)
)


def generated_four_bar(params: tuple[float, float, float, float]) -> Mechanism:
    """A crank-rocker: the crank shortest and ``s + l < p + q`` (Grashof), so the crank turns fully."""
    ground, crank, frac, theta = params
    # rocker = ground, coupler between (ground - rocker + crank) + margin and (ground + rocker - crank) - margin
    rocker = ground
    lo, hi = crank + 0.2, ground + rocker - crank - 0.2
    coupler = lo + frac * (hi - lo)
    return planar_four_bar(ground, crank, coupler, rocker, theta * DEG)


@PROPERTY
@given(grashof_crank)
def test_generated_four_bar_closed_path_and_singular_values(
    params: tuple[float, float, float, float],
) -> None:
    tr = lw.trace(generated_four_bar(params), progress=lambda done, total: None)
    assert tr.branches[0].end_reason == "closed path"
    assert assert_closed_rows_match(tr) == 1
    assert_sigma_is_fresh_svd(tr, rows_to_check(tr, 6))


spherical_crank = st.tuples(
    st.floats(60.0, 80.0),  # ground arc (deg)
    st.floats(15.0, 30.0),  # crank arc (shortest)
    st.floats(60.0, 80.0),  # coupler arc
    st.floats(60.0, 80.0),  # rocker arc
    st.floats(20.0, 160.0),  # crank angle at the start (deg)
)


def generated_spherical(params: tuple[float, ...]) -> Mechanism:
    g, c, k, r, theta = params
    return spherical_four_bar(g * DEG, c * DEG, k * DEG, r * DEG, theta * DEG)


@PROPERTY
@given(spherical_crank)
def test_generated_spherical_4r_closed_path_and_singular_values(params: tuple[float, ...]) -> None:
    tr = lw.trace(generated_spherical(params), progress=lambda done, total: None)
    assert tr.branches[0].end_reason == "closed path"
    assert assert_closed_rows_match(tr) == 1
    assert_sigma_is_fresh_svd(tr, rows_to_check(tr, 6))


# ------------------------------------------------------------------------------------ targets
#: A reached target: the drive's last value equals it (radians).
TARGET_TOL = 1e-12


def reported_range(tr: Trace) -> tuple[float, float]:
    """The drive's range on the first branch, as the tracer reports it (its points and folds)."""
    d = tr.mechanism.index(tr.drive)
    values = [tr.angles[tr.branch == 0, d], [f.angles[d] for f in tr.folds if f.branch == 0]]
    joined = np.concatenate([np.asarray(v, dtype=float) for v in values])
    return float(joined.min()), float(joined.max())


def targets_inside(tr: Trace) -> list[float]:
    """Targets strictly inside the reported range of the drive, and for a drive that turns round, exactly one
    turn from the start and just below it (both ways round)."""
    lo, hi = reported_range(tr)
    start = float(tr.angles[0, tr.mechanism.index(tr.drive)])
    span = hi - lo
    out = [lo + 0.03 * span, lo + 0.41 * span, lo + 0.97 * span]
    if span >= 2.0 * np.pi - 1e-9:
        turn = np.sign(hi + lo - 2.0 * start) or 1.0
        out += [
            start + turn * 2.0 * np.pi,
            start + turn * (2.0 * np.pi - 1e-6),
            start + turn * (2 * np.pi - 0.01),
        ]
    return out


def assert_reaches_every_target(mech: Mechanism, free: Trace, **options: object) -> None:
    d = mech.index(free.drive)
    for target in targets_inside(free):
        tr = lw.trace(mech, drive=free.drive, until=(free.drive, target), **options)  # type: ignore[arg-type]
        assert tr.stats.unmet is None, f"{mech.name}: {tr.stats.unmet}"
        assert tr.branches[0].end_reason == "reached target"
        assert abs(tr.angles[tr.branch == 0, d][-1] - target) <= TARGET_TOL * max(1.0, abs(target))


@pytest.mark.parametrize("name", BUILT_INS)
def test_every_built_in_reaches_every_target_inside_its_range(name: str) -> None:
    mech = lw.load(name)
    assert_reaches_every_target(mech, built_in_trace(name, False))


@pytest.mark.parametrize(
    "mech",
    [
        stephenson_six_bar(0.0),
        spherical_four_bar(70 * DEG, 20 * DEG, 70 * DEG, 70 * DEG, 40 * DEG),
        planar_four_bar(2.0, 1.0, 2.5, 2.0, 60 * DEG),
    ],
    ids=["stephenson", "spherical-4r", "four-bar"],
)
def test_exactly_one_turn_and_just_below_are_reached(mech: Mechanism) -> None:
    free = lw.trace(mech)
    assert_reaches_every_target(mech, free)
    assert_reaches_every_target(mech, free, progress=lambda done, total: None)


def test_one_turn_of_a_four_bar_in_equal_steps_lands_on_it() -> None:
    mech = lw.load("four-bar")
    start = float(mech.offsets[0])
    for target, steps in ((start + 2 * np.pi, 360), (start + 2 * np.pi - 0.5 * DEG, 359)):
        tr = lw.trace(mech, until=("A", target), steps=steps)
        assert tr.branches[0].end_reason == "reached target"
        assert abs(tr.angles[-1, 0] - target) <= TARGET_TOL * abs(target)


@PROPERTY
@given(spherical_crank)
def test_generated_spherical_4r_reaches_every_target(params: tuple[float, ...]) -> None:
    mech = generated_spherical(params)
    assert_reaches_every_target(mech, lw.trace(mech))


@PROPERTY
@given(st.floats(0.0, 360.0), st.floats(-1.0, 1.0))
def test_generated_stephenson_reaches_one_turn(theta: float, spread: float) -> None:
    mech = stephenson_six_bar(theta * DEG, spread)
    assert_reaches_every_target(mech, lw.trace(mech))


# ------------------------------------------------------------------------------------ folds
#: At a located fold the drive's component of the (independent) null vector is below this.
FOLD_TANGENT_TOL = 1e-5


def assert_folds_turn_back(tr: Trace) -> None:
    """Every reported fold is a turning point of the drive: the independent Jacobian's null vector has no drive
    component there, the drive's value is an extreme of its neighbouring rows, and no fold sits on a branch along
    which the drive stays put."""
    mech = tr.mechanism
    d = mech.index(tr.drive)
    g = int(mech.groups[d])
    for f in tr.folds:
        drive = tr.angles[tr.branch == f.branch, d]
        assert np.ptp(drive) > 1e-6, f"fold on branch {f.branch}, where {tr.drive} stays at {drive[0]:.12g}"
        assert f.value == f.angles[d]
        null = np.linalg.svd(jacobian(mech, f.angles))[2][-1]
        assert abs(null[g]) < FOLD_TANGENT_TOL
        steps = tr.step[tr.branch == f.branch]
        k = int(np.flatnonzero(steps == f.step)[0])
        around = drive[max(k - 1, 0) : k + 3] - f.value
        assert np.all(around <= 1e-12) or np.all(around >= -1e-12), "the drive does not turn back at the fold"


@pytest.mark.parametrize("name", BUILT_INS)
def test_folds_are_only_where_the_drive_turns_back(name: str) -> None:
    for branches in (False, True):
        assert_folds_turn_back(built_in_trace(name, branches))


def test_guest_frame_branches_along_which_the_drive_stays_put_have_no_folds() -> None:
    tr = built_in_trace("guest-frame", True)
    d = tr.mechanism.index("A")
    still = [br.id for br in tr.branches if np.ptp(tr.angles[tr.branch == br.id, d]) < 1e-9]
    assert still, "Guest's frame has branches along which A stays at the bifurcation point's value"
    assert not [f for f in tr.folds if f.branch in still]
    assert {f.branch for f in tr.folds} >= {0}


def test_a_fold_value_is_the_joint_value_in_python_and_report_json() -> None:
    """Slider-crank (crank 1, rod 3, offset 0.1) driven by the slider: it turns back where crank and rod are in
    line, at sqrt((rod +- crank)^2 - offset^2) (closed form)."""
    from linkwork.io.results import report_dict

    tr = lw.trace(lw.load("slider-crank", crank=1.0, rod=3.0, offset=0.1, theta=0.0), drive="D")
    extremes = sorted(f.value for f in tr.folds)
    np.testing.assert_allclose(
        extremes, [np.sqrt(2.0**2 - 0.01), np.sqrt(4.0**2 - 0.01)], rtol=0.0, atol=1e-9
    )
    report = report_dict(tr)
    np.testing.assert_allclose(sorted(f["value"] for f in report["folds"]), extremes, rtol=0.0, atol=1e-12)


@PROPERTY
@given(st.floats(1.6, 2.6), st.floats(30.0, 150.0))
def test_generated_four_bar_driven_by_its_rocker_folds_at_its_extremes(coupler: float, theta: float) -> None:
    """A crank-rocker (ground 2, crank 0.6, rocker 2) driven by the rocker D folds twice per turn of the crank."""
    mech = planar_four_bar(2.0, 0.6, coupler, 2.0, theta * DEG)
    tr = lw.trace(mech, drive="D")
    assert tr.branches[0].end_reason == "closed path"
    assert len(tr.folds) == 2
    assert_folds_turn_back(tr)


# ------------------------------------------------------------------------------------ landing on a bifurcation
#: The parallelogram relation on every row, and the crossing's crank angle (radians).
PARALLELOGRAM_TOL = 1e-9


@PROPERTY
@given(st.sampled_from([0.5, 1.0, 2.0, 2.5, 3.0, 5.0]), st.integers(3, 60), st.integers(3, 30))
def test_equal_steps_landing_on_a_bifurcation_recognise_it_and_stay_on_their_branch(
    delta: float, before: int, after: int
) -> None:
    """A parallelogram four-bar (ground 2, crank 1, coupler 2, rocker 1) crosses its other branch where every
    pivot is on one line (crank at 180 deg). Equal drive steps of ``delta`` deg with one landing exactly there:
    the point is a bifurcation point with two branch tangents, and every row keeps the parallelogram relation
    (coupler parallel to the ground: q_B = -q_A, q_C = q_A, q_D = -q_A modulo a turn)."""
    assume(10.0 <= before * delta <= 170.0)  # the start between the crossings, on the parallelogram branch
    theta = 180.0 - before * delta
    mech = planar_four_bar(2.0, 1.0, 2.0, 1.0, theta * DEG)
    tr = lw.trace(mech, until=("A", (before + after) * delta * DEG), steps=before + after)
    assert tr.branches[0].end_reason == "reached target"
    q = tr.angles - mech.offsets
    for j, sign in ((1, -1.0), (2, 1.0), (3, -1.0)):
        np.testing.assert_allclose(wrapped(q[:, j] - sign * q[:, 0]), 0.0, atol=PARALLELOGRAM_TOL)
    crossings = [b for b in tr.bifurcations if b.kind == "bifurcation"]
    assert len(crossings) == 1
    assert abs(wrapped(theta * DEG + crossings[0].angles[0] - np.pi)) < PARALLELOGRAM_TOL
    assert len(crossings[0].tangents) == 2


def test_the_reported_four_bar_landing_on_its_crossing_reaches_its_target() -> None:
    """`trace four-bar --set ground=2 --set crank=1 --set coupler=2 --set rocker=1 --set theta=60 --until A=419
    --steps 359`: 1-degree steps, one on each crossing (A = 180 and 360 deg)."""
    mech = lw.load("four-bar", ground=2.0, crank=1.0, coupler=2.0, rocker=1.0, theta=60 * DEG)
    for branches in (False, True):
        tr = lw.trace(mech, until=("A", 419 * DEG), steps=359, branches=branches)
        assert tr.branches[0].end_reason == "reached target"
        found = sorted(float(np.degrees(b.angles[0])) for b in tr.bifurcations)
        np.testing.assert_allclose(found, [180.0, 360.0], atol=1e-7)
        assert_sigma_is_fresh_svd(tr, rows_to_check(tr, 12))


# ------------------------------------------------------------------------------------ scale-free steps
#: The same linkage in another unit or place: every row's angles agree (radians).
SAME_STEPS_TOL = 1e-9


def rigid(seed: int) -> np.ndarray:
    """A random rigid motion (rotation up to pi about a random axis, translation up to 5), by scipy's expm."""
    rng = np.random.default_rng(seed)
    axis = rng.normal(size=3)
    w = axis / np.linalg.norm(axis) * rng.uniform(0.1, np.pi - 0.1)
    return expm(hat(np.concatenate([w, rng.uniform(-5.0, 5.0, size=3)])))


def moved(mech: Mechanism, T: np.ndarray, scale: float = 1.0) -> Mechanism:
    """Every hinge line scaled by ``scale`` about the origin, then moved by the rigid motion ``T``: a line
    through ``p`` along ``w`` goes through ``R s p + d`` along ``R w``."""
    R, d = T[:3, :3], T[:3, 3]
    w, v = mech.twists[:, :3], scale * mech.twists[:, 3:]
    twists = np.concatenate([w @ R.T, v @ R.T + np.cross(d, w @ R.T)], axis=1)
    return replace(mech, twists=twists, hinge_points=np.zeros((0, 3)))


def assert_same_steps(a: Trace, b: Trace) -> None:
    assert a.angles.shape == b.angles.shape, f"{len(a.angles)} points against {len(b.angles)}"
    np.testing.assert_allclose(b.angles, a.angles, rtol=0.0, atol=SAME_STEPS_TOL)
    assert [br.end_reason for br in a.branches] == [br.end_reason for br in b.branches]


@PROPERTY
@given(bennett_params, st.integers(0, 1000))
def test_the_step_sequence_of_a_bennett_linkage_does_not_depend_on_unit_or_place(
    params: tuple[float, float, float], seed: int
) -> None:
    """Metres against millimetres (every length times 1000, the closed form built in each unit) and the linkage
    moved and turned: the adaptive steps land on the same points (it differed by up to 0.106 deg)."""
    a1, da, t1 = params
    metres = bennett(a1 * DEG, (a1 + da) * DEG, t1 * DEG)
    millimetres = bennett(a1 * DEG, (a1 + da) * DEG, t1 * DEG, scale=1000.0)
    reference = lw.trace(metres)
    assert_same_steps(reference, lw.trace(millimetres))
    assert_same_steps(reference, lw.trace(moved(metres, rigid(seed))))


@pytest.mark.parametrize("name", ["bricard-line", "goldberg", "hedgepeth-rods", "guest-frame", "four-bar"])
def test_the_step_sequence_of_a_built_in_does_not_depend_on_unit_or_place(name: str) -> None:
    mech = lw.load(name)
    reference = built_in_trace(name, False)
    T = rigid(7)
    if mech.planar:  # turned about z and moved in the plane: a planar mechanism stays in z = 0
        c, s = np.cos(2.1), np.sin(2.1)
        T = np.array([[c, -s, 0.0, 3.0], [s, c, 0.0, -4.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    for variant in (moved(mech, np.eye(4), 1000.0), moved(mech, T, 0.001)):
        assert_same_steps(reference, lw.trace(variant))


slider_crank_params = st.tuples(
    st.floats(0.5, 2.0),  # crank
    st.floats(1.3, 4.0),  # rod / crank
    st.floats(-0.6, 0.6),  # offset / crank
    st.floats(5.0, 355.0),  # crank angle at the start, deg
)


@PROPERTY
@given(slider_crank_params, st.sampled_from([1000.0, 0.001]))
def test_the_step_sequence_of_a_slider_crank_does_not_depend_on_unit_or_place(
    params: tuple[float, float, float, float], scale: float
) -> None:
    """A linkage with a prismatic unknown, built by its closed form in two length units (every length times
    ``scale``) and moved and turned in its plane: the same steps, the slider's column in the unit it is in.

    It differed (274 rows against 284 for an offset slider-crank in thousandths): the tangent was oriented in
    the plain metric, where a slider in a small unit outweighs every angle, and turned back where the slider
    does."""
    crank, ratio, offset, start = params
    rod, e = ratio * crank, offset * crank
    assume(abs(crank * np.sin(start * DEG) - e) < 0.95 * rod)  # the rod reaches the guide, not at a fold
    reference = lw.trace(lw.load("slider-crank", crank=crank, rod=rod, offset=e, theta=start * DEG))
    scaled = lw.trace(
        lw.load("slider-crank", crank=scale * crank, rod=scale * rod, offset=scale * e, theta=start * DEG)
    )
    assert scaled.angles.shape == reference.angles.shape, (
        f"{len(scaled.angles)} against {len(reference.angles)}"
    )
    unit = np.array([1.0, 1.0, 1.0, scale])
    np.testing.assert_allclose(scaled.angles / unit, reference.angles, rtol=0.0, atol=SAME_STEPS_TOL)
    assert [b.end_reason for b in scaled.branches] == [b.end_reason for b in reference.branches]
    c, s = np.cos(2.1), np.sin(2.1)
    T = np.array([[c, -s, 0.0, 3.0], [s, c, 0.0, -4.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    mech = lw.load("slider-crank", crank=crank, rod=rod, offset=e, theta=start * DEG)
    assert_same_steps(reference, lw.trace(moved(mech, T)))  # a slider's twist (0, d) turns, and is not scaled


#: name, parameters, drive (None: the first joint), the target's distance from the start (deg), equal steps.
PAPER_PATHS = {
    "crank-rocker, two turns": ("four-bar", {}, "A", 720.0, 480),
    "parallelogram through both crossings": (
        "four-bar", {"ground": 2.0, "crank": 1.0, "coupler": 2.0, "rocker": 1.0, "theta": 60 * DEG}, "A", 359.0, 359,
    ),
    "slider-crank driven by its crank": ("slider-crank", {"offset": 0.4}, "A", 390.0, 250),
    "bennett": ("bennett", {}, None, 300.0, 230),
}  # fmt: skip


@pytest.mark.parametrize("case", PAPER_PATHS)
def test_paper_rows_do_not_depend_on_how_the_march_is_called(case: str) -> None:
    """Paper mode with a progress callback (what the command line passes: the compiled march is called for 100
    steps at a time) writes the rows of one call, to round-off: each call's first step extrapolates from the row
    before it, as every other step does. It differed by up to 7.4e-10 deg through a crossing."""
    name, params, drive, target, steps = PAPER_PATHS[case]
    mech = lw.load(name, **params)
    drive = drive or mech.joint_names[0]
    start = float(mech.offsets[mech.joint_names.index(drive)])
    until = (drive, start + target * DEG)  # the target, from the start
    one = lw.trace(mech, drive=drive, until=until, steps=steps, max_steps=2 * steps)
    calls: list[int] = []
    chunked = lw.trace(
        mech,
        drive=drive,
        until=until,
        steps=steps,
        max_steps=2 * steps,
        progress=lambda d, n: calls.append(d),
    )
    assert len(calls) >= 3, "the march was not called several times"
    assert one.branches[0].end_reason == "reached target"
    # the same rows but for round-off (each call starts the SVD's Jacobi sweeps cold), and on a crossing to the
    # row's accuracy there: both paths are within 2.6e-11 rad of the closed form (A, -A, A, A) on the parallelogram
    # branch, the rows on the crossing itself (A = 180 deg, a double point) the least accurate
    if case.startswith("parallelogram"):
        A = one.angles[:, 0]
        for tr in (one, chunked):
            np.testing.assert_allclose(tr.angles, np.column_stack([A, -A, A, A]), rtol=0.0, atol=5e-11)
        atol = 5e-11
    else:
        atol = 1e-14  # without the row before each call: 2.2e-14 (crank-rocker), 3.3e-12 (bennett)
    np.testing.assert_allclose(chunked.angles, one.angles, rtol=0.0, atol=atol)
    np.testing.assert_allclose(chunked.sigma, one.sigma, rtol=0.0, atol=atol * float(np.max(one.sigma)))
