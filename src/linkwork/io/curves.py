"""Polylines of the profile readers: the checks every design profile passes, and the flattening of curved
geometry (SVG arcs and Bezier curves, DXF bulges and splines) into straight pieces within a tolerance and a
stated budget of points.

Every bound here is stated and enforced with a :class:`~linkwork.errors.SpecError`: coordinates within
:data:`MAX_COORDINATE`, at most :data:`MAX_FLATTENED_POINTS` points from curved geometry, DXF bulges within
:data:`MAX_BULGE`.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.errors import SpecError
from linkwork.messages import escape_line

Points = NDArray[np.float64]

FLATTEN_TOLERANCE = 1e-4
"""Largest distance of a flattened piece from the true curve, as a fraction of the drawing's size."""

COINCIDENT = 1e-9
"""Two consecutive points closer than this fraction of the curve's size count as one repeated point."""

MAX_COORDINATE = 1e12
"""The largest coordinate (absolute value) of a profile point accepted."""

MAX_FLATTENED_POINTS = 200_000
"""The most points curved geometry (arcs, bulges, Bézier curves, splines) may be flattened into."""

MAX_CROSSING_PAIRS = 50_000_000
"""The most pairs of pieces the self-crossing check of a profile tests (about a minute on one core): a curve
folding back and forth across its whole width in both x and y needs more, and is refused rather than checked
for hours."""

MAX_BULGE = 1e6
"""The largest DXF bulge (tan of a quarter of the arc's included angle) accepted."""

_MAX_DEPTH = 24  # recursion limit of the adaptive flattening: 2**24 pieces per curve segment at most


# ---------------------------------------------------------------------------------------------------- checks


def bounding_size(points: Points) -> float:
    """The diagonal of the bounding box of ``points`` (1 for a degenerate box: tolerances stay positive)."""
    if len(points) == 0:
        return 1.0
    diagonal = float(np.hypot(*(points.max(axis=0) - points.min(axis=0))))
    return diagonal if diagonal > 0.0 else 1.0


def _fmt_point(point: Sequence[float] | Points) -> str:
    return f"({float(point[0]):.6g}, {float(point[1]):.6g})"


def is_closed(points: ArrayLike) -> bool:
    """True when the polyline returns to its first point (to :data:`COINCIDENT` of its size).

    Parameters
    ----------
    points
        A polyline of shape ``(N, 2)``.
    """
    pts = np.asarray(points, dtype=float)
    if len(pts) < 3:
        return False
    return bool(np.hypot(*(pts[-1] - pts[0])) <= COINCIDENT * bounding_size(pts))


def find_self_crossing(points: ArrayLike) -> tuple[int, int] | None:
    """The first pair of pieces of a polyline that meet other than at their shared point, or None.

    Piece ``i`` joins points ``i`` and ``i + 1``. Neighbouring pieces may share their common point but must
    not fold back onto each other; no other two pieces may touch. For a closed polyline (last point equal
    to the first) the first and last pieces share the closing point, which is not a crossing.

    Parameters
    ----------
    points
        A polyline of shape ``(N, 2)`` with distinct consecutive points.

    Returns
    -------
    tuple of int or None
        ``(i, j)`` with ``i < j``, the indices of two offending pieces, or ``None`` for a simple curve.
    """
    pts = np.asarray(points, dtype=float)
    n_pieces = len(pts) - 1
    if n_pieces < 2:
        return None
    closed = is_closed(pts)
    length_tol = COINCIDENT * bounding_size(pts)
    a, b = pts[:-1], pts[1:]
    direction = b - a
    piece_length = np.hypot(direction[:, 0], direction[:, 1])

    # Neighbours fold back when they are antiparallel and collinear (a turn of 180 degrees).
    pairs = [(i, i + 1) for i in range(n_pieces - 1)]
    if closed and n_pieces > 2:
        pairs.append((0, n_pieces - 1))
    for p, q in pairs:
        cross = direction[p, 0] * direction[q, 1] - direction[p, 1] * direction[q, 0]
        dot = direction[p] @ direction[q]
        if abs(cross) <= length_tol * max(piece_length[p], piece_length[q]) and dot < 0.0:
            return (p, q)

    lo = np.minimum(a, b) - length_tol
    hi = np.maximum(a, b) + length_tol

    # Sweep along x or y: after sorting pieces by their low end on that axis, piece k can only meet the pieces
    # that start before it ends, a contiguous run found by searchsorted; the run is short for any curve but a
    # tangle. The axis is the one with fewer candidate pairs: a zigzag of pieces across the whole width (a
    # serpentine, hatching) overlaps every other piece along x, so the x sweep alone was quadratic (10,000
    # points took 20 s, the 200,000 a profile may have, hours).
    order, counts = _sweep(lo, hi, 0)
    total = int(counts.sum())
    if total > n_pieces:
        order_y, counts_y = _sweep(lo, hi, 1)
        if int(counts_y.sum()) < total:
            order, counts, total = order_y, counts_y, int(counts_y.sum())
    if total > MAX_CROSSING_PAIRS:
        raise SpecError(
            f"the curve's {n_pieces} pieces lie so close together along x and y that checking it for "
            f"self-crossings means {total} pairs of pieces; expected at most {MAX_CROSSING_PAIRS} (fewer points, "
            "or a curve that does not fold back and forth across its whole width)"
        )
    offsets = np.cumsum(counts) - counts
    batch = 1_000_000
    for first in range(0, total, batch):
        flat = np.arange(first, min(first + batch, total))
        k = np.searchsorted(offsets, flat, side="right") - 1
        first_piece, other_piece = order[k], order[k + 1 + flat - offsets[k]]
        i, j = np.minimum(first_piece, other_piece), np.maximum(first_piece, other_piece)
        keep = (j >= i + 2) & np.all(lo[i] <= hi[j], axis=1) & np.all(lo[j] <= hi[i], axis=1)
        if closed:
            keep &= ~((i == 0) & (j == n_pieces - 1))
        i, j = i[keep], j[keep]
        hit = _pieces_meet(a[i], b[i], a[j], b[j], length_tol)
        if hit.any():
            pick = np.lexsort((j[hit], i[hit]))[0]
            return (int(i[hit][pick]), int(j[hit][pick]))
    return None


def _sweep(lo: Points, hi: Points, axis: int) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """The pieces in order of their low end along ``axis``, and for each how many later pieces start before it
    ends there (the candidates it is tested against)."""
    order = np.argsort(lo[:, axis], kind="stable")
    run_end = np.searchsorted(lo[order, axis], hi[order, axis], side="right")
    return order, np.maximum(run_end - np.arange(len(order)) - 1, 0)


def _pieces_meet(a: Points, b: Points, c: Points, d: Points, length_tol: float) -> NDArray[np.bool_]:
    """Whether pieces ``a-b`` and ``c-d`` (rows of ``(K, 2)`` arrays) touch; their bounding boxes overlap.

    Each piece's end points must lie on opposite sides of (or on) the other piece's line; "on" means within
    ``length_tol``. Collinear pieces pass both tests, and their overlapping boxes then mean they overlap.
    """

    def orient(p: Points, q: Points, r: Points) -> Points:
        return (q[:, 0] - p[:, 0]) * (r[:, 1] - p[:, 1]) - (q[:, 1] - p[:, 1]) * (r[:, 0] - p[:, 0])

    zero_ab = length_tol * np.hypot(*(b - a).T)
    zero_cd = length_tol * np.hypot(*(d - c).T)
    d1, d2 = orient(a, b, c), orient(a, b, d)
    d3, d4 = orient(c, d, a), orient(c, d, b)
    straddle_cd = ((d1 <= zero_ab) & (d2 >= -zero_ab)) | ((d1 >= -zero_ab) & (d2 <= zero_ab))
    straddle_ab = ((d3 <= zero_cd) & (d4 >= -zero_cd)) | ((d3 >= -zero_cd) & (d4 <= zero_cd))
    return np.asarray(straddle_ab & straddle_cd)


def _meeting_point(points: Points, i: int, j: int) -> Points:
    """Where pieces ``i`` and ``j`` of a polyline meet (their lines' intersection, or a shared end point)."""
    a, b, c, d = points[i], points[i + 1], points[j], points[j + 1]
    u, v = b - a, d - c
    det = u[0] * v[1] - u[1] * v[0]
    if abs(det) > 1e-300:
        t = ((c[0] - a[0]) * v[1] - (c[1] - a[1]) * v[0]) / det
        return a + min(max(t, 0.0), 1.0) * u
    return c if np.dot(c - a, c - b) <= 0.0 else a


def check_profile(points: ArrayLike, source: str | Path | None = None) -> Points:
    """Check that ``points`` is a usable design profile and return it as a float array of shape ``(N, 2)``.

    A usable profile has at least two points, every coordinate finite, no point repeating the one before it,
    and does not cross itself (a closed curve may return to its first point).

    Parameters
    ----------
    points
        The polyline, shape ``(N, 2)``.
    source
        The file it came from, named in the error message.

    Raises
    ------
    SpecError
        Naming ``source``, what is wrong (1-based point numbers) and what was expected.
    """
    where = escape_line(str(source)) if source is not None else None
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2:
        if pts.size == 0:
            raise SpecError("no points; expected a curve of at least 2 points (x, y)", source=where)
        raise SpecError(f"expected points of shape (N, 2), got shape {pts.shape}", source=where)
    if len(pts) == 0:
        raise SpecError("no points; expected a curve of at least 2 points (x, y)", source=where)
    if len(pts) == 1:
        raise SpecError(
            f"a single point {_fmt_point(pts[0])}; expected a curve of at least 2 points", source=where
        )
    bad = np.flatnonzero(~np.isfinite(pts).all(axis=1))
    if len(bad):
        raise SpecError(
            f"point {bad[0] + 1} is {_fmt_point(pts[bad[0]])}; expected finite numbers", source=where
        )
    huge = np.flatnonzero((np.abs(pts) > MAX_COORDINATE).any(axis=1))
    if len(huge):
        raise SpecError(
            f"point {huge[0] + 1} is {_fmt_point(pts[huge[0]])}; expected coordinates within +-{MAX_COORDINATE:g}",
            source=where,
        )
    step = np.hypot(*np.diff(pts, axis=0).T)
    repeated = np.flatnonzero(step <= COINCIDENT * bounding_size(pts))
    if len(repeated):
        i = int(repeated[0])
        raise SpecError(
            f"points {i + 1} and {i + 2} repeat {_fmt_point(pts[i])}; expected distinct consecutive points",
            source=where,
        )
    crossing = find_self_crossing(pts)
    if crossing is not None:
        i, j = crossing
        raise SpecError(
            f"the curve crosses itself: piece {i + 1}-{i + 2} meets piece {j + 1}-{j + 2} at "
            f"{_fmt_point(_meeting_point(pts, i, j))}; expected a curve that does not overlap itself",
            source=where,
        )
    return pts


# ------------------------------------------------------------------------------------------- flattening


def flatten_curve(
    curve: Callable[[float], tuple[float, float]],
    tolerance: float,
    depth: int = 0,
    t0: float = 0.0,
    t1: float = 1.0,
    p0: tuple[float, float] | None = None,
    p1: tuple[float, float] | None = None,
) -> list[tuple[float, float]]:
    """Points of ``curve`` on ``(t0, t1]`` such that no chord strays more than ``tolerance`` from the curve.

    The chord is checked against the curve at a quarter, half and three quarters of its parameter range, and
    the first two levels always subdivide, so an S-shaped piece whose middle happens to lie on its chord is
    still followed.
    """
    p0 = curve(t0) if p0 is None else p0
    p1 = curve(t1) if p1 is None else p1
    if depth >= 2 and depth < _MAX_DEPTH:
        chord = np.subtract(p1, p0)
        chord_length = float(np.hypot(*chord))
        worst = 0.0
        for s in (0.25, 0.5, 0.75):
            q = np.subtract(curve(t0 + s * (t1 - t0)), p0)
            if chord_length > 0.0:
                along = min(max(float(q @ chord) / chord_length**2, 0.0), 1.0)
                worst = max(worst, float(np.hypot(*(q - along * chord))))
            else:
                worst = max(worst, float(np.hypot(*q)))
        if worst <= tolerance:
            return [p1]
    elif depth >= _MAX_DEPTH:
        return [p1]
    tm = 0.5 * (t0 + t1)
    pm = curve(tm)
    return flatten_curve(curve, tolerance, depth + 1, t0, tm, p0, pm) + flatten_curve(
        curve, tolerance, depth + 1, tm, t1, pm, p1
    )


def _arc_points(
    center: tuple[float, float], radius: float, start: float, sweep: float, tolerance: float
) -> list[tuple[float, float]]:
    """Points on a circular arc after its start, at equal angles, with sagitta at most ``tolerance``."""
    if radius <= tolerance:
        count = 1
    else:
        # sagitta r (1 - cos(dphi / 2)) <= tolerance, i.e. dphi = 4 asin(sqrt(tolerance / (2 r))) (no
        # cancellation for a huge radius)
        dphi = 4.0 * math.asin(min(1.0, math.sqrt(tolerance / (2.0 * radius))))
        wanted = abs(sweep) / dphi if dphi > 0.0 else math.inf
        if not wanted <= MAX_FLATTENED_POINTS:
            raise SpecError(
                f"an arc of radius {radius:.6g} would need {wanted:.3g} points; expected at most "
                f"{MAX_FLATTENED_POINTS} (a smaller arc or a larger tolerance)"
            )
        count = max(1, math.ceil(wanted))
    angles = start + sweep * np.arange(1, count + 1) / count
    return [(center[0] + radius * math.cos(a), center[1] + radius * math.sin(a)) for a in angles]


def spline_points(entity: Any, tolerance: float, path: Path) -> Points:
    """A DXF SPLINE flattened by ezdxf to ``tolerance`` times the size of its control points (refused when they
    leave a plane z = constant by more than ``1e-9`` of their size)."""
    count = len(entity.control_points)
    order = int(entity.dxf.get("degree", 3)) + 1
    if count < max(2, order) and len(entity.fit_points) < 2:
        raise SpecError(
            f"the SPLINE has {count} control points for degree {order - 1}; expected at least {max(2, order)}",
            source=escape_line(str(path)),
        )
    spline = entity.construction_tool()
    control_xyz = np.array([(v.x, v.y, v.z) for v in spline.control_points], dtype=float).reshape(-1, 3)
    control, heights = control_xyz[:, :2], control_xyz[:, 2]
    if not np.all(np.isfinite(control_xyz)) or np.abs(control_xyz).max() > MAX_COORDINATE:
        raise SpecError(
            f"the SPLINE has a control point that is not finite or beyond +-{MAX_COORDINATE:g}",
            source=escape_line(str(path)),
        )
    # A SPLINE is in world coordinates: its x and y are the profile only when it lies in a plane z = constant
    # (as a 3-D POLYLINE's, read_profile_dxf); one that leaves it would be read as its projection.
    if float(np.ptp(heights)) > 1e-9 * float(np.abs(control_xyz).max()):
        raise SpecError(
            f"the SPLINE's control points' z runs from {heights.min() + 0.0:g} to {heights.max() + 0.0:g}; expected a "
            "profile drawn in a plane z = constant (its x and y are the profile)",
            source=escape_line(str(path)),
        )
    absolute = tolerance * bounding_size(control)
    points = []
    for v in spline.flattening(absolute, segments=8):
        points.append((v.x, v.y))
        if len(points) > MAX_FLATTENED_POINTS:
            raise SpecError(
                f"the SPLINE flattens into more than {MAX_FLATTENED_POINTS} points",
                source=escape_line(str(path)),
            )
    return np.array(points, dtype=float)


def bulge_polyline(vertices: list[tuple[float, float, float]], closed: bool, tolerance: float) -> Points:
    """Flatten polyline vertices ``(x, y, bulge)`` whose bulge turns the piece after a vertex into an arc."""
    from ezdxf.math import bulge_to_arc

    if not vertices:
        return np.empty((0, 2))
    absolute = tolerance * bounding_size(np.array([v[:2] for v in vertices], dtype=float))
    chain = [*vertices, vertices[0]] if closed else vertices
    points = [chain[0][:2]]
    for number, ((x0, y0, bulge), (x1, y1, _)) in enumerate(itertools.pairwise(chain), start=1):
        if not (math.isfinite(bulge) and abs(bulge) <= MAX_BULGE):
            raise SpecError(
                f"vertex {number}: bulge {bulge!r}; expected a finite bulge within +-{MAX_BULGE:g}"
            )
        # An arc whose sagitta (|bulge| * chord / 2) is within the tolerance is its chord.
        if abs(bulge) * math.hypot(x1 - x0, y1 - y0) / 2.0 <= absolute or (x0, y0) == (x1, y1):
            points.append((x1, y1))
            continue
        center, _start, _end, radius = bulge_to_arc((x0, y0), (x1, y1), bulge)
        sweep = 4.0 * math.atan(bulge)  # included angle; positive bulge turns counter-clockwise
        begin = math.atan2(y0 - center.y, x0 - center.x)
        arc = _arc_points((center.x, center.y), radius, begin, sweep, absolute)
        arc[-1] = (x1, y1)  # land exactly on the next vertex
        points += arc
        if len(points) > MAX_FLATTENED_POINTS:
            raise SpecError(
                f"the bulges flatten into more than {MAX_FLATTENED_POINTS} points; expected fewer"
            )
    return np.array(points, dtype=float)
