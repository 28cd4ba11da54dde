"""Every joint's range (issue 18, fifteenth round: "every joint's range is its swing"), checked against the law of
cosines written here, on the built-in ``four-bar`` (ground A-D = 2) as a crank-rocker: crank 1, coupler 2.5,
rocker 2. The rocker joint D's reading swings by the difference of the two angles at D where crank and coupler
line up (``|AC| = coupler +- crank``): 78.04133 deg.

A range is read from ``linkwork.kinematics.extremes.joint_ranges`` and from report.json (``branches[].range``).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import linkwork as lw
from linkwork.cli import app
from linkwork.kinematics.extremes import joint_ranges

GROUND, CRANK, COUPLER, ROCKER = 2.0, 1.0, 2.5, 2.0


def rocker_swing() -> float:
    """The rocker's swing (deg) by the law of cosines: its angles where crank and coupler line up."""
    ends = []
    for ac in (COUPLER + CRANK, COUPLER - CRANK):
        c = (ROCKER**2 + GROUND**2 - ac**2) / (2 * ROCKER * GROUND)
        ends.append(np.degrees(np.arccos(c)))
    return float(abs(ends[0] - ends[1]))


def crank_at_rocker_extreme() -> float:
    """The crank angle (deg) at which crank and coupler lie in line (|AC| = coupler + crank), above the ground
    line: the rocker's extreme there."""
    ac = COUPLER + CRANK
    return float(np.degrees(np.arccos((ac**2 + GROUND**2 - ROCKER**2) / (2 * ac * GROUND))))


def traced_swing(theta_deg: float, steps: int | None) -> tuple[float, float]:
    """(range's swing, rows' swing) of D in degrees, one full turn of the crank from ``theta_deg``."""
    mech = lw.load("four-bar", crank=CRANK, coupler=COUPLER, rocker=ROCKER, theta=np.radians(theta_deg))
    until = None if steps is None else ("A", np.radians(theta_deg + 360.0))
    trace = lw.trace(mech, drive="A", until=until, steps=steps)
    lo, hi = np.degrees(joint_ranges(trace, 0)["D"])
    rows = np.degrees(trace.angles[:, list(mech.joint_names).index("D")])
    return float(hi - lo), float(rows.max() - rows.min())


def test_the_reference_is_right() -> None:
    """The crank angle of the extended position is 28.955 deg (cos = 0.875) and the swing 78.041 deg."""
    assert abs(crank_at_rocker_extreme() - np.degrees(np.arccos(0.875))) < 1e-12
    assert abs(rocker_swing() - 78.04133) < 1e-5


@pytest.mark.parametrize(("theta", "steps"), [(60.0, None), (200.0, None), (60.0, 180), (28.0, None)])
def test_the_rockers_range_is_its_swing(theta: float, steps: int | None) -> None:
    """Holds: adaptive from 60, 200 and 28 deg and 2-deg paper steps from 60 deg: the swing to 1e-7 deg (measured
    4e-12), never narrower than the rows."""
    swing, rows = traced_swing(theta, steps)
    assert abs(swing - rocker_swing()) < 1e-7
    assert swing >= rows - 1e-12


@pytest.mark.parametrize("steps", [None, 180, 720])
@pytest.mark.parametrize("after", [-0.9, -0.545, -0.055, 0.055, 0.545, 1.0])
def test_an_extreme_next_to_the_seam_of_a_closed_path(after: float, steps: int | None) -> None:
    """Start the crank ``after`` deg from the rocker's extreme at 28.955 deg (negative: the extreme comes just
    after the start, positive: in the step that closes the turn), adaptive or in 2- and 0.5-deg paper steps.
    Got before the fix: swings short of the law of cosines by up to 3.7e-3 deg (adaptive, start 29.5) and 1.2e-2
    deg (180 steps, start 29.955), the rows' swing. Right: the swing to 1e-7 deg, as from any other start
    (measured after: 2.3e-11). Cause: kinematics/extremes.py joint_extremes compared consecutive increments only
    in the rows' order, never the last step of a path back at its start with the first, so a turning point next
    to the start had no sign change to bracket it. Fixed there: a branch that closes (or, in paper mode, ends a
    whole turn from its start) is looked at across that seam too."""
    swing, rows = traced_swing(crank_at_rocker_extreme() + after, steps)
    assert abs(swing - rocker_swing()) < 1e-7
    assert swing >= rows - 1e-12


@pytest.mark.parametrize("steps", [36, 12, 6, 4])
def test_the_rockers_range_in_long_paper_steps(steps: int) -> None:
    """Paper mode, one turn from 60 deg in 36, 12, 6 or 4 equal steps (10 to 90 deg): the swing to 1e-7 deg of
    the law of cosines. Was (with 36 and 12 steps): 0.0136 and 0.190 deg short (the rows' swing: 0.0252 and
    0.190), since kinematics/extremes.py skipped every bracket whose chord exceeded 0.5 rad; now a bracket up to
    a turn long is located, and a point kept only beyond its rows by less than the bracket's length."""
    swing, _ = traced_swing(60.0, steps)
    assert abs(swing - rocker_swing()) < 1e-7


def test_report_json_with_large_closure_tol_keeps_the_swing(tmp_path: Path) -> None:
    """Holds: with ``--closure-tol 1000`` (play accepted up to the bound's range) the report's range of D is still
    the law-of-cosines swing to 1e-7 deg and exit 0."""
    out = tmp_path / "t"
    args = ["trace", "four-bar", "--set", "crank=1", "--set", "coupler=2.5", "--set", "rocker=2"]
    result = CliRunner().invoke(app, [*args, "--closure-tol", "1000", "-o", str(out), "--no-plots"])
    assert result.exit_code == 0, result.output
    lo, hi = json.loads((out / "report.json").read_text())["branches"][0]["range"]["D"]
    assert abs((hi - lo) - rocker_swing()) < 1e-7
