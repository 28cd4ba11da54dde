"""Drawings at the user's scale: ``units`` in a problem file sets the DXF ``$INSUNITS`` and the SVG's true width
and height, and ``linkwork export dxf`` draws a planar mechanism's links and pivots where the closed form puts
them, both read back with ezdxf."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from typer.testing import CliRunner

from linkwork.cli import app
from linkwork.data import example
from linkwork.io.problem import load_problem

runner = CliRunner()
MM, INCH = 4, 1  # $INSUNITS codes of the DXF reference (AutoCAD DXF Reference, HEADER section)


@pytest.fixture(scope="module")
def closed_in_mm(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("closed")
    source = example("closed").parent
    for f in source.iterdir():
        shutil.copy(f, folder / f.name)
    problem = folder / "problem.toml"
    problem.write_text(problem.read_text() + 'units = "mm"\n')
    return problem


def test_problem_units_reach_dxf_and_svg(closed_in_mm: Path, tmp_path: Path) -> None:
    assert load_problem(closed_in_mm).units == "mm"
    out = tmp_path / "out"
    result = runner.invoke(app, ["synth", str(closed_in_mm), "--no-plots", "--out", str(out)])
    assert result.exit_code == 0, result.stderr
    document = ezdxf.readfile(out / "outline.dxf")
    assert document.header["$INSUNITS"] == MM and document.units == MM
    svg = (out / "outline.svg").read_text()
    m = re.search(r'width="([0-9.e+-]+)mm" height="([0-9.e+-]+)mm" viewBox="\S+ \S+ (\S+) (\S+)"', svg)
    assert m is not None
    # one profile unit is one millimetre on paper: the drawing's size equals its viewBox, in mm
    np.testing.assert_allclose([float(m[1]), float(m[2])], [float(m[3]), float(m[4])], rtol=1e-5)


def test_unknown_unit_is_a_one_line_error(closed_in_mm: Path, tmp_path: Path) -> None:
    bad = closed_in_mm.parent / "bad.toml"
    bad.write_text(closed_in_mm.read_text().replace('units = "mm"', 'units = "furlong"'))
    result = runner.invoke(app, ["synth", str(bad), "--no-plots", "--out", str(tmp_path / "o")])
    assert result.exit_code == 2 and "units" in result.stderr and result.stderr.count("\n") == 1


def test_mechanism_dxf_links_and_pivots_at_the_closed_form(tmp_path: Path) -> None:
    out = tmp_path / "four_bar.dxf"
    args = ["export", "dxf", "four-bar", "--set", "theta=30", "--units", "in", "-o", str(out)]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.stderr
    document = ezdxf.readfile(out)
    assert document.header["$INSUNITS"] == INCH
    space = document.modelspace()
    centres = sorted((round(c.dxf.center.x, 9), round(c.dxf.center.y, 9)) for c in space.query("CIRCLE"))
    # the default four-bar: ground 2, crank 1, coupler 2.5, rocker 2; at crank angle 30 deg, B by the crank and C
    # by the law of cosines in triangle B C D (open circuit, C above the ground line)
    b = np.array([np.cos(np.radians(30.0)), np.sin(np.radians(30.0))])
    f = np.linalg.norm(np.array([2.0, 0.0]) - b)
    beta = np.arccos((2.0**2 + f**2 - 2.5**2) / (2 * 2.0 * f))
    gamma = np.arctan2(b[1], b[0] - 2.0)
    c = np.array([2.0, 0.0]) + 2.0 * np.array([np.cos(gamma - beta), np.sin(gamma - beta)])
    expected = sorted((round(x, 9), round(y, 9)) for x, y in [(0.0, 0.0), tuple(b), tuple(c), (2.0, 0.0)])
    np.testing.assert_allclose(centres, expected, atol=1e-8)
    ground = [e for e in space.query("LWPOLYLINE") if e.dxf.layer == "ground"]
    assert len(ground) == 1
    pts = np.array(ground[0].get_points("xy"))
    assert np.isclose(np.linalg.norm(pts[1] - pts[0]), 2.0, atol=1e-12)  # the ground link's length


def test_spatial_mechanism_has_no_dxf(tmp_path: Path) -> None:
    result = runner.invoke(app, ["export", "dxf", "bennett", "-o", str(tmp_path / "b.dxf")])
    assert result.exit_code == 2 and "planar" in result.stderr
    assert not (tmp_path / "b.dxf").exists()
