"""``records.record`` builds what a frozen dataclass's constructor builds (equal, the same ``__dict__``), and
refuses what it cannot build that way: a missing or unknown field, a class with ``__post_init__`` or one that is
not a frozen dataclass."""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
import pytest

import linkwork as lw
from linkwork.kinematics.marcher import MarchSettings
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import DEFAULT
from linkwork.kinematics.records import record
from linkwork.kinematics.stops import StopReason
from linkwork.kinematics.trace_result import Branch, Trace
from linkwork.kinematics.trace_stats import TraceStats


def every_field(obj: object) -> dict[str, object]:
    """Every field of a dataclass instance by name."""
    return {f.name: getattr(obj, f.name) for f in fields(obj)}  # type: ignore[arg-type]


def built_both_ways() -> list[tuple[object, object]]:
    """``(constructor's, record's)`` pairs of the records a trace builds, with values that are not defaults."""
    rng = np.random.default_rng(11)
    mech = lw.load("four-bar")
    branch = Branch(
        0, None, None, 1, 90, StopReason.TARGET.text, mobility=1, end_kind=StopReason.TARGET, end_joint="A",
        end_value=0.25,
    )  # fmt: skip
    stats = TraceStats(start_rank=3, start_mobility=1, mode="paper", closure_tol=1e-9, max_misfit=3e-15,
                       has_target=True, points=91, seconds=0.5)  # fmt: skip
    arrays = {name: rng.normal(size=(91, 4)) for name in ("angles", "sigma", "residual", "arclength", "test")}
    columns = {name: np.arange(91, dtype=np.int64) for name in ("branch", "step", "rank")}
    trace = Trace(
        mechanism=mech, drive="A", bifurcations=(), branches=(branch,), stats=stats, **arrays, **columns
    )
    lo, hi = np.full(4, -np.inf), np.full(4, np.inf)
    settings = MarchSettings(drive=0, target=1.5, min_step=1e-9, max_step=0.03, cos_turn=0.98, r_path=3, n_sigma=3,
                             periodic=np.ones(4, dtype=bool), lo=lo, hi=hi, tol=DEFAULT, drive_joint=0)  # fmt: skip
    return [(obj, record(type(obj), **every_field(obj))) for obj in (branch, stats, trace, settings)]


@pytest.mark.parametrize("index", range(4))
def test_record_is_the_constructors_instance(index: int) -> None:
    """Equal to the constructor's, of the same type, with the same ``__dict__`` (the same objects in it), and
    still frozen."""
    made, built = built_both_ways()[index]
    assert type(built) is type(made) and built == made
    assert vars(built).keys() == vars(made).keys()
    assert all(vars(built)[k] is vars(made)[k] for k in vars(made))
    with pytest.raises(AttributeError):
        built.steps = 3  # type: ignore[attr-defined]


def test_a_traced_record_keeps_its_cached_property() -> None:
    """A Trace built by ``record`` computes and keeps its normalised condition ratios as a constructed one."""
    made, built = built_both_ways()[2]
    assert isinstance(made, Trace) and isinstance(built, Trace)
    traced = lw.trace(lw.load("four-bar"), until=("A", 1.0), steps=20)
    again = record(Trace, **every_field(traced))
    np.testing.assert_array_equal(again.condition(), traced.condition())


def test_record_refuses_a_missing_or_an_unknown_field() -> None:
    """Every field is required (defaults are not filled in), and only fields."""
    branch = Branch(0, None, None, 1, 5, "reached target")
    values = every_field(branch)
    with pytest.raises(TypeError, match="missing \\['end_point'\\]"):
        record(Branch, **{k: v for k, v in values.items() if k != "end_point"})
    with pytest.raises(TypeError, match="unknown \\['colour'\\]"):
        record(Branch, colour="red", **values)


def test_record_refuses_classes_its_constructor_would_change() -> None:
    """A ``__post_init__`` (Mechanism copies and freezes its arrays there), a mutable dataclass, a plain class."""

    @dataclass
    class Mutable:
        x: int

    class Plain:
        x: int = 0

    with pytest.raises(TypeError, match="__post_init__"):
        record(Mechanism, **{f.name: None for f in fields(Mechanism)})
    for cls in (Mutable, Plain):
        with pytest.raises(TypeError, match="frozen dataclass"):
            record(cls, x=1)
