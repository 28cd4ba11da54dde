"""A planar mechanism's links and pivots as a DXF drawing for CAD, at one configuration, in the user's units.

Layer ``links`` holds every moving body as a polyline through its joints (closed for three or more), ``ground``
the fixed body, ``pivots`` a circle on every revolute joint, ``sliders`` a line along every prismatic joint.
Coordinates are the mechanism's x and y (its plane); ``$INSUNITS`` states the unit.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from linkwork.errors import SpecError
from linkwork.io.profiles import new_dxf
from linkwork.io.writer import require_finite
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.points import positions

#: Pivot circle radius as a fraction of the drawing's size.
PIVOT_RADIUS = 0.01


def write_mechanism_dxf(
    file: str | Path, mech: Mechanism, angles: ArrayLike, units: str | None = None
) -> None:
    """Write ``mech`` at joint values ``angles`` (radians) as a DXF drawing (see the module docstring)."""
    joints, _ = positions(mech, angles)
    xyz = require_finite(joints[0], f"{mech.name}: the joints' positions")
    if np.ptp(xyz[:, 2]) > 1e-9 * max(float(np.ptp(xyz[:, :2])), 1.0):
        raise SpecError(f"{mech.name}: a DXF drawing needs a planar mechanism (every joint at one z)")
    xy = xyz[:, :2]
    size = float(np.max(np.ptp(xy, axis=0))) or 1.0
    document = new_dxf(units)
    for layer, colour in (("links", 5), ("ground", 8), ("pivots", 1), ("sliders", 3)):
        document.layers.add(layer, color=colour)
    space = document.modelspace()
    ground = mech.ground
    for body in mech.bodies:
        members = [j for j, pair in enumerate(mech.joint_bodies) if body in pair]
        corners = [tuple(map(float, xy[j])) for j in members]
        layer = "ground" if body == ground else "links"
        if len(corners) >= 2:
            space.add_lwpolyline(corners, format="xy", close=len(corners) > 2, dxfattribs={"layer": layer})
    for j, kind in enumerate(mech.joint_types):
        centre = tuple(map(float, xy[j]))
        if kind == "R":
            space.add_circle(centre, PIVOT_RADIUS * size, dxfattribs={"layer": "pivots"})
        else:
            d = mech.twists[j, 3:5] / np.linalg.norm(mech.twists[j, 3:5])
            a, b = xy[j] - 0.1 * size * d, xy[j] + 0.1 * size * d
            space.add_line(tuple(map(float, a)), tuple(map(float, b)), dxfattribs={"layer": "sliders"})
    document.saveas(str(file))
