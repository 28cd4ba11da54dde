"""The registry of built-in linkages: each a named constructor with documented parameters.

Parameters are given to constructors in API units (radians); ``unit = "deg"`` marks an angle, which files, flags
(``--set alpha=45``) and printed tables give in degrees.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from linkwork.errors import SpecError
from linkwork.kinematics.mechanism import Mechanism
from linkwork.messages import closest, show

MAX_RODS = 100
"""The largest ``n`` of a built-in hoop (Hedgepeth's n rods)."""

#: The range of a parameter in file units, by unit, unless the parameter states its own: lengths within
#: +-1e6, angles within +-720 degrees, whole numbers from 0 to 1000.
DEFAULT_BOUNDS = {"length": (-1e6, 1e6), "deg": (-720.0, 720.0), "int": (0, 1000)}


@dataclass(frozen=True)
class Param:
    """One parameter of a built-in linkage: default (API units), unit (``"deg"``, ``"length"``, ``"int"``,
    ``"text"``), help, and the range ``[low, high]`` a given value must be in (file units; :data:`DEFAULT_BOUNDS`
    when ``None``). A ``"text"`` parameter is a string matching the regular expression ``pattern`` (whole
    string); the constructor checks what the pattern cannot say."""

    default: float | int | str
    unit: str
    help: str
    low: float | None = None
    high: float | None = None
    pattern: str | None = None

    @property
    def bounds(self) -> tuple[float, float]:
        """``(low, high)`` in file units (degrees for angles); ``(nan, nan)`` for text."""
        if self.unit == "text":
            return (math.nan, math.nan)
        low, high = DEFAULT_BOUNDS[self.unit]
        return (low if self.low is None else self.low, high if self.high is None else self.high)


@dataclass(frozen=True)
class LinkageEntry:
    """A built-in linkage: its CLI name, constructor, parameters and one-line summary."""

    name: str
    build: Callable[..., Mechanism]
    summary: str
    params: Mapping[str, Param] = field(default_factory=dict)

    def make(self, **given: Any) -> Mechanism:
        """Build with ``given`` parameters in FILE units (degrees for angles), checking names, types and ranges.

        This is the one place a built-in's ``--set`` values are validated: each must be a finite number within
        its parameter's :attr:`Param.bounds` (a whole number for ``"int"``); the message states the range.
        """
        unknown = sorted(set(given) - set(self.params))
        if unknown:
            expected = ", ".join(self.params) or "no parameters"
            raise SpecError(
                f"{self.name}: unknown parameter {show(unknown[0])}; expected {expected}", key="--set"
            )
        kwargs: dict[str, Any] = {}
        for key, param in self.params.items():
            kwargs[key] = param.default if key not in given else self._checked(key, param, given[key])
        return self.build(**kwargs)

    def check_value(self, key: str, value: Any) -> float | int | str:
        """``value`` (file units) of parameter ``key`` checked against its range or pattern and converted to API
        units; a :class:`SpecError` naming the parameter otherwise."""
        return self._checked(key, self.params[key], value)

    def _checked(self, key: str, param: Param, value: Any) -> float | int | str:
        """``value`` (file units) checked against ``param`` and converted to API units."""
        if param.unit == "text":
            if not isinstance(value, str) or re.fullmatch(param.pattern or ".*", value) is None:
                raise SpecError(
                    f"{self.name}: parameter {key} expected {param.help}, got {show(value)}", key="--set"
                )
            return value
        low, high = param.bounds
        unit = " deg" if param.unit == "deg" else ""
        what = "a whole number" if param.unit == "int" else "a finite number"
        bad = SpecError(
            f"{self.name}: parameter {key} expected {what} from {low:g} to {high:g}{unit}, got {show(value)}",
            key="--set",
        )
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise bad
        number = float(value) if isinstance(value, float) or abs(value) < 10**300 else math.inf
        if not (math.isfinite(number) and low <= number <= high):
            raise bad
        if param.unit == "int":
            if number != int(number):
                raise bad
            return int(number)
        return math.radians(number) if param.unit == "deg" else number

    def file_defaults(self) -> dict[str, float | int | str]:
        """Defaults in file units (degrees for angles)."""
        return {
            k: (float(np.degrees(p.default)) if p.unit == "deg" else p.default)
            for k, p in self.params.items()
        }


REGISTRY: dict[str, LinkageEntry] = {}


def register(entry: LinkageEntry) -> LinkageEntry:
    """Add a built-in linkage to :data:`REGISTRY` (name clashes are a programming error)."""
    if entry.name in REGISTRY:
        raise ValueError(f"linkage {entry.name!r} registered twice")
    REGISTRY[entry.name] = entry
    return entry


def get(name: str) -> LinkageEntry:
    """The registered linkage called ``name`` (underscores and dashes are equivalent)."""
    key = name.replace("_", "-").lower()
    for entry in REGISTRY.values():
        if entry.name == key:
            return entry
    close = closest(key, sorted(REGISTRY))
    hint = f"did you mean {close!r}? " if close else ""
    raise SpecError(f"unknown linkage {name!r}; {hint}built-ins are {', '.join(sorted(REGISTRY))}")
