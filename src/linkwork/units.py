"""Length units linkwork's files may name (on the ground floor: problem rules, drawings and the command line read
it)."""

from __future__ import annotations

__all__ = ["DXF_INSUNITS", "LENGTH_UNITS", "METRES"]

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

#: A DXF drawing's ``$INSUNITS`` header code: the unit's name and its length in metres (AutoCAD's DXF reference,
#: "HEADER section group codes", ``$INSUNITS``). Code 0 is "unitless" and is not listed; nor are the astronomical
#: units (17-20), which no profile is drawn in.
DXF_INSUNITS: dict[int, tuple[str, float]] = {
    1: ("in", 0.0254),
    2: ("ft", 0.3048),
    3: ("mi", 1609.344),
    4: ("mm", 1e-3),
    5: ("cm", 1e-2),
    6: ("m", 1.0),
    7: ("km", 1e3),
    8: ("microinch", 2.54e-8),
    9: ("mil", 2.54e-5),
    10: ("yd", 0.9144),
    11: ("angstrom", 1e-10),
    12: ("nm", 1e-9),
    13: ("um", 1e-6),
    14: ("dm", 1e-1),
    15: ("dam", 1e1),
    16: ("hm", 1e2),
    21: ("US survey ft", 1200.0 / 3937.0),
    22: ("US survey in", 100.0 / 3937.0),
    23: ("US survey yd", 3600.0 / 3937.0),
    24: ("US survey mi", 6336000.0 / 3937.0),
}

#: Metres in one of each unit a drawing may be in: those of :data:`DXF_INSUNITS` by name (which include every
#: key of :data:`LENGTH_UNITS`).
METRES: dict[str, float] = {name: metres for name, metres in DXF_INSUNITS.values()}
