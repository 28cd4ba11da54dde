"""Hostile input files of kinds the earlier fuzz rounds did not try (session 13's red team): CSV profiles
written by spreadsheets and editors (thousands separators, ragged rows, a repeated header column, form feeds and
NEL in comments, digits Python's ``float`` takes but no CSV reader does), TOML with a byte-order mark, file names
holding a line break, names holding C1 controls or bidirectional overrides, and a problem value quoted back wrong.

Each case is checked against something outside linkwork's reader: Python's :mod:`csv` module and an editor's line
numbering (``\\n``, ``\\r\\n`` or ``\\r`` end a line, nothing else), the same file without the mark, or the
message's own promise (one line, the file first, the value as written).
"""

from __future__ import annotations

import csv
import io
import math
import re
import time
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from fuzzkit import FUZZ, one_line_error
from hypothesis import given
from hypothesis import strategies as st

from linkwork.errors import LinkworkError, SpecError
from linkwork.io.problem import load_problem
from linkwork.io.profiles import load_profile, save_profile
from linkwork.io.spec import dump_spec, load_spec
from linkwork.linkages.bennett import bennett
from linkwork.studies.study_file import load_study

#: Characters that make a line read as something else on screen: C1 controls (``\x9b`` is the one-byte CSI of
#: an escape sequence, ``\x85`` a line break) and the bidirectional embeddings, overrides and isolates.
INVISIBLE_CONTROLS = [
    "\x85",
    "\x9b",
    "\u202a",
    "\u202b",
    "\u202d",
    "\u202e",
    "\u2066",
    "\u2067",
    "\u2068",
    "\u2069",
]
#: What must never appear raw in a message.
RAW = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029\u202a-\u202e\u2066-\u2069]")


def editor_lines(text: str) -> list[str]:
    """The lines of ``text`` as an editor numbers them (line 1 is ``[0]``)."""
    return re.split(r"\r\n|\r|\n", text)


# ------------------------------------------------------------------------------------------- CSV profiles


def spreadsheet_number(value: float, thousands: bool) -> str:
    """``value`` as a spreadsheet writes it, with a thousands separator if asked (``1,234.5``)."""
    return f"{value:,.3f}" if thousands else f"{value:.3f}"


@FUZZ
@given(
    xs=st.lists(st.floats(min_value=-5000.0, max_value=5000.0), min_size=2, max_size=8, unique=True),
    separated=st.integers(min_value=0, max_value=7),
    ending=st.sampled_from(["\n", "\r\n", "\r"]),
    comment=st.sampled_from(
        ["# plain", "# form\x0cfeed", "# next\x85line", "# sep\u2028arator", "# tab\tbed"]
    ),
)
def test_a_csv_profile_reads_as_the_csv_module_reads_it_or_names_the_broken_line(
    tmp_path_factory: pytest.TempPathFactory, xs: list[float], separated: int, ending: str, comment: str
) -> None:
    """A number written with a thousands separator splits into two cells. It used to be read silently as two
    numbers (``1,234.500,7`` as x = 1, y = 234.5): now the file reads as Python's csv module reads it, or the
    error names the line an editor shows for the broken row. Comments holding a form feed or NEL are comments
    (they used to start a data line and shift every later line number)."""
    rows = [(x, 0.001 * i) for i, x in enumerate(sorted(xs))]
    thousands = [abs(x) >= 1000 and i == separated % len(rows) for i, (x, _) in enumerate(rows)]
    body = [comment, "x,y"] + [
        f"{spreadsheet_number(x, t)},{spreadsheet_number(y, False)}"
        for (x, y), t in zip(rows, thousands, strict=True)
    ]
    text = ending.join(body) + ending
    file = tmp_path_factory.mktemp("csv") / "profile.csv"
    file.write_bytes(text.encode("utf-8"))
    lines = editor_lines(text)
    # the outside reader: csv.reader on the data lines, the header's width on every row
    parsed = list(csv.reader(io.StringIO("\n".join(lines[1:]))))
    width = len(parsed[0])
    ragged = [i for i, row in enumerate(parsed[1:], start=3) if row and len(row) != width]
    message = one_line_error(lambda: load_profile(file), (SpecError,))
    if ragged:
        assert message is not None, f"read a file whose line {ragged[0]} has a thousands separator"
        assert message.startswith(f"{file}: line {ragged[0]}: "), message
        assert lines[ragged[0] - 1] and len(lines[ragged[0] - 1].split(",")) == 3
        return
    expected = np.array([[float(x), float(y)] for x, y in (row for row in parsed[1:] if row)])
    if message is None:
        np.testing.assert_array_equal(load_profile(file), expected)
    else:  # a curve refused as a curve (too short, repeated points): never for a line of the file
        assert "line" not in message, message


@pytest.mark.parametrize(
    ("content", "fragment"),
    [
        ("x,y\n0,0\n1,000.5,2\n3,4\n", "line 3: 3 cells"),  # a thousands separator: was (1, 0.5), exit 0
        ("0,0\n1,000.5,2\n3,4\n", "line 2: 3 cells"),  # the same without a header
        ("x,y\n0,0,9\n1,1,9\n", "line 2: 3 cells"),  # more cells than the header: was read, the rest dropped
        ("x,x,y\n0,5,0\n1,6,1\n", "names column x 2 times"),  # which x? was the first, silently
        ("x,y\n1_000,0\n2_000,1\n", "line 2: expected numbers"),  # Python's float reads 1000
        ("x,y\n\u0661,0\n\u0662,1\n", "line 2: expected numbers"),  # Arabic-Indic digits: Python reads 1
        ("x,y\n\uff11,0\n\uff12,1\n", "line 2: expected numbers"),  # full-width digits
        ("x,y\n# a\x0ccomment\n0,0\nbad,1\n", "line 4: expected numbers"),  # was "line 3 ... 'comment'"
        ("x,y\n0,0\n" + "a" * 1_000_000 + "\n", "line 3: "),  # the message quoted the whole megabyte
    ],
)
def test_csv_profiles_written_by_spreadsheets_and_editors(
    tmp_path: Path, content: str, fragment: str
) -> None:
    file = tmp_path / "profile.csv"
    file.write_text(content, encoding="utf-8", newline="")
    message = one_line_error(lambda: load_profile(file), (SpecError,))
    assert message is not None and message.startswith(f"{file}: ")
    assert fragment in message
    assert len(message) < 400, len(message)


@pytest.mark.parametrize("suffix", [".csv", ".dat"])
def test_a_profile_file_named_with_a_line_break_is_one_line(tmp_path: Path, suffix: str) -> None:
    """``SpecError(source=str(path))``: a file named ``a<newline>b.csv`` made a two-line message."""
    file = tmp_path / f"a\nb{suffix}"
    file.write_text("x,y\n0,0\nbad,1\n" if suffix == ".csv" else "name\n0 0\nbad 1\n", encoding="utf-8")
    message = one_line_error(lambda: load_profile(file), (SpecError,))
    assert message is not None and "a\\nb" in message and "line 3" in message


# ------------------------------------------------------------------------------------------------- TOML


def test_a_spec_saved_with_a_byte_order_mark_reads_as_without(tmp_path: Path) -> None:
    """Notepad writes a UTF-8 byte-order mark: the file was "invalid TOML: Invalid statement" at line 1,
    column 1, a place where the user sees nothing wrong."""
    text = dump_spec(bennett())
    plain, marked = tmp_path / "plain.toml", tmp_path / "marked.toml"
    plain.write_text(text, encoding="utf-8")
    marked.write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode("utf-8"))
    np.testing.assert_array_equal(load_spec(marked).mechanism.twists, load_spec(plain).mechanism.twists)


def test_a_spec_in_latin_1_names_the_line_of_the_first_bad_byte(tmp_path: Path) -> None:
    file = tmp_path / "latin.toml"
    file.write_bytes(dump_spec(bennett()).replace("Bennett linkage", "Bennétt").encode("latin-1"))
    message = one_line_error(lambda: load_spec(file), (SpecError,))
    line = next(i for i, text in enumerate(file.read_bytes().split(b"\n"), start=1) if b"\xe9" in text)
    assert (
        message
        == f"{file}: not a UTF-8 text file (byte 0xe9 at line {line}); expected a linkage spec file (TOML)"
    )


@pytest.mark.parametrize("reader", ["spec", "problem", "study"])
def test_a_toml_file_named_with_a_line_break_is_one_line(tmp_path: Path, reader: str) -> None:
    file = tmp_path / "bad\nname.toml"
    file.write_text("name = 1\n", encoding="utf-8")
    load = {"spec": load_spec, "problem": load_problem, "study": load_study}[reader]
    message = one_line_error(lambda: load(file), (LinkworkError,))
    assert message is not None and message.startswith(str(file).replace("\n", "\\n"))


# ------------------------------------------------------------------------------------------------ names


def _spec_with(tmp_path: Path, field: str, name: str) -> Path:
    """A four-bar spec ([mechanism]) with one name replaced: the linkage, a joint, a body or a point."""
    spec = {
        "linkage": name,
        "joint": "A",
        "body": "crank",
        "point": "P",
    }
    spec[field] = name
    text = f"""name = {_toml(spec["linkage"] if field == "linkage" else "four-bar")}
[mechanism]
planar = true
[[mechanism.joints]]
name = {_toml(spec["joint"])}
bodies = ["ground", {_toml(spec["body"])}]
point = [0.0, 0.0]
[[mechanism.joints]]
name = "B"
bodies = [{_toml(spec["body"])}, "coupler"]
point = [1.0, 0.0]
[[mechanism.joints]]
name = "C"
bodies = ["coupler", "rocker"]
point = [1.5, 1.0]
[[mechanism.joints]]
name = "D"
bodies = ["rocker", "ground"]
point = [0.0, 1.2]
[[points]]
name = {_toml(spec["point"])}
body = "coupler"
position = [1.2, 0.5]
"""
    file = tmp_path / "four-bar.toml"
    file.write_text(text, encoding="utf-8")
    return file


def _toml(text: str) -> str:
    return '"' + "".join(c if c.isprintable() and c not in '"\\' else f"\\u{ord(c):04x}" for c in text) + '"'


@pytest.mark.parametrize("char", INVISIBLE_CONTROLS)
@pytest.mark.parametrize("field", ["linkage", "joint", "body", "point"])
def test_spec_names_with_c1_or_bidirectional_controls_are_refused(
    tmp_path: Path, field: str, char: str
) -> None:
    """A linkage name with U+202E (right-to-left override) was accepted and printed: the rest of every table row
    and error line showing it read backwards; body names were not checked at all (a line break in one broke
    the error line of a body joined to itself)."""
    assert load_spec(_spec_with(tmp_path, field, "ok")).mechanism.n_joints == 4  # the file is sound otherwise
    file = _spec_with(tmp_path, field, f"a{char}b")
    message = one_line_error(lambda: load_spec(file), (SpecError,))
    assert message is not None and message.startswith(f"{file}: "), message
    assert not RAW.search(message), ascii(message)


@pytest.mark.parametrize("char", INVISIBLE_CONTROLS)
def test_profile_and_study_names_with_c1_or_bidirectional_controls_are_refused(
    tmp_path: Path, char: str
) -> None:
    t = np.linspace(0.0, 1.0, 20)
    save_profile(tmp_path / "a.csv", np.column_stack([t, 0.2 * t**2]))
    save_profile(tmp_path / "b.csv", np.column_stack([1.2 * t, 0.3 * t**2]))
    problem = tmp_path / "problem.toml"
    problem.write_text(
        f'profiles = ["a.csv", "b.csv"]\npiece_length = 0.1\ndesign = "MC"\nnames = [{_toml("x" + char)}, "y"]\n',
        encoding="utf-8",
    )
    message = one_line_error(lambda: load_problem(problem), (SpecError,))
    assert message is not None and "names[0]: expected a name without line breaks" in message
    assert not RAW.search(message)
    study = tmp_path / "study.toml"
    study.write_text(f'name = {_toml("s" + char)}\nlinkage = "bennett"\n', encoding="utf-8")
    message = one_line_error(lambda: load_study(study), (SpecError,))
    assert message is not None and f"{study}: name: expected a name without line breaks" in message
    assert not RAW.search(message)


def test_a_body_name_a_megabyte_long_is_refused_in_a_short_line(tmp_path: Path) -> None:
    file = _spec_with(tmp_path, "body", "b" * 1_000_000)
    message = one_line_error(lambda: load_spec(file), (SpecError,))
    assert message is not None and "at most 100 characters" in message and len(message) < 500


def test_an_unknown_joint_in_couple_is_quoted_on_one_line(tmp_path: Path) -> None:
    file = _spec_with(tmp_path, "joint", "A")
    file.write_text(
        file.read_text(encoding="utf-8").replace("planar = true", 'planar = true\ncouple = [["A\\nZ", "B"]]'),
        encoding="utf-8",
    )
    message = one_line_error(lambda: load_spec(file), (SpecError,))
    assert message is not None and 'unknown joint "A\\nZ"' in message


# --------------------------------------------------------------------------------------------- problems


@pytest.mark.parametrize(
    ("line", "fragment"),
    [
        ("merge_below = nan", "0 <= merge_below < 180, got nan"),  # was "got inf": not what the file says
        ("merge_below = -inf", "got -inf"),
        ("seed = 18446744073709551615", "seed: expected a whole number <= 9223372036854775807"),
    ],
)
def test_problem_values_are_quoted_as_written(tmp_path: Path, line: str, fragment: str) -> None:
    t = np.linspace(0.0, 1.0, 20)
    save_profile(tmp_path / "a.csv", np.column_stack([t, 0.2 * t**2]))
    save_profile(tmp_path / "b.csv", np.column_stack([1.2 * t, 0.3 * t**2]))
    file = tmp_path / "problem.toml"
    file.write_text(
        f'profiles = ["a.csv", "b.csv"]\npiece_length = 0.1\ndesign = "MC"\n{line}\n', encoding="utf-8"
    )
    message = one_line_error(lambda: load_problem(file), (SpecError,))
    assert message is not None and fragment in message, message


# ------------------------------------------------------------------------------------------ DXF profiles


def _distance_to_polyline(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """The distance of each point to a dense polyline (its pieces)."""
    a, b = polyline[:-1], polyline[1:]
    d = b - a
    t = np.clip(np.einsum("pkj,kj->pk", points[:, None, :] - a[None], d) / np.einsum("kj,kj->k", d, d), 0, 1)
    nearest = a[None] + t[..., None] * d[None]
    return np.min(np.linalg.norm(points[:, None, :] - nearest, axis=2), axis=1)


@pytest.mark.parametrize("entity", ["LWPOLYLINE", "POLYLINE"])
@pytest.mark.parametrize("normal", [(0.0, 0.0, 1.0), (0.0, 0.0, -1.0), (0.0, 0.0, -2.5)])
def test_a_mirrored_dxf_polyline_is_read_where_cad_draws_it(
    tmp_path: Path, entity: str, normal: tuple
) -> None:
    """A polyline mirrored in CAD is written with the extrusion (0, 0, -1): its vertices are in an object
    coordinate system whose x is the world's -x, and its arcs turn the other way. linkwork read the raw numbers:
    the profile came out mirrored, silently. Checked against ezdxf's own path of the entity in world
    coordinates (``ezdxf.path.make_path``, flattened densely)."""
    from ezdxf import path as dxf_path

    document = ezdxf.new("R2010")
    space = document.modelspace()
    vertices = [(0.0, 0.0, 0.4), (1.0, 0.0, 0.0), (2.0, 0.5, -0.3), (3.0, 0.2, 0.0)]
    attributes = {"extrusion": normal}
    if entity == "LWPOLYLINE":
        drawn = space.add_lwpolyline(vertices, format="xyb", dxfattribs=attributes)
    else:
        drawn = space.add_polyline2d([v[:2] for v in vertices], dxfattribs=attributes)
        for vertex, (_, _, bulge) in zip(drawn.vertices, vertices, strict=True):
            vertex.dxf.bulge = bulge
    file = tmp_path / "mirrored.dxf"
    document.saveas(str(file))
    corners = np.array([(v.x, v.y) for v in drawn.ocs().points_to_wcs([(x, y, 0.0) for x, y, _ in vertices])])
    reference = np.array([(p.x, p.y) for p in dxf_path.make_path(drawn).flattening(distance=1e-7)])
    points = load_profile(file)
    for corner in corners:  # every vertex where ezdxf puts it in world coordinates, to rounding
        assert np.min(np.linalg.norm(points - corner, axis=1)) <= 1e-12
    # ezdxf's path draws the arcs as cubic Bezier curves (within about 3e-4 of the radius); a mirrored or
    # turned-over arc is 0.1 away
    size = float(np.hypot(*np.ptp(reference, axis=0)))
    assert _distance_to_polyline(points, reference).max() <= 1e-3 * size


def test_a_dxf_polyline_outside_the_xy_plane_is_refused(tmp_path: Path) -> None:
    document = ezdxf.new("R2010")
    document.modelspace().add_lwpolyline(
        [(0, 0), (1, 0), (2, 0.5)], dxfattribs={"extrusion": (1.0, 0.0, 0.0)}
    )
    file = tmp_path / "side.dxf"
    document.saveas(str(file))
    message = one_line_error(lambda: load_profile(file), (SpecError,))
    assert message is not None and message.startswith(
        f"{file}: the LWPOLYLINE lies in a plane with normal (1, 0, 0)"
    )


# ------------------------------------------------------------------------------------- the Python API


@pytest.mark.parametrize("suffix", [".csv", ".dat", ".svg", ".dxf"])
@pytest.mark.parametrize(
    "points",
    [[[0.0, 0.0], [1.0, math.nan]], [[0.0, 0.0], [1.0, math.inf]], [[0, 0, 0], [1, 1, 1]], [[0.0, 0.0]], []],
    ids=["nan", "inf", "three-columns", "one-point", "empty"],
)
def test_save_profile_writes_only_what_load_profile_reads(tmp_path: Path, suffix: str, points: list) -> None:
    """save_profile wrote ``nan`` into a CSV, Selig or DXF file (the reader then refused its own file), dropped a
    third column into a DXF silently, and failed on an empty SVG with numpy's "zero-size array"."""
    file = tmp_path / f"profile{suffix}"
    message = one_line_error(lambda: save_profile(file, points), (SpecError,))
    assert message is not None and message.startswith(str(file))
    assert not file.exists()


@pytest.mark.parametrize(
    "profiles",
    [
        None,
        (p for p in ()),
        ([[0, 0], [1]], [[0, 0], [1, 1]]),
        (np.array([[0, "a"], [1, 1]], dtype=object), [[0, 0], [1, 1]]),
    ],
    ids=["None", "generator", "ragged", "text"],
)
def test_a_problem_built_in_a_script_from_odd_profiles_is_one_spec_error(profiles: object) -> None:
    """numpy's ValueError ("inhomogeneous shape"), TypeError ("object of type 'NoneType' has no len()",
    "ufunc 'isfinite' not supported") came out of Problem(...) instead of the SpecError of its rules."""
    from linkwork.synthesis import Problem

    message = one_line_error(lambda: Problem(profiles=profiles, piece_length=0.2, design="MC"), (SpecError,))  # type: ignore[arg-type]
    assert message is not None and message.startswith("profiles")


def test_a_selig_file_in_millimetres_is_read_not_taken_for_lednicer(tmp_path: Path) -> None:
    """A Selig airfoil in millimetres starts at its trailing edge, ``100 20``: two whole numbers above 1.5,
    which the reader took for a Lednicer point-count line and refused. Checked against numpy.loadtxt."""
    file = tmp_path / "wing-mm.dat"
    file.write_text("wing in mm\n100 20\n50 30\n0 0\n50 -10\n100 0\n", encoding="utf-8")
    np.testing.assert_array_equal(load_profile(file), np.loadtxt(file, skiprows=1))
    lednicer = tmp_path / "lednicer.dat"  # the real layout: counts, a blank line, upper then lower surface
    lednicer.write_text(
        "NACA 0012\n3.       3.\n\n0 0\n0.5 0.06\n1 0\n\n0 0\n0.5 -0.06\n1 0\n", encoding="utf-8"
    )
    message = one_line_error(lambda: load_profile(lednicer), (SpecError,))
    assert message is not None and "line 2: looks like a Lednicer point-count line" in message


def test_a_coupling_naming_a_joint_twice_is_refused_as_the_flag_is(tmp_path: Path) -> None:
    """``--couple A=A`` is refused ("names a joint twice"); ``couple = [["A", "A"]]`` in a file was read."""
    file = _spec_with(tmp_path, "joint", "A")
    file.write_text(
        file.read_text(encoding="utf-8").replace("planar = true", 'planar = true\ncouple = [["A", "A"]]'),
        encoding="utf-8",
    )
    message = one_line_error(lambda: load_spec(file), (SpecError,))
    assert message is not None and "mechanism.couple[0]: names a joint twice" in message


def test_a_profile_saved_as_dxf_declares_no_unit(tmp_path: Path) -> None:
    """save_profile wrote ezdxf's default header, ``$INSUNITS`` 6: a unitless profile declared in metres to
    every CAD program that opens it. Read back by ezdxf."""
    file = tmp_path / "profile.dxf"
    save_profile(file, [[0.0, 0.0], [1.0, 0.5], [2.0, 0.0]])
    assert ezdxf.readfile(str(file)).header["$INSUNITS"] == 0


# --------------------------------------------------------------------------------- self-crossing, bounded


@pytest.mark.parametrize("along", ["x", "y"])
def test_a_serpentine_profile_of_200000_points_is_checked_in_seconds(tmp_path: Path, along: str) -> None:
    """A zigzag across the whole width (hatching, a serpentine) overlapped every other piece along x: the
    crossing check was quadratic, 20 s for 10,000 points and hours for the 200,000 a profile may have."""
    n = 200_000
    across = (np.arange(n) % 2).astype(float)
    up = np.arange(n) * 1e-3
    points = np.column_stack([across, up] if along == "x" else [up, across])
    file = tmp_path / "serpentine.csv"
    file.write_text("x,y\n" + "\n".join(f"{x:.3f},{y:.3f}" for x, y in points) + "\n", encoding="utf-8")
    start = time.perf_counter()
    np.testing.assert_array_equal(load_profile(file), np.loadtxt(file, delimiter=",", skiprows=1))
    assert time.perf_counter() - start < 60.0  # about 3 s on a loaded 2-core machine


def test_a_tangle_beyond_the_budget_is_refused_at_once(tmp_path: Path) -> None:
    """Long pieces side by side along both x and y: both sweeps are quadratic, so the check is refused with its
    budget stated (it would have run for minutes to hours) rather than started."""
    n = 20_000
    k = np.arange(n)
    points = np.column_stack([(k % 2) + 1e-4 * k, (k % 2) * 1.0 + 2e-4 * k])
    file = tmp_path / "tangle.csv"
    file.write_text("x,y\n" + "\n".join(f"{x:.17g},{y:.17g}" for x, y in points) + "\n", encoding="utf-8")
    start = time.perf_counter()
    message = one_line_error(lambda: load_profile(file), (SpecError,))
    assert time.perf_counter() - start < 30.0
    assert message is not None and "pairs of pieces; expected at most" in message
