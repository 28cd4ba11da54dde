"""A paper trace whose last row, the target, lands exactly on a crossing of a parallelogram or a deltoid (the crank
along the ground line, at a multiple of 180 deg), after rows that may pass or land on other crossings: the target
is reached there (exit 0, no ``unmet``), in exactly ``steps`` rows, the last row on the closed form
(``audit_reference.FourBar``: circle intersections) (where the circles touch, to the closed form's own accuracy there) and a located point at the target.

Found in session 19: the built-in ``four-bar`` as a parallelogram (ground 2, crank 1, coupler 2, rocker 1) from 10
deg to A = 360 in 2 steps (rows 10, 185, 360) went on past its target, row after row, to the step budget (5,000
rows, A = 875,010 deg) and said "A did not reach 360.00 deg": the march's last row landed on a singular point and
on the target at once, and the landed row's handling (``BranchMarcher``: the rows after a landed row may be on
another branch) dropped the row's stop code, so the march went on from it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from audit_reference import FourBar, nearest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

import linkwork as lw

RAD = np.pi / 180.0


@settings(deadline=None, max_examples=30, derandomize=True)
@given(
    kind=st.sampled_from(["parallelogram", "deltoid"]),
    ground=st.floats(1.5, 4.0),
    ratio=st.floats(0.15, 0.8),
    start=st.floats(2.0, 178.0),
    side=st.sampled_from([0, 1]),
    turns=st.integers(1, 4),
    steps=st.integers(1, 5),
)
@example(kind="parallelogram", ground=2.0, ratio=0.5, start=10.0, side=0, turns=2, steps=2)  # the case found
@example(kind="parallelogram", ground=2.0, ratio=0.5, start=0.5 + 2.0, side=0, turns=2, steps=2)
@example(kind="deltoid", ground=2.0, ratio=0.5, start=10.0, side=0, turns=2, steps=2)
@example(kind="parallelogram", ground=2.0, ratio=0.5, start=20.0, side=1, turns=1, steps=1)
def test_a_target_on_a_crossing_is_reached(
    tmp_path_factory: object,
    kind: str,
    ground: float,
    ratio: float,
    start: float,
    side: int,
    turns: int,
    steps: int,
) -> None:
    g, a = ground, ratio * ground
    case = (
        FourBar(kind, g, a, g, a, start, side=side)
        if kind == "parallelogram"
        else FourBar(kind, g, a, a, g, start, side=side)
    )
    target = 180.0 * turns
    assume((target - start) / steps <= 360.0)  # rows of at most a turn
    spec = tmp_path_factory.mktemp("cross") / "fb.toml"  # type: ignore[attr-defined]
    spec.write_text(case.mech.toml())
    trace = lw.trace(lw.load(str(spec)), until=("A", target * RAD), steps=steps, max_steps=500)
    assert trace.stats.unmet is None, trace.stats.unmet
    rows = np.degrees(np.asarray(trace.angles))
    assert len(rows) == steps + 1
    assert abs(rows[-1, 0] - target) < 1e-9
    for row in rows[
        1:
    ]:  # every row on the closed form: to 1e-9 deg more than 5 deg from a crossing; within 5
        # deg to 5e-8 (rows 1-4 deg from a crossing are 1e-9 to 1.4e-8 deg off, the most with a short crank: open,
        # CHANGELOG); on one, where the circles touch (a double root, where the reference's own square root of a
        # round-off discriminant is about 1e-8 of the crank off), to 1e-5 deg
        named = dict(zip("ABCD", row, strict=True))
        off = abs((row[0] + 90.0) % 180.0 - 90.0)
        tol = 1e-5 if off < 1e-9 else 5e-8 if off < 5.0 else 1e-9
        assert nearest(case.solve("A", named["A"]), named, list("ABCD"), set())[0] < tol
    at_target = [
        b
        for b in trace.bifurcations
        if abs((np.degrees(b.angles[0]) - target + 180.0) % 360.0 - 180.0) < 1e-6
    ]
    assert at_target, "the crossing at the target is not reported"
    # the last row is that point (met whole turns on): the row polished with it, not the held corrector's
    point = np.degrees(at_target[0].angles)
    assert np.abs((rows[-1] - point + 180.0) % 360.0 - 180.0).max() < 1e-9
    assert math.isclose(float(rows[0, 0]), start, abs_tol=1e-9)


def test_the_command_line_exits_0(tmp_path: Path) -> None:
    """``linkwork trace four-bar --set crank=1 --set coupler=2 --set rocker=1 --set theta=10 --until A=360
    --steps 2``: exit 0 (was 3 after 5,000 rows)."""
    from typer.testing import CliRunner

    from linkwork.cli import app

    args = [
        "trace",
        "four-bar",
        "--set",
        "crank=1",
        "--set",
        "coupler=2",
        "--set",
        "rocker=1",
        "--set",
        "theta=10",
    ]
    result = CliRunner().invoke(
        app, [*args, "--until", "A=360", "--steps", "2", "--no-plots", "-o", str(tmp_path / "o")]
    )
    assert result.exit_code == 0, result.output


def test_an_adaptive_target_on_a_crossing_met_again_is_that_point(tmp_path: Path) -> None:
    """A deltoid (ground 2, crank 1.5) traced adaptively from 2 deg to A = 720 deg: its crossing at 360 deg is
    located on the way, and the target, the same crossing a turn on, is that point (to 1e-9 deg, whole turns
    apart), and on the closed form (to 1e-5 deg: a double root there). Before, the last row was where the corrector
    holding the drive stopped, 4.5e-5 deg off (the square root of its closure residual)."""
    case = FourBar("deltoid", 2.0, 1.5, 1.5, 2.0, 2.0, side=0)
    spec = tmp_path / "fb.toml"
    spec.write_text(case.mech.toml())
    trace = lw.trace(lw.load(str(spec)), until=("A", 720.0 * RAD))
    assert trace.stats.unmet is None
    last = np.degrees(np.asarray(trace.angles))[-1]
    points = [np.degrees(b.angles) for b in trace.bifurcations if abs(np.degrees(b.angles[0]) - 360.0) < 1e-6]
    assert points
    assert np.abs((last - points[0] + 180.0) % 360.0 - 180.0).max() < 1e-9
    named = dict(zip("ABCD", last, strict=True))
    assert nearest(case.solve("A", named["A"]), named, list("ABCD"), set())[0] < 1e-5
