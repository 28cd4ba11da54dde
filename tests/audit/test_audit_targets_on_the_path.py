"""Targets (``until``) on the path that an adaptive trace stepped over or went round the wrong way to, checked
against the audit's own references (``audit_reference``): a four-bar's circle intersections, Goldberg's 5R from
its two Bennett loops' closed form, and a generic 7R's closure by the audit's own product of exponentials.

Got, before the fixes (compiled kernels):

* a target a hair short of where an adaptive step landed was stepped over: the tangent's prediction fell short of
  it, so the step was not shortened to land on it, and the corrector (on the hyperplane normal to the tangent,
  where the path curves on) carried the drive past it; the path went on and the target was never reached. With
  targets a thousandth of a step short of each row's drive value, 30 of 91 missed on a crank-rocker's crank, 51
  of 133 on a Goldberg 5R, 50 of 182 on a Bennett loop; a random target of a Goldberg 5R, 334.560794143 deg,
  missed: 'A never reaches 334.56 deg on this path: its range is [-11.10, 348.90] deg'.
* a generic 7R whose joint B turns one way at first and by a whole turn the other way round the loop: the trace
  to B = -410.347 (exactly one turn below the start, -50.347) or to -300 deg, both inside the range the free
  trace reports ([-548.58, -49.13] deg), set off with B moving down, closed having turned B a whole turn up, and
  said 'B never reaches -410.35 deg on this path: its range is [-188.58, 310.87] deg'.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from audit_reference import FourBar, Goldberg, Mech, nearest, wrap_deg

import linkwork as lw

RAD = np.pi / 180.0


def load(tmp_path: Path, name: str, text: str) -> lw.Mechanism:
    spec = tmp_path / f"{name}.toml"
    spec.write_text(text)
    return lw.load(str(spec))


def targets_short_of_rows(values: np.ndarray, every: int) -> list[float]:
    """A thousandth of a step short of every ``every``-th row's drive value, while the drive moves one way from
    the start (so each target is on the path, before the drive turns back)."""
    out = []
    steps = np.diff(values)
    for i in range(1, len(values) - 1, every):
        if np.any(np.sign(steps[:i]) != np.sign(steps[i - 1])):
            break
        out.append(float(values[i] - 1e-3 * steps[i - 1]))
    return out


def landed_rows(mech: lw.Mechanism) -> list[tuple[float, np.ndarray]]:
    """``(target, last row in degrees)`` of an adaptive trace of ``mech`` to each target a thousandth of a step short
    of every sixth row of its free trace (more than 40): each reached, A exactly on it."""
    free = np.degrees(np.asarray(lw.trace(mech).angles))
    targets = targets_short_of_rows(free[:, 0], every=6)
    assert len(targets) > 40
    out = []
    for target in targets:
        trace = lw.trace(mech, until=("A", target * RAD))
        assert trace.stats.unmet is None, trace.stats.unmet
        last = np.degrees(np.asarray(trace.angles)[-1])
        assert last[0] == pytest.approx(target, abs=1e-10)
        out.append((target, last))
    return out


def test_targets_a_crank_rocker_steps_near_are_landed_on(tmp_path: Path) -> None:
    """Every target on the crank's first turn is reached, exactly, on the circle intersections."""
    case = FourBar("crank-rocker", 4.0, 1.3, 3.7, 2.9, 35.0)
    for target, last in landed_rows(load(tmp_path, "cr", case.mech.toml())):
        err, _ = nearest(case.solve("A", target), dict(zip("ABCD", last, strict=True)), list("ABCD"), set())
        assert err < 1e-9


def test_targets_a_goldberg_linkage_steps_near_are_landed_on(tmp_path: Path) -> None:
    """Goldberg 5R (two Bennett loops 40/100 and 70/100 deg): every target of A's first turn reached exactly,
    the last row on both Bennett loops' closed form (delta = -B)."""
    case = Goldberg("goldberg-audit", 1.0, 40.0, 100.0, 70.0, 50.0, 30.0)
    for _target, last in landed_rows(load(tmp_path, "gb", case.toml())):
        assert np.max(np.abs(wrap_deg(case.predict(-last[1]) - last))) < 1e-9


#: A generic 7R (hinge lines rounded to three decimals: seven lines close at the start by construction).
SEVEN_R = [
    ((-0.84, -0.859, -0.324), (0.934, -0.345, 0.094), -121.65),
    ((-0.57, 0.977, -0.301), (-0.559, -0.063, -0.827), -50.347),
    ((0.731, 0.684, -0.705), (0.942, 0.203, 0.266), 123.965),
    ((-0.908, -0.4, -0.736), (0.075, -0.939, 0.335), -5.819),
    ((-0.563, -0.202, 0.803), (0.392, 0.828, 0.401), 14.091),
    ((0.985, -0.332, -0.781), (0.294, -0.551, 0.781), -75.195),
    ((0.484, 0.533, -0.784), (0.915, -0.304, -0.265), 17.967),
]


def seven_r() -> Mech:
    joints = [
        dict(name=n, bodies=[f"L{(i - 1) % 7}", f"L{i}"], point=list(p), direction=list(d), value=v)
        for i, (n, (p, d, v)) in enumerate(zip("ABCDEFG", SEVEN_R, strict=True))
    ]
    return Mech("seven-r", joints, planar=False, root="L6")


@pytest.mark.parametrize("placed", [False, True], ids=["as-written", "x1000-moved"])
def test_a_target_round_a_closed_path_the_other_way_is_reached(tmp_path: Path, placed: bool) -> None:
    """B first moves up and turns a whole turn down round the loop: targets below the start inside the free
    trace's range (one turn below the start, a hair above that, and further round) are reached exactly, on a
    row that closes (the audit's product of exponentials) with numpy's singular values."""
    case = seven_r()
    motion = np.eye(4)
    if placed:
        c, s = np.cos(2.1), np.sin(2.1)
        motion[:3, :3] = [[c, -s, 0.0], [s * 0.6, c * 0.6, -0.8], [s * 0.8, c * 0.8, 0.6]]
        motion[:3, 3] = [120.0, -40.0, 70.0]
    mech = load(tmp_path, "r7", case.toml(scale=1000.0 if placed else 1.0, motion=motion))
    free = lw.trace(mech, drive="B")
    b = np.degrees(np.asarray(free.angles)[:, 1])
    start = b[0]
    assert free.branches[0].end_kind == lw.StopReason.CLOSED
    assert b[1] > start and b[-1] == pytest.approx(start - 360.0, abs=1e-9)
    for target in (start - 360.0, start - 360.0 + 1e-9, -300.0, b.min() + 1e-6):
        assert b.min() <= target <= b.max()
        trace = lw.trace(mech, drive="B", until=("B", target * RAD))
        assert trace.stats.unmet is None, (target, trace.stats.unmet)
        last = np.degrees(np.asarray(trace.angles)[-1])
        assert last[1] == pytest.approx(target, abs=1e-9)
        reference = seven_r()  # in the unit and place the audit wrote it: the same joint values
        row = dict(zip(reference.names, last, strict=True))
        assert reference.poses(row)[1] < 1e-11
        if not placed:
            s_ref = np.linalg.svd(reference.jacobian(row), compute_uv=False)
            sig = np.asarray(trace.sigma)[-1]
            assert np.max(np.abs(sig - s_ref[: sig.shape[0]])) < 1e-11 * s_ref[0]


#: Four-bars whose links all lie on the ground line with the crank at 180 deg: a crossing of two branches there
#: (Grashof's change point; the parallelogram also crosses at 0 deg). (ground, crank, coupler, rocker, start).
CROSSING_AT_180 = {
    "parallelogram": (3.0, 1.0, 3.0, 1.0, 30.0),
    "change-point": (4.0, 1.5, 3.0, 2.5, 60.0),
}


@pytest.mark.parametrize("name", sorted(CROSSING_AT_180))
def test_the_step_landing_on_a_target_past_a_crossing_reports_it(tmp_path: Path, name: str) -> None:
    """The last step, the one that lands on the target, passes the crossing at A = 180 deg: the crossing is
    reported (at the closed form's point: A = 180 deg, every link on the ground line) and the target reached.

    Got: no bifurcation (the landing step ended the march before its sign change of the test function was
    looked at), in paper mode (one or two equal steps from the start to 190 or 210 deg) and adaptively."""
    dims = CROSSING_AT_180[name]
    case = FourBar(name, *dims)
    mech = load(tmp_path, name, case.mech.toml())
    free = np.degrees(np.asarray(lw.trace(mech).angles)[:, 0])
    i = int(np.flatnonzero((free[:-1] < 180.0) & (free[1:] > 180.0))[0])
    adaptive_target = 180.0 + 0.5 * (free[i + 1] - 180.0)  # within the step that crosses
    for target, steps in ((190.0, 1), (210.0, 2), (adaptive_target, None)):
        trace = lw.trace(mech, until=("A", target * RAD), steps=steps)
        assert trace.stats.unmet is None
        assert np.degrees(trace.angles[-1, 0]) == pytest.approx(target, abs=1e-10)
        assert len(trace.bifurcations) == 1, (target, steps)
        at = np.degrees(np.asarray(trace.bifurcations[0].angles))
        row = dict(zip("ABCD", at, strict=True))
        assert row["A"] == pytest.approx(180.0, abs=1e-7)
        err, _ = nearest(case.solve("A", 180.0), row, list("ABCD"), set())
        assert err < 1e-6  # degrees: a crossing located to Tolerances.locate, a double root's square root off
        for r in np.degrees(np.asarray(trace.angles)):
            err, _ = nearest(case.solve("A", r[0]), dict(zip("ABCD", r, strict=True)), list("ABCD"), set())
            assert err < 1e-8


def _moved_spatial(case: FourBar, scale: float) -> str:
    """The four-bar as a spatial [mechanism] (its hinges still parallel), lengths times ``scale``, turned and moved."""
    g = np.eye(4)
    c, s = np.cos(0.7), np.sin(0.7)
    g[:3, :3] = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]) @ np.array(
        [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    )
    g[:3, 3] = [40.0, -25.0, 60.0]
    return case.mech.toml(scale=scale, motion=g).replace("planar = true", "planar = false")


@pytest.mark.parametrize("variant", ["planar", "x1000", "spatial-moved"])
def test_equal_steps_in_parts_across_a_parallelogram_crossing_stay_on_it(
    tmp_path: Path, variant: str
) -> None:
    """A parallelogram (ground = coupler 2.5, crank = rocker 1) driven from 50 to 410 deg in 18 equal steps of
    20 deg, each taken in parts no longer than max_step (2 deg): every row on the parallelogram's own closed form
    (coupler translating: B = -(A - 50), C = A - 50, D = -(A - 50)), both crossings (A = 180 and 360 deg)
    reported, the target reached.

    Got: the parts of 170 -> 190 deg met the crossing at 180 exactly, where the tangent has no direction: as
    written, 'drive turning point' at 170 deg (the drive never turns back) and the target unmet; x1000 and moved
    in space, the path went on along the other branch (the anti-parallelogram) at 190 deg, one crossing reported."""
    case = FourBar("parallelogram", 2.5, 1.0, 2.5, 1.0, 50.0)
    text = {
        "planar": case.mech.toml(),
        "x1000": case.mech.toml(scale=1000.0),
        "spatial-moved": _moved_spatial(case, 1.0),
    }[variant]
    trace = lw.trace(load(tmp_path, "pg", text), until=("A", 410.0 * RAD), steps=18)
    assert trace.stats.unmet is None, trace.stats.unmet
    rows = np.degrees(np.asarray(trace.angles))
    np.testing.assert_allclose(rows[:, 0], np.linspace(50.0, 410.0, 19), rtol=0.0, atol=1e-9)
    turned = rows[:, 0] - 50.0
    expected = np.column_stack([rows[:, 0], -turned, turned, -turned])
    assert np.max(np.abs(wrap_deg(rows - expected))) < 1e-9
    crossings = sorted(float(np.degrees(b.angles[0])) % 360.0 for b in trace.bifurcations)
    assert len(crossings) == 2
    assert min(crossings[0], 360.0 - crossings[-1]) < 1e-7  # A = 0 (mod 360)
    assert 180.0 in [pytest.approx(c, abs=1e-7) for c in crossings]


def test_one_equal_step_across_a_change_point_crossing(tmp_path: Path) -> None:
    """Grashof's change-point four-bar (4, 1.5, 3, 2.5) from 60 to 190 deg in one step (65 parts of 2 deg, one
    of them at the crossing at 180 deg in the equal division): reached, on the closed form, the crossing reported.

    Got: 'corrector failed at a fixed drive step', range [60, 60] (the part at 180 failed, and so did every
    retake in twice as many parts, which met 180 exactly again)."""
    case = FourBar("change-point", 4.0, 1.5, 3.0, 2.5, 60.0)
    trace = lw.trace(load(tmp_path, "cp", case.mech.toml()), until=("A", 190.0 * RAD), steps=1)
    assert trace.stats.unmet is None, trace.stats.unmet
    for r in np.degrees(np.asarray(trace.angles)):
        err, _ = nearest(case.solve("A", r[0]), dict(zip("ABCD", r, strict=True)), list("ABCD"), set())
        assert err < 1e-9
    assert [np.degrees(b.angles[0]) for b in trace.bifurcations] == [pytest.approx(180.0, abs=1e-7)]
