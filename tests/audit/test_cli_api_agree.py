"""The command line without ``--closure-tol`` traces what ``lw.trace`` without ``closure_tol`` traces: the same
rows (path.csv to its printed digits) and the same bifurcation points (report.json), also for a linkage far from
the origin, where the tracer works in the linkage's own frame. Reference: the API's own trace of the same file,
and the parallelogram's change points at crank angles 180 and 360 deg (closed form).

Before, the command line always passed ``closure_tol=1e-12``, which the own frame reads as play of ``1e-12 / L``
(``L`` the linkage's length): an x1e3 parallelogram 1e4 sizes away had rows 3.8e-8 deg from the API's, and an
x1e-3 one 1e6 sizes away its first crossing 9e-8 deg from the API's (helper ``range19``'s note).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from audit_reference import FourBar, rot
from typer.testing import CliRunner

import linkwork as lw
from linkwork.cli import app


def motion(distance: float) -> np.ndarray:
    """A turn of 0.9 rad about z and a move ``distance`` away from the origin."""
    m = np.eye(4)
    m[:3, :3] = rot([0.0, 0.0, 1.0], 0.9)
    m[:3, 3] = [distance, -0.4 * distance, 0.0]
    return m


@pytest.mark.parametrize(("size", "far"), [(1e3, 1e4), (1e-3, 1e6), (1.0, 0.0)])
def test_the_command_line_traces_what_the_api_traces(tmp_path: Path, size: float, far: float) -> None:
    spec = tmp_path / "par.toml"
    spec.write_text(FourBar("par", 2.0, 1.0, 2.0, 1.0, 60.0).mech.toml(size, motion(far * size)))
    api = lw.trace(lw.load(str(spec)), drive="A")
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["trace", str(spec), "--drive", "A", "--no-plots", "-o", str(out)])
    assert result.exit_code == 0, result.output
    with (out / "path.csv").open() as fh:
        rows = np.array([[float(r[k]) for k in "ABCD"] for r in csv.DictReader(fh)])
    assert rows.shape == api.angles.shape
    np.testing.assert_allclose(rows, np.degrees(api.angles), rtol=0.0, atol=1e-10)
    report = json.loads((out / "report.json").read_text())
    cli_points = sorted(b["angles"]["A"] for b in report["bifurcations"])
    api_points = sorted(float(np.degrees(b.angles[0])) for b in api.bifurcations)
    np.testing.assert_allclose(cli_points, api_points, rtol=0.0, atol=1e-9)
    np.testing.assert_allclose(cli_points, [180.0, 360.0], rtol=0.0, atol=1e-6)


def test_a_given_closure_tolerance_is_still_play(tmp_path: Path) -> None:
    """``--closure-tol 1e-6`` given is still passed on: report.json states it, as ``lw.trace(...,
    closure_tol=1e-6)``'s stats do."""
    out = tmp_path / "out"
    args = ["trace", "four-bar", "--set", "ground=2.0000001", "--set", "crank=1", "--set", "coupler=2"]
    args += ["--set", "rocker=1", "--closure-tol", "1e-6", "--no-plots", "-o", str(out)]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    assert json.loads((out / "report.json").read_text())["closure_tol"] == pytest.approx(1e-6)
