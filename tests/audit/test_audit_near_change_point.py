"""Four-bars a hair from Grashof's change point (s + l = p + q within 1e-6 of the ground), traced adaptively and
checked against the audit's own references (``audit_reference``): the law of cosines for the input's extremes and
the assembly mode (the side of the line B-D that C is on), from the audit's forward kinematics of every row.

Near the change point the two assembly modes pass within about ``sqrt(eps)`` of each other where the crank is at
180 deg: an imperfect bifurcation. Got, before the tracer took such a step again in smaller ones
(``marcher.BranchMarcher._jumped``): the Grashof crank-rocker (eps = +1e-6, +1e-8) jumped to the other assembly
mode with a 1.15-deg step at A = 179.19 deg and back at 539.84, closing after two crank turns (631 rows); the
non-Grashof triple rocker (eps = -1e-6, -1e-8) stepped over the 0.136-deg (0.014-deg) stretch of A it can never
reach, turned its input through whole turns and reported no fold.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from audit_reference import FourBar, wrap_deg

import linkwork as lw


def assembly_modes(case: FourBar, rows_deg: np.ndarray) -> np.ndarray:
    """+1 / -1: which side of the line from B to D the pin C is on, from the audit's poses of each row."""
    out = []
    for r in rows_deg:
        g, _ = case.mech.poses(dict(zip("ABCD", r, strict=True)))
        b = g["crank"][:3, :3] @ case.pts["B"] + g["crank"][:3, 3]
        c = g["coupler"][:3, :3] @ case.pts["C"] + g["coupler"][:3, 3]
        d, e = case.pts["D"] - b, c - b
        out.append(np.sign(d[0] * e[1] - d[1] * e[0]))
    return np.array(out)


@pytest.mark.parametrize("eps", [1e-6, -1e-6, 1e-8, -1e-8])
def test_near_change_point_four_bar_keeps_its_assembly_mode(tmp_path: Path, eps: float) -> None:
    """Ground 5, crank 2, coupler 4 + eps, rocker 3 (s + l = 7 against p + q = 7 + eps).

    Grashof (eps > 0): the crank turns; one assembly mode throughout, closed after one turn (A back at 430 deg).
    Non-Grashof (eps < 0): the input rocks between +-arccos((a^2 + g^2 - (b + c)^2) / (2 a g)), the two folds
    there (to 1e-7 deg), the assembly mode changing only at them, and the range of A inside them."""
    case = FourBar("near-change-point", 5.0, 2.0, 4.0 + eps, 3.0, 70.0)
    spec = tmp_path / "ncp.toml"
    spec.write_text(case.mech.toml())
    trace = lw.trace(lw.load(str(spec)), max_steps=3000)
    rows = np.degrees(np.asarray(trace.angles))
    assert trace.branches[0].end_kind == lw.StopReason.CLOSED
    modes = assembly_modes(case, rows)
    if eps > 0:
        assert np.all(modes == modes[0])
        assert rows[-1, 0] == pytest.approx(430.0, abs=1e-9)
        assert len(trace.folds) == 0
    else:
        top = np.degrees(np.arccos((2.0**2 + 5.0**2 - (7.0 + eps) ** 2) / (2 * 2.0 * 5.0)))
        found = sorted(float(np.degrees(f.value)) for f in trace.folds)
        np.testing.assert_allclose(found, [-top, top], atol=1e-7)
        assert np.max(np.abs(rows[:, 0])) <= top + 1e-7
        flips = np.flatnonzero(np.diff(modes) != 0)
        assert len(flips) == 2
        for k in flips:  # at a fold: the rows either side are within a small step of the extreme
            assert min(abs(float(wrap_deg(rows[k, 0] - s * top))) for s in (1, -1)) < 0.05


def test_a_target_just_beyond_an_extreme_is_told_apart_from_it(tmp_path: Path) -> None:
    """A triple rocker's input (law of cosines: extreme 93.859364476671 deg) asked to reach 1e-6 deg beyond its
    extreme: unmet, and the line shows the target and the range's ends with enough decimals to tell them apart.

    Got: "A never reaches 93.86 deg on this path: its range is [-93.86, 93.86] deg"."""
    case = FourBar("triple-rocker", 3.0, 2.6, 1.9, 2.2, 40.0)
    spec = tmp_path / "tr.toml"
    spec.write_text(case.mech.toml())
    top = max(case.fold_refs("A"))
    trace = lw.trace(lw.load(str(spec)), until=("A", np.radians(top + 1e-6)))
    line = trace.stats.unmet
    assert line is not None
    numbers = [float(x) for x in re.findall(r"-?\d+\.\d+", line)]
    target, lo, hi = numbers[0], numbers[-2], numbers[-1]
    assert target != hi and target != lo
    assert target == pytest.approx(top + 1e-6, abs=1e-5) and hi == pytest.approx(top, abs=1e-5)
