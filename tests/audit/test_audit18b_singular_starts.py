"""Starts at singular points (issue 18, fifteenth round, helper ``fix18``), against closed forms written here.

* The built-in ``four-bar`` (ground A-D = 2) with crank 1, coupler 2, rocker 1 is a parallelogram; laid flat
  (theta = 0) it sits on its change point, where the parallelogram branch (readings ``B = -A``, ``C = D = A``)
  crosses the antiparallelogram. At crank 90 deg the antiparallelogram's C is (1.2, -0.6) (the second root of
  ``|C - B| = 2``, ``|C - D| = 1`` with B = (0, 1), D = (2, 0)): coupler at -53.130 deg, rocker at -143.130 deg,
  so B = coupler - crank = -143.130, C = rocker - coupler = -90, D = rocker = -143.130 deg.
* The built-in ``slider-crank`` with no offset (crank 1, rod 3) at its dead centres theta = 0 (D = 4) and 180
  (D = 2), driven by the slider to D = 3: ``3 = cos A + sqrt(9 - sin^2 A)`` gives ``cos A = 1/6``.
* A four-bar laid straight with crank + coupler + rocker = ground (0.5 + 1 + 0.5 = 2) is an isolated point.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from linkwork.cli import app

FLAT_PARALLELOGRAM = [
    "trace",
    "four-bar",
    "--set",
    "crank=1",
    "--set",
    "coupler=2",
    "--set",
    "rocker=1",
    "--set",
    "theta=0",
]


def antiparallelogram_at_90() -> dict[str, float]:
    """The antiparallelogram's readings (deg) at crank 90 deg, from the circle intersection written above."""
    b, d = np.array([0.0, 1.0]), np.array([2.0, 0.0])
    # |C - B|^2 = 4 and |C - D|^2 = 1 subtract to y = 2x - 3; then 5x^2 - 16x + 12 = 0
    roots = np.roots([5.0, -16.0, 12.0])
    x = float(roots[np.argmin(np.abs(roots - 1.2))])
    c = np.array([x, 2 * x - 3])
    coupler = np.degrees(np.arctan2(*(c - b)[::-1]))
    rocker = np.degrees(np.arctan2(*(c - d)[::-1]))
    return {"B": coupler - 90.0, "C": rocker - coupler, "D": rocker}


def run(tmp_path: Path, base: list[str], *args: str) -> tuple[int, str, Path]:
    out = tmp_path / "o"
    result = CliRunner().invoke(app, [*base, *args, "-o", str(out), "--no-plots"])
    return result.exit_code, result.output, out


def rows_of(out: Path) -> list[dict[str, str]]:
    with (out / "path.csv").open() as fh:
        return list(csv.DictReader(fh))


@pytest.mark.parametrize("target", [90.0, -90.0, 135.0])
@pytest.mark.parametrize("steps", [["--steps", "1"], ["--steps", "3"], []])
def test_flat_parallelogram_traced_from_its_crossing(tmp_path: Path, target: float, steps: list[str]) -> None:
    """Holds: from the change point, either way, in 1 or 3 equal steps or adaptive: exit 0, point 0 a bifurcation
    at A = 0, every row of branch 0 on the parallelogram (B = -A, C = D = A) to 1e-9 deg, the target reached."""
    code, output, out = run(tmp_path, FLAT_PARALLELOGRAM, "--until", f"A={target:g}", *steps)
    assert code == 0, output
    report = json.loads((out / "report.json").read_text())
    first = report["bifurcations"][0]
    assert first["step"] == 0 and abs(first["angles"]["A"]) < 1e-9
    rows = [r for r in rows_of(out) if r["branch"] == "0"]
    a = np.array([float(r["A"]) for r in rows])
    for name, sign in (("B", -1.0), ("C", 1.0), ("D", 1.0)):
        assert np.max(np.abs(np.array([float(r[name]) for r in rows]) - sign * a)) < 1e-9
    assert abs(a[-1] - target) < 1e-9


@pytest.mark.parametrize("steps", [["--steps", "9"], []])
def test_flat_parallelogram_with_branches_reaches_the_antiparallelogram(
    tmp_path: Path, steps: list[str]
) -> None:
    """Holds: with ``--branches`` to A = 90, a branch that leaves the start ends on the target on the
    antiparallelogram, its readings the circle intersection's to 1e-9 deg; every row of every branch is on one of
    the two closed-form branches (the parallelogram, or the antiparallelogram's C with the coupler and rocker
    angles from the circles) to 1e-7 deg."""
    code, output, out = run(tmp_path, FLAT_PARALLELOGRAM, "--branches", "--until", "A=90", *steps)
    assert code == 0, output
    rows = rows_of(out)
    ends = {}
    for r in rows:
        ends[r["branch"]] = r
    ref = antiparallelogram_at_90()
    anti = [
        r for r in ends.values() if abs(float(r["A"]) - 90.0) < 1e-9 and abs(float(r["C"]) - ref["C"]) < 1e-6
    ]
    assert anti, "no branch reached A = 90 on the antiparallelogram"
    for r in anti:
        for name in "BCD":
            assert abs(float(r[name]) - ref[name]) < 1e-9
    for r in rows:
        a = np.radians(float(r["A"]))
        b = np.array([np.cos(a), np.sin(a)])
        rocker = np.radians(float(r["D"]))
        c = np.array([2.0, 0.0]) + np.array([np.cos(rocker), np.sin(rocker)])
        # the loop closes: the coupler's length and its direction (crank + B) both as read
        coupler = np.radians(float(r["A"]) + float(r["B"]))
        assert abs(np.linalg.norm(c - b) - 2.0) < 1e-7
        assert np.allclose(c - b, 2.0 * np.array([np.cos(coupler), np.sin(coupler)]), atol=1e-7)


@pytest.mark.parametrize("theta", [0.0, 180.0])
@pytest.mark.parametrize("steps", [["--steps", "1"], ["--steps", "4"], []])
def test_slider_crank_driven_by_the_slider_from_a_dead_centre(
    tmp_path: Path, theta: float, steps: list[str]
) -> None:
    """Holds: from either dead centre, the slider driven to D = 3 in 1 or 4 equal steps or adaptive: exit 0, no
    fold reported at the start, the crank at ``arccos(1/6)`` = 80.4059 deg (or 360 - that from 180) to 1e-9 deg,
    every row's slider ``cos A + sqrt(9 - sin^2 A)`` to 1e-9."""
    base = ["trace", "slider-crank", "--set", "crank=1", "--set", "rod=3", "--set", "offset=0"]
    code, output, out = run(
        tmp_path, [*base, "--set", f"theta={theta:g}"], "--drive", "D", "--until", "D=3", *steps
    )
    assert code == 0, output
    report = json.loads((out / "report.json").read_text())
    assert all(f["step"] > 0 for f in report["folds"])
    rows = rows_of(out)
    a = np.radians([float(r["A"]) for r in rows])
    d = np.array([float(r["D"]) for r in rows])
    assert np.max(np.abs(np.cos(a) + np.sqrt(9.0 - np.sin(a) ** 2) - d)) < 1e-9
    ref = np.degrees(np.arccos(1.0 / 6.0))
    assert abs(float(rows[-1]["A"]) % 360.0 - (ref if theta == 0.0 else 360.0 - ref)) < 1e-9


def test_a_four_bar_laid_straight_is_refused(tmp_path: Path) -> None:
    """Holds: crank 0.5, coupler 1, rocker 0.5 on ground 2, laid straight: exit 2, one error line, nothing
    written."""
    base = [
        "trace",
        "four-bar",
        "--set",
        "crank=0.5",
        "--set",
        "coupler=1",
        "--set",
        "rocker=0.5",
        "--set",
        "theta=0",
    ]
    code, output, out = run(tmp_path, base)
    assert code == 2
    errors = [line for line in output.splitlines() if line.startswith("error:")]
    assert len(errors) == 1 and "rigid" in errors[0]
    assert not out.exists()
