"""A DXF profile's unit (``$INSUNITS``) is read, and a problem's profiles are brought into one unit.

The drawings are written by ezdxf itself (an outside writer: linkwork's own ``new_dxf`` is not used to make the
inputs), in text and binary DXF; the expected factors are the exact definitions of the units (1 in = 25.4 mm,
1 ft = 12 in, 1 yd = 3 ft, 1 US survey ft = 1200/3937 m).
"""

from __future__ import annotations

from pathlib import Path

import ezdxf
import numpy as np
import pytest
from typer.testing import CliRunner

from linkwork.cli import app
from linkwork.errors import SpecError
from linkwork.io.problem import load_problem
from linkwork.io.profiles import dxf_unit, load_profile, profile_unit, save_profile

X = np.linspace(0.0, 3.0, 13)
CURVE = np.column_stack([X, 0.2 * np.sin(X)])  # in mm

SETTINGS = 'type = "open"\npiece_length = 0.25\nmin_pieces = 3\ndesign = "mcm"\nstarts = 2\nseed = 7\n'


def drawing(path: Path, points: np.ndarray, code: int | None, fmt: str = "asc") -> Path:
    """``points`` as one LWPOLYLINE in a drawing written by ezdxf with ``$INSUNITS = code`` (none set: ezdxf's
    default header)."""
    document = ezdxf.new("R2010")
    if code is not None:
        document.header["$INSUNITS"] = code
    document.modelspace().add_lwpolyline([(float(x), float(y)) for x, y in points])
    document.saveas(path, fmt=fmt)
    return path


@pytest.mark.parametrize(
    ("code", "name"),
    [(1, "in"), (2, "ft"), (4, "mm"), (5, "cm"), (6, "m"), (10, "yd"), (13, "um"), (21, "US survey ft")],
)
@pytest.mark.parametrize("fmt", ["asc", "bin"])
def test_the_declared_unit_is_read(tmp_path: Path, code: int, name: str, fmt: str) -> None:
    path = drawing(tmp_path / "p.dxf", CURVE, code, fmt)
    assert dxf_unit(path) == profile_unit(path) == name
    assert np.allclose(load_profile(path), CURVE, rtol=0, atol=1e-12)  # the points as drawn


def test_unitless_drawings_and_other_formats_declare_none(tmp_path: Path) -> None:
    assert profile_unit(drawing(tmp_path / "zero.dxf", CURVE, 0)) is None
    assert profile_unit(drawing(tmp_path / "odd.dxf", CURVE, 99)) is None  # no length unit has code 99
    save_profile(tmp_path / "p.csv", CURVE)
    assert profile_unit(tmp_path / "p.csv") is None
    # a header whose $INSUNITS value is not a number: unitless, the curve still read
    text = drawing(tmp_path / "bad.dxf", CURVE, 4).read_text(encoding="utf-8")
    lines = text.splitlines()
    at = lines.index("$INSUNITS")
    lines[at + 2] = "millimetres"
    (tmp_path / "bad.dxf").write_text("\n".join(lines) + "\n", encoding="utf-8")
    assert dxf_unit(tmp_path / "bad.dxf") is None


def problem(folder: Path, files: list[str], units: str | None = None) -> Path:
    path = folder / "problem.toml"
    listed = ", ".join(f'"{f}"' for f in files)
    path.write_text(
        f"profiles = [{listed}]\n" + (f'units = "{units}"\n' if units else "") + SETTINGS, encoding="utf-8"
    )
    return path


@pytest.mark.parametrize(("code", "per_mm"), [(1, 1 / 25.4), (5, 0.1), (6, 1e-3), (13, 1e3), (2, 1 / 304.8)])
def test_a_drawing_in_another_unit_is_converted_into_the_problems(
    tmp_path: Path, code: int, per_mm: float
) -> None:
    """The same curve, in mm as CSV and in inches (cm, m, um, ft) as DXF, is one curve in a problem in mm."""
    save_profile(tmp_path / "a.csv", CURVE)
    drawing(tmp_path / "b.dxf", CURVE * per_mm, code)
    loaded = load_problem(problem(tmp_path, ["a.csv", "b.dxf"], units="mm"))
    assert loaded.units == "mm"
    assert np.allclose(loaded.profiles[1], CURVE, rtol=0, atol=1e-14)  # the drawing's, converted
    assert np.allclose(loaded.profiles[0], CURVE, rtol=0, atol=1e-12)  # the CSV's (written to 12 digits)


def test_without_units_drawings_must_agree_and_set_the_unit(tmp_path: Path) -> None:
    drawing(tmp_path / "a.dxf", CURVE, 4)
    drawing(tmp_path / "b.dxf", CURVE / 25.4, 1)
    save_profile(tmp_path / "c.csv", CURVE)
    with pytest.raises(SpecError, match=r"is drawn in in \(\$INSUNITS\) and .*a\.dxf.* in mm") as caught:
        load_problem(problem(tmp_path, ["a.dxf", "c.csv", "b.dxf"]))
    assert caught.value.key == "profiles[2]"
    result = CliRunner().invoke(app, ["synth", str(tmp_path / "problem.toml"), "-o", str(tmp_path / "out")])
    assert result.exit_code == 2 and "Traceback" not in result.output, result.output
    assert "profiles[2]" in result.output and not (tmp_path / "out").exists()
    # drawings that agree: the problem is in their unit, the CSV as written
    drawing(tmp_path / "b.dxf", CURVE, 4)
    loaded = load_problem(problem(tmp_path, ["a.dxf", "c.csv", "b.dxf"]))
    assert loaded.units == "mm"
    assert np.allclose(loaded.profiles[0], CURVE, atol=1e-12) and np.allclose(
        loaded.profiles[2], CURVE, atol=1e-12
    )
    # a unit no output can carry (yards): taken as drawn, the problem unitless
    drawing(tmp_path / "a.dxf", CURVE, 10)
    drawing(tmp_path / "b.dxf", CURVE, 10)
    assert load_problem(problem(tmp_path, ["a.dxf", "b.dxf"])).units is None
