"""Length units linkwork's files may name (on the ground floor: problem rules, drawings and the command line read
it)."""

from __future__ import annotations

__all__ = ["LENGTH_UNITS"]

#: Length units a problem file may name (``units = "mm"``): DXF ``$INSUNITS`` code, and the SVG unit and factor
#: that express one such length (SVG has no metre, foot or micrometre).
LENGTH_UNITS: dict[str, tuple[int, str, float]] = {
    "mm": (4, "mm", 1.0),
    "cm": (5, "cm", 1.0),
    "m": (6, "mm", 1000.0),
    "um": (13, "mm", 0.001),
    "in": (1, "in", 1.0),
    "ft": (2, "in", 12.0),
}
