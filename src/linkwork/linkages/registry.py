"""The registry of built-in linkages: each a named constructor with documented parameters.

Parameters are given to constructors in API units (radians); ``unit = "deg"`` marks an angle, which files, flags
(``--set alpha=45``) and printed tables give in degrees.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from linkwork.errors import SpecError
from linkwork.kinematics.mechanism import Mechanism


@dataclass(frozen=True)
class Param:
    """One parameter of a built-in linkage: default (API units), unit (``"deg"``, ``"length"``, ``"int"``), help."""

    default: float | int
    unit: str
    help: str


@dataclass(frozen=True)
class LinkageEntry:
    """A built-in linkage: its CLI name, constructor, parameters and one-line summary."""

    name: str
    build: Callable[..., Mechanism]
    summary: str
    params: Mapping[str, Param] = field(default_factory=dict)

    def make(self, **given: Any) -> Mechanism:
        """Build with ``given`` parameters in FILE units (degrees for angles), checking names and types."""
        unknown = sorted(set(given) - set(self.params))
        if unknown:
            expected = ", ".join(self.params) or "no parameters"
            raise SpecError(f"{self.name}: unknown parameter {unknown[0]!r}; expected {expected}")
        kwargs: dict[str, Any] = {}
        for key, param in self.params.items():
            if key not in given:
                kwargs[key] = param.default
                continue
            value = given[key]
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise SpecError(f"{self.name}: parameter {key!r} expected a number, got {value!r}")
            if param.unit == "int":
                if float(value) != int(value):
                    raise SpecError(f"{self.name}: parameter {key!r} expected a whole number, got {value!r}")
                kwargs[key] = int(value)
            elif param.unit == "deg":
                kwargs[key] = float(np.radians(value))
            else:
                kwargs[key] = float(value)
        return self.build(**kwargs)

    def file_defaults(self) -> dict[str, float | int]:
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
    raise SpecError(f"unknown linkage {name!r}; built-ins are {', '.join(sorted(REGISTRY))}")
