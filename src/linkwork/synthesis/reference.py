"""Plain-Python reference of the segment fits (Secs. 3.3, 3.4): loops over points, no numpy batching.

The readable twin of :mod:`~linkwork.synthesis.mean_segment` and :mod:`~linkwork.synthesis.arc_segment`; tests
check that both agree, and the benchmark times the search with it as the non-vectorised baseline.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013), Eqs. (12)-(21).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

Point = tuple[float, float]


def register_rigid(source: Sequence[Point], target: Sequence[Point]) -> tuple[float, float, float]:
    """``(angle, tx, ty)`` of the rigid motion that best maps ``source`` onto ``target`` (least squares)."""
    n = len(source)
    mx = sum(p[0] for p in source) / n
    my = sum(p[1] for p in source) / n
    nx = sum(p[0] for p in target) / n
    ny = sum(p[1] for p in target) / n
    dot = cross = 0.0
    for (x, y), (u, v) in zip(source, target, strict=True):
        x, y, u, v = x - mx, y - my, u - nx, v - ny
        dot += x * u + y * v
        cross += x * v - y * u
    angle = math.atan2(cross, dot)
    c, s = math.cos(angle), math.sin(angle)
    return angle, nx - (c * mx - s * my), ny - (s * mx + c * my)


def apply_rigid(transform: tuple[float, float, float], points: Sequence[Point]) -> list[Point]:
    """Apply ``(angle, tx, ty)`` to points."""
    angle, tx, ty = transform
    c, s = math.cos(angle), math.sin(angle)
    return [(c * x - s * y + tx, s * x + c * y + ty) for x, y in points]


def max_distance(a: Sequence[Point], b: Sequence[Point]) -> float:
    """Largest distance between corresponding points (Eq. 21)."""
    return max(math.hypot(p[0] - q[0], p[1] - q[1]) for p, q in zip(a, b, strict=True))


def mean_segment_errors(pieces: Sequence[Sequence[Point]]) -> list[float]:
    """Errors of an M-segment on each piece (Eqs. 12-15, 21)."""
    first = pieces[0]
    shifted = [list(first)] + [apply_rigid(register_rigid(z, first), z) for z in pieces[1:]]
    n, p = len(first), len(pieces)
    mean = [(sum(s[i][0] for s in shifted) / p, sum(s[i][1] for s in shifted) / p) for i in range(n)]
    return [max_distance(apply_rigid(register_rigid(mean, z), mean), z) for z in pieces]


def arc_segment_errors(pieces: Sequence[Sequence[Point]]) -> list[float]:
    """Errors of a C-segment on each piece (Eqs. 16-21, averaging curvature, Eq. 20 with ``1/p``)."""
    kappas: list[float] = []
    means: list[float] = []
    for z in pieces:
        chords = [math.dist(z[i], z[i + 1]) for i in range(len(z) - 1)]
        means.append(sum(chords) / len(chords))
        for i in range(1, len(z) - 1):
            ax, ay = z[i][0] - z[i - 1][0], z[i][1] - z[i - 1][1]
            bx, by = z[i + 1][0] - z[i][0], z[i + 1][1] - z[i][1]
            denom = math.hypot(ax, ay) * math.hypot(bx, by) * math.dist(z[i + 1], z[i - 1])
            kappas.append(2.0 * (ax * by - ay * bx) / denom if denom > 0 else 0.0)
    kappa = sum(kappas) / len(kappas) if kappas else 0.0
    s_bar = sum(means) / len(means)
    turn = 2.0 * math.asin(max(-1.0, min(1.0, 0.5 * kappa * s_bar)))
    errors = []
    for z in pieces:
        arc = [(0.0, 0.0)]
        for i in range(len(z) - 1):
            x, y = arc[-1]
            arc.append((x + s_bar * math.cos(turn * i), y + s_bar * math.sin(turn * i)))
        errors.append(max_distance(apply_rigid(register_rigid(arc, z), arc), z))
    return errors
