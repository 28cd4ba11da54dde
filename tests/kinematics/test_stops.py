"""Every branch ends with a structured reason (kind, joint, value) that agrees with its points and its text, and
``Trace.stats`` is a typed record whose old dict-like reading still works with a DeprecationWarning."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import linkwork as lw
from linkwork.kinematics import march
from linkwork.kinematics.stops import StopReason
from linkwork.kinematics.trace_stats import TraceStats

DEG = np.pi / 180.0
FOUR_BAR = Path(__file__).resolve().parents[2] / "examples" / "specs" / "four-bar.toml"


@pytest.fixture(scope="module")
def four_bar() -> lw.Mechanism:
    return lw.load(str(FOUR_BAR))


def test_the_march_stop_codes_are_the_enum_values() -> None:
    for name in ("BUDGET", "TARGET", "CLOSED", "FAILED", "SIGN_CHANGE", "LIMIT", "TURNING", "NO_PROGRESS"):
        assert getattr(march, name) == StopReason[name].value
    assert march.NO_EVENT not in {int(r) for r in StopReason}
    assert not hasattr(march, "STOP_REASONS")


def test_a_target_ends_with_the_drive_at_its_value(four_bar: lw.Mechanism) -> None:
    tr = lw.trace(four_bar, until=("A", 100 * DEG))
    br = tr.branches[0]
    assert (br.end_kind, br.end_reason, br.end_joint) == (StopReason.TARGET, "reached target", "A")
    assert br.end_value == tr.angles[-1, four_bar.index("A")]  # the value at the last row itself
    assert br.end_value == pytest.approx(100 * DEG, abs=1e-12)
    assert br.end == lw.Branch.ended(0, None, None, 1, br.steps, br.end).end


def test_a_limit_ends_with_the_limited_joint_on_its_bound(four_bar: lw.Mechanism) -> None:
    tr = lw.trace(four_bar, limits={"D": (-5 * DEG, 30 * DEG)})
    br = tr.branches[0]
    assert (br.end_kind, br.end_reason, br.end_joint) == (StopReason.LIMIT, "limit D", "D")
    assert br.end_value == pytest.approx(-5 * DEG, abs=1e-11)  # the drive is A, the reason is about D


def test_a_closed_path_ends_one_turn_of_the_crank_round(four_bar: lw.Mechanism) -> None:
    tr = lw.trace(four_bar)
    br = tr.branches[0]
    a0 = tr.angles[0, four_bar.index("A")]
    assert (br.end_kind, br.end_reason, br.end_joint) == (StopReason.CLOSED, "closed path", "A")
    assert abs(br.end_value - a0) == pytest.approx(2 * np.pi, abs=1e-9)


def test_a_budget_and_a_turning_point_are_kinds_too(four_bar: lw.Mechanism) -> None:
    assert lw.trace(four_bar, max_steps=5).branches[0].end_kind == StopReason.BUDGET
    # Paper mode driven by the rocker towards a value beyond its range: equal drive steps end at its located fold
    # as a turning point, however long the steps (tests/audit/test_audit_paper_long_steps.py).
    ended = lw.trace(four_bar, until=("D", -80 * DEG), steps=400)
    br = ended.branches[0]
    assert br.end_kind == StopReason.TURNING
    assert br.end_reason.startswith(br.end_kind.text)
    assert br.end_joint == "D" and br.end_value == ended.angles[-1, four_bar.index("D")]
    assert ended.stats.unmet is not None


def test_branches_from_bifurcation_points_name_the_point_they_reach() -> None:
    tr = lw.trace(lw.load("four-bar"), branches=True)
    kinds = {br.end_kind for br in tr.branches}
    assert None not in kinds
    for br in tr.branches:
        if br.end_kind == StopReason.KNOWN_POINT:
            assert br.end_reason == f"reached bifurcation {br.end_point}"
            point = tr.bifurcations[br.end_point].angles
            last = tr.angles[tr.branch == br.id][-1]
            assert np.max(np.abs((last - point + np.pi) % (2 * np.pi) - np.pi)) < 1e-9


def test_stats_is_a_typed_record_with_the_old_reading_deprecated(four_bar: lw.Mechanism) -> None:
    tr = lw.trace(four_bar, until=("A", 100 * DEG))
    assert isinstance(tr.stats, TraceStats)
    assert tr.stats.has_target and tr.stats.unmet is None and tr.stats.points == len(tr.angles)
    with pytest.warns(DeprecationWarning, match="TraceStats"):
        assert tr.stats["points"] == len(tr.angles)
    with pytest.warns(DeprecationWarning):
        assert "unmet" not in tr.stats  # as on the dict: the key is there only when the target was not met
    with pytest.warns(DeprecationWarning):
        assert tr.stats.get("unmet", "met") == "met"
    with pytest.warns(DeprecationWarning), pytest.raises(KeyError):
        tr.stats["no_such_key"]
    unmet = lw.trace(four_bar, until=("D", -95 * DEG))
    with pytest.warns(DeprecationWarning):
        assert "unmet" in unmet.stats and unmet.stats["unmet"] == unmet.stats.unmet
