"""Every joint's range on a spherical crank-rocker and on an offset slider-crank's rod, against spherical
trigonometry and the planar closed form written here (``audit_reference.Spherical4R`` builds the hinge lines only).

Spherical 4R, arcs ground g (A-D), crank a (A-B), coupler b (B-C), rocker c (C-D): the rocker turns back where
crank and coupler lie on one great circle, arc A-C = b + a or b - a; the dihedral angle at D of the triangle A-C-D
is then ``arccos((cos AC - cos g cos c) / (sin g sin c))`` (spherical law of cosines), and the reading of D swings
by the difference of the two.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from audit_reference import Spherical4R, rot

import linkwork as lw
from linkwork.kinematics.extremes import joint_ranges

G, A, B, C = 60.0, 20.0, 55.0, 45.0


def spherical_swing() -> float:
    """The rocker's swing (deg) by the spherical law of cosines."""
    g, c = np.radians(G), np.radians(C)
    ends = [
        np.arccos((np.cos(np.radians(ac)) - np.cos(g) * np.cos(c)) / (np.sin(g) * np.sin(c)))
        for ac in (B + A, B - A)
    ]
    return float(np.degrees(abs(ends[0] - ends[1])))


def crank_at_extreme(case: Spherical4R, theta0: float) -> list[float]:
    """The crank readings (deg) within 180 deg of ``theta0`` at which crank and coupler lie on one great circle
    (arc A-C = a + b), one per assembly: C placed b beyond B on the great circle through A and B must lie at arc c
    from D. Roots on a grid, refined by bisection (numpy only)."""
    u_a, u_b, u_d = case.u["A"], case.u["B"], case.u["D"]

    # arc A-C = a + b: C on the great circle through A and B, b beyond B; its arc to D must be c
    def miss(theta: float) -> float:
        turned = rot(u_a, np.radians(theta - theta0)) @ u_b
        axis = np.cross(u_a, turned)
        axis /= np.linalg.norm(axis)
        c_dir = rot(axis, np.radians(B)) @ turned
        return float(np.degrees(np.arccos(np.clip(c_dir @ u_d, -1.0, 1.0))) - C)

    grid = np.linspace(theta0 - 180.0, theta0 + 180.0, 3601)
    vals = np.array([miss(t) for t in grid])
    roots = []
    for i in np.flatnonzero(np.sign(vals[:-1]) != np.sign(vals[1:])):
        lo, hi = grid[i], grid[i + 1]
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            if np.sign(miss(mid)) == np.sign(miss(lo)):
                lo = mid
            else:
                hi = mid
        roots.append(0.5 * (lo + hi))
    return roots


def swing_of(tmp_path: Path, theta0: float, steps: int | None, far: bool) -> tuple[float, float]:
    case = Spherical4R("spherical-crank-rocker", G, A, B, C, theta0)
    motion = None
    if far:
        motion = np.eye(4)
        motion[:3, :3] = rot([1.0, 2.0, 3.0], 0.7)
        motion[:3, 3] = [1e4, -3e4, 2e4]
    spec = tmp_path / "s.toml"
    spec.write_text(case.toml(motion))
    mech = lw.load(str(spec))
    until = None if steps is None else ("A", np.radians(theta0 + 360.0))
    trace = lw.trace(mech, drive="A", until=until, steps=steps)
    lo, hi = np.degrees(joint_ranges(trace, 0)["D"])
    rows = np.degrees(trace.angles[:, list(mech.joint_names).index("D")])
    return float(hi - lo), float(rows.max() - rows.min())


@pytest.mark.parametrize("far", [False, True])
@pytest.mark.parametrize("steps", [None, 180])
@pytest.mark.parametrize("start", ["generic", "next-to-extreme-0", "next-to-extreme-1"])
def test_spherical_rockers_range_is_its_swing(
    tmp_path: Path, steps: int | None, far: bool, start: str
) -> None:
    """The rocker's range over one turn of the crank, adaptive or 2-deg paper steps, centred at the origin or moved
    3.7e4 away and turned, started at a generic crank angle or 0.3 deg past either crank angle of an extreme:
    the spherical law of cosines' swing (58.39179 deg) to 1e-7 deg, never narrower than the rows. The four cases
    started past the traced assembly's extreme (``next-to-extreme-1``) failed before this branch's fix in
    kinematics/extremes.py (the extreme in the step that closes the turn); all pass after."""
    theta0 = 35.0
    if start.startswith("next-to-extreme"):
        roots = crank_at_extreme(Spherical4R("s", G, A, B, C, theta0), theta0)
        theta0 = roots[int(start[-1])] + 0.3
    swing, rows = swing_of(tmp_path, theta0, steps, far)
    assert abs(swing - spherical_swing()) < 1e-7
    assert swing >= rows - 1e-12
