"""The stated bounds of every number a user gives: a flag's value or a study-file key, checked the same way.

A :class:`Limit` says what a value must be (a whole number or a finite real, within ``[low, high]``, either end
open if asked) and words it once, so that a flag and a file key with the same meaning give the same message:
``expected a whole number of steps, 1 <= --max-steps <= 1e+06``. The limits that protect the machine (memory,
processes, grid points, samples) are stated here too, so that the documentation and the checks quote one number.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

MAX_TRACE_STEPS = 1_000_000
"""The largest step budget of a trace (``--max-steps``, ``--steps``, ``trace.max_steps``, ``trace.steps``)."""

MAX_SAMPLES = 10_000_000
"""The most Monte Carlo samples of one robustness study (each keeps about 40 bytes in memory)."""

MAX_STUDY_SAMPLES = 100_000_000
"""The most Monte Carlo samples of a whole sweep: grid points times ``robustness.samples``."""

MAX_PATH_POINTS = 10_000
"""The most points of a robustness study's nominal path: every chunk in flight keeps two histograms of about
1,900 counts per path point (about 30 kB per point), so a longer path would need gigabytes."""

MAX_SEED = 2**63 - 1
"""The largest seed (the largest whole number a TOML file can hold)."""

SMALLEST_STEP_DEGREES = math.degrees(1e-9)
"""The tracer's smallest step (``linkwork.trace``'s ``min_step``, 1e-9 radians) in degrees: the least
``--max-step`` (a largest step below it spent the whole step budget advancing nothing, exit 0)."""

MAX_MAGNITUDE = 1e12
"""The largest absolute value of a length or a tolerance given by a user."""


PLAIN_NUMBER = re.compile(
    r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|[+-]?(?:nan|inf|infinity)", re.I
)
"""A number as a person types it in a flag or a CSV or Selig file writes it: ASCII digits, an optional sign,
decimal point and exponent, or nan / inf (refused later as not finite, by whoever needs it finite). Python's
``float`` would also take ``1_000`` (a typo for 1.000 in some locales), surrounding spaces, Arabic-Indic and
full-width digits, which no spreadsheet or other reader takes for the same number."""

PLAIN_INTEGER = re.compile(r"[+-]?[0-9]+")
"""A whole number as a person types it: ASCII digits with an optional sign."""


def plain_number(text: str) -> float | None:
    """The number ``text`` is when it is written as :data:`PLAIN_NUMBER` says, else ``None``."""
    return float(text) if PLAIN_NUMBER.fullmatch(text) else None


def machine_cores() -> int:
    """The cores of this machine, ``os.cpu_count()`` (at least 1): the most local worker processes."""
    return max(1, os.cpu_count() or 1)


@dataclass(frozen=True)
class Limit:
    """The bounds of one user-given number.

    Attributes
    ----------
    what
        What the value is, for the message: ``"a whole number of steps"``.
    low, high
        The bounds; ``high`` may be a function of the machine (the cores for ``--workers``).
    whole
        A whole number (``True``) or a finite real.
    open_low, open_high
        Whether ``low`` / ``high`` themselves are excluded.
    why
        Why the upper bound is what it is, when it is a limit of the machine (shown in the message).
    """

    what: str
    low: float
    high: float | Callable[[], float]
    whole: bool = False
    open_low: bool = False
    open_high: bool = False
    why: str = ""

    @property
    def upper(self) -> float:
        """The upper bound now (a machine-dependent bound is evaluated; a whole number stays exact)."""
        return self.high() if callable(self.high) else self.high

    def expected(self, name: str) -> str:
        """``what, low <= name <= high`` (with ``<`` at an open end, and the reason of a machine limit)."""
        low = "<" if self.open_low else "<="
        high = "<" if self.open_high else "<="
        why = f" ({self.why})" if self.why else ""
        return f"{self.what}, {_number(self.low)} {low} {name} {high} {_number(self.upper)}{why}"

    def broken(self, value: Any) -> bool:
        """Whether ``value`` is not a number of the right kind within the bounds (``True`` is not a number;
        NaN and infinities never are)."""
        if isinstance(value, bool):
            return True
        if self.whole:
            if not isinstance(value, int):
                return True
        elif not isinstance(value, int | float):
            return True
        try:
            number = float(value)
        except OverflowError:
            return True
        if not math.isfinite(number):
            return True
        too_low = value < self.low or (self.open_low and value == self.low)
        too_high = value > self.upper or (self.open_high and value == self.upper)
        return bool(too_low or too_high)


def _number(value: float) -> str:
    """A bound as written in a message: whole numbers below a million in full, others as ``%g`` unless that
    would round them (``2**63 - 1`` is written in full)."""
    if float(value).is_integer() and (abs(value) < 1e6 or int(float(f"{value:g}")) != value):
        return str(int(value))
    return f"{value:g}"


STEPS = Limit("a whole number of steps", 1, MAX_TRACE_STEPS, whole=True)
SAMPLES = Limit("a whole number of samples", 1, MAX_SAMPLES, whole=True)
SEED = Limit("a whole number", 0, MAX_SEED, whole=True)
POSITION_TOL = Limit("a length", 0.0, MAX_MAGNITUDE)
DIRECTION_TOL = Limit("an angle in degrees", 0.0, 90.0, open_high=True)
WORKERS = Limit(
    "a whole number of local worker processes (0 runs in this process)",
    0,
    machine_cores,
    whole=True,
    why="the cores of this machine, os.cpu_count()",
)


MECHANIZE: dict[str, Limit] = {
    "dof": Limit("a whole number of degrees of freedom", 1, 20, whole=True),
    "link_offset": Limit("a number of body lengths", 0.0, MAX_MAGNITUDE),
    "max_link": Limit("a length in the profiles' units", 0.0, MAX_MAGNITUDE, open_low=True),
    "max_link_fraction": Limit(
        "a multiple of the profiles' largest extent", 0.0, MAX_MAGNITUDE, open_low=True
    ),
    "max_structural_error": Limit("a length in the profiles' units", 0.0, MAX_MAGNITUDE, open_low=True),
    "min_transmission": Limit("an angle in degrees", 0.0, 90.0, open_high=True),
    "attempts": Limit("a whole number of designs", 1, 100_000, whole=True),
    "designs": Limit("a whole number of designs", 1, 20, whole=True),
    "time_limit": Limit("a number of seconds", 0.0, 7 * 24 * 3600.0, open_low=True),
}
"""The bounds of the mechanization options, by problem-file key: the flag of the same name (``--time-limit``)
and the key (``time_limit``) have one bound, so a problem file cannot ask what the flag refuses
(``time_limit = 1e308`` was taken)."""
