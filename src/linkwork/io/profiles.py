"""Design-profile files: read a planar curve from CSV, Selig ``.dat``, SVG or DXF into an ``(N, 2)`` polyline,
and write one back. (A synthesised chain's outline on every profile, as SVG or DXF for CAD, is written by
:mod:`linkwork.io.outlines`; its functions keep this module's import path too.)

Every reader goes through one registry of formats keyed by file suffix (:data:`FORMATS`) behind
:func:`load_profile`, and every polyline it returns has passed :func:`check_profile`: at least two finite,
distinct consecutive points on a curve that does not cross itself. Problems are reported as
:class:`~linkwork.errors.SpecError` naming the file, the line or entity, and what was expected.

Curved geometry (SVG arcs and Bézier curves, DXF bulges and splines) is flattened into straight pieces whose
largest distance from the true curve (the sagitta) is at most ``tolerance`` times the size of the drawing, the
diagonal of the bounding box of the shape's defining points (vertices and control points). The default,
:data:`FLATTEN_TOLERANCE`, is ``1e-4``: a curve one unit across is followed to within 0.0001. Every
vertex of the flattened polyline lies on the true curve (to rounding). The checks and the flattening live in
:mod:`linkwork.io.curves`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from linkwork.errors import SpecError
from linkwork.io.curves import (
    COINCIDENT,
    FLATTEN_TOLERANCE,
    MAX_BULGE,
    MAX_COORDINATE,
    MAX_FLATTENED_POINTS,
    Points,
    bounding_size,
    bulge_polyline,
    check_profile,
    find_self_crossing,
    flatten_curve,
    is_closed,
    spline_points,
)
from linkwork.io.drawing import LENGTH_UNITS, new_dxf, svg_d, svg_document, svg_path
from linkwork.io.outlines import final_chain, write_outline_dxf, write_outline_svg
from linkwork.io.toml_reader import MAX_FILE_BYTES as MAX_PROFILE_BYTES
from linkwork.io.toml_reader import check_input_file, escape_line
from linkwork.io.writer import require_finite
from linkwork.limits import plain_number
from linkwork.units import DXF_INSUNITS

__all__ = [
    "COINCIDENT",
    "FLATTEN_TOLERANCE",
    "FORMATS",
    "LENGTH_UNITS",
    "MAX_BULGE",
    "MAX_COORDINATE",
    "MAX_FLATTENED_POINTS",
    "MAX_PROFILE_BYTES",
    "ProfileFormat",
    "check_profile",
    "dxf_unit",
    "final_chain",
    "find_self_crossing",
    "is_closed",
    "load_profile",
    "new_dxf",
    "profile_unit",
    "read_profile_csv",
    "read_profile_dat",
    "read_profile_dxf",
    "read_profile_svg",
    "register_format",
    "save_profile",
    "write_outline_dxf",
    "write_outline_svg",
    "write_profile_csv",
    "write_profile_dat",
    "write_profile_dxf",
    "write_profile_svg",
]

_CONTROLS = ("control1", "control2", "control")  # svgelements' names of Bézier control points


# ---------------------------------------------------------------------------------------------------- CSV


def read_profile_csv(path: str | Path, tolerance: float = FLATTEN_TOLERANCE) -> Points:
    """Read a profile from a CSV file of ``x,y`` rows (or ``x,y,z`` rows of a curve in a plane z = constant).

    A header row is optional; when present it must name an ``x`` and a ``y`` column once each (any order), and
    at most one ``z`` column; other columns are ignored. Without a header the first two columns are x and y and
    a third, if any, is z. A z column is read as DXF's 3-D polylines are (:func:`read_profile_dxf`): one whose
    every value is the first row's (to ``1e-9`` of the curve's size) is dropped, since x and y are then the
    curve; one that varies is refused, naming its first line off the plane, since x and y alone would be the
    curve's projection, not the curve. Every row has as many cells as the header (or, without one, as the first
    row): a row with more is refused rather than read wrong, since a thousands separator (``1,000.5``) or a
    decimal comma splits a number into two cells. Numbers are written as CSV files write them
    (:func:`_csv_number`). Blank lines and lines starting with ``#`` are skipped. ``tolerance`` is unused (the
    points are taken as they are).
    """
    path = Path(path)
    source = escape_line(str(path))
    lines = _read_lines(path)
    x_col, y_col = 0, 1
    z_col: int | None = None
    header = False
    rows: list[tuple[float, float]] = []
    # each row's line, z and z as written, when there is a z column
    heights: list[tuple[int, float, str]] = []
    width: tuple[int, int] | None = None  # the cells of every row, and the line that set it
    for number, line in lines:
        cells = [cell.strip() for cell in line.split(",")]
        if width is None and plain_number(cells[0]) is None:
            names = [cell.lower() for cell in cells]
            if "x" not in names or "y" not in names:
                raise SpecError(
                    f"line {number}: header {_quoted(line)} names no x and y columns; expected e.g. 'x,y'",
                    source=source,
                )
            for column in ("x", "y", "z"):
                if names.count(column) > 1:
                    raise SpecError(
                        f"line {number}: header {_quoted(line)} names column {column} {names.count(column)} times; "
                        "expected one x and one y column (and at most one z)",
                        source=source,
                    )
            x_col, y_col = names.index("x"), names.index("y")
            z_col = names.index("z") if "z" in names else None
            width, header = (len(cells), number), True
            continue
        if width is None:
            width = (len(cells), number)
            z_col = 2 if len(cells) > 2 else None  # no header: x, y, z
        if len(cells) != width[0] and len(cells) > max(x_col, y_col):
            raise SpecError(
                f"line {number}: {_cells(len(cells))} in {_quoted(line)}, but line {width[1]} has {width[0]}; "
                "expected the same number of cells on every line (a thousands separator or a decimal comma "
                "splits a number into two cells)",
                source=source,
            )
        x, y = (
            (plain_number(cells[x_col]), plain_number(cells[y_col]))
            if len(cells) == width[0]
            else (None, None)
        )
        if x is None or y is None:
            raise SpecError(
                f"line {number}: expected numbers in columns x and y, got {_quoted(line)}", source=source
            )
        if z_col is not None:
            z = plain_number(cells[z_col])
            if z is None:
                raise SpecError(
                    f"line {number}: expected a number in column {_z_column(z_col, header)}, got "
                    f"{_quoted(cells[z_col])} in {_quoted(line)}",
                    source=source,
                )
            heights.append((number, z, cells[z_col]))
        rows.append((x, y))
    points = np.array(rows, dtype=float).reshape(-1, 2)
    if heights and z_col is not None:
        _check_plane(points, heights, _z_column(z_col, header), source)
    return points


def _z_column(index: int, header: bool) -> str:
    """How a message names a CSV file's z column: by its header's name, or by its place and meaning."""
    return "z" if header else f"{index + 1} (z)"


def _check_plane(points: Points, heights: list[tuple[int, float, str]], column: str, source: str) -> None:
    """Refuse a curve whose z (``heights``: each row's line, z, and z as written) leaves the plane of its first
    row by more than ``1e-9`` of the curve's size (the largest |x|, |y| or |z|), as a 3-D DXF polyline is."""
    z = np.array([height for _, height, _ in heights])
    finite = points[np.isfinite(points)]
    size = max(float(np.abs(finite).max(initial=0.0)), float(np.abs(z[np.isfinite(z)]).max(initial=0.0)))
    off = np.flatnonzero(~(np.abs(z - z[0]) <= 1e-9 * size))
    if len(off) == 0:
        return
    number, _, written = heights[int(off[0])]
    first, _, written0 = heights[0]
    raise SpecError(
        f"line {number}: column {column} is {written}, but line {first} has {written0}; expected a profile "
        "drawn in a plane z = constant (a constant z column is dropped: x and y are the profile)",
        source=source,
    )


def write_profile_csv(path: str | Path, points: ArrayLike) -> None:
    """Write a profile as a CSV file with an ``x,y`` header (12 significant digits)."""
    pts = np.asarray(points, dtype=float)
    lines = ["x,y"] + [f"{x:.12g},{y:.12g}" for x, y in pts]
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")


# ------------------------------------------------------------------------------------------- Selig .dat


def read_profile_dat(path: str | Path, tolerance: float = FLATTEN_TOLERANCE) -> Points:
    """Read an airfoil in Selig format: a name line, then one ``x y`` pair per line.

    The points run from the trailing edge over the upper surface to the leading edge and back along the lower
    surface. A file without the name line is accepted. Lednicer files (upper and lower surfaces listed
    separately after a line of point counts) are recognised and refused: their first line of numbers is two
    whole numbers above 1.5 lying beyond every point of the curve (``61. 61.`` before a chord from 0 to 1); a
    Selig file in millimetres, whose first point ``100 20`` is its trailing edge, is read. ``tolerance`` is
    unused.
    """
    path = Path(path)
    source = escape_line(str(path))
    rows: list[tuple[float, float]] = []
    first = (0, "")
    for index, (number, line) in enumerate(_read_lines(path)):
        cells = line.replace(",", " ").split()
        values = [plain_number(cell) for cell in cells]
        if index == 0 and (len(values) != 2 or None in values):
            continue  # the airfoil's name
        if len(values) != 2 or values[0] is None or values[1] is None:
            raise SpecError(f"line {number}: expected two numbers 'x y', got {_quoted(line)}", source=source)
        if not rows:
            first = (number, line)
        rows.append((float(values[0]), float(values[1])))
    if rows:
        x, y = rows[0]
        counts = x > 1.5 and y > 1.5 and x.is_integer() and y.is_integer()
        if counts and (len(rows) == 1 or x > max(p[0] for p in rows[1:])):
            raise SpecError(
                f"line {first[0]}: looks like a Lednicer point-count line {_quoted(first[1])}; expected Selig "
                "format (one list from the trailing edge over the upper surface and back along the lower)",
                source=source,
            )
    return np.array(rows, dtype=float).reshape(-1, 2)


def write_profile_dat(path: str | Path, points: ArrayLike, name: str | None = None) -> None:
    """Write a profile in Selig format: ``name`` (the file stem by default), then ``x y`` lines."""
    pts = np.asarray(points, dtype=float)
    # The title is the first line of a Selig file: line breaks in a name would start the coordinates early.
    title = " ".join((name if name is not None else Path(path).stem).split()) or "profile"
    lines = [title] + [f"{x: .12g} {y: .12g}" for x, y in pts]
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")


# ---------------------------------------------------------------------------------------------------- SVG


def read_profile_svg(path: str | Path, tolerance: float = FLATTEN_TOLERANCE) -> Points:
    """Read a profile from an SVG drawing holding exactly one shape (a path, polyline, polygon, line, ...).

    Coordinates are the drawing's user units (those of its ``viewBox``) with transforms applied and the y axis
    turned to point up (SVG's points down), so the curve looks as it does in a browser. The shape must be one
    continuous curve (one ``M`` command). Arcs and Bézier curves are flattened to ``tolerance`` times the
    shape's size; a closing ``Z`` returns to the first point.
    """
    import svgelements as svg_lib

    path = Path(path)
    _check_readable(path)
    try:
        document = svg_lib.SVG.parse(str(path), reify=True)
    except Exception as exc:  # svgelements raises bare parser errors of several kinds
        raise SpecError(
            f"not a readable SVG drawing ({escape_line(str(exc))[:200]}); expected an SVG file",
            source=escape_line(str(path)),
        ) from None
    shapes = [element for element in document.elements() if isinstance(element, svg_lib.Shape)]
    shapes = [shape for shape in shapes if len(svg_lib.Path(shape)) > 0]
    if len(shapes) != 1:
        raise SpecError(
            f"found {len(shapes)} shapes; expected exactly one path (or polyline, polygon, line)",
            source=escape_line(str(path)),
        )
    outline = svg_lib.Path(shapes[0])
    user_units = ~svg_lib.Matrix(document.viewbox_transform) if document.viewbox_transform else None
    if user_units is not None:
        outline = outline * user_units
        outline.reify()
    segments = [segment for segment in outline.segments() if not isinstance(segment, svg_lib.Move)]
    moves = sum(isinstance(segment, svg_lib.Move) for segment in outline.segments())
    if moves > 1:
        raise SpecError(
            f"the path has {moves} parts (M commands); expected one continuous curve",
            source=escape_line(str(path)),
        )
    if not segments:
        raise SpecError(
            "the shape has no points; expected a curve of at least 2 points", source=escape_line(str(path))
        )
    defining: list[tuple[float, float]] = []
    for segment in segments:
        anchors = (segment.start, segment.end, *(getattr(segment, name, None) for name in _CONTROLS))
        defining += [(float(point.x), float(point.y)) for point in anchors if point is not None]
        if isinstance(segment, svg_lib.Arc):
            box = segment.bbox()
            defining += [(box[0], box[1]), (box[2], box[3])]
    absolute = tolerance * bounding_size(np.array(defining, dtype=float))
    first = segments[0].start
    points: list[tuple[float, float]] = [(float(first.x), float(first.y))]
    for segment in segments:
        if isinstance(segment, svg_lib.Close) and segment.start == segment.end:
            continue  # "Z" after the curve already returned to its start adds nothing
        if isinstance(segment, (svg_lib.Line, svg_lib.Close)):
            points.append((float(segment.end.x), float(segment.end.y)))
        else:

            def curve(t: float, segment: Any = segment) -> tuple[float, float]:
                point = segment.point(t)
                return (float(point.x), float(point.y))

            points += flatten_curve(curve, absolute)
    pts = np.array(points, dtype=float)
    return np.column_stack([pts[:, 0], -pts[:, 1]]) + 0.0  # + 0.0 turns -0.0 into 0.0


def write_profile_svg(path: str | Path, points: ArrayLike) -> None:
    """Write a profile as an SVG drawing: one path of straight pieces (y up, as :func:`read_profile_svg`)."""
    pts = np.asarray(points, dtype=float)
    Path(path).write_text(svg_document([svg_path(svg_d(pts), "#1f77b4")], [pts]), encoding="utf-8")


# ---------------------------------------------------------------------------------------------------- DXF


def read_profile_dxf(path: str | Path, tolerance: float = FLATTEN_TOLERANCE) -> Points:
    """Read a profile from a DXF drawing whose model space holds exactly one LWPOLYLINE, POLYLINE or SPLINE.

    Polyline bulges (arc pieces) are flattened exactly onto their arcs, splines with ezdxf's adaptive
    flattening; both to ``tolerance`` times the size of the entity's vertices or control points. A polyline
    flagged closed returns to its first point. Only x and y are read (the drawing is taken as planar).
    """
    import ezdxf

    path = Path(path)
    _check_readable(path)
    try:
        document = ezdxf.readfile(str(path))
    except (OSError, ezdxf.DXFError) as exc:
        raise SpecError(
            f"not a readable DXF drawing ({escape_line(str(exc))[:200]}); expected a DXF file",
            source=escape_line(str(path)),
        ) from None
    entities = list(document.modelspace().query("LWPOLYLINE POLYLINE SPLINE"))
    if len(entities) != 1:
        raise SpecError(
            f"found {len(entities)} LWPOLYLINE/POLYLINE/SPLINE entities in model space; expected exactly one",
            source=escape_line(str(path)),
        )
    entity = entities[0]
    kind = entity.dxftype()
    if kind == "SPLINE":
        return spline_points(entity, tolerance, path)
    if kind == "LWPOLYLINE":
        vertices = [(float(x), float(y), float(bulge)) for x, y, bulge in entity.get_points("xyb")]
        closed = bool(entity.closed)
    else:
        if not entity.is_2d_polyline and not entity.is_3d_polyline:
            raise SpecError(
                f"the POLYLINE is a {entity.get_mode()}; expected a 2-D or 3-D polyline",
                source=escape_line(str(path)),
            )
        vertices = [
            (float(v.dxf.location.x), float(v.dxf.location.y), float(v.dxf.get("bulge", 0.0)))
            for v in entity.vertices
        ]
        closed = bool(entity.is_closed)
        if entity.is_3d_polyline:  # its x and y are read: a profile that leaves a plane z = const is refused
            heights = [float(v.dxf.location.z) for v in entity.vertices]
            size = max((max(abs(x), abs(y)) for x, y, _ in vertices), default=0.0)
            if heights and max(heights) - min(heights) > 1e-9 * max(size, max(map(abs, heights))):
                raise SpecError(
                    f"the 3-D POLYLINE's z runs from {min(heights):g} to {max(heights):g}; expected a profile "
                    "drawn in a plane z = constant (its x and y are the profile)",
                    source=escape_line(str(path)),
                )
    if kind == "LWPOLYLINE" or entity.is_2d_polyline:
        vertices = _ocs_to_xy(vertices, entity, path)
    return bulge_polyline(vertices, closed, tolerance)


def _ocs_to_xy(
    vertices: list[tuple[float, float, float]], entity: Any, path: Path
) -> list[tuple[float, float, float]]:
    """The ``(x, y, bulge)`` of a 2-D polyline's vertices in the drawing's x and y (world coordinates).

    A 2-D polyline is written in its object coordinate system (DXF's "arbitrary axis algorithm" on its
    extrusion vector): a polyline mirrored in CAD has the extrusion ``(0, 0, -1)``, whose x axis is the world's
    ``-x``, and its arcs turn the other way seen from ``+z`` (the bulges change sign). Read as they were, its
    points came out mirrored. A polyline in a plane that is not parallel to the world's x-y plane is refused.
    """
    nx, ny, nz = (float(c) for c in entity.dxf.get("extrusion", (0.0, 0.0, 1.0)))
    size = math.sqrt(nx * nx + ny * ny + nz * nz)
    if not (math.isfinite(size) and size > 0.0) or abs(nx) > 1e-12 * size or abs(ny) > 1e-12 * size:
        raise SpecError(
            f"the {entity.dxftype()} lies in a plane with normal ({nx:g}, {ny:g}, {nz:g}); expected a profile "
            "drawn in the x-y plane (normal (0, 0, 1), or (0, 0, -1) when mirrored)",
            source=escape_line(str(path)),
        )
    if nz > 0.0:
        return vertices
    return [
        (0.0 - x, y, -bulge) for x, y, bulge in vertices
    ]  # the arbitrary axis x for -z is -x (0 - x: no -0.0)


_BINARY_DXF = b"AutoCAD Binary DXF"


def dxf_unit(path: str | Path) -> str | None:
    """The length unit a DXF drawing declares in its header (``$INSUNITS``, a name of
    :data:`linkwork.units.DXF_INSUNITS`), or ``None`` for a unitless drawing (code 0, no such variable, or a
    code that is no length unit). The header of a text DXF is scanned as group-code / value line pairs up to the
    end of its HEADER section (the profile itself is read by :func:`read_profile_dxf`); a binary DXF is read
    with ezdxf."""
    path = Path(path)
    with path.open("rb") as file:
        start = file.read(len(_BINARY_DXF))
    code: object = 0
    if start == _BINARY_DXF:
        import ezdxf

        code = ezdxf.readfile(str(path)).header.get("$INSUNITS", 0)
    else:
        with path.open("r", encoding="utf-8", errors="replace", newline=None) as file:
            lines = (line.strip() for line in file)
            for group, value in zip(lines, lines, strict=False):
                if group == "0" and value in ("ENDSEC", "EOF"):
                    break  # the header, where $INSUNITS is, has ended
                if group == "9" and value == "$INSUNITS":
                    pair = (next(lines, ""), next(lines, ""))
                    code = pair[1] if pair[0] == "70" else 0
                    break
    try:
        number = int(str(code).strip())
    except ValueError:
        return None
    entry = DXF_INSUNITS.get(number)
    return entry[0] if entry else None


def profile_unit(path: str | Path) -> str | None:
    """The length unit a profile file declares (a DXF drawing's ``$INSUNITS``, see :func:`dxf_unit`), or
    ``None``: CSV, Selig and SVG profiles, and unitless drawings, are in the problem's units as written."""
    path = Path(path)
    if path.suffix.lower() != ".dxf":
        return None
    _check_readable(path)
    try:
        return dxf_unit(path)
    except Exception:  # an unreadable header is said by load_profile, which reads the whole drawing
        return None


def write_profile_dxf(path: str | Path, points: ArrayLike) -> None:
    """Write a profile as a DXF drawing with one LWPOLYLINE (flagged closed, without the repeated point, when
    the profile returns to its first point), unitless (``$INSUNITS`` 0: a profile carries no unit; ezdxf's own
    default header said metres)."""
    pts = np.asarray(points, dtype=float)
    closed = is_closed(pts)
    document = new_dxf(None)
    document.modelspace().add_lwpolyline(pts[:-1] if closed else pts, format="xy", close=closed)
    document.saveas(str(path))


# ------------------------------------------------------------------------------------------- registry


@dataclass(frozen=True)
class ProfileFormat:
    """One profile file format: its suffixes, a one-line description, and its reader and writer."""

    name: str
    suffixes: tuple[str, ...]
    description: str
    read: Callable[[Path, float], Points]
    write: Callable[[Path, Points], None]


FORMATS: dict[str, ProfileFormat] = {}
"""Every profile format by lower-case suffix (``".csv"``, ``".dat"``, ``".svg"``, ``".dxf"``)."""


def register_format(fmt: ProfileFormat) -> None:
    """Add a profile format to :data:`FORMATS` under each of its suffixes."""
    for suffix in fmt.suffixes:
        FORMATS[suffix.lower()] = fmt


register_format(
    ProfileFormat("CSV", (".csv",), "x,y columns, header optional", read_profile_csv, write_profile_csv)
)
register_format(
    ProfileFormat(
        "Selig", (".dat",), "Selig airfoil: name line, then x y pairs", read_profile_dat, write_profile_dat
    )
)
register_format(
    ProfileFormat(
        "SVG", (".svg",), "one SVG path (y up, curves flattened)", read_profile_svg, write_profile_svg
    )
)
register_format(
    ProfileFormat(
        "DXF", (".dxf",), "one DXF LWPOLYLINE, POLYLINE or SPLINE", read_profile_dxf, write_profile_dxf
    )
)


def _format_for(path: Path) -> ProfileFormat:
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        known = ", ".join(sorted(FORMATS))
        got = f"suffix {path.suffix!r}" if path.suffix else "no suffix"
        raise SpecError(
            f"unknown profile format ({got}); expected one of {known}", source=escape_line(str(path))
        )
    return fmt


def load_profile(path: str | Path, *, tolerance: float = FLATTEN_TOLERANCE) -> Points:
    """Read a design profile from a file, choosing the format by its suffix, and check it.

    Parameters
    ----------
    path
        A ``.csv``, ``.dat`` (Selig), ``.svg`` or ``.dxf`` file (see :data:`FORMATS`).
    tolerance
        Flattening tolerance of curved geometry, a fraction of the drawing's size.

    Returns
    -------
    numpy.ndarray
        The polyline, shape ``(N, 2)``, ``N >= 2``, checked by :func:`check_profile`.

    Raises
    ------
    SpecError
        For an unknown suffix, a missing or unreadable file, or a curve that fails :func:`check_profile`.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> save_profile(folder / "line.csv", [[0.0, 0.0], [1.0, 0.5]])
    >>> load_profile(folder / "line.csv").tolist()
    [[0.0, 0.0], [1.0, 0.5]]
    >>> _ = (folder / "dot.csv").write_text("x,y\\n0,0\\n")
    >>> load_profile(folder / "dot.csv")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    linkwork.errors.SpecError: .../dot.csv: a single point (0, 0); expected a curve of at least 2 points
    """
    path = Path(path)
    fmt = _format_for(path)
    _check_readable(path)
    if path.stat().st_size > MAX_PROFILE_BYTES:
        raise SpecError(
            f"is {path.stat().st_size} bytes, larger than the limit of {MAX_PROFILE_BYTES}; expected a profile",
            source=escape_line(str(path)),
        )
    try:
        points = fmt.read(path, tolerance)
    except SpecError as exc:
        if exc.source is None:
            raise SpecError(exc.detail, source=escape_line(str(path)), key=exc.key) from None
        raise
    except Exception as exc:  # a hostile file can make a third-party parser fail in many ways
        raise SpecError(
            f"could not be read as a {fmt.name} curve ({type(exc).__name__}: {escape_line(str(exc))[:200]})",
            source=escape_line(str(path)),
        ) from None
    return check_profile(points, source=path)


def save_profile(path: str | Path, points: ArrayLike) -> None:
    """Write a profile in the format its suffix names (the inverse of :func:`load_profile`).

    Only what :func:`load_profile` reads back is written: a polyline of shape ``(N, 2)``, ``N >= 2``, every
    coordinate finite (:func:`linkwork.io.writer.require_finite`). A NaN used to be written as ``nan`` into a
    CSV, Selig or DXF file, and a third column dropped silently."""
    path = Path(path)
    fmt = _format_for(path)
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 2:
        raise SpecError(
            f"expected a profile of shape (N, 2) with N >= 2 to write, got shape {pts.shape}",
            source=escape_line(str(path)),
        )
    fmt.write(path, require_finite(pts, f"{escape_line(str(path))}: the profile's points"))


# --------------------------------------------------------------------------------------------- helpers


def _check_readable(path: Path) -> None:
    check_input_file(path, "a profile file")
    try:
        with path.open("rb"):
            pass
    except OSError as exc:
        raise SpecError(
            f"cannot be read ({exc.strerror}); expected a readable file", source=escape_line(str(path))
        ) from None


def _read_lines(path: Path) -> list[tuple[int, str]]:
    """Numbered (1-based), stripped, non-blank lines that are not ``#`` comments.

    Lines end at ``\\n``, ``\\r\\n`` or ``\\r`` only, as in a text editor and Python's ``csv`` module (not at
    every character :meth:`str.splitlines` takes for a break: a form feed or ``\\x85`` inside a comment would
    start a data line, and every later line number would be wrong)."""
    _check_readable(path)
    try:
        text = path.read_bytes().decode("utf-8-sig")
    except UnicodeDecodeError:
        raise SpecError("is not a UTF-8 text file; expected text", source=escape_line(str(path))) from None
    return [
        (number, line.strip())
        for number, line in enumerate(_LINE_END.split(text), start=1)
        if line.strip() and not line.lstrip().startswith("#")
    ]


_LINE_END = re.compile(r"\r\n|\r|\n")


def _quoted(line: str) -> str:
    """A line of a profile file as a message quotes it: Python's ``repr`` (control characters escaped), cut after
    60 characters (a line can be megabytes long)."""
    return repr(line if len(line) <= 60 else line[:57] + "...")


def _cells(count: int) -> str:
    return f"{count} cell" if count == 1 else f"{count} cells"
