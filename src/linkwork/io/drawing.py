"""Drawings for CAD and browsers: SVG documents (text) and DXF documents (ezdxf) in a stated length unit.

The writers of profile files (:mod:`linkwork.io.profiles`) and of a synthesised chain's outline
(:mod:`linkwork.io.outlines`) build on these. Coordinates are profile coordinates with the y axis up; SVG's points
down, so every SVG coordinate written here has its y negated.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from linkwork.io.curves import Points, bounding_size
from linkwork.io.writer import require_finite
from linkwork.names import xml_text
from linkwork.units import LENGTH_UNITS

__all__ = ["LENGTH_UNITS", "new_dxf", "svg_d", "svg_document", "svg_path", "xml_escape"]


def svg_path(d: str, colour: str, *, dashed: bool = False, label: str | None = None) -> str:
    dash = ' stroke-dasharray="4 3"' if dashed else ""
    title = f"<title>{xml_escape(label)}</title>" if label else ""
    return (
        f'<path d="{d}" fill="none" stroke="{colour}" stroke-width="1.5" '
        f'vector-effect="non-scaling-stroke"{dash}>{title}</path>'
    )


def svg_d(points: Points) -> str:
    return "M " + " L ".join(f"{x:.12g},{-y:.12g}" for x, y in points)


def svg_document(
    body: Iterable[str], extents: Sequence[Points], pixels: float = 800.0, units: str | None = None
) -> str:
    """An SVG document whose viewBox holds every point of ``extents`` (profile coordinates, y up); with ``units``
    (a key of :data:`LENGTH_UNITS`) its width and height are the drawing's true size in that unit, else
    ``pixels`` across."""
    everything = require_finite(
        np.vstack([np.asarray(e, dtype=float).reshape(-1, 2) for e in extents]), "the drawing's coordinates"
    )
    lo, hi = everything.min(axis=0), everything.max(axis=0)
    margin = 0.05 * bounding_size(everything)
    x0, y0 = lo[0] - margin, -hi[1] - margin
    width, height = hi[0] - lo[0] + 2 * margin, hi[1] - lo[1] + 2 * margin
    if units is None:
        scale, unit = pixels / max(width, height), ""
    else:
        _code, unit, scale = LENGTH_UNITS[units]
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width * scale:.6g}{unit}" '
        f'height="{height * scale:.6g}{unit}" viewBox="{x0:.12g} {y0:.12g} {width:.12g} {height:.12g}">',
        *body,
        "</svg>",
    ]
    return "\n".join(lines) + "\n"


def xml_escape(text: str) -> str:
    """``text`` as XML character data or attribute value (the name policy's :func:`linkwork.names.xml_text`):
    markup characters escaped, characters XML 1.0 does not allow replaced by U+FFFD."""
    return xml_text(text)


def new_dxf(units: str | None = None) -> Any:
    """A new ezdxf document (R2010) whose ``$INSUNITS`` says the drawing's length unit (0, unitless, when
    ``units`` is ``None``) and whose ``$MEASUREMENT`` is metric or imperial to match."""
    import ezdxf

    document = ezdxf.new("R2010")
    code = LENGTH_UNITS[units][0] if units is not None else 0
    document.header["$INSUNITS"] = code
    document.header["$MEASUREMENT"] = 0 if units in ("in", "ft") else 1
    return document
