"""Every joint's range along a branch is its swing, located between the rows (kinematics/extremes.py).

Outside references: the crank-rocker's rocker swing from the law of cosines at the two positions where crank and
coupler are collinear; the slider-crank's slider between ``rod - crank`` and ``rod + crank``; and, for every
built-in, that a range is never narrower than its rows and its located points close the loop.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import linkwork as lw
from linkwork.kinematics.closure import closure_residual
from linkwork.kinematics.extremes import joint_extremes, joint_ranges
from linkwork.linkages import REGISTRY

DEG = np.pi / 180.0
FOUR_BAR = Path(__file__).resolve().parents[2] / "examples" / "specs" / "four-bar.toml"
A0, B0, C0, D0 = (np.array(p, dtype=float) for p in ([0, 0], [1, 1], [3.5, 3], [4, 0]))


def rocker_swing_deg() -> float:
    """The rocker's swing: the angle at D of triangle A-C-D with |AC| = coupler + crank and coupler - crank."""
    crank, coupler = np.linalg.norm(B0 - A0), np.linalg.norm(C0 - B0)
    rocker, ground = np.linalg.norm(D0 - C0), np.linalg.norm(D0 - A0)

    def at_d(ac: float) -> float:
        return float(np.degrees(np.arccos((ground**2 + rocker**2 - ac**2) / (2 * ground * rocker))))

    return at_d(coupler + crank) - at_d(coupler - crank)


@pytest.mark.parametrize("steps", [None, 90, 360])
def test_a_rockers_range_is_its_swing(steps: int | None) -> None:
    """Driven by the crank (adaptive 2-deg steps, or 90 and 360 equal steps): the rocker's range spans the law of
    cosines' swing to 1e-7 deg; its rows alone fall short (by 1e-4 deg or more at 2-4 deg steps)."""
    mech = lw.load(str(FOUR_BAR))
    until = None if steps is None else ("A", float(mech.offsets[0]) + 360 * DEG)
    trace = lw.trace(mech, until=until, steps=steps)
    low, high = joint_ranges(trace, 0)["D"]
    assert np.degrees(high - low) == pytest.approx(rocker_swing_deg(), abs=1e-7)
    rows = np.degrees(np.ptp(trace.angles[:, mech.index("D")]))
    if steps != 360:
        assert rows < rocker_swing_deg() - 1e-5  # the test can fail: the rows miss the extremes


@pytest.mark.parametrize(("crank", "rod"), [(1.0, 3.0), (0.002, 0.005), (40.0, 90.0)])
def test_a_sliders_range_is_rod_minus_to_plus_crank(crank: float, rod: float) -> None:
    """An in-line slider-crank driven round by its crank: the slider D travels from ``rod - crank`` to ``rod +
    crank`` (its dead centres), in any length unit, to 1e-9 of the crank."""
    mech = lw.load("slider-crank", crank=crank, rod=rod, offset=0.0, theta=30 * DEG)
    trace = lw.trace(mech, until=("A", float(mech.offsets[0]) + 360 * DEG))
    low, high = joint_ranges(trace, 0)["D"]
    assert abs(high - (rod + crank)) < 1e-9 * crank and abs(low - (rod - crank)) < 1e-9 * crank


@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_every_builtins_ranges_hold_their_rows_and_close(name: str) -> None:
    """Every built-in with its branches: each branch's range holds its rows' values, and every located turning
    point closes the loop (residual 1e-10), within one bracket's length of the rows."""
    mech = lw.load(name)
    trace = lw.trace(mech, branches=True, max_steps=2000)
    for branch in trace.branches:
        rows = trace.angles[trace.branch == branch.id]
        ranges = joint_ranges(trace, branch.id)
        for j, joint in enumerate(mech.joint_names):
            low, high = ranges[joint]
            assert low <= rows[:, j].min() and high >= rows[:, j].max()
            assert rows[:, j].min() - low < 0.1 and high - rows[:, j].max() < 0.1
        for point in joint_extremes(trace, branch.id):
            q = mech.q_from_angles(point)
            assert np.linalg.norm(closure_residual(mech, q)) < 1e-10
