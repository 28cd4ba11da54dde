"""Guest's rectangular frame (Gan & Pellegrino 2006, Sec. 6): six door hinges derived from its physical description.

The paper describes the frame only physically: square-section rods forming a rectangle, one set of section
diagonals in the frame's plane, corners mitred at 45 degrees, the short sides cut in the middle, six door hinges
on upward-facing faces (the four corner hinges on inward faces, the two mid-side hinges on outward faces). A door
hinge turns about the line where the face it is screwed to meets the cut plane; :func:`guest_hinges` gives those
six lines, and ``docs/linkages.md`` derives them.
"""

from __future__ import annotations

import numpy as np

from linkwork.errors import SpecError
from linkwork.geometry import line_twist
from linkwork.kinematics.mechanism import Mechanism
from linkwork.linkages.registry import LinkageEntry, Param, register

JOINTS = ("A", "B", "C", "D", "E", "F")

#: ``(sx, sy)`` of each joint around the loop: A and D mid-side (sy = 0), B, C, E, F corners (anticlockwise).
HINGE_SITES = ((1, 0), (1, 1), (-1, 1), (-1, 0), (-1, -1), (1, -1))


def guest_hinges(length: float, width: float, section: float) -> tuple[np.ndarray, np.ndarray]:
    """Hinge points ``(6, 3)`` and unit directions ``(6, 3)`` of Guest's frame, flat, in loop order A..F.

    The frame lies in z = 0 with the rods' centre lines on the rectangle ``|x| = length / 2``,
    ``|y| = width / 2``; ``h = section / sqrt(2)`` is the half-diagonal of the square section.

    * Corner ``(sx, sy)`` (B, C, E, F): the upward-inward face of the long rod, ``-sy (y - sy W/2) + z = h``,
      meets the vertical mitre plane ``sy (x - sx L/2) - sx (y - sy W/2) = 0`` in the line through
      ``(sx (L/2 - h), sy (W/2 - h), 0)`` along ``(sx, sy, 1)``: the mitre's inner-upper edge, which is also on
      the short rod's upward-inward face ``-sx (x - sx L/2) + z = h``.
    * Mid-side ``sx`` (A, D): the upward-outward face ``sx (x - sx L/2) + z = h`` meets the cut plane y = 0 in the
      line through ``(sx (L/2 + h), 0, 0)`` along ``(sx, 0, -1)``.

    Directions are oriented so that a positive angle opens the cut (the only way a door hinge on those faces
    can turn without the rods running into each other) and lifts the far end of the rod after the joint.
    """
    h = section / np.sqrt(2.0)
    half_l, half_w = length / 2.0, width / 2.0
    points, directions = [], []
    for sx, sy in HINGE_SITES:
        if sy == 0:  # mid-side hinge, upward-outward face with the cut plane y = 0
            points.append((sx * (half_l + h), 0.0, 0.0))
            directions.append((sx, 0.0, -1.0))
        else:  # corner hinge, upward-inward face with the mitre plane
            points.append((sx * (half_l - h), sy * (half_w - h), 0.0))
            directions.append((sx, sy, 1.0))
    d = np.array(directions, dtype=float)
    return np.array(points, dtype=float), d / np.linalg.norm(d, axis=1, keepdims=True)


def guest_frame(length: float = 2.0, width: float = 1.0, section: float = 0.1) -> Mechanism:
    """Guest's rectangular frame, flat (every angle zero), joints ``A..F`` anticlockwise seen from above.

    A is the mid-side hinge at x = +length/2, B the corner (+, +), C the corner (-, +), D the mid-side hinge at
    x = -length/2, E the corner (-, -), F the corner (+, -). The six rods are the half short sides and the two
    long sides. Folding (the rods rising out of the plane) makes all six angles grow together from the flat start,
    where the Jacobian has rank 5 (mobility 1).

    Parameters
    ----------
    length, width
        Sides of the rectangle of the rods' centre lines (long sides along x).
    section
        Side of the rods' square section; ``0 < section < width`` so the frame has a hole.

    References
    ----------
    .. [1] W. W. Gan, S. Pellegrino, "Numerical approach to the kinematic analysis of deployable structures
       forming a closed loop", Proc. IMechE Part C: J. Mech. Eng. Sci. 220 (2006) 1045-1056, Sec. 6 and
       Fig. 14 (the frame, due to S. D. Guest).
    """
    if not (length > 0.0 and width > 0.0):
        raise SpecError(f"guest-frame: length and width must be positive, got {length} and {width}")
    if not 0.0 < section < min(length, width):
        raise SpecError(f"guest-frame: section must lie in (0, min(length, width)), got {section}")
    points, directions = guest_hinges(length, width, section)
    twists = line_twist(points, directions)
    meta = {
        "linkage": "guest-frame",
        "length": length,
        "width": width,
        "section": section,
        "convention": "hinge-lines",
    }
    return Mechanism.single_loop("Guest's rectangular frame", JOINTS, twists, meta=meta)


register(
    LinkageEntry(
        name="guest-frame",
        build=guest_frame,
        summary="Guest's rectangular frame with six door hinges (Gan & Pellegrino 2006, Sec. 6)",
        params={
            "length": Param(2.0, "length", "long side (along x) of the rods' centre-line rectangle"),
            "width": Param(1.0, "length", "short side (along y), cut in the middle"),
            "section": Param(0.1, "length", "side of the rods' square section"),
        },
    )
)
