"""Failures the audit found in the tracer (kinematics/), as regression tests (each was reproduced as the
docstring's "Got:" says, and is fixed). See CHANGELOG.md.

Each reference is the audit's own: the paper mode's promise of N equal drive steps, the law of cosines for a
four-bar's extremes, and the same linkage written in another length unit.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from audit_reference import FourBar, SliderCrank

import linkwork as lw

RAD = np.pi / 180.0


def load(tmp_path: Path, name: str, text: str) -> lw.Mechanism:
    spec = tmp_path / f"{name}.toml"
    spec.write_text(text)
    return lw.load(str(spec))


@pytest.mark.parametrize("steps", [36, 360])
def test_paper_mode_full_turn_takes_equal_steps(tmp_path: Path, steps: int) -> None:
    """A double crank's output crank D driven one full turn in N equal steps: N + 1 rows, D at k * 360 / N.

    Got (compiled and plain Python alike): N = 36, 2 rows, 'closed path' after one step and exit 3 on the command
    line ('D never reaches 360.00 deg on this path: its range is [0.00, 0.00] deg'); N = 360, 360 rows, the last
    step 2 deg (358 -> 360)."""
    case = FourBar("double-crank", 1.0, 2.5, 3.0, 2.8, 70.0)
    trace = lw.trace(load(tmp_path, "dc", case.mech.toml()), drive="D", until=("D", 2 * np.pi), steps=steps)
    d = np.degrees(np.asarray(trace.angles)[:, 3])
    assert len(d) == steps + 1
    assert np.max(np.abs(d - np.linspace(0.0, 360.0, steps + 1))) < 1e-9


def test_paper_mode_fold_is_a_turning_point(tmp_path: Path) -> None:
    """Equal 2-degree steps of a triple rocker's input towards 170 deg cross its extreme at 157.7628 deg (law of
    cosines, coupler and rocker in line): docs/tracing.md promises a located fold, `drive turning point`, and the
    branch's range reaching the extreme. Got 'corrector failed at a fixed drive step', no fold, range up to 156."""
    case = FourBar("triple-rocker", 4.0, 2.0, 3.5, 2.4, 20.0)
    trace = lw.trace(load(tmp_path, "tr", case.mech.toml()), until=("A", 170 * RAD), steps=75)
    top = max(case.fold_refs("A"))
    assert trace.branches[0].end_kind == lw.StopReason.TURNING
    assert [np.degrees(f.value) for f in trace.folds] == [pytest.approx(top, abs=1e-9)]


def test_slider_crank_in_thousandths_closes_with_the_same_first_steps(tmp_path: Path) -> None:
    """The offset slider-crank in units and in thousandths (every length x1000): the step control measures the
    slider in the linkage's own length, so both close, on the same steps up to the slider's extreme.

    Was: 292 rows closed in units; x1000 ran out of steps (5000 by default) with the crank turned 12.6 deg."""
    case = SliderCrank("offset-slider-crank", 1.0, 3.0, 0.4, 40.0)
    t1 = lw.trace(load(tmp_path, "sc1", case.mech.toml()), max_steps=600)
    t1000 = lw.trace(load(tmp_path, "sc1000", case.mech.toml(scale=1000.0)), max_steps=600)
    assert t1.branches[0].end_kind == lw.StopReason.CLOSED
    assert t1000.branches[0].end_kind == lw.StopReason.CLOSED
    assert abs(len(t1.angles) - len(t1000.angles)) <= 0.1 * len(t1.angles)
    lengths = np.array([1.0, 1.0, 1.0, 1000.0])
    np.testing.assert_allclose(t1.angles[:100] * lengths, t1000.angles[:100], rtol=1e-12, atol=1e-12)


def test_slider_crank_steps_do_not_depend_on_the_length_unit(tmp_path: Path) -> None:
    """The offset slider-crank in units and in thousandths (every length x1000) closes in the same steps.

    Got: 274 rows in units, 284 in thousandths (the same rows up to row 110, next to the slider's extreme: the
    new tangent was oriented against the old one in the plain metric, where the slider in thousandths outweighs
    every angle, so the path seemed to turn back where the slider does and the step was halved)."""
    case = SliderCrank("offset-slider-crank", 1.0, 3.0, 0.4, 40.0)
    t1 = lw.trace(load(tmp_path, "sc1", case.mech.toml()), max_steps=600)
    t1000 = lw.trace(load(tmp_path, "sc1000", case.mech.toml(scale=1000.0)), max_steps=600)
    assert t1.branches[0].end_kind == lw.StopReason.CLOSED
    assert t1000.branches[0].end_kind == lw.StopReason.CLOSED
    assert len(t1.angles) == len(t1000.angles)
    np.testing.assert_allclose(t1000.angles / [1.0, 1.0, 1.0, 1000.0], t1.angles, rtol=0.0, atol=1e-9)


def test_small_closed_loop_is_recognised(tmp_path: Path) -> None:
    """A nearly rigid non-Grashof four-bar (ground 2.9999, the others 1): its whole loop is about 8 deg of
    arclength and the input rocks within +-0.6616 deg (law of cosines). The path must close after one lap.

    Got: no 'closed path'; the trace goes round about 111 times to the step budget (5000 by default) and reports
    223 folds (`linkwork trace four-bar --set ground=2.9999 --set crank=1 --set coupler=1 --set rocker=1
    --set theta=0.1`); with --max-step 0.5 it closes in 44 rows."""
    case = FourBar("nearly-rigid", 2.9999, 1.0, 1.0, 1.0, 0.1)
    trace = lw.trace(load(tmp_path, "nr", case.mech.toml()), max_steps=600)
    assert trace.branches[0].end_kind == lw.StopReason.CLOSED
    assert len(trace.folds) == 2


@pytest.mark.parametrize("target", [-30.0, -54.958143662771])
def test_paper_mode_first_step_near_a_fold(tmp_path: Path, target: float) -> None:
    """The crank-rocker's rocker D starts 0.00127 deg below its upper extreme (law of cosines) and is driven down
    in 20 equal steps: every target down to its lower extreme -54.958 deg is on the path, and the crank, which
    only swings back from 35 deg towards 15.7 deg on the first step (closed form), never turns a whole turn.

    Got: target -30, 'corrector failed' at step 1 (exit 3, "range so far [0.00, 0.00]"); target -54.958143662771,
    reached, but row 1 has A = 3975.68 deg (15.68 + 11 turns), B = -2492.76, s = 4881.7 deg, and report.json's
    range of A is [35, 3975.68]."""
    case = FourBar("crank-rocker", 4.0, 1.3, 3.7, 2.9, 35.0)
    trace = lw.trace(load(tmp_path, "cr", case.mech.toml()), drive="D", until=("D", target * RAD), steps=20)
    assert trace.stats.unmet is None
    a = np.degrees(np.asarray(trace.angles)[:, 0])
    assert np.max(np.abs(np.diff(a))) < 90.0  # the closed form: at most 33 deg a step, on the last one


@pytest.mark.parametrize("theta", [181.0, 182.0])
def test_change_point_started_next_to_its_crossing_closes_after_two_turns(
    tmp_path: Path, theta: float
) -> None:
    """Grashof's change-point four-bar (4, 1.5, 3, 2.5) goes round its whole loop in two crank turns, through the
    crossing at A = 180 deg and again at 540 (the path from A = 60 closes at 780). Started at 181 or 182 deg it
    must close at A = theta + 720 and report the crossing.

    Got: theta = 181, 'closed path' at A = 541 (the row at 541 lies on the branch crossing the start's, 1.8 deg
    from the start, and is snapped onto it) with no bifurcation reported; theta = 182, no closure at 902 (the
    march restarted after passing the known point at 900 and its `far` guard was not yet armed) and a false one
    at 1262, a 3.9-deg step snapped across from the other branch."""
    case = FourBar("change-point", 4.0, 1.5, 3.0, 2.5, theta)
    trace = lw.trace(load(tmp_path, "cp", case.mech.toml()))
    assert trace.branches[0].end_kind == lw.StopReason.CLOSED
    assert np.degrees(trace.branches[0].end_value) == pytest.approx(theta + 720.0, abs=1e-9)
    assert len(trace.bifurcations) == 1


@pytest.mark.parametrize("max_step", [1.085, 1.089])
def test_closure_does_not_depend_on_progress_chunks(tmp_path: Path, max_step: float) -> None:
    """The audit's crank-rocker closes after one crank turn (about 503 rows) however the march is chunked.

    Got, with a progress callback (what the CLI always passes: chunks of 100 steps, each re-arming the
    closed-path guard from its own first point): 1006, 1505 and 4501 rows, the crank turned 2, 3 and 9 times.
    Without one, 504, 503 and 502 rows. The built-in four-bar shows it on the command line:
    `linkwork trace four-bar --max-step 1.408` runs out of steps (5001 rows, A = 4584 deg)."""
    case = FourBar("crank-rocker", 4.0, 1.3, 3.7, 2.9, 35.0)
    mech = load(tmp_path, "cr", case.mech.toml())
    plain = lw.trace(mech, max_step=max_step * RAD)
    chunked = lw.trace(mech, max_step=max_step * RAD, max_steps=1200, progress=lambda *a: None)
    assert chunked.branches[0].end_kind == lw.StopReason.CLOSED
    assert len(chunked.angles) == len(plain.angles)
