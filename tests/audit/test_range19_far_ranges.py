"""Located turning points, folds and bifurcation points of linkages far from the origin and of any size, against
closed forms written here (helper ``range19``).

- Offset slider-crank (crank r = 1, rod l = 3, offset e = 0.7): the slider's ends where crank and rod lie in line,
  ``x = sqrt((l +- r)^2 - e^2)``.
- Crank-rocker four-bar (ground 2, crank 1, coupler 2.5, rocker 2): the rocker turns back where crank and coupler
  lie in line, ``|AC| = coupler +- crank``; its angle at D by the law of cosines,
  ``cos D = (rocker^2 + ground^2 - AC^2) / (2 rocker ground)``.
- Spherical crank-rocker (arcs ground 60, crank 20, coupler 55, rocker 45 deg): the same with the spherical law of
  cosines, ``cos D = (cos AC - cos g cos c) / (sin g sin c)``.
- Parallelogram (ground 2, crank 1, coupler 2, rocker 1): its change points at crank angles 0 and 180 deg.

Each is written x ``size`` (1e-3, 1, 1e3) and moved ``far`` sizes from the origin (1 to 1e6; the spherical one 1e8
lengths) and turned (``audit_reference.Mech.toml``). Values to 1e-9 of the crank (lengths) or 1e-9 rad (angles).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from audit_reference import FourBar, SliderCrank, Spherical4R, rot
from typer.testing import CliRunner

import linkwork as lw
from linkwork.cli import app
from linkwork.kinematics.extremes import joint_ranges

R, L, E = 1.0, 3.0, 0.7
GROUND, CRANK, COUPLER, ROCKER = 2.0, 1.0, 2.5, 2.0
SG, SA, SB, SC = 60.0, 20.0, 55.0, 45.0
SIZES = [1e-3, 1.0, 1e3]
DISTANCES = [1.0, 1e2, 1e4, 1e6]
TOL = 1e-9


def motion(distance: float) -> np.ndarray:
    """A turn of 0.9 rad about z and a move ``distance`` (in the file's unit) away from the origin."""
    g = np.eye(4)
    g[:3, :3] = rot([0.0, 0.0, 1.0], 0.9)
    g[:3, 3] = [distance, -0.4 * distance, 0.0]
    return g


def slider_ends() -> tuple[float, float]:
    """The slider's stroke ends (unit size): crank and rod folded, and stretched, in line."""
    return float(np.sqrt((L - R) ** 2 - E**2)), float(np.sqrt((L + R) ** 2 - E**2))


def rocker_angles_at_d() -> tuple[float, float]:
    """The four-bar's interior angle at D (rad) where crank and coupler are stretched and folded in line."""

    def at_d(ac: float) -> float:
        return float(np.arccos((ROCKER**2 + GROUND**2 - ac**2) / (2 * ROCKER * GROUND)))

    return at_d(COUPLER + CRANK), at_d(COUPLER - CRANK)


def spherical_angles_at_d() -> tuple[float, float]:
    """The spherical crank-rocker's dihedral angle at D (rad) where crank and coupler lie on one great circle."""
    g, c = np.radians(SG), np.radians(SC)

    def at_d(ac: float) -> float:
        return float(np.arccos((np.cos(np.radians(ac)) - np.cos(g) * np.cos(c)) / (np.sin(g) * np.sin(c))))

    return at_d(SB + SA), at_d(SB - SA)


def written(tmp_path: Path, text: str, name: str) -> lw.Mechanism:
    """A spec file of the audit's mechanism (its ``toml`` text), loaded."""
    spec = tmp_path / name
    spec.write_text(text)
    return lw.load(str(spec))


def test_the_references_are_right() -> None:
    """The closed forms against numbers worked by hand: the slider's stroke ends 1.8735 and 3.9383, the rocker's
    swing 78.041 deg (crank-rocker: stretched AC = 3.5 gives cos D = -0.53125), the spherical swing 58.392 deg."""
    lo, hi = slider_ends()
    assert abs(lo - np.sqrt(3.51)) < 1e-15 and abs(hi - np.sqrt(15.51)) < 1e-15
    stretched, folded = rocker_angles_at_d()
    assert abs(np.cos(stretched) + 0.53125) < 1e-15
    assert abs(np.degrees(stretched - folded) - 78.04133) < 1e-5
    s_stretched, s_folded = spherical_angles_at_d()
    assert abs(np.degrees(s_stretched - s_folded) - 58.39179) < 1e-5


@pytest.mark.parametrize("steps", [None, 180])
@pytest.mark.parametrize("far", DISTANCES)
@pytest.mark.parametrize("size", SIZES)
def test_a_sliders_range_far_away_is_its_stroke(
    tmp_path: Path, size: float, far: float, steps: int | None
) -> None:
    """The slider's range, crank driven a turn (adaptive, or 2-deg paper steps), is its stroke to 1e-9 of the
    crank (measured after: up to 8.7e-11 at 1e6 sizes, 1.4e-12 nearer). Before: 7.7e-8 (x 1e3, 1e2 sizes away)
    and the rows' stroke, 3.1e-5 short, once the linkage stood 1e6 of the file's units away or more (the points
    were located in the raw frame, not in the linkage's own frame where the tracer traced the rows)."""
    lo_ref, hi_ref = slider_ends()
    mech = written(tmp_path, SliderCrank("sc", R, L, E, 40.0).mech.toml(size, motion(far * size)), "sc.toml")
    until = None if steps is None else ("A", np.radians(400.0))
    trace = lw.trace(mech, drive="A", until=until, steps=steps)
    lo, hi = joint_ranges(trace, 0)["D"]
    assert abs(lo - lo_ref * size) < TOL * R * size
    assert abs(hi - hi_ref * size) < TOL * R * size


@pytest.mark.parametrize("steps", [None, 180])
@pytest.mark.parametrize("far", DISTANCES)
@pytest.mark.parametrize("size", SIZES)
def test_a_rockers_range_far_away_is_its_swing(
    tmp_path: Path, size: float, far: float, steps: int | None
) -> None:
    """The rocker's range, crank driven a turn: its ends at the readings of D where crank and coupler lie in
    line (the audit's ``FourBar.fold_refs``, the circles' intersections) and its swing by the law of cosines, to
    1e-9 rad (measured after: 5e-11 rad at 1e6 sizes). Before: the rows' swing, 7.2e-4 deg short adaptive and
    1.2e-2 deg in 2-deg steps, from 1e6 of the file's units away."""
    four_bar = FourBar("fb", GROUND, CRANK, COUPLER, ROCKER, 60.0)
    mech = written(tmp_path, four_bar.mech.toml(size, motion(far * size)), "fb.toml")
    until = None if steps is None else ("A", np.radians(420.0))
    trace = lw.trace(mech, drive="A", until=until, steps=steps)
    lo, hi = joint_ranges(trace, 0)["D"]
    stretched, folded = rocker_angles_at_d()
    assert abs((hi - lo) - abs(stretched - folded)) < TOL
    ends = np.radians(four_bar.fold_refs("D"))
    for value in (lo, hi):
        assert np.min(np.abs((ends - value + np.pi) % (2 * np.pi) - np.pi)) < TOL


@pytest.mark.parametrize("steps", [None, 180])
@pytest.mark.parametrize("far", [1e2, 1e4, 1e6, 1e8])
def test_a_spherical_rockers_range_far_away_is_its_swing(
    tmp_path: Path, far: float, steps: int | None
) -> None:
    """A spherical crank-rocker (hinge lines through one point: its own length is the file's unit) moved ``far``
    and turned about a skew axis: the rocker's swing by the spherical law of cosines to 1e-9 rad (measured
    after: 2.3e-11 deg). Before: the rows' swing (7.6e-4 deg short adaptive, 2.5e-3 in 2-deg steps) from 1e6 away;
    at 1e8 also after locating on the linkage's own frame, until a turning point's tangent was read with the
    tracer's rank test (there its zero singular value reads 2.4e-9 of the largest, above the fixed 1e-10 level
    used before)."""
    g = np.eye(4)
    g[:3, :3] = rot([0.3, 0.5, 0.8], 0.7)
    g[:3, 3] = [far, -0.4 * far, 0.3 * far]
    mech = written(tmp_path, Spherical4R("sph", SG, SA, SB, SC, 30.0).toml(motion=g), "sph.toml")
    until = None if steps is None else ("A", np.radians(390.0))
    trace = lw.trace(mech, drive="A", until=until, steps=steps)
    lo, hi = joint_ranges(trace, 0)["D"]
    stretched, folded = spherical_angles_at_d()
    assert abs((hi - lo) - abs(stretched - folded)) < TOL


@pytest.mark.parametrize("far", DISTANCES)
@pytest.mark.parametrize("size", SIZES)
def test_the_folds_of_a_far_linkage_driven_by_its_slider_and_its_rocker(
    tmp_path: Path, size: float, far: float
) -> None:
    """``Trace.folds`` (where the drive turns back) driven by the slider: its stroke's ends to 1e-9 of the crank;
    driven by the rocker: D at the readings where crank and coupler lie in line, to 1e-9 rad (measured 8.7e-11
    of the crank and 5e-11 rad at 1e6 sizes). These held before too: the tracer locates its folds in the
    linkage's own frame."""
    lo_ref, hi_ref = slider_ends()
    slider = written(
        tmp_path, SliderCrank("sc", R, L, E, 40.0).mech.toml(size, motion(far * size)), "sc.toml"
    )
    folds = sorted(float(f.value) for f in lw.trace(slider, drive="D").folds)
    assert len(folds) == 2
    assert abs(folds[0] - lo_ref * size) < TOL * R * size and abs(folds[1] - hi_ref * size) < TOL * R * size
    four_bar = FourBar("fb", GROUND, CRANK, COUPLER, ROCKER, 60.0)
    rocker = written(tmp_path, four_bar.mech.toml(size, motion(far * size)), "fb.toml")
    values = [float(f.value) for f in lw.trace(rocker, drive="D").folds]
    ends = np.radians(four_bar.fold_refs("D"))
    assert len(values) == 2
    for value in values:
        assert np.min(np.abs((ends - value + np.pi) % (2 * np.pi) - np.pi)) < TOL


@pytest.mark.parametrize(("size", "far"), [(1e3, 1e4), (1e-3, 1e6), (1.0, 1e6)])
def test_report_json_of_a_far_linkage_has_its_folds_and_range(
    tmp_path: Path, size: float, far: float
) -> None:
    """report.json of ``linkwork trace`` (file units: lengths, degrees): the slider driven, its folds at the
    stroke's ends to 1e-9 of the crank; the crank driven, the slider's range the stroke to 1e-9 of the crank.
    Before: the range was the rows' stroke (x 1e3 at 1e7 and x 1 at 1e6 away)."""
    lo_ref, hi_ref = slider_ends()
    spec = tmp_path / "sc.toml"
    spec.write_text(SliderCrank("sc", R, L, E, 40.0).mech.toml(size, motion(far * size)))
    for drive in ("D", "A"):
        out = tmp_path / drive
        result = CliRunner().invoke(app, ["trace", str(spec), "--drive", drive, "--no-plots", "-o", str(out)])
        assert result.exit_code == 0, result.output
        report = json.loads((out / "report.json").read_text())
        if drive == "D":
            folds = sorted(f["value"] for f in report["folds"])
            assert len(folds) == 2
            assert abs(folds[0] - lo_ref * size) < TOL * size and abs(folds[1] - hi_ref * size) < TOL * size
        else:
            lo, hi = report["branches"][0]["range"]["D"]
            assert abs(lo - lo_ref * size) < TOL * size and abs(hi - hi_ref * size) < TOL * size


@pytest.mark.parametrize("far", DISTANCES)
@pytest.mark.parametrize("size", SIZES)
def test_a_far_parallelograms_change_points(tmp_path: Path, size: float, far: float) -> None:
    """A parallelogram's crank turned once from 60 deg: two bifurcation points, at crank angles 180 and 360 deg
    (not a turn or more away: on the branch's own rows), each within its reported accuracy plus 1e-9 rad (the
    file's coordinates hold the shape to 2e-10 of its size at 1e6 sizes away; measured 5e-11 rad there, 2.7e-9
    rad with an accuracy of 1.1e-8 for the x 1e-3 one), through the API and in report.json. Before: report.json
    of the x 1e-3 one 1e6 sizes away put the second point at 77040 deg (214 turns off: a trial of the locator
    the corrector could not close was kept as the bracket's end, kinematics/bifurcation.py ``locate``)."""
    spec = tmp_path / "par.toml"
    spec.write_text(FourBar("par", 2.0, 1.0, 2.0, 1.0, 60.0).mech.toml(size, motion(far * size)))
    trace = lw.trace(lw.load(str(spec)), drive="A")
    points = [(float(b.angles[0]), float(b.bracket)) for b in trace.bifurcations]
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["trace", str(spec), "--drive", "A", "--no-plots", "-o", str(out)])
    assert result.exit_code == 0, result.output
    report = json.loads((out / "report.json").read_text())
    points_cli = [(np.radians(b["angles"]["A"]), b["accuracy"]) for b in report["bifurcations"]]
    for found in (points, points_cli):
        assert len(found) == 2
        for (value, accuracy), ref in zip(sorted(found), (np.pi, 2 * np.pi), strict=True):
            assert abs(value - ref) < TOL + accuracy
