"""The checks :func:`linkwork.trace` makes of its arguments before any work, each failure one
:class:`~linkwork.errors.SpecError` naming the argument and what it expects.

The command line checks its flags in its own layer (``cli.options``); a script or a notebook calls ``lw.trace``
directly, and a NaN, ``None``, a string or a zero step given there must not reach the compiled march (a NaN
``max_step`` looped there for ever, a zero one traced nothing for the whole budget) or surface as numpy's or
numba's internal errors.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from numbers import Integral, Real
from typing import Any

import numpy as np

from linkwork.errors import SpecError
from linkwork.limits import MAX_TRACE_STEPS

__all__ = ["check_trace_arguments", "check_trace_subject"]


def _real(name: str, value: Any, unit: str, *, positive: bool = False, finite: bool = True) -> float:
    """``value`` as a float, or a SpecError naming ``name``: a real number (not a bool), finite unless
    ``finite`` is False (then not NaN), above zero when ``positive``."""
    if type(value) is float or (not isinstance(value, bool) and isinstance(value, Real)):
        x = float(value)
        if not (math.isnan(x) or (finite and math.isinf(x)) or (positive and not x > 0.0)):
            return x
    what = ("a positive " if positive else "a ") + ("finite number" if finite else "number")
    raise SpecError(f"{name}={value!r}: expected {what}{f' ({unit})' if unit else ''}")


def _count(name: str, value: Any, low: int, high: int = MAX_TRACE_STEPS) -> int:
    """``value`` as an int from ``low`` to ``high``, or a SpecError naming ``name`` (a whole number, not a
    float). The top is the command line's (``--max-steps``): ``max_steps=2**70`` was numpy's "Maximum allowed
    dimension exceeded"."""
    if type(value) is int and low <= value <= high:  # the usual case, without the ABCs' checks
        return value
    if isinstance(value, bool) or not isinstance(value, Integral) or not low <= int(value) <= high:
        raise SpecError(f"{name}={value!r}: expected a whole number, {low} <= {name} <= {high}")
    return int(value)


def check_trace_subject(mech: Any, branches: Any, progress: Any) -> None:
    """Refuse, with one :class:`SpecError` naming the argument, a ``mech`` that is not a
    :class:`~linkwork.kinematics.mechanism.Mechanism` (a name or a path: ``lw.load`` makes one), a ``branches``
    that is not a bool (``"no"`` is true) and a ``progress`` that cannot be called: each was a raw
    ``AttributeError`` or ``TypeError`` from inside the trace."""
    from linkwork.kinematics.mechanism import Mechanism

    if not isinstance(mech, Mechanism):
        hint = " (lw.load(NAME or FILE) makes one)" if isinstance(mech, str) else ""
        raise SpecError(f"mech={mech!r:.80}: expected a Mechanism{hint}")
    if not isinstance(branches, bool | np.bool_):  # numpy's bool too
        raise SpecError(f"branches={branches!r:.80}: expected True or False")
    if progress is not None and not callable(progress):
        raise SpecError(f"progress={progress!r:.80}: expected a function progress(done, total) or None")


def check_trace_arguments(
    until: Any,
    steps: Any,
    max_step: Any,
    min_step: Any,
    max_turn: Any,
    max_steps: Any,
    limits: Any,
    closure_tol: Any,
) -> None:
    """Refuse, with one :class:`SpecError` naming the argument, any of :func:`linkwork.trace`'s settings that is
    not what it documents: ``until`` a ``(joint, value)`` pair with a finite value; ``steps`` and ``max_steps``
    whole numbers >= 1; ``max_step``, ``min_step`` (radians) and ``closure_tol`` positive finite numbers,
    ``max_turn`` one in ``(0, pi]``; ``limits`` a mapping of joint names to ``(low, high)`` numbers (not NaN; an
    end may be infinite)."""
    if until is not None:
        if isinstance(until, str | bytes) or not hasattr(until, "__len__") or len(until) != 2:
            raise SpecError(f"until={until!r}: expected (joint, value)")
        _real("until", until[1], "radians, or a length for a prismatic joint")
    if steps is not None:
        _count("steps", steps, 1)
    largest = _real("max_step", max_step, "radians", positive=True)
    smallest = _real("min_step", min_step, "radians", positive=True)
    if largest < smallest:  # every step would be refused as too small: the budget spent advancing nothing
        raise SpecError(f"max_step={max_step!r}: expected at least min_step ({min_step!r} radians)")
    turn = _real("max_turn", max_turn, "radians", positive=True)
    if turn > math.pi:
        raise SpecError(f"max_turn={max_turn!r}: expected a positive finite number up to pi (radians)")
    _count("max_steps", max_steps, 1)
    if closure_tol is not None:
        _real("closure_tol", closure_tol, "", positive=True)
    if limits is not None:
        if not isinstance(limits, Mapping):
            raise SpecError(f"limits={limits!r}: expected a mapping {{joint: (low, high)}}")
        for joint, ends in limits.items():
            if isinstance(ends, str | bytes) or not hasattr(ends, "__len__") or len(ends) != 2:
                raise SpecError(f"limits[{joint!r}]={ends!r}: expected (low, high)")
            for end in ends:
                _real(f"limits[{joint!r}]", end, "radians, or lengths for a prismatic joint", finite=False)
