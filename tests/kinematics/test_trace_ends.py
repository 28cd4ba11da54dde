"""Two ends of a trace that used to cost the whole step budget or everything traced, proven over every built-in
linkage and generated cranks:

* a signal held by the command line (:func:`linkwork.interrupts.held_signals`) ends the trace at its next chunk
  of steps with a structured end (``StopReason.INTERRUPTED``, ``stats.stopped``), keeping every row marched,
  consistent; a second signal raises at once;
* a target further round than the step budget can go is refused as soon as the path has closed once (one cycle
  of the drive, its steps counted), not after the whole budget; a target the budget reaches (several turns) is
  still reached, however close to the budget; a rocker's target beyond its range ends at the first closure.

The references are outside the code under test: the free trace's own cycle (its steps and the drive's turn), and
the rows' shapes against each other.
"""

from __future__ import annotations

import math
import os
import signal
from functools import cache

import numpy as np
import pytest
from bookkeeping_reference import planar_four_bar, spherical_four_bar, stephenson_six_bar
from hypothesis import given, settings
from hypothesis import strategies as st

import linkwork as lw
from linkwork.interrupts import Interrupted, held_signals, requested
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.stops import StopReason
from linkwork.kinematics.trace_result import Trace
from linkwork.linkages.registry import REGISTRY

DEG = np.pi / 180.0
BUILT_INS = sorted(REGISTRY)
PROPERTY = settings(deadline=None, max_examples=5, derandomize=True)
TARGET_TOL = 1e-12
"""A reached target: the drive's last value equals it (radians, relative to the target)."""


@cache
def free_trace(name: str) -> Trace:
    """The default trace of a built-in (the first branch only)."""
    return lw.trace(lw.load(name))


def assert_rows_consistent(tr: Trace) -> None:
    """Every per-row array has one row per point, and each branch's steps count up from its first row."""
    n = len(tr.branch)
    assert n == tr.stats.points
    for rows in (tr.angles, tr.sigma, tr.residual, tr.step, tr.arclength, tr.test, tr.rank):
        assert len(rows) == n
    assert np.all(np.isfinite(tr.angles)) and np.all(np.isfinite(tr.sigma))
    for br in tr.branches:
        steps = tr.step[tr.branch == br.id]
        assert np.all(np.diff(steps) == 1), f"branch {br.id}: steps {steps[:5]}..."


# ------------------------------------------------------------------------------------ interruptions
def signal_after(calls: int, signum: int = signal.SIGTERM) -> object:
    """A progress callback that sends ``signum`` to this process at its ``calls``-th call (between two chunks)."""
    seen = [0]

    def progress(done: int, total: int | None) -> None:
        seen[0] += 1
        if seen[0] == calls:
            os.kill(os.getpid(), signum)

    return progress


@pytest.mark.parametrize("name", BUILT_INS)
@pytest.mark.parametrize("branches", [False, True], ids=["first-branch", "every-branch"])
def test_a_held_signal_ends_every_trace_keeping_its_rows(name: str, branches: bool) -> None:
    mech = lw.load(name)
    whole = lw.trace(mech, branches=branches, progress=lambda done, total: None)
    with held_signals() as hold:
        cut = lw.trace(mech, branches=branches, progress=signal_after(1))
        assert requested() == signal.SIGTERM  # held, not acted on: the process is still here
    assert hold.signum == signal.SIGTERM and requested() == 0
    assert_rows_consistent(cut)
    if cut.stats.stopped is None:  # the trace was done by the first chunk's end: nothing was cut
        assert len(cut.branch) == len(whole.branch)
        return
    assert cut.stats.stopped == "interrupted (SIGTERM)"
    assert len(cut.branch) < len(whole.branch)
    # what was kept is the start of the whole trace, row for row
    n0 = int(np.sum(cut.branch == 0))
    np.testing.assert_allclose(cut.angles[:n0], whole.angles[:n0], rtol=0, atol=1e-9)
    ended = [br for br in cut.branches if br.end_kind == StopReason.INTERRUPTED]
    assert len(ended) <= 1
    for br in ended:
        assert br.end_reason == "interrupted (SIGTERM)"
        assert br.end_value == pytest.approx(
            cut.angles[cut.branch == br.id][-1, cut.mechanism.index(br.end_joint)]
        )


@pytest.mark.parametrize("name", ["guest-frame", "bricard-trihedral", "rect-frame"])
def test_a_signal_at_any_chunk_of_a_branching_trace_keeps_a_prefix_of_it(name: str) -> None:
    """Cut after every chunk in turn (branch 0, the other direction, the queued branches): the rows kept are
    the whole trace's first rows, every branch but the last traced whole, and the queue is not followed on."""
    mech = lw.load(name)
    calls: list[int] = []
    whole = lw.trace(mech, branches=True, progress=lambda done, total: calls.append(done))
    assert len(calls) >= 3, "too short a trace to cut"
    for k in range(1, len(calls) + 1):
        with held_signals():
            cut = lw.trace(mech, branches=True, progress=signal_after(k))
        assert_rows_consistent(cut)
        n = len(cut.branch)
        assert n <= len(whole.branch)
        np.testing.assert_allclose(cut.angles, whole.angles[:n], rtol=0, atol=1e-9)
        if cut.stats.stopped is None:
            assert n == len(whole.branch)
            continue
        assert len(cut.branches) <= len(whole.branches)
        for mine, full in zip(cut.branches[:-1], whole.branches, strict=False):
            assert (mine.end_kind, mine.steps) == (full.end_kind, full.steps)


def test_an_interrupted_trace_with_a_target_says_it_was_not_reached() -> None:
    mech = lw.load("four-bar")
    target = ("A", float(mech.offsets[0]) + 3 * 2 * np.pi)
    with held_signals():
        tr = lw.trace(mech, until=target, max_step=0.2 * DEG, progress=signal_after(2, signal.SIGINT))
    assert tr.stats.stopped == "interrupted (SIGINT)"
    assert tr.branches[0].end_kind == StopReason.INTERRUPTED
    assert tr.stats.unmet is not None and "interrupted (SIGINT)" in tr.stats.unmet
    assert_rows_consistent(tr)


def test_a_second_signal_stops_at_once() -> None:
    mech = lw.load("four-bar")

    def twice(done: int, total: int | None) -> None:
        os.kill(os.getpid(), signal.SIGTERM)  # held: the trace will end at its next chunk
        os.kill(os.getpid(), signal.SIGTERM)  # the second: at once

    with pytest.raises(Interrupted) as raised, held_signals():
        lw.trace(mech, max_step=0.2 * DEG, progress=twice)
    assert raised.value.signum == signal.SIGTERM


def test_without_held_signals_a_trace_is_never_cut() -> None:
    """A library call (no command line holding the signals) traces to its end: nothing is ever requested."""
    assert requested() == 0
    tr = lw.trace(lw.load("four-bar"), progress=lambda done, total: None)
    assert tr.stats.stopped is None and tr.branches[0].end_kind == StopReason.CLOSED


# ------------------------------------------------------------------------------------ targets beyond the budget
def cycle_of(free: Trace) -> tuple[int, float] | None:
    """``(steps, turn)`` of the free trace's first branch when it closed with the drive turned by a whole turn
    (a crank), else None."""
    br = free.branches[0]
    if br.end_kind != StopReason.CLOSED:
        return None
    d = free.mechanism.index(free.drive)
    drive = free.angles[free.branch == 0, d]
    turn = float(drive[-1] - drive[0])
    return (br.steps, turn) if abs(turn) > np.pi else None


def closes(name: str) -> bool:
    return free_trace(name).branches[0].end_kind == StopReason.CLOSED


CLOSING = [name for name in BUILT_INS if closes(name)]
CRANKS = [name for name in CLOSING if cycle_of(free_trace(name)) is not None]


def test_the_built_ins_include_cranks_and_rockers() -> None:
    """The properties below are not vacuous: some built-ins' drives turn round, some close without turning."""
    assert CRANKS and set(CLOSING) - set(CRANKS), (CLOSING, CRANKS)


def assert_far_target_refused_after_one_cycle(mech: Mechanism, free: Trace, sign: float) -> None:
    """A target a million turns away (``sign``: which way) ends the trace after its first cycle, exit-3 style."""
    d = mech.index(free.drive)
    start = float(free.angles[0, d])
    steps, _ = cycle_of(free) or (0, 0.0)
    target = start + sign * 1e6 * 2 * np.pi
    tr = lw.trace(mech, drive=free.drive, until=(free.drive, target))
    br = tr.branches[0]
    assert br.end_kind == StopReason.BUDGET
    assert tr.stats.unmet is not None
    assert tr.stats.unmet.startswith(f"{free.drive} cannot reach"), tr.stats.unmet
    assert "--max-steps" in tr.stats.unmet and "cycles" in tr.stats.unmet
    # one cycle (either way round the same closed curve), not the 5000 steps of the budget
    assert br.steps <= 1.5 * steps + 10, (br.steps, steps)


def assert_reachable_turns_reached(mech: Mechanism, free: Trace) -> None:
    """Targets several turns away, with a budget just large enough (the first cycle is the longest: it starts
    with a short step), are reached."""
    d = mech.index(free.drive)
    start = float(free.angles[0, d])
    steps, turn = cycle_of(free) or (0, 0.0)
    for turns in (2.0, 3.0, 3.5, 4.0 - 1e-6):
        target = start + turns * turn
        budget = math.ceil(turns) * steps + 5
        tr = lw.trace(mech, drive=free.drive, until=(free.drive, target), max_steps=budget)
        assert tr.stats.unmet is None, f"{mech.name}, {turns} turns in {budget} steps: {tr.stats.unmet}"
        assert abs(tr.angles[-1, d] - target) <= TARGET_TOL * max(1.0, abs(target))


@pytest.mark.parametrize("name", CRANKS)
@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["ahead", "behind"])
def test_every_crank_refuses_a_target_beyond_the_budget_after_one_cycle(name: str, sign: float) -> None:
    assert_far_target_refused_after_one_cycle(lw.load(name), free_trace(name), sign)


@pytest.mark.parametrize("name", CRANKS)
def test_every_crank_reaches_targets_turns_away_within_the_budget(name: str) -> None:
    assert_reachable_turns_reached(lw.load(name), free_trace(name))


@pytest.mark.parametrize("name", sorted(set(CLOSING) - set(CRANKS)))
def test_every_rocker_refuses_a_target_beyond_its_range_at_the_first_closure(name: str) -> None:
    mech = lw.load(name)
    free = free_trace(name)
    d = mech.index(free.drive)
    target = float(free.angles[0, d]) + 1e6 * 2 * np.pi
    tr = lw.trace(mech, drive=free.drive, until=(free.drive, target))
    assert tr.branches[0].end_kind == StopReason.CLOSED
    assert tr.stats.unmet is not None and "never reaches" in tr.stats.unmet
    assert tr.branches[0].steps <= 1.5 * free.branches[0].steps + 10


crank_params = st.tuples(
    st.floats(1.5, 3.0),  # ground
    st.floats(0.3, 1.0),  # crank (shortest: a crank-rocker)
    st.floats(0.0, 1.0),  # coupler, as a fraction of its Grashof range
    st.floats(20.0, 160.0),  # crank angle at the start (deg)
)


def generated_four_bar(params: tuple[float, float, float, float]) -> Mechanism:
    ground, crank, frac, theta = params
    lo, hi = crank + 0.2, 2 * ground - crank - 0.2
    return planar_four_bar(ground, crank, lo + frac * (hi - lo), ground, theta * DEG)


@PROPERTY
@given(crank_params)
def test_generated_four_bars_refuse_far_targets_and_reach_near_ones(
    params: tuple[float, float, float, float],
) -> None:
    mech = generated_four_bar(params)
    free = lw.trace(mech)
    assert cycle_of(free) is not None
    assert_far_target_refused_after_one_cycle(mech, free, 1.0)
    assert_reachable_turns_reached(mech, free)


@pytest.mark.parametrize(
    "mech",
    [stephenson_six_bar(0.0), spherical_four_bar(70 * DEG, 20 * DEG, 70 * DEG, 70 * DEG, 40 * DEG)],
    ids=["stephenson", "spherical-4r"],
)
def test_other_cranks_refuse_far_targets_and_reach_near_ones(mech: Mechanism) -> None:
    free = lw.trace(mech)
    assert cycle_of(free) is not None
    for sign in (1.0, -1.0):
        assert_far_target_refused_after_one_cycle(mech, free, sign)
    assert_reachable_turns_reached(mech, free)


# ------------------------------------------------------------------------------------ paper mode
@pytest.mark.parametrize("name", CRANKS)
@pytest.mark.parametrize("turns", [2.5, 3.0, -2.25], ids=["2.5-turns", "3-turns", "back-2.25-turns"])
def test_equal_steps_several_turns_round_land_on_the_target_in_that_many_steps(
    name: str, turns: float
) -> None:
    """A crank's target turns away in equal drive steps: reached, in exactly the steps asked (each closure of the
    path snaps a step short; the steps after it are evened out onto the target, which they used to pass)."""
    mech = lw.load(name)
    free = free_trace(name)
    d = mech.index(free.drive)
    start = float(free.angles[0, d])
    target = start + np.sign(cycle_of(free)[1]) * turns * 2 * np.pi  # type: ignore[index]
    steps = round(abs(turns) * 360 / 4.0)  # 4 deg steps
    tr = lw.trace(mech, until=(free.drive, target), steps=steps)
    assert tr.stats.unmet is None, tr.stats.unmet
    assert tr.branches[0].steps == steps
    assert abs(tr.angles[-1, d] - target) <= TARGET_TOL * abs(target)
    drive_steps = np.diff(tr.angles[:, d]) * np.sign(target - start)
    nominal = abs(target - start) / steps
    # always towards the target; a closing step is snapped onto the start (the march's rule: up to two steps long)
    assert np.all(drive_steps > 0.2 * nominal) and np.all(drive_steps < 2.0 * nominal)
    assert np.median(drive_steps) == pytest.approx(nominal, rel=0.05)


def test_more_equal_steps_than_the_budget_are_refused_before_any_step() -> None:
    mech = lw.load("four-bar")
    start = float(mech.offsets[0])
    with pytest.raises(lw.SpecError, match=r"steps \(6000, --steps\).*max_steps \(5000, --max-steps\)"):
        lw.trace(mech, until=("A", start + 1.0), steps=6000)
    tr = lw.trace(mech, until=("A", start + 1.0), steps=50, max_steps=50)  # exactly the budget: reached
    assert tr.stats.unmet is None and tr.branches[0].steps == 50


@pytest.mark.parametrize("name", BUILT_INS)
def test_equal_steps_of_any_size_never_crash(name: str) -> None:
    """Large equal steps over one to several turns: a trace (reached, or ended with a reason) or a refusal, never
    another exception (a march failing at the first step of a later chunk left an empty block: IndexError)."""
    mech = lw.load(name)
    d = mech.joint_names[int(np.flatnonzero(mech.groups >= 0)[0])]
    j = mech.index(d)
    if mech.joint_types[j] != "R":
        pytest.skip("a prismatic drive")
    start = float(mech.offsets[j])
    for step_deg in (30.0, 60.0, 89.0, 500.0):
        for turns in (0.9, 1.7, 2.3, 50.0):
            steps = math.ceil(turns * 360.0 / step_deg)
            tr = lw.trace(mech, until=(d, start + np.radians(turns * 360.0)), steps=steps)
            assert_rows_consistent(tr)
            assert tr.branches[0].end_kind is not None
