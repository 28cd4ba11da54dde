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


def test_a_parallelogram_laid_flat_is_a_crossing_of_two_branches() -> None:
    mech = lw.load("four-bar", ground=2.0, crank=1.0, coupler=2.0, rocker=1.0, theta=0.0)
    with pytest.raises(LinkworkError, match=r"2 one-parameter branches cross .*mobility one, not 2"):
        lw.trace(mech)
    # a degree away it is traced through that point, which is located as a bifurcation
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
