"""Profile files: every reader round-trips analytic curves, flattens curves within its stated tolerance, and
refuses bad input with one line naming the file and what was expected."""

from __future__ import annotations

import math
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from linkwork.errors import SpecError
from linkwork.io.profiles import (
    FLATTEN_TOLERANCE,
    FORMATS,
    check_profile,
    find_self_crossing,
    is_closed,
    load_profile,
    save_profile,
    write_profile_dat,
)

ROUND_TRIP = 1e-9  # files keep 12 significant digits: coordinates of size ~10 come back within 1e-10


def parabola(count: int = 41) -> np.ndarray:
    """Points of y = x (2 - x) on [0, 2]."""
    x = np.linspace(0.0, 2.0, count)
    return np.column_stack([x, x * (2.0 - x)])


def circle_arc(radius: float = 2.0, count: int = 50) -> np.ndarray:
    t = np.linspace(0.0, 0.75 * math.pi, count)
    return np.column_stack([radius * np.cos(t) + 1.0, radius * np.sin(t) - 3.0])


def chord_deviation(points: np.ndarray, curve: np.ndarray) -> float:
    """Largest distance of the densely sampled ``curve`` from the polyline ``points``."""
    a, b = points[:-1], points[1:]
    d = b - a
    worst = 0.0
    for p in curve:
        t = np.clip(np.einsum("ij,ij->i", p - a, d) / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
        worst = max(worst, float(np.min(np.hypot(*(a + t[:, None] * d - p).T))))
    return worst


def size(points: np.ndarray) -> float:
    return float(np.hypot(*np.ptp(points, axis=0)))


# ------------------------------------------------------------------------------------------ round trips


@pytest.mark.parametrize("suffix", [".csv", ".dat", ".svg", ".dxf"])
@pytest.mark.parametrize("curve", [parabola(), circle_arc()], ids=["parabola", "arc"])
def test_polyline_round_trip_in_every_format(tmp_path: Path, suffix: str, curve: np.ndarray) -> None:
    path = tmp_path / f"curve{suffix}"
    save_profile(path, curve)
    back = load_profile(path)
    assert back.shape == curve.shape
    np.testing.assert_allclose(back, curve, rtol=0, atol=ROUND_TRIP)


@pytest.mark.parametrize("suffix", [".csv", ".svg", ".dxf"])
def test_closed_curve_round_trip_returns_to_its_start(tmp_path: Path, suffix: str) -> None:
    t = np.linspace(0.0, 2.0 * math.pi, 37)
    ring = np.column_stack([np.cos(t), 0.5 * np.sin(t)])
    ring[-1] = ring[0]
    path = tmp_path / f"ring{suffix}"
    save_profile(path, ring)
    back = load_profile(path)
    assert is_closed(back)
    np.testing.assert_allclose(back, ring, rtol=0, atol=ROUND_TRIP)


def test_csv_header_is_optional_and_names_columns(tmp_path: Path) -> None:
    plain = tmp_path / "plain.csv"
    plain.write_text("0,0\n1,2\n3,4\n", encoding="utf-8")
    named = tmp_path / "named.csv"
    named.write_text("# a comment\nid,Y,X\n1,0,0\n2,2,1\n\n3,4,3\n", encoding="utf-8")
    expected = np.array([[0.0, 0.0], [1.0, 2.0], [3.0, 4.0]])
    np.testing.assert_allclose(load_profile(plain), expected, rtol=0, atol=0)
    np.testing.assert_allclose(load_profile(named), expected, rtol=0, atol=0)


def test_selig_file_with_name_line(tmp_path: Path) -> None:
    path = tmp_path / "foil.dat"
    write_profile_dat(path, parabola(), name="NACA 0012 test")
    assert path.read_text(encoding="utf-8").splitlines()[0] == "NACA 0012 test"
    np.testing.assert_allclose(load_profile(path), parabola(), rtol=0, atol=ROUND_TRIP)


# ------------------------------------------------------------------------------------------- flattening


def test_svg_arc_is_flattened_onto_the_circle(tmp_path: Path) -> None:
    path = tmp_path / "arc.svg"
    # A half circle of radius 2 about the origin, drawn in millimetres with a viewBox: user units come back.
    path.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="60mm" height="40mm" viewBox="-3 -3 6 4">'
        '<g transform="translate(0.5, 0)"><path d="M 1.5,0 A 2 2 0 0 0 -2.5 0"/></g></svg>',
        encoding="utf-8",
    )
    pts = load_profile(path)
    radius = np.hypot(*pts.T)
    np.testing.assert_allclose(radius, 2.0, rtol=0, atol=1e-9)  # every vertex on the circle
    assert pts[len(pts) // 2, 1] > 1.9  # y up: the arc bulges to +y (SVG's -y)
    half_angle = np.arccos(np.clip(np.einsum("ij,ij->i", pts[:-1], pts[1:]) / 4.0, -1, 1)) / 2.0
    sagitta = 2.0 * (1.0 - np.cos(half_angle))
    tolerance = FLATTEN_TOLERANCE * size(pts)
    assert sagitta.max() <= tolerance * (1 + 1e-9)
    assert sagitta.max() >= 0.25 * tolerance  # not wastefully fine


def test_svg_quadratic_bezier_is_flattened_onto_the_parabola(tmp_path: Path) -> None:
    # The quadratic Bézier (0,0) (1,-2) (2,0) in SVG coordinates is y = x (2 - x) after flipping y.
    path = tmp_path / "parabola.svg"
    path.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg"><path d="M 0,0 Q 1,-2 2,0"/></svg>', encoding="utf-8"
    )
    pts = load_profile(path)
    np.testing.assert_allclose(pts[:, 1], pts[:, 0] * (2.0 - pts[:, 0]), rtol=0, atol=1e-9)
    np.testing.assert_allclose(pts[[0, -1]], [[0.0, 0.0], [2.0, 0.0]], rtol=0, atol=1e-12)
    tolerance = FLATTEN_TOLERANCE * size(np.array([[0.0, 0.0], [1.0, 2.0], [2.0, 0.0]]))
    assert chord_deviation(pts, parabola(4001)) <= tolerance * (1 + 1e-6)


def test_dxf_bulge_is_flattened_onto_its_arc(tmp_path: Path) -> None:
    document = ezdxf.new()
    # (0,0) -> (2,0) straight, then a half circle (bulge 1, counter-clockwise) to (2,2), then to (0,2).
    document.modelspace().add_lwpolyline([(0, 0, 0), (2, 0, 1), (2, 2, 0), (0, 2, 0)], format="xyb")
    path = tmp_path / "bulge.dxf"
    document.saveas(path)
    pts = load_profile(path)
    on_arc = pts[1:-1]
    np.testing.assert_allclose(np.hypot(on_arc[:, 0] - 2.0, on_arc[:, 1] - 1.0), 1.0, rtol=0, atol=1e-9)
    assert on_arc[:, 0].max() > 2.99  # counter-clockwise from (2,0) to (2,2) passes (3,1)
    np.testing.assert_allclose(pts[[0, 1, -2, -1]], [[0, 0], [2, 0], [2, 2], [0, 2]], rtol=0, atol=1e-12)
    tolerance = FLATTEN_TOLERANCE * size(np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=float))
    t = np.linspace(-math.pi / 2, math.pi / 2, 4001)
    arc = np.column_stack([2.0 + np.cos(t), 1.0 + np.sin(t)])
    assert chord_deviation(on_arc, arc) <= tolerance * (1 + 1e-6)


def test_dxf_spline_is_flattened_onto_the_parabola(tmp_path: Path) -> None:
    # A clamped quadratic B-spline with control points (0,0) (1,2) (2,0) is the parabola y = x (2 - x).
    document = ezdxf.new()
    document.modelspace().add_open_spline([(0, 0), (1, 2), (2, 0)], degree=2)
    path = tmp_path / "spline.dxf"
    document.saveas(path)
    pts = load_profile(path)
    np.testing.assert_allclose(pts[:, 1], pts[:, 0] * (2.0 - pts[:, 0]), rtol=0, atol=1e-9)
    np.testing.assert_allclose(pts[[0, -1]], [[0.0, 0.0], [2.0, 0.0]], rtol=0, atol=1e-12)
    tolerance = FLATTEN_TOLERANCE * size(np.array([[0.0, 0.0], [1.0, 2.0], [2.0, 0.0]]))
    assert chord_deviation(pts, parabola(4001)) <= tolerance * (1 + 1e-6)


def test_tighter_tolerance_gives_more_points(tmp_path: Path) -> None:
    path = tmp_path / "arc.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg"><path d="M 1,0 A 1 1 0 0 0 -1 0"/></svg>')
    coarse, fine = load_profile(path, tolerance=1e-3), load_profile(path, tolerance=1e-5)
    # sagitta ~ r dphi^2 / 8: a hundredth of the tolerance needs about ten times the points (within 30 %).
    assert 7.0 <= (len(fine) - 1) / (len(coarse) - 1) <= 13.0


# ---------------------------------------------------------------------------------------------- refusals


def one_line_error(path: Path, **kwargs: float) -> str:
    with pytest.raises(SpecError) as info:
        load_profile(path, **kwargs)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: ")
    return message


@pytest.mark.parametrize(
    ("name", "content", "expected"),
    [
        ("empty.csv", "", "no points; expected a curve of at least 2 points"),
        ("header_only.csv", "x,y\n", "no points"),
        ("single.csv", "x,y\n1,2\n", "a single point (1, 2); expected a curve of at least 2 points"),
        ("nan.csv", "0,0\n1,nan\n2,0\n", "point 2 is (1, nan); expected finite numbers"),
        ("inf.csv", "0,0\n1,1\ninf,0\n", "point 3 is (inf, 0); expected finite numbers"),
        ("repeat.csv", "0,0\n1,1\n1,1\n2,0\n", "points 2 and 3 repeat (1, 1); expected distinct consecutive"),
        (
            "cross.csv",
            "0,0\n2,2\n2,0\n0,2\n",
            "the curve crosses itself: piece 1-2 meets piece 3-4 at (1, 1)",
        ),
        ("fold.csv", "0,0\n2,0\n1,0\n", "the curve crosses itself: piece 1-2 meets piece 2-3"),
        (
            "touch.csv",
            "0,0\n4,0\n4,2\n2,0\n",
            "the curve crosses itself: piece 1-2 meets piece 3-4 at (2, 0)",
        ),
        ("text.csv", "0,0\n1,abc\n", "line 2: expected numbers in columns x and y, got '1,abc'"),
        ("columns.csv", "a,b\n0,0\n", "line 1: header 'a,b' names no x and y columns"),
        ("short.csv", "0,0\n1\n", "line 2: expected numbers in columns x and y"),
        ("bad.dat", "foil\n0 0\n1\n", "line 3: expected two numbers 'x y', got '1'"),
        ("lednicer.dat", "foil\n61. 61.\n0 0\n1 0\n", "looks like a Lednicer point-count line"),
        ("bad.svg", "<svg><path d='M 0 0 L", "not a readable SVG drawing"),
        (
            "none.svg",
            '<svg xmlns="http://www.w3.org/2000/svg"></svg>',
            "found 0 shapes; expected exactly one",
        ),
        (
            "two.svg",
            '<svg xmlns="http://www.w3.org/2000/svg"><path d="M0,0 L1,1"/><path d="M2,0 L3,1"/></svg>',
            "found 2 shapes; expected exactly one",
        ),
        (
            "parts.svg",
            '<svg xmlns="http://www.w3.org/2000/svg"><path d="M0,0 L1,1 M2,0 L3,1"/></svg>',
            "the path has 2 parts (M commands); expected one continuous curve",
        ),
        ("bad.dxf", "this is not a drawing\n", "not a readable DXF drawing"),
        (
            "curve.txt",
            "0,0\n1,1\n",
            "unknown profile format (suffix '.txt'); expected one of .csv, .dat, .dxf, .svg",
        ),
        ("noext", "0,0\n1,1\n", "unknown profile format (no suffix)"),
    ],
)
def test_bad_profile_is_one_line_naming_the_file(
    tmp_path: Path, name: str, content: str, expected: str
) -> None:
    path = tmp_path / name
    path.write_text(content, encoding="utf-8")
    assert expected in one_line_error(path)


def test_missing_folder_and_binary_files(tmp_path: Path) -> None:
    assert "file not found; expected a profile file" in one_line_error(tmp_path / "gone.csv")
    (tmp_path / "dir.csv").mkdir()
    assert "is a folder; expected a profile file" in one_line_error(tmp_path / "dir.csv")
    binary = tmp_path / "binary.csv"
    binary.write_bytes(b"\xff\xfe\x00\x81garbage")
    assert "is not a UTF-8 text file" in one_line_error(binary)


def test_dxf_without_a_curve(tmp_path: Path) -> None:
    document = ezdxf.new()
    document.modelspace().add_line((0, 0), (1, 1))
    path = tmp_path / "line_only.dxf"
    document.saveas(path)
    assert (
        "found 0 LWPOLYLINE/POLYLINE/SPLINE entities in model space; expected exactly one"
        in one_line_error(path)
    )


def test_closed_curve_may_return_to_its_start_but_not_cross() -> None:
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]], dtype=float)
    assert find_self_crossing(square) is None
    np.testing.assert_array_equal(check_profile(square), square)
    bowtie = np.array([[0, 0], [1, 1], [1, 0], [0, 1], [0, 0]], dtype=float)
    assert find_self_crossing(bowtie) == (0, 2)
    with pytest.raises(SpecError, match=r"^bowtie.csv: the curve crosses itself"):
        check_profile(bowtie, "bowtie.csv")


def test_every_format_is_registered_with_reader_and_writer() -> None:
    assert sorted(FORMATS) == [".csv", ".dat", ".dxf", ".svg"]
    for fmt in FORMATS.values():
        assert callable(fmt.read) and callable(fmt.write) and fmt.description


# --------------------------------------------------------------------------------------- self-crossing


def brute_force_crossing(points: np.ndarray) -> bool:
    """Whether two non-neighbouring pieces intersect, by exact orientation tests on every pair."""

    def orient(p: np.ndarray, q: np.ndarray, r: np.ndarray) -> float:
        return float((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))

    n = len(points) - 1
    for i in range(n):
        for j in range(i + 2, n):
            a, b, c, d = points[i], points[i + 1], points[j], points[j + 1]
            if orient(a, b, c) * orient(a, b, d) < 0 and orient(c, d, a) * orient(c, d, b) < 0:
                return True
    return False


@settings(max_examples=200, deadline=None)
@given(st.integers(min_value=0, max_value=2**32 - 1), st.integers(min_value=3, max_value=14))
def test_crossing_search_agrees_with_brute_force_on_random_walks(seed: int, count: int) -> None:
    # Random walks in general position: proper crossings are the only way to meet, so the sweep and the
    # O(n^2) check must agree exactly (a fold-back of neighbours counts for the sweep only).
    walk = np.cumsum(np.random.default_rng(seed).normal(size=(count, 2)), axis=0)
    found = find_self_crossing(walk)
    if found is not None and found[1] == found[0] + 1:
        return
    assert (found is not None) == brute_force_crossing(walk)


@settings(max_examples=40, derandomize=True, deadline=None)
@given(
    coordinates=st.lists(
        st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)), min_size=3, max_size=12, unique=True
    ),
    transpose=st.booleans(),
)
def test_the_self_crossing_check_agrees_with_every_pair_tested(
    coordinates: list[tuple[float, float]], transpose: bool
) -> None:
    """The sweep now runs along x or y, whichever has fewer candidate pairs; either way it finds a crossing
    exactly when testing every pair does (random points: general position, open curves)."""
    points = np.array(coordinates)[:, ::-1] if transpose else np.array(coordinates)
    if np.min(np.hypot(*np.diff(points, axis=0).T)) < 1e-6:
        return  # repeated points are refused before the crossing check
    closeness = np.abs(np.diff(points, axis=0)).min()
    if closeness < 1e-9:
        return  # nearly axis-parallel pieces: within the check's tolerance, not general position
    u, v = np.diff(points, axis=0)[:-1], np.diff(points, axis=0)[1:]
    sine = np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]) / (np.hypot(*u.T) * np.hypot(*v.T))
    if np.any((sine < 1e-9) & (np.sum(u * v, axis=1) < 0.0)):
        return  # a piece doubling back along the last, within the check's tolerance: it overlaps, which the
        # every-pair reference (non-adjacent pieces only) does not test; (0, 1e-12) -> (1, 1) -> (0, 0) is one
    assert (find_self_crossing(points) is not None) == brute_force_crossing(points)


@settings(max_examples=100, deadline=None)
@given(st.integers(min_value=0, max_value=2**32 - 1), st.integers(min_value=3, max_value=60))
def test_star_shaped_polygons_are_simple(seed: int, count: int) -> None:
    rng = np.random.default_rng(seed)
    angles = np.sort(rng.uniform(0.0, 2.0 * math.pi, count))
    gaps = np.diff(angles, append=angles[0] + 2 * math.pi)
    angles = angles[gaps > 1e-3]
    assume(len(angles) >= 3 and gaps.max() < math.pi)  # a polygon (not a fold) around the origin
    radii = rng.uniform(0.5, 2.0, len(angles))
    polygon = np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])
    polygon = np.vstack([polygon, polygon[:1]])
    assert find_self_crossing(polygon) is None
