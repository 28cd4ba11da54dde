"""A profile file that carries a z coordinate is a curve in space: read as its x and y only where it lies in a
plane z = constant, refused with one line (file, line or entity, what was expected) where z varies, in every
format that can carry a z (CSV's z column, DXF's 3-D POLYLINE and SPLINE), and from the command line (exit 2).

The reference is the curve written into the file: a circle, flat or climbing ``z = rise * x``.

Was: a CSV's z column was ignored (a climbing helix read as its circle, exit 0), and so was a DXF SPLINE's z.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from typer.testing import CliRunner

from linkwork.cli import app
from linkwork.errors import SpecError
from linkwork.io.profiles import load_profile

ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")
ROUND_TRIP = 1e-12  # coordinates written with repr(): read back to round-off

CIRCLE = np.array([(math.cos(t * math.pi / 30), math.sin(t * math.pi / 30)) for t in range(40)])


def csv_text(points: np.ndarray, z: np.ndarray, header: str | None) -> str:
    """The points and their z as CSV rows (each number as Python's repr: read back exactly)."""
    cells = [(repr(float(x)), repr(float(y)), repr(float(h))) for (x, y), h in zip(points, z, strict=True)]
    if header == "z,x,y":  # the columns in another order
        cells = [(h, x, y) for x, y, h in cells]
    rows = [",".join(row) for row in cells]
    return "\n".join(([header] if header else []) + rows) + "\n"


def one_line_error(path: Path) -> str:
    with pytest.raises(SpecError) as info:
        load_profile(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{path}: ")
    return message


@pytest.mark.parametrize("header", ["x,y,z", "z,x,y", "X,Y,Z,note", None])
@pytest.mark.parametrize("height", [0.0, 5.0, -1e3])
def test_a_csv_z_column_that_is_constant_is_dropped(
    tmp_path: Path, header: str | None, height: float
) -> None:
    path = tmp_path / "flat.csv"
    text = csv_text(CIRCLE, np.full(len(CIRCLE), height), header)
    if header == "X,Y,Z,note":
        text = "\n".join(line + (",note" if i else "") for i, line in enumerate(text.splitlines())) + "\n"
    path.write_text(text, encoding="utf-8")
    np.testing.assert_allclose(load_profile(path), CIRCLE, rtol=0, atol=ROUND_TRIP)


@pytest.mark.parametrize("rise", [0.1, 1e-6, -2.0])
@pytest.mark.parametrize(("header", "column"), [("x,y,z", "z"), ("z,x,y", "z"), (None, "3 (z)")])
def test_a_csv_z_column_that_varies_is_refused_naming_the_line(
    tmp_path: Path, rise: float, header: str | None, column: str
) -> None:
    """The circle climbing z = rise * x: its first point is at x = 1, every later one lower or higher."""
    path = tmp_path / "climbing.csv"
    z = rise * CIRCLE[:, 0]
    path.write_text(csv_text(CIRCLE, z, header), encoding="utf-8")
    message = one_line_error(path)
    first = 2 if header else 1  # the file's line of the first point
    # The first point off the first point's plane (by more than 1e-9 of the curve's size, here 1) is the second.
    assert abs(z[1] - z[0]) > 1e-9
    assert (
        f"line {first + 1}: column {column} is {float(z[1])!r}, but line {first} has {float(z[0])!r}"
        in message
    )
    assert message.endswith("expected a profile drawn in a plane z = constant (a constant z column is dropped: x "
                            "and y are the profile)")  # fmt: skip


def test_a_z_within_round_off_of_its_plane_is_that_plane(tmp_path: Path) -> None:
    """A z column off by 1e-12 of the curve's size (a CAD export's round-off) is the plane z = 2."""
    path = tmp_path / "roundoff.csv"
    z = 2.0 + 1e-12 * np.sin(np.arange(len(CIRCLE)))
    path.write_text(csv_text(CIRCLE, z, "x,y,z"), encoding="utf-8")
    np.testing.assert_allclose(load_profile(path), CIRCLE, rtol=0, atol=ROUND_TRIP)


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        ("x,y,z\n0,0,1\n1,0,\n1,1,1\n", "line 3: expected a number in column z, got '' in '1,0,'"),
        ("x,y,z,Z\n0,0,1,1\n1,0,1,1\n", "names column z 2 times; expected one x and one y column (and at most one z)"),
        ("0,0,0\n1,0,abc\n", "line 2: expected a number in column 3 (z), got 'abc'"),
    ],
)  # fmt: skip
def test_a_csv_z_column_must_be_numbers(tmp_path: Path, content: str, expected: str) -> None:
    path = tmp_path / "bad.csv"
    path.write_text(content, encoding="utf-8")
    assert expected in one_line_error(path)


def test_a_selig_file_with_a_third_number_is_refused(tmp_path: Path) -> None:
    """Selig files are x y pairs: a z is not dropped silently there either (refused, constant or not)."""
    path = tmp_path / "foil.dat"
    path.write_text("foil\n" + "".join(f"{x!r} {y!r} 0.0\n" for x, y in CIRCLE.tolist()), encoding="utf-8")
    assert "line 2: expected two numbers 'x y'" in one_line_error(path)


@pytest.mark.parametrize("rise", [0.1, 1e-3, -2.0])
def test_a_dxf_spline_leaving_its_plane_is_refused_and_a_flat_one_read(tmp_path: Path, rise: float) -> None:
    """A clamped quadratic B-spline with control points (0, 0) (1, 2) (2, 0) is the parabola y = x (2 - x):
    climbing (z = rise * x at its control points), refused; in the plane z = 5, read onto the parabola."""
    control = [(0.0, 0.0), (1.0, 2.0), (2.0, 0.0)]
    climbing = tmp_path / "climbing.dxf"
    document = ezdxf.new()
    document.modelspace().add_open_spline([(x, y, rise * x) for x, y in control], degree=2)
    document.saveas(climbing)
    low, high = sorted([0.0, 2.0 * rise])
    assert f"the SPLINE's control points' z runs from {low:g} to {high:g}" in one_line_error(climbing)
    flat = tmp_path / "flat.dxf"
    document = ezdxf.new()
    document.modelspace().add_open_spline([(x, y, 5.0) for x, y in control], degree=2)
    document.saveas(flat)
    points = load_profile(flat)
    np.testing.assert_allclose(points[:, 1], points[:, 0] * (2.0 - points[:, 0]), rtol=0, atol=1e-9)
    np.testing.assert_allclose(points[[0, -1]], [[0.0, 0.0], [2.0, 0.0]], rtol=0, atol=1e-12)


def invoke(args: list[str]) -> tuple[int, list[str]]:
    result = CliRunner().invoke(app, args)
    assert "Traceback" not in result.stdout + result.stderr
    lines = [ln for ln in ANSI.sub("", result.stderr).strip().splitlines() if not ln.startswith("note:")]
    return result.exit_code, lines


def write_problem(home: Path, z_of_a: np.ndarray) -> None:
    t = np.linspace(0.0, 1.0, 40)
    a = np.column_stack([t, 0.2 * t**2])
    (home / "a.csv").write_text(csv_text(a, z_of_a, "x,y,z"), encoding="utf-8")
    (home / "b.csv").write_text(
        "x,y\n" + "".join(f"{1.2 * s!r},{0.3 * s**2!r}\n" for s in t.tolist()), encoding="utf-8"
    )
    (home / "problem.toml").write_text(
        'profiles = ["a.csv", "b.csv"]\npiece_length = 0.1\ndesign = "MC"\nstarts = 1\n', encoding="utf-8"
    )


def test_synth_and_mechanize_read_a_flat_z_column_and_refuse_a_varying_one(tmp_path: Path) -> None:
    """``linkwork synth`` reads a.csv at z = 3 as its x and y; with z climbing, ``synth`` and ``mechanize``
    (which reads the problem's profiles again) exit 2 with one line naming a.csv, its line and column."""
    write_problem(tmp_path, np.full(40, 3.0))
    chain = tmp_path / "chain"
    code, lines = invoke(["synth", str(tmp_path / "problem.toml"), "--out", str(chain), "--no-plots"])
    assert code == 0, lines
    write_problem(tmp_path, np.linspace(0.0, 0.5, 40))
    expected = f"error: {tmp_path / 'a.csv'}: line 3: column z is "
    code, lines = invoke(["synth", str(tmp_path / "problem.toml"), "--out", str(tmp_path / "again")])
    assert code == 2 and len(lines) == 1 and lines[0].startswith(expected), lines
    assert "expected a profile drawn in a plane z = constant" in lines[0]
    assert not (tmp_path / "again").exists()
    before = sorted(p.name for p in chain.rglob("*"))
    code, lines = invoke(["mechanize", str(chain), "--problem", str(tmp_path / "problem.toml"), "--no-plots"])
    assert code == 2 and len(lines) == 1 and expected in lines[0], lines
    assert sorted(p.name for p in chain.rglob("*")) == before
