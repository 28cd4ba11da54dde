"""A four-bar started at a fold of its rocker and driven by the rocker (issue 18, fifteenth round: starts at a
fold of the drive). Crank-rocker on the built-in ``four-bar`` (ground A-D = 2, crank 1, coupler 2.5, rocker 2)
with the crank at ``arccos(0.875)`` = 28.955 deg: crank and coupler in line, the rocker at its least reading
57.910 deg (law of cosines). The rocker's reading at D is the direction of D->C from the x axis (180 deg less
the angle ADC), so ``C = (2 + 2 cos D, 2 sin D)`` and the crank's B = (cos A, sin A) must lie 2.5 from it.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from linkwork.cli import app

THETA = float(np.degrees(np.arccos(0.875)))


def coupler_length(a_deg: np.ndarray, d_deg: np.ndarray) -> np.ndarray:
    """|B - C| for crank reading A and rocker reading D (deg): 2.5 on the loop."""
    a, d = np.radians(a_deg), np.radians(d_deg)
    b = np.stack([np.cos(a), np.sin(a)], axis=-1)
    c = np.stack([2.0 + 2.0 * np.cos(d), 2.0 * np.sin(d)], axis=-1)
    return np.linalg.norm(b - c, axis=-1)


def test_the_start_is_the_rockers_least_reading() -> None:
    """The reference: at the start the loop closes and D = 57.910 deg is the law of cosines' least reading."""
    d_min = 180.0 - np.degrees(np.arccos((4.0 + 4.0 - 3.5**2) / 8.0))
    assert abs(coupler_length(np.array(THETA), np.array(d_min)) - 2.5) < 1e-12
    assert abs(d_min - 57.910048743719699) < 1e-9


@pytest.mark.parametrize("steps", [["--steps", "1"], ["--steps", "2"], ["--steps", "5"], []])
def test_driven_by_the_rocker_from_its_fold(tmp_path: Path, steps: list[str]) -> None:
    """Holds: from the fold, D driven to 70 deg in 1, 2, 5 equal steps or adaptive: exit 0, no fold reported at
    the start, every row on the loop (coupler 2.5 to 1e-9), D = 70 at the end, and A there the closed form's
    root on the side where the crank increases (68.157445706 deg, "the first unknown that moves increases",
    tracer._start_direction) to 1e-9 deg in every mode."""
    out = tmp_path / "o"
    args = ["trace", "four-bar", "--set", "crank=1", "--set", "coupler=2.5", "--set", "rocker=2"]
    args += ["--set", f"theta={THETA!r}", "--drive", "D", "--until", "D=70", *steps]
    result = CliRunner().invoke(app, [*args, "-o", str(out), "--no-plots"])
    assert result.exit_code == 0, result.output
    report = json.loads((out / "report.json").read_text())
    assert report["folds"] == []
    with (out / "path.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    a = np.array([float(r["A"]) for r in rows])
    d = np.array([float(r["D"]) for r in rows])
    assert np.max(np.abs(coupler_length(a, d) - 2.5)) < 1e-9
    assert abs(d[-1] - 70.0) < 1e-9
    roots = []
    for s in (1.0, -1.0):
        c = np.array([2.0 + 2.0 * np.cos(np.radians(70.0)), 2.0 * np.sin(np.radians(70.0))])
        # |B|=1, |B-C|=2.5: B . C = (1 + |C|^2 - 6.25) / 2
        k = (1.0 + c @ c - 6.25) / 2.0
        base = np.arctan2(c[1], c[0])
        roots.append(np.degrees(base + s * np.arccos(k / np.linalg.norm(c))))
    # the two roots (68.157 and 1.843 deg) meet at the fold; the start leaves with A increasing (tracer's rule)
    assert abs(a[-1] - max(roots)) < 1e-9
