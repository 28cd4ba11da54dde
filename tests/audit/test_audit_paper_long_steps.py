"""Paper mode (equal drive steps) towards a target past a fold of the drive, with steps far longer than the probe
that looks for the fold: the trace ends at the located turning point, with the range the closed form gives,
whatever the step length.

References (no linkwork): the four-bar's rocker extremes where crank and coupler are in line (circle
intersection, ``FourBar.fold_refs``), the offset slider-crank's slider extremes ``sqrt((l +- r)^2 - e^2)``, and
the spherical four-bar's input extremes where coupler and output are in line (the spherical law of cosines).

Was: with 1 to 7 steps, 258 of 600 crank-rocker and slider-crank cases (random start angles and targets) ended
'corrector failed at a fixed drive step', no fold, range only the start (e.g. the crank-rocker below, 3 steps of
-80 deg from 0 towards -240 deg: its fold at -36.64 deg was beyond the probe's 60 adaptive steps, the crank
turning several times as far as the rocker).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from audit_reference import FourBar, SliderCrank, Spherical4R
from typer.testing import CliRunner

import linkwork as lw
from linkwork.cli import app

RAD = np.pi / 180.0
ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")

#: The located fold against the closed form: Tolerances.locate (1e-10) with margin, degrees or lengths.
FOLD_TOL = 1e-7


def spherical_input_extremes(g: float, a: float, b: float, c: float, theta0: float) -> list[float]:
    """Input readings (deg) where the spherical four-bar's coupler and output lie in one great circle.

    ``Spherical4R`` puts the input axis on z, the ground axis ``g`` from it at azimuth 0 and the input's moving
    axis ``a`` from it at azimuth ``theta - 90`` (``theta`` the input reading). The angle between the two moving
    axes is then, by the spherical law of cosines, ``cos x = cos a cos g + sin a sin g sin theta``; the input is
    at an extreme where ``x = b + c`` or ``|b - c|``."""
    g, a, b, c = np.radians([g, a, b, c])
    out = []
    for x in (b + c, abs(b - c)):
        s = (np.cos(x) - np.cos(a) * np.cos(g)) / (np.sin(a) * np.sin(g))
        if abs(s) <= 1.0:
            root = float(np.degrees(np.arcsin(s)))
            out += [root, 180.0 - root, root - 360.0, 180.0 - root - 360.0]
    return out


def load(tmp_path: Path, text: str) -> lw.Mechanism:
    spec = tmp_path / "mech.toml"
    spec.write_text(text)
    return lw.load(str(spec))


# name: (spec text, drive, reading at the start, closed-form extremes, targets past them, unit: deg or 1)
CROCKER = FourBar("crank-rocker", 4.0, 1.3, 3.7, 2.9, 100.0)
SLIDER = SliderCrank("offset-slider-crank", 1.0, 3.0, 0.4, 100.0)
SPHERE = Spherical4R("spherical-4r", 50.0, 75.0, 40.0, 60.0, 30.0)  # non-Grashof: the input rocks
CASES = {
    "crank-rocker at the rocker": (CROCKER.mech.toml(), "D", 0.0, CROCKER.fold_refs("D"), (-240.0, 240.0), RAD),
    "slider-crank at the slider": (SLIDER.mech.toml(), "D", SLIDER.x0, SLIDER.fold_refs("D"), (-3.0, 10.0), 1.0),
    "spherical 4R at the input": (
        SPHERE.toml(), "A", 30.0, spherical_input_extremes(50.0, 75.0, 40.0, 60.0, 30.0), (-240.0, 240.0), RAD,
    ),
}  # fmt: skip


def expected_extreme(start: float, extremes: list[float], target: float) -> float:
    """The first closed-form extreme met from ``start`` going towards ``target``."""
    ahead = [x for x in extremes if (x - start) * (target - start) > 0.0]
    return min(ahead, key=lambda x: abs(x - start))


@pytest.mark.parametrize("steps", [1, 2, 3, 7])
@pytest.mark.parametrize("side", [0, 1], ids=["down", "up"])
@pytest.mark.parametrize("name", sorted(CASES))
def test_long_equal_steps_past_a_fold_end_at_its_turning_point(
    tmp_path: Path, name: str, side: int, steps: int
) -> None:
    text, drive, start, extremes, targets, unit = CASES[name]
    mech = load(tmp_path, text)
    target = targets[side]
    fold = expected_extreme(start, extremes, target)
    trace = lw.trace(mech, drive=drive, until=(drive, target * unit), steps=steps)
    branch = trace.branches[0]
    assert branch.end_kind == lw.StopReason.TURNING, branch.end_reason
    assert [f.value / unit for f in trace.folds] == [pytest.approx(fold, abs=FOLD_TOL)]
    # The line a user reads names the range from the start to the closed form's extreme, as with short steps.
    lo, hi = sorted([start, fold])
    if unit == RAD:
        span = f"[{lo:.2f}, {hi:.2f}] deg"
        shown = f"{target:.2f} deg"
    else:
        span = f"[{lo:.6g}, {hi:.6g}]"
        shown = f"{target:.6g}"
    assert trace.stats.unmet is not None
    assert trace.stats.unmet.startswith(f"{drive} never reaches {shown} on this path (it turns back near ")
    assert trace.stats.unmet.endswith(f": its range is {span}")
    # Every row is still one of the equal steps, on the path (the closed form solves each drive reading).
    values = trace.angles[:, mech.index(drive)] / unit
    np.testing.assert_allclose(values, start + (target - start) / steps * np.arange(len(values)), atol=1e-9)


TRIPLE = FourBar("triple-rocker", 4.0, 2.0, 3.5, 2.4, 20.0)  # its input A rocks in [-157.76, 157.76] deg


GAP_CASES = {
    # 20 -> 85 -> 150 -> 215: the last step, 65 deg, lands beyond the gap (157.76, 202.24) (= -145 deg)
    "triple rocker, 3 x 65 deg": (TRIPLE.mech.toml(), "A", 20.0, TRIPLE.fold_refs("A"), 215.0, 3),
    # one step of 340 deg (= -20 deg, inside the range) from 0
    "crank-rocker, 1 x 340 deg": (CROCKER.mech.toml(), "D", 0.0, CROCKER.fold_refs("D"), 340.0, 1),
    # one step of 330 deg (= 0 deg, inside the range) from 30
    "spherical 4R, 1 x 330 deg": (SPHERE.toml(), "A", 30.0, CASES["spherical 4R at the input"][3], 360.0, 1),
}


@pytest.mark.parametrize("name", sorted(GAP_CASES))
def test_a_long_step_across_the_gap_beyond_a_fold_is_not_a_reached_target(tmp_path: Path, name: str) -> None:
    """A step that would land past the range's gap, where the drive's value comes round again, meets the fold as
    short steps do. Was: 'reached target', the last row on the other side of the gap (the four-bars: in closed
    form and by the predictor-corrector alike)."""
    text, drive, start, extremes, target, steps = GAP_CASES[name]
    trace = lw.trace(load(tmp_path, text), drive=drive, until=(drive, target * RAD), steps=steps)
    assert trace.branches[0].end_kind == lw.StopReason.TURNING, (name, trace.branches[0].end_reason)
    fold = expected_extreme(start, extremes, target)
    assert [np.degrees(f.value) for f in trace.folds] == [pytest.approx(fold, abs=FOLD_TOL)]


def test_the_command_line_exits_3_at_the_turning_point_of_three_long_steps(tmp_path: Path) -> None:
    """``linkwork trace --steps 3 --until D=-240`` of the crank-rocker driven at its rocker: 80-deg steps."""
    spec = tmp_path / "crank-rocker.toml"
    spec.write_text(CROCKER.mech.toml())
    args = ["trace", str(spec), "--drive", "D", "--steps", "3", "--until", "D=-240", "--no-plots"]
    result = CliRunner().invoke(app, [*args, "--out", str(tmp_path / "out")])
    assert result.exit_code == 3, result.stderr
    lines = [ln for ln in ANSI.sub("", result.stderr).strip().splitlines() if not ln.startswith("note:")]
    fold = expected_extreme(0.0, CROCKER.fold_refs("D"), -240.0)
    assert lines == [
        f"error: D never reaches -240.00 deg on this path (it turns back near {fold:.2f} deg): its range is "
        f"[{fold:.2f}, 0.00] deg"
    ]
