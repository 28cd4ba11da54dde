"""The two open items of the session-16 audit, closed in session 17, and the one found then, closed in 18 (they
were strict expected failures), with properties over generated inputs of each kind, checked against closed forms.

* One paper row over two crossings reported neither: the test function changes sign twice inside the row, and the
  march compared its sign row to row (the rows themselves were right). Now the sign is compared part by part
  within a row, and each part over which it changed is located (``march.MAX_CROSSINGS``).
* Paper steps of about 80 deg or more failed on a Goldberg 5R whose drive nearly stops (other joints move up to 435
  times as fast as the drive A there): one equal step to A + 60 deg was reached, to A + 80 deg it ended 'corrector
  failed at a fixed drive step' after the start (every retake up to 1,311 equal parts failed: a part of 0.06 deg of
  A moves the other joints up to 26 deg there), though an adaptive trace reaches every value of A. Now a step that
  fails in every number of parts follows the path adaptively to the row's drive value and lands on it
  (``BranchMarcher._follow_row``).
* (Found in session 17, closed in 18.) A paper row whose own drive value lands a hair from a crossing went on
  along the other branch: the row's value is fixed, so it is now approached again from the same side in closing
  parts; a row on the crossing to round-off goes on along the tangent it came in with.
* (Found in session 18, closed in 19.) A long paper row (150 to 350 deg) landing within 1e-9 to 1e-5 deg of a
  crossing, then more rows, went on along the other branch: the row on the crossing to round-off kept the SVD's
  null vector where it had turned by less than ``max_turn``, and a row landed on the located crossing was stepped
  from in equal parts, unjudged, one of which landed a hair from the next crossing, 180 deg on. A paper row on a
  singular point now always keeps the tangent it came in with, and the row after a located crossing is marched
  as every row is.

References (no linkwork): a four-bar's singular configurations are those with its four pivots in line, the crank
along the ground line (``FourBar.solve`` gives the rows); Goldberg's 5R from Bennett's relation
``tan(t1/2) tan(t2/2) = sin((beta + alpha)/2) / sin((beta - alpha)/2)`` of its two Bennett loops (Goldberg 1943;
the angles of ``linkages.goldberg``'s module docstring, written out again here).
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from audit_reference import FourBar, nearest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

import linkwork as lw
from linkwork.linkages.goldberg import goldberg

RAD = np.pi / 180.0

GOLDBERG = """name = "g"
[loop]
convention = "hinge-lines"
[[loop.joints]]
name = "A"
point = [0.6763723584498789, -0.4083216409094894, 0.0]
direction = [-0.3798152453144945, -0.6291523826079277, -0.6781649201230171]
theta = -162.4472241382195
[[loop.joints]]
name = "B"
point = [-0.004764705654008994, -0.018998834356259764, 0.02029428143576991]
direction = [0.02585874022680818, -0.006867488864354649, 0.999642017499555]
theta = 179.7034014234257
[[loop.joints]]
name = "C"
point = [0.7848132297926311, 7.979727989493313e-17, -2.42861286636753e-17]
direction = [-3.4070806119431744e-17, -0.7300226084902118, -0.6834229957304241]
theta = 54.852880171675565
[[loop.joints]]
name = "D"
point = [-0.273924344582003, -0.1245151796200486, 0.1330053228977243]
direction = [0.16947385422244718, -0.6457198323366622, 0.7445297246330072]
theta = -95.57632739886338
[[loop.joints]]
name = "E"
point = [-0.970504512147737, -0.4606958749202211, 0.0]
direction = [-0.4285330465425569, 0.9027501176258373, -0.03743865846276526]
theta = -23.418881198948867
"""


def test_one_paper_row_over_two_crossings_reports_both(tmp_path: Path) -> None:
    """A parallelogram (ground = coupler 3, crank = rocker 1) from 30 to 370 deg in one equal step passes its
    crossings at A = 180 and 360 deg: both are bifurcation points of the closed form."""
    spec = tmp_path / "pg.toml"
    spec.write_text(FourBar("parallelogram", 3.0, 1.0, 3.0, 1.0, 30.0).mech.toml())
    trace = lw.trace(lw.load(str(spec)), until=("A", 370.0 * RAD), steps=1)
    assert trace.stats.unmet is None
    crossings = sorted(float(np.degrees(b.angles[0])) % 360.0 for b in trace.bifurcations)
    assert len(crossings) == 2


def test_a_long_paper_step_of_a_goldberg_linkage_is_taken(tmp_path: Path) -> None:
    """The Goldberg 5R above, one equal step from A = -162.447 to -82.447 deg: the adaptive trace reaches that
    value, so the paper step must too."""
    spec = tmp_path / "g.toml"
    spec.write_text(GOLDBERG)
    mech = lw.load(str(spec))
    target = float(mech.offsets[mech.index("A")]) + 80.0 * RAD
    assert lw.trace(mech, until=("A", target)).stats.unmet is None  # adaptive: reached
    assert lw.trace(mech, until=("A", target), steps=1).stats.unmet is None


# ---- properties: one paper row over both crossings of a parallelogram or a deltoid

PROPERTY = settings(deadline=None, max_examples=10, derandomize=True)


def on_special_branch(case: FourBar, kind: str, start: float, row: np.ndarray) -> bool:
    """Whether a row (deg) is on the parallelogram's parallelogram branch (the coupler's direction that of the
    ground, 0 deg) or the deltoid's folded branch (C on A: the rocker points from D to A, 180 deg): the coupler's
    direction is its start's plus A's and B's turns, the rocker's its start's minus D's (D turns the ground
    relative to the rocker)."""
    pts = case.pts
    if kind == "parallelogram":
        c = pts["C"] - pts["B"]
        angle = np.degrees(np.arctan2(c[1], c[0])) + (row[0] - start) + row[1]
    else:
        c = pts["C"] - pts["D"]
        angle = np.degrees(np.arctan2(c[1], c[0])) - row[3] - 180.0
    return abs((float(angle) + 180.0) % 360.0 - 180.0) < 1e-6


def four_pivots_in_line(case: FourBar, reading: float) -> float:
    """The distance (deg) from a crank reading to the nearest reading with the crank along the ground line, where
    a four-bar's singular configurations are (its four pivots in line)."""
    return float(min(abs((reading - x + 180.0) % 360.0 - 180.0) for x in (0.0, 180.0)))


@PROPERTY
@given(
    kind=st.sampled_from(["parallelogram", "deltoid"]),
    ground=st.floats(1.5, 4.0),
    ratio=st.floats(0.15, 0.8),
    start=st.floats(15.0, 165.0),
    end=st.floats(365.0, 535.0),
    side=st.sampled_from([0, 1]),
)
@example(
    kind="parallelogram", ground=2.0, ratio=0.5, start=15.0, end=472.6875, side=1
)  # a part 0.0007 deg short
def test_one_paper_row_over_both_crossings_reports_both(
    tmp_path_factory: object, kind: str, ground: float, ratio: float, start: float, end: float, side: int
) -> None:
    """A parallelogram (ground = coupler, crank = rocker) or a deltoid (crank = coupler, ground = rocker) meets its
    two singular configurations, the crank along the ground line at 0 and 180 deg, once a turn. One equal step over
    both (and no third) reports both, each a bifurcation on the closed form, and the row is on the closed form, on
    the branch the start is on: a parallelogram's coupler keeps its direction (readings A + B constant) on the
    parallelogram branch only; a deltoid's rocker stays put (D constant, the coupler folded back onto the crank, C
    on A) on its folded branch only. (A part of the row a hair from a crossing had gone on along the other branch:
    the parallelogram 2 x 1 from 15 to 472.69 deg, a part 0.0007 deg short of 360 deg.)"""
    g, a = ground, ratio * ground
    if kind == "parallelogram":
        case = FourBar(kind, g, a, g, a, start, side=side)
        pts = case.pts
        special = bool(np.linalg.norm((pts["C"] - pts["B"]) - (pts["D"] - pts["A"])) < 1e-9)
    else:
        case = FourBar(kind, g, a, a, g, start, side=side)
        special = bool(np.linalg.norm(case.pts["C"] - case.pts["A"]) < 1e-9)
    spec = tmp_path_factory.mktemp("pg") / "pg.toml"  # type: ignore[attr-defined]
    spec.write_text(case.mech.toml())
    trace = lw.trace(lw.load(str(spec)), until=("A", end * RAD), steps=1)
    assert trace.stats.unmet is None
    rows = np.degrees(np.asarray(trace.angles))
    np.testing.assert_allclose(rows[:, 0], [start, end], rtol=0.0, atol=1e-9)
    for r in rows:  # the rows, as before
        row = dict(zip("ABCD", r, strict=True))
        assert nearest(case.solve("A", row["A"]), row, list("ABCD"), set())[0] < 1e-9
    on_special = on_special_branch(case, kind, start, rows[-1])
    assert on_special == special, "the row went on along the other branch through a crossing"
    points = [np.degrees(b.angles) for b in trace.bifurcations]
    assert sorted(round(float(p[0]) % 360.0 / 180.0) % 2 for p in points) == [
        0,
        1,
    ]  # one at 0, one at 180 deg
    for p in points:
        assert four_pivots_in_line(case, float(p[0])) < 1e-7
        # the other joints against the closed form at the crossing's own reading, to the square root of round-off:
        # at a double point the circle intersection's discriminant is zero, and its round-off (and the located
        # reading's 1e-10 rad) moves the joints as its square root, 1e-6 deg
        row = dict(zip("ABCD", p, strict=True))
        exact = float(p[0]) - ((float(p[0]) + 90.0) % 180.0 - 90.0)
        assert nearest(case.solve("A", exact), row, list("BCD"), set())[0] < 1e-4
    assert {b.kind for b in trace.bifurcations} == {"bifurcation"}


# ---- properties: long paper steps where the drive nearly stops, against the adaptive path and the closed form


def wrapped_gap(a: np.ndarray, b: np.ndarray) -> float:
    """The largest difference (rad) between two rows of joint angles, modulo whole turns."""
    return float(np.max(np.abs(np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b)))))))


@settings(deadline=None, max_examples=8, derandomize=True)
@given(degrees=st.floats(40.0, 170.0), sign=st.sampled_from([1.0, -1.0]), steps=st.sampled_from([1, 2, 3]))
@example(
    degrees=70.0, sign=1.0, steps=1
)  # before: 19 of the 84 steps of 40, 50, ... 170 deg either way, in 1, 2
@example(degrees=140.0, sign=1.0, steps=2)  # or 3 steps, failed (every one upwards of 70 deg in one step, of
@example(degrees=170.0, sign=1.0, steps=1)  # 130 deg in two), though the adaptive trace reached each target
def test_long_paper_steps_of_the_goldberg_linkage_land_on_the_adaptive_path(
    tmp_path_factory: object, degrees: float, sign: float, steps: int
) -> None:
    """The audit's Goldberg 5R (other joints up to 435 times as fast as the drive A) in ``steps`` equal steps of A
    over up to 170 deg either way: wherever the adaptive trace reaches the target without a fold of A on the way,
    the paper trace does too, and each of its rows is the adaptive trace's point landed on that row's value of A,
    to 1e-10 rad."""
    spec = tmp_path_factory.mktemp("g") / "g.toml"  # type: ignore[attr-defined]
    spec.write_text(GOLDBERG)
    mech = lw.load(str(spec))
    start = float(mech.offsets[mech.index("A")])
    target = start + sign * degrees * RAD
    adaptive = lw.trace(mech, until=("A", target))
    if adaptive.stats.unmet is not None or adaptive.folds:
        return  # a fold of A before the target: equal steps of A end at its turning point (tested elsewhere)
    paper = lw.trace(mech, until=("A", target), steps=steps)
    assert paper.stats.unmet is None
    rows = np.asarray(paper.angles)
    np.testing.assert_allclose(rows[:, 0], np.linspace(start, target, steps + 1), rtol=0.0, atol=1e-12)
    for row in rows[1:]:
        landed = lw.trace(mech, until=("A", float(row[0])))
        assert landed.stats.unmet is None
        assert wrapped_gap(landed.angles[-1], row) < 1e-10


def bennett_partner(t1: np.ndarray, a1: float, a2: float) -> np.ndarray:
    """Bennett's relation ``tan(t1/2) tan(t2/2) = sin((a2 + a1)/2) / sin((a2 - a1)/2)`` solved for ``t2``
    (Bennett 1914), by ``atan2`` so that ``t1 = 0`` gives ``t2 = pi``."""
    k = np.sin((a2 + a1) / 2.0) / np.sin((a2 - a1) / 2.0)
    return 2.0 * np.arctan2(k * np.cos(t1 / 2.0), np.sin(t1 / 2.0))


def goldberg_readings(theta: np.ndarray, alpha: float, beta: float, gamma: float) -> np.ndarray:
    """Goldberg's 5R joint angles ``(5, n)`` at the first Bennett loop's angles ``theta`` (Goldberg 1943: two
    Bennett loops sharing the link of twist ``beta``, welded; ``linkages.goldberg``'s docstring), up to whole
    and half turns a mechanism's readings add."""
    t2 = bennett_partner(theta, alpha, beta)
    p1 = bennett_partner(t2, gamma, beta)
    return np.array([theta + np.pi - p1, t2, -theta, np.pi + p1, -t2])


def near_stop(seed: int) -> tuple[float, float, float, int, float, float, float]:
    """A Goldberg 5R and a stretch of its path along which joint ``j`` moves one way only, through a point where
    another joint moves at least 50 times as fast: ``(alpha, beta, gamma, j, theta_start, theta_end, theta_far)``
    (the first loop's angle at the start and at the end of the step; ``theta_far`` the end of the stretch)."""
    rng = np.random.default_rng(seed)
    theta = np.linspace(-np.pi, np.pi, 8001)
    while True:
        alpha, beta = np.radians(rng.uniform(15.0, 85.0)), np.radians(rng.uniform(50.0, 140.0))
        gamma = np.radians(rng.choice([-1.0, 1.0]) * rng.uniform(10.0, 70.0))
        if (
            min(
                abs(np.sin((beta - alpha) / 2)),
                abs(np.sin((beta - gamma) / 2)),
                abs(np.sin((alpha - gamma) / 2)),
            )
            < 0.05
        ):
            continue
        moves = np.diff(np.unwrap(goldberg_readings(theta, alpha, beta, gamma), axis=1), axis=1)
        fastest = np.abs(moves).max(axis=0)
        best = None
        for j in range(5):
            turns = np.flatnonzero(np.sign(moves[j][1:]) != np.sign(moves[j][:-1])) + 1
            ends = [0, *turns.tolist(), moves.shape[1]]
            for lo, hi in itertools.pairwise(ends):
                ratio = fastest[lo:hi] / np.maximum(np.abs(moves[j][lo:hi]), 1e-300)
                k = lo + int(np.argmax(ratio))
                if (
                    hi - lo >= 100
                    and 50.0 < ratio.max() < 5000.0
                    and lo + 0.1 * (hi - lo) < k < hi - 0.1 * (hi - lo)
                ):
                    if best is None or ratio.max() > best[0]:
                        best = (float(ratio.max()), j, lo, hi, k)
        if best is None:
            continue
        _, j, lo, hi, k = best
        i0 = lo + int(rng.uniform(0.02, 0.3) * (k - lo))
        i1 = k + int(rng.uniform(0.3, 0.95) * (hi - k))
        return alpha, beta, gamma, j, float(theta[i0]), float(theta[i1]), float(theta[hi - 1])


@settings(deadline=None, max_examples=6, derandomize=True)
@given(seed=st.integers(0, 2**31 - 1))
def test_one_paper_step_through_a_near_stop_of_the_drive_is_on_the_closed_form(seed: int) -> None:
    """Random Goldberg 5Rs driven by a joint over a stretch where another moves 50 to 5,000 times as fast, in one
    equal step: the row is the closed form's point at the target (its first loop's angle found by bisection on the
    stretch, where the drive is monotone) to 1e-9 rad, and the adaptive trace's point landed there to 1e-10 rad."""
    alpha, beta, gamma, j, th0, th1, th_far = near_stop(seed)
    mech = goldberg(alpha, beta, gamma, 1.0, th0)

    def drive_at(x: float) -> float:  # joint j's reading, continuous along the stretch from th0
        path = np.unwrap(goldberg_readings(np.linspace(th0, x, 4001), alpha, beta, gamma), axis=1)
        return float(mech.offsets[j] + path[j, -1] - path[j, 0])

    target = drive_at(th1)
    name = mech.joint_names[j]
    paper = lw.trace(mech, until=(name, target), steps=1)
    adaptive = lw.trace(mech, until=(name, target))
    assert adaptive.stats.unmet is None
    assert paper.stats.unmet is None
    x = brentq(lambda v: drive_at(v) - target, th0, th_far, xtol=1e-15)
    shift = np.asarray(mech.offsets, dtype=float) - goldberg_readings(np.array(th0), alpha, beta, gamma)
    reference = goldberg_readings(np.array(x), alpha, beta, gamma) + shift
    assert wrapped_gap(paper.angles[-1], reference) < 1e-9
    assert wrapped_gap(paper.angles[-1], adaptive.angles[-1]) < 1e-10


# ---- a paper row whose own drive value lands a hair from a crossing (found in session 17, closed in 18)


@pytest.mark.parametrize(("steps", "row"), [(3, 2), (100, 60)])
def test_a_paper_row_a_hair_short_of_a_crossing_stays_on_its_branch(
    tmp_path: Path, steps: int, row: int
) -> None:
    """The parallelogram 2 x 1 on its antiparallelogram branch (side 1) from 15 deg, in equal steps whose row
    ``row`` lands 1e-4 deg short of the crossing at 360 deg: the corrector holding the drive there meets both
    branches within the prediction's error, and the rows after it went on along the parallelogram branch (the last
    row 15 deg off the adaptive trace's for 3 steps, 100 deg for 100 steps; 1e-6 deg short as well, and 1e-2 deg
    in 3 steps; 1e-6 deg past the crossing they stay). The inner parts of a row are retaken where this happens (a
    part that turns next to a singular point); a row's own value is fixed, so that rule did not apply to it. Now
    the row's value is approached again from the same side in closing parts. Right answer: the start's branch to
    the end."""
    case = FourBar("parallelogram", 2.0, 1.0, 2.0, 1.0, 15.0, side=1)
    pts = case.pts
    assert (
        np.linalg.norm((pts["C"] - pts["B"]) - (pts["D"] - pts["A"])) > 1e-3
    )  # the antiparallelogram branch
    spec = tmp_path / "pg.toml"
    spec.write_text(case.mech.toml())
    end = 15.0 + steps * (345.0 - 1e-4) / row
    trace = lw.trace(lw.load(str(spec)), until=("A", end * RAD), steps=steps)
    assert trace.stats.unmet is None
    last = np.degrees(np.asarray(trace.angles))[-1]
    assert (
        nearest(case.solve("A", float(last[0])), dict(zip("ABCD", last, strict=True)), list("ABCD"), set())[0]
        < 1e-9
    )
    assert not on_special_branch(case, "parallelogram", 15.0, last)  # still the antiparallelogram


def test_one_long_row_a_hair_short_of_a_crossing_then_one_more_stays_on_its_branch(tmp_path: Path) -> None:
    """Found by the property below when its examples changed (hypothesis's derandomized seed follows the test's
    source; a strict expected failure in session 18, closed in 19): the parallelogram 2 x 1.59375 on its
    antiparallelogram branch (side 1) from 15 deg, one equal row of 345 deg landing 1e-6 deg short of the crossing
    at 360 deg, then one more: the last row (705 deg) was on the parallelogram branch. The row's last part landed
    on the crossing to round-off (``sigma_r / sigma_1`` 3.4e-7) with the SVD's null vector, any of a plane's
    there, turned 9.8 deg from the tangent it came in with: under ``max_turn``, so neither kept as the tangent
    nor approached again in closing parts, and the next row's first part, not judged (from a point whose tangent
    has no direction), went on along the other branch. Right answer: the start's branch to the end."""
    case = FourBar("parallelogram", 2.0, 2.0 * 0.796875, 2.0, 2.0 * 0.796875, 15.0, side=1)
    pts = case.pts
    assert np.linalg.norm((pts["C"] - pts["B"]) - (pts["D"] - pts["A"])) > 1e-3  # the antiparallelogram
    spec = tmp_path / "pg.toml"
    spec.write_text(case.mech.toml())
    step = 360.0 - 1e-6 - 15.0
    trace = lw.trace(lw.load(str(spec)), until=("A", (15.0 + 2 * step) * RAD), steps=2)
    assert trace.stats.unmet is None
    last = np.degrees(np.asarray(trace.angles))[-1]
    assert (
        nearest(case.solve("A", float(last[0])), dict(zip("ABCD", last, strict=True)), list("ABCD"), set())[0]
        < 1e-9
    )
    assert not on_special_branch(case, "parallelogram", 15.0, last)  # still the antiparallelogram


@settings(deadline=None, max_examples=12, derandomize=True)
@given(
    kind=st.sampled_from(["parallelogram", "deltoid"]),
    ground=st.floats(1.5, 4.0),
    ratio=st.floats(0.15, 0.8),
    start=st.floats(15.0, 165.0),
    side=st.sampled_from([0, 1]),
    crossing=st.sampled_from([180.0, 360.0]),
    before=st.integers(1, 12),
    after=st.integers(1, 12),
    exponent=st.floats(-7.0, -2.0),
    sign=st.sampled_from([1.0, -1.0, 0.0]),
)
@example(  # the strict expected failure's case above, 1e-4 deg short in 3 steps
    kind="parallelogram", ground=2.0, ratio=0.5, start=15.0, side=1, crossing=360.0, before=2, after=1,
    exponent=-4.0, sign=1.0,
)  # fmt: skip
@example(  # a row exactly on the crossing: the row is the bifurcation point (its tangent had no direction)
    kind="parallelogram", ground=2.0, ratio=0.5, start=15.0, side=1, crossing=360.0, before=2, after=1,
    exponent=-4.0, sign=0.0,
)  # fmt: skip
def test_a_paper_row_a_hair_from_a_crossing_keeps_the_starts_branch(
    tmp_path_factory: object,
    kind: str,
    ground: float,
    ratio: float,
    start: float,
    side: int,
    crossing: float,
    before: int,
    after: int,
    exponent: float,
    sign: float,
) -> None:
    """A parallelogram or a deltoid in equal steps whose row ``before`` lands ``sign * 10**exponent`` deg short of
    a crossing (the crank along the ground line, at 180 or 360 deg; negative: past it; 0: on it), and ``after``
    rows more: the last row is on the closed form, on the branch the start is on (:func:`on_special_branch`,
    the four-bar's closed form); a row on the crossing is a bifurcation point of the closed form, reported, and
    the row is that point."""
    g, a = ground, ratio * ground
    if kind == "parallelogram":
        case = FourBar(kind, g, a, g, a, start, side=side)
        pts = case.pts
        special = bool(np.linalg.norm((pts["C"] - pts["B"]) - (pts["D"] - pts["A"])) < 1e-9)
    else:
        case = FourBar(kind, g, a, a, g, start, side=side)
        special = bool(np.linalg.norm(case.pts["C"] - case.pts["A"]) < 1e-9)
    short = sign * 10.0**exponent
    step = (crossing - short - start) / before
    end = start + (before + after) * step
    assume(four_pivots_in_line(case, end) > 1.0)  # the last row's branch told apart by the closed form
    spec = tmp_path_factory.mktemp("near") / "near.toml"  # type: ignore[attr-defined]
    spec.write_text(case.mech.toml())
    trace = lw.trace(lw.load(str(spec)), until=("A", end * RAD), steps=before + after)
    assert trace.stats.unmet is None
    rows = np.degrees(np.asarray(trace.angles))
    assert len(rows) == before + after + 1
    np.testing.assert_allclose(rows[before, 0], crossing - short, rtol=0.0, atol=1e-9)
    last = dict(zip("ABCD", rows[-1], strict=True))
    assert nearest(case.solve("A", last["A"]), last, list("ABCD"), set())[0] < 1e-9
    assert on_special_branch(case, kind, start, rows[-1]) == special, "on along the other branch"
    if sign == 0.0:
        on_it = [
            np.degrees(b.angles)
            for b in trace.bifurcations
            if abs(float(np.degrees(b.angles[0])) - crossing) < 1e-9
        ]
        assert len(on_it) == 1 and four_pivots_in_line(case, float(on_it[0][0])) < 1e-9
        assert float(np.max(np.abs((rows[before] - on_it[0] + 180.0) % 360.0 - 180.0))) < 1e-9


# ---- long paper rows a hair from a crossing (found in session 18, closed in 19)


@settings(deadline=None, max_examples=150, derandomize=True)
@given(
    kind=st.sampled_from(["parallelogram", "deltoid"]),
    ground=st.floats(1.5, 4.0),
    ratio=st.floats(0.15, 0.8),
    side=st.sampled_from([0, 1]),
    crossing=st.sampled_from([180.0, 360.0]),
    before=st.integers(1, 2),
    row=st.floats(150.0, 350.0),
    exponent=st.floats(-9.0, -2.0),
    sign=st.sampled_from([1.0, -1.0]),
    after=st.integers(1, 3),
)
@example(  # the last part landed on the crossing to round-off, its SVD null vector turned 7.6 deg
    kind="deltoid", ground=3.7638, ratio=0.7718, side=1, crossing=360.0, before=1, row=151.58, exponent=-6.33,
    sign=1.0, after=1,
)  # fmt: skip
@example(  # 3e-8 deg past the crossing: the next row, retaken in 651 parts from that tangent, on the other branch
    kind="parallelogram", ground=3.5114, ratio=0.7917, side=1, crossing=360.0, before=1, row=323.35,
    exponent=-7.53, sign=-1.0, after=1,
)  # fmt: skip
@example(  # the row, a located crossing, stepped from in equal parts: one landed 2e-4 deg short of the next
    kind="parallelogram", ground=2.3511, ratio=0.5, side=1, crossing=180.0, before=2, row=192.0, exponent=-6.04,
    sign=1.0, after=1,
)  # fmt: skip
@example(
    kind="deltoid", ground=3.8377, ratio=0.7704, side=0, crossing=360.0, before=1, row=236.07, exponent=-5.55,
    sign=1.0, after=2,
)  # fmt: skip
def test_long_paper_rows_a_hair_from_a_crossing_keep_the_starts_branch(
    tmp_path_factory: object,
    kind: str,
    ground: float,
    ratio: float,
    side: int,
    crossing: float,
    before: int,
    row: float,
    exponent: float,
    sign: float,
    after: int,
) -> None:
    """A parallelogram or a deltoid in equal rows of ``row`` deg (150 to 350: 75 to 175 of the march's parts
    each), whose row ``before`` (1 or 2) lands ``sign * 10**exponent`` deg (1e-9 to 1e-2) short of a crossing (the
    crank along the ground line, at 180 or 360 deg, whole turns on; negative: past it), then ``after`` rows more:
    every row is at its drive value and the last is on the closed form, on the branch the start is on
    (:func:`on_special_branch`, the four-bar's closed form). The last row is kept 3 deg from a crossing, where
    the closed form tells the branches apart and paper rows meet it to 1e-9 deg (within 2 deg they are off by
    up to 2e-9 deg, in any number of rows, as before)."""
    short = sign * 10.0**exponent
    start = (crossing - short - before * row) % 360.0
    end = start + (before + after) * row
    g, a = ground, ratio * ground
    if kind == "parallelogram":
        case = FourBar(kind, g, a, g, a, start, side=side)
        pts = case.pts
        special = bool(np.linalg.norm((pts["C"] - pts["B"]) - (pts["D"] - pts["A"])) < 1e-9)
    else:
        case = FourBar(kind, g, a, a, g, start, side=side)
        special = bool(np.linalg.norm(case.pts["C"] - case.pts["A"]) < 1e-9)
    assume(four_pivots_in_line(case, start) > 1.0 and four_pivots_in_line(case, end) > 3.0)
    spec = tmp_path_factory.mktemp("long") / "long.toml"  # type: ignore[attr-defined]
    spec.write_text(case.mech.toml())
    trace = lw.trace(lw.load(str(spec)), until=("A", end * RAD), steps=before + after)
    assert trace.stats.unmet is None
    rows = np.degrees(np.asarray(trace.angles))
    assert len(rows) == before + after + 1
    np.testing.assert_allclose(rows[:, 0], start + row * np.arange(before + after + 1), rtol=0.0, atol=1e-9)
    assert abs(four_pivots_in_line(case, float(rows[before, 0])) - abs(short)) < 1e-10
    last = dict(zip("ABCD", rows[-1], strict=True))
    assert nearest(case.solve("A", last["A"]), last, list("ABCD"), set())[0] < 1e-9
    assert on_special_branch(case, kind, start, rows[-1]) == special, "on along the other branch"


def crossings_passed(start: float, end: float) -> int:
    """How many crank readings 180 deg + whole turns (a change-point four-bar's crossing, ``g + a = b + c``: the
    crank along the ground line away from the rocker's pivot, its four pivots in line) lie between two readings."""
    return int(np.floor((end - 180.0) / 360.0) - np.floor((start - 180.0) / 360.0))


@settings(deadline=None, max_examples=60, derandomize=True)
@given(
    ground=st.floats(1.5, 4.0),
    ratio=st.floats(0.15, 0.75),
    frac=st.floats(0.02, 0.98),
    side=st.sampled_from([0, 1]),
    before=st.integers(1, 2),
    row=st.floats(150.0, 350.0),
    exponent=st.floats(-9.0, -2.0),
    sign=st.sampled_from([1.0, -1.0]),
    after=st.integers(1, 3),
)
@example(
    ground=1.5827, ratio=0.2805, frac=0.4833, side=0, before=2, row=289.47, exponent=-8.88, sign=-1.0, after=2
)  # fmt: skip
@example(
    ground=1.5966, ratio=0.2249, frac=0.637, side=1, before=1, row=278.69, exponent=-8.09, sign=1.0, after=2
)  # fmt: skip
@example(
    ground=2.0184, ratio=0.6142, frac=0.288, side=1, before=1, row=323.4, exponent=-5.95, sign=1.0, after=3
)  # fmt: skip
def test_long_paper_rows_a_hair_from_a_change_point_keep_to_the_smooth_branch(
    tmp_path_factory: object,
    ground: float,
    ratio: float,
    frac: float,
    side: int,
    before: int,
    row: float,
    exponent: float,
    sign: float,
    after: int,
) -> None:
    """A change-point crank-rocker (ground ``g`` longest, crank ``a`` shortest, ``g + a = b + c``) in equal rows of
    ``row`` deg whose row ``before`` lands ``sign * 10**exponent`` deg short of its crossing at 180 deg (whole turns
    on), then ``after`` rows more. Its two branches cross there transversally, the two assembly modes (the two
    intersections of the coupler's and the rocker's circles) meeting, so the branch the rows follow changes
    assembly mode at every crossing it passes: the last row is the closed form's solution of the start's mode,
    changed once for each crossing passed. The row landed on the located crossing went on along the branch
    tangent nearest the tangent of the row before, a whole row back, instead of the one it came in with: 101 of
    498 random such traces (half of them a hair from 360 deg, no crossing) ended off the adaptive trace before,
    none after."""
    g, a = ground, ratio * ground
    b = a + frac * (g - a)
    c = g + a - b
    short = sign * 10.0**exponent
    start = (180.0 - short - before * row) % 360.0
    end = start + (before + after) * row
    case = FourBar("change-point", g, a, b, c, start, side=side)
    assume(four_pivots_in_line(case, start) > 1.0 and four_pivots_in_line(case, end) > 3.0)
    spec = tmp_path_factory.mktemp("change") / "change.toml"  # type: ignore[attr-defined]
    spec.write_text(case.mech.toml())
    trace = lw.trace(lw.load(str(spec)), until=("A", end * RAD), steps=before + after)
    assert trace.stats.unmet is None
    rows = np.degrees(np.asarray(trace.angles))
    assert len(rows) == before + after + 1
    np.testing.assert_allclose(rows[:, 0], start + row * np.arange(before + after + 1), rtol=0.0, atol=1e-9)
    last = dict(zip("ABCD", rows[-1], strict=True))
    off, mode = nearest(case.solve("A", last["A"]), last, list("ABCD"), set())
    assert off < 1e-9
    assert mode == (side + crossings_passed(start, end)) % 2, "on along the other branch"
