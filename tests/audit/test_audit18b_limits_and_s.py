"""Limits met by the step that lands on the target, and path.csv's ``s`` with a slider, on the built-in
``slider-crank`` (crank 1, rod 3, offset 0.5, start 30 deg), against its closed form written here: the rod's angle
``phi`` with ``sin phi = (offset - crank sin A) / rod``, the slider ``D = crank cos A + rod cos phi``, the joint
readings ``B = phi - A`` and ``C = -phi`` (degrees, matching the start's rows: B = -30, C = 0 at A = 30).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq
from typer.testing import CliRunner

from linkwork.cli import app

CRANK, ROD, OFFSET, START = 1.0, 3.0, 0.5, 30.0
SLIDER_CRANK = [
    "trace",
    "slider-crank",
    "--set",
    f"crank={CRANK}",
    "--set",
    f"rod={ROD}",
    "--set",
    f"offset={OFFSET}",
    "--set",
    f"theta={START}",
]


def slider(a_deg: float) -> float:
    """The slider's position D at crank angle ``a_deg`` (closed form)."""
    a = np.radians(a_deg)
    phi = np.arcsin((OFFSET - CRANK * np.sin(a)) / ROD)
    return float(CRANK * np.cos(a) + ROD * np.cos(phi))


def file_speed(a: float) -> float:
    """|d(A, B, C in degrees; D in length)/dA| at crank angle ``a`` (radians): the integrand of ``s``."""
    phi = np.arcsin((OFFSET - CRANK * np.sin(a)) / ROD)
    dphi = -CRANK * np.cos(a) / (ROD * np.cos(phi))
    d_d = -CRANK * np.sin(a) - ROD * np.sin(phi) * dphi
    k = np.degrees(1.0)
    return float(np.sqrt(k**2 + (k * (dphi - 1.0)) ** 2 + (k * dphi) ** 2 + d_d**2))


def run(tmp_path: Path, *args: str) -> tuple[int, dict, list[dict[str, str]]]:
    out = tmp_path / "o"
    result = CliRunner().invoke(app, [*SLIDER_CRANK, *args, "-o", str(out), "--no-plots"])
    report = json.loads((out / "report.json").read_text())
    with (out / "path.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    return result.exit_code, report, rows


def test_the_closed_form_matches_the_start() -> None:
    """The reference's slider at the start: 1 cos 30 + 3 = 3.8660254."""
    assert abs(slider(START) - (np.cos(np.radians(30)) + 3.0)) < 1e-15


@pytest.mark.parametrize("steps", [["--steps", "1"], ["--steps", "3"], []])
def test_a_slider_limit_crossed_by_the_landing_step(tmp_path: Path, steps: list[str]) -> None:
    """Holds: the crank driven to 120 deg (D = 2.4776 there) with ``--limit D=2.6:5``, in 1, 3 equal steps or
    adaptive: exit 3, the branch ends 'limit' on D = 2.6, and A there is the closed form's root of D(A) = 2.6
    (measured 111.660890216853 deg, to 1e-9)."""
    code, report, rows = run(tmp_path, "--until", "A=120", *steps, "--limit", "D=2.6:5")
    assert code == 3
    branch = report["branches"][0]
    assert branch["end_kind"] == "limit" and branch["end_joint"] == "D"
    a_ref = brentq(lambda a: slider(a) - 2.6, 90.0, 120.0, xtol=1e-13)
    assert abs(float(rows[-1]["D"]) - 2.6) < 1e-9
    assert abs(float(rows[-1]["A"]) - a_ref) < 1e-9


@pytest.mark.parametrize("steps", [["--steps", "2"], []])
def test_a_prismatic_limit_equal_to_the_target_is_reached(tmp_path: Path, steps: list[str]) -> None:
    """Holds: the slider driven to D = 2.5 with ``--limit D=2.5:5``: exit 0, target reached, A the closed form's
    root (118.417958 deg) to 1e-9."""
    code, report, rows = run(tmp_path, "--drive", "D", "--until", "D=2.5", *steps, "--limit", "D=2.5:5")
    assert code == 0
    assert report["branches"][0]["end_kind"] == "target"
    a_ref = brentq(lambda a: slider(a) - 2.5, 90.0, 150.0, xtol=1e-13)
    assert abs(float(rows[-1]["A"]) - a_ref) < 1e-9


@pytest.mark.parametrize("steps", [["--steps", "2"], []])
def test_a_revolute_limit_crossed_by_a_slider_driven_landing(tmp_path: Path, steps: list[str]) -> None:
    """Holds: the slider driven to D = 2.5 with ``--limit A=0:100``: exit 3, the branch ends on A = 100 with D the
    closed form's D(100) to 1e-9."""
    code, report, rows = run(tmp_path, "--drive", "D", "--until", "D=2.5", *steps, "--limit", "A=0:100")
    assert code == 3
    assert report["branches"][0]["end_joint"] == "A"
    assert abs(float(rows[-1]["A"]) - 100.0) < 1e-9
    assert abs(float(rows[-1]["D"]) - slider(100.0)) < 1e-9


def reference_s() -> float:
    """The arclength from A = 30 to 120 deg in file units (degrees for A, B, C; length for D), by quadrature."""
    return float(quad(file_speed, np.radians(START), np.radians(120.0), epsabs=1e-12)[0])


def test_s_adaptive_is_the_arclength_in_file_units(tmp_path: Path) -> None:
    """Holds: adaptive to A = 120: the last ``s`` is the quadrature's 133.33901 to 1e-3 (measured 1.7e-4 short,
    the rows' chords)."""
    code, _, rows = run(tmp_path, "--until", "A=120")
    assert code == 0
    assert abs(float(rows[-1]["s"]) - reference_s()) < 1e-3


@pytest.mark.parametrize("steps", ["1", "3"])
def test_s_in_long_paper_steps_is_the_arclength_in_file_units(tmp_path: Path, steps: str) -> None:
    """The same end point in 1 or 3 equal steps: the last ``s`` is the quadrature's 133.339 to 1e-3 (measured
    133.33861 both, 4e-4 short: the chords of the rows' parts, no longer than max_step of the drive).

    Was (audit18b): 133.638 (1 step) and 133.454 (3 steps), an ``s`` that depended on the step count: each row's
    internal arclength rescaled by one chord ratio ``|du_file| / |du|``, exact only where the direction in the
    unknowns is constant over the row, while a long paper row's parts turn. Fixed (s19): the march sums its
    parts' chords in file units too (``Trace.arclength_in_file_units``)."""
    _, _, rows = run(tmp_path, "--until", "A=120", "--steps", steps)
    assert abs(float(rows[-1]["s"]) - reference_s()) < 1e-3
