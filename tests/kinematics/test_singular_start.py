"""A start whose Jacobian rank says "mobility 2": a crossing of one-parameter branches, an isolated rigid point,
or a true two-degree-of-freedom linkage are told apart, each refused with what is true of it.

Outside references: a parallelogram four-bar laid flat is the change point where its parallelogram and
antiparallelogram branches cross (two lines); a four-bar whose crank, coupler and rocker add up to the ground,
laid straight, cannot move (the triangle inequality holds with equality); a planar five-bar has mobility 2
(Gruebler: 3 (5 - 1) - 2 * 5).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import linkwork as lw
from linkwork.errors import LinkworkError

DEG = np.pi / 180.0


def flat_parallelogram_rows(angles: np.ndarray, a: float, g: float) -> tuple[float, np.ndarray]:
    """The largest closure mismatch of the parallelogram four-bar (crank and rocker ``a``, coupler and ground ``g``,
    laid flat at the start: every joint reads 0 there) at each row, by circle intersection written here (B on the
    crank circle at angle A, C = B + g (cos, sin) of the coupler's angle A + B, then |C - D| = a with D = (g, 0)),
    and whether each row is on the parallelogram branch (B = -A, wrapped)."""
    ang_a, ang_b = angles[:, 0], angles[:, 1]
    pb = a * np.stack([np.cos(ang_a), np.sin(ang_a)], axis=1)
    pc = pb + g * np.stack([np.cos(ang_a + ang_b), np.sin(ang_a + ang_b)], axis=1)
    mismatch = float(np.abs(np.linalg.norm(pc - np.array([g, 0.0]), axis=1) - a).max())
    return mismatch, np.abs((ang_b + ang_a + np.pi) % (2 * np.pi) - np.pi) < 1e-9


@pytest.mark.parametrize(("a", "g"), [(1.0, 2.0), (0.5, 3.0), (2.0, 2.5), (3.0, 1.2)])
@pytest.mark.parametrize(
    ("kw", "parallelogram_only"),
    [
        ({}, True),
        ({"until": ("A", 90 * DEG)}, True),
        ({"until": ("A", -120 * DEG), "steps": 12}, True),
        ({"branches": True, "max_steps": 3000}, False),
    ],
)
def test_a_parallelogram_laid_flat_is_traced_from_its_crossing(
    a: float, g: float, kw: dict, parallelogram_only: bool
) -> None:
    """The flat start is the crossing of the parallelogram and antiparallelogram branches (rank 2 there, 3
    beside it): traced from it, branch 0 along the branch tangent that moves the crank most (the parallelogram
    branch, B = -A), the start bifurcation 0; with branches the antiparallelogram is traced too. Every row closes
    the circle |C - D| = a (1e-9 of the size)."""
    mech = lw.load("four-bar", ground=g, crank=a, coupler=g, rocker=a, theta=0.0)
    trace = lw.trace(mech, **kw)
    assert trace.stats.unmet is None
    mismatch, on_parallelogram = flat_parallelogram_rows(trace.angles, a, g)
    assert mismatch < 1e-9 * max(a, g)
    assert on_parallelogram[trace.branch == 0].all()
    assert on_parallelogram.all() == parallelogram_only
    assert trace.bifurcations[0].kind == "bifurcation" and np.abs(trace.bifurcations[0].angles).max() < 1e-12
    if "until" in kw:
        assert abs(trace.angles[-1, 0] - kw["until"][1]) < 1e-12


def test_a_parallelogram_a_degree_from_flat_is_traced_through_it() -> None:
    """A degree away the path passes through the flat point, which is located as a bifurcation."""
    near = lw.load("four-bar", ground=2.0, crank=1.0, coupler=2.0, rocker=1.0, theta=1 * DEG)
    trace = lw.trace(near, until=("A", 361 * DEG))
    off = [abs((np.degrees(b.angles[0]) + 180.0) % 360.0 - 180.0) for b in trace.bifurcations]
    assert min(off, default=1.0) < 1e-6, off


def test_a_four_bar_laid_straight_is_rigid() -> None:
    mech = lw.load("four-bar", ground=3.0, crank=1.0, coupler=1.0, rocker=1.0, theta=0.0)
    with pytest.raises(LinkworkError, match="the start is rigid"):
        lw.trace(mech)


def test_a_five_bar_has_mobility_two(tmp_path: Path) -> None:
    points = [(0.0, 0.0), (0.3, 1.0), (1.2, 1.4), (2.2, 0.9), (2.5, 0.0)]
    bodies = [("ground", "a"), ("a", "b"), ("b", "c"), ("c", "d"), ("d", "ground")]
    joints = "".join(
        f'[[mechanism.joints]]\nname = "{"ABCDE"[i]}"\ntype = "R"\nbodies = ["{p}", "{q}"]\n'
        f"point = [{x}, {y}]\n\n"
        for i, ((p, q), (x, y)) in enumerate(zip(bodies, points, strict=True))
    )
    spec = tmp_path / "five-bar.toml"
    spec.write_text(f'name = "five-bar"\nangles = "deg"\n\n[mechanism]\nplanar = true\n\n{joints}')
    with pytest.raises(LinkworkError, match=r"mobility 2 at the start .*couple or fix joints"):
        lw.trace(lw.load(str(spec)))


@pytest.mark.parametrize("branches", [False, True])
@pytest.mark.parametrize("steps", [None, 12])
def test_a_crossing_start_reports_its_own_rank(branches: bool, steps: int | None) -> None:
    """The flat parallelogram's start rank is the rank of its Jacobian there, written here from the four pivots
    on the ground line (each hinge's planar column ``(1, y, -x)``: the y row is zero, rank 2), and its mobility 2
    (4 unknowns); the branches leaving it have rank 3. Before: the stats gave the branches' rank, 3, and mobility
    1, so report.json's ``rank`` at the start was not the start's."""
    mech = lw.load("four-bar", ground=2.0, crank=1.0, coupler=2.0, rocker=1.0, theta=0.0)
    pivots = np.array([[0.0, 0.0], [1.0, 0.0], [3.0, 0.0], [2.0, 0.0]])  # A, B, C, D laid flat
    columns = np.array([[1.0, y, -x] for x, y in pivots]).T
    rank = int(np.linalg.matrix_rank(columns))
    assert rank == 2
    until = None if steps is None else ("A", np.radians(90.0))
    tr = lw.trace(mech, branches=branches, until=until, steps=steps, max_steps=2000)
    assert tr.stats.start_rank == rank and tr.stats.start_mobility == 4 - rank
    assert tr.rank[0] == rank and tr.rank[1] == 3
    assert all(b.mobility == 1 for b in tr.branches)
