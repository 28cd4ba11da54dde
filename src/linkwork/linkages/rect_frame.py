"""Guest-type rectangular frames (Gan & Pellegrino 2006, Sec. 6): a family of door-hinged picture frames.

Square-section rods (section diagonals horizontal and vertical) form a rectangle with corners mitred at 45
degrees; any of the four sides may be cut at mid-length; every mitre and cut carries a door hinge on an upward
face, inward- or outward-facing. Guest's frame (:mod:`linkwork.linkages.guest`) is the member with the two short
sides cut, the corner hinges inward and the mid-side hinges outward. The paper's search for deployable
rectangular structures (Sec. 6) screened frames like these; ``linkwork search`` does it over this family.
``docs/linkages.md`` derives the hinge lines.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from linkwork.errors import SpecError
from linkwork.geometry import line_twist
from linkwork.geometry.names import default_joint_names
from linkwork.kinematics.mechanism import Mechanism
from linkwork.linkages.registry import LinkageEntry, Param, register

#: The eight sites anticlockwise from the east side's midpoint: ``(name, sx, sy)``; a corner has both signs, a
#: mid-side site one zero. E and W are the short sides (x = +-length/2), N and S the long ones (y = +-width/2).
SITES = (
    ("E", 1, 0),
    ("NE", 1, 1),
    ("N", 0, 1),
    ("NW", -1, 1),
    ("W", -1, 0),
    ("SW", -1, -1),
    ("S", 0, -1),
    ("SE", 1, -1),
)

SIDES = "NESW"

GUEST_CUTS = "EW"
"""Guest's frame: the two short sides cut."""


def hinge_sites(cuts: str) -> list[tuple[str, int, int]]:
    """The hinged sites in loop order (anticlockwise from the east side's midpoint): the four corners and the
    midpoints of the sides in ``cuts``."""
    return [site for site in SITES if site[0] in cuts or (site[1] != 0 and site[2] != 0)]


def auto_faces(cuts: str) -> str:
    """Guest's rule: corner hinges on inward faces (``i``), mid-side hinges on outward faces (``o``)."""
    return "".join("i" if sx and sy else "o" for _, sx, sy in hinge_sites(cuts))


def check_cuts(cuts: str) -> str:
    """``cuts`` as written (letters N, E, S, W, each at most once), refused otherwise."""
    if any(c not in SIDES for c in cuts) or len(set(cuts)) != len(cuts):
        raise SpecError(
            f"rect-frame: cuts expected distinct letters from N, E, S, W (the sides cut at mid-length), got {cuts!r}",
            key="--set",
        )
    return cuts


def resolve_faces(cuts: str, faces: str) -> str:
    """The face of every hinge in loop order (``i`` inward, ``o`` outward); ``"auto"`` is Guest's rule."""
    n = len(hinge_sites(cuts))
    if faces == "auto":
        return auto_faces(cuts)
    if len(faces) != n or any(c not in "io" for c in faces):
        raise SpecError(
            f"rect-frame: faces expected 'auto' or {n} letters i/o (one per hinge of cuts={cuts!r}, anticlockwise "
            f"from the east side), got {faces!r}",
            key="--set",
        )
    return faces


def rect_frame_hinges(
    length: float, width: float, section: float, cuts: str = GUEST_CUTS, faces: str = "auto"
) -> tuple[np.ndarray, np.ndarray]:
    """Hinge points ``(k, 3)`` and unit directions ``(k, 3)`` of the flat frame, in loop order.

    The rods' centre lines form the rectangle ``|x| = length / 2``, ``|y| = width / 2`` in z = 0;
    ``h = section / sqrt(2)`` is the half-diagonal of the section. A site at centre-line point ``c`` with outward
    direction ``n`` (``(sx, sy)`` at a corner, the side's unit normal at a midpoint) has its hinge

    * on the upward-inward face: through ``c - h n``, along ``(n, 1)``;
    * on the upward-outward face: through ``c + h n``, along ``(n, -1)``,

    the line where that face meets the mitre plane (a corner) or the cut plane (a midpoint). Signs as Guest's
    frame: a positive angle lifts the far end of the rod after the joint.
    """
    faces = resolve_faces(check_cuts(cuts), faces)
    h = section / np.sqrt(2.0)
    points, directions = [], []
    for (_, sx, sy), face in zip(hinge_sites(cuts), faces, strict=True):
        centre = np.array([sx * length / 2.0, sy * width / 2.0, 0.0])
        n = np.array([sx, sy, 0.0])
        up = 1.0 if face == "i" else -1.0
        points.append(centre - up * h * n)
        directions.append(n + np.array([0.0, 0.0, up]))
    d = np.array(directions)
    return np.array(points), d / np.linalg.norm(d, axis=1, keepdims=True)


def frame_points(length: float, width: float, cuts: str) -> list[dict[str, Any]]:
    """Named points for the deployment measures: the four corners and the four side midpoints of the rods'
    centre lines, each on the rod that carries it (at a hinged site, the rod after the hinge)."""
    hinged = [name for name, _, _ in hinge_sites(cuts)]
    order = [name for name, _, _ in SITES]
    out = []
    for name, sx, sy in SITES:
        # The body after the last hinge at or before this site, going anticlockwise round the loop.
        k = order.index(name)
        before = [order[(k - i) % 8] for i in range(8)]
        last = next(site for site in before if site in hinged)
        label = f"corner_{name}" if sx and sy else f"mid_{name}"
        out.append(
            {
                "name": label,
                "body": f"link{hinged.index(last)}",
                "position": [sx * length / 2.0, sy * width / 2.0, 0.0],
            }
        )
    return out


def rect_frame(
    length: float = 2.0,
    width: float = 1.0,
    section: float = 0.1,
    cuts: str = GUEST_CUTS,
    faces: str = "auto",
) -> Mechanism:
    """A Guest-type rectangular frame, flat (every angle zero), joints ``A, B, ...`` anticlockwise from the east
    side's midpoint seen from above.

    Parameters
    ----------
    length, width
        Sides of the rectangle of the rods' centre lines (``length`` along x).
    section
        Side of the rods' square section, ``0 < section < min(length, width)``.
    cuts
        The sides cut at mid-length, letters from ``N``, ``E``, ``S``, ``W`` (E, W: the sides at x = +-length/2;
        N, S: at y = +-width/2). Every cut adds a hinge: four corners plus the cuts, 4 to 8 hinges.
    faces
        One letter per hinge in loop order, ``i`` (upward-inward face) or ``o`` (upward-outward), or ``"auto"``:
        corners inward, mid-sides outward (Guest's rule).

    ``rect_frame()`` (the defaults) has the same hinge lines, joint order and motion as ``guest_frame()``. Its
    named points are the corners and side midpoints of the centre lines (``corner_NE``, ``mid_E``, ...), the
    attachment points of the deployment measures.
    """
    if not (length > 0.0 and width > 0.0):
        raise SpecError(
            f"rect-frame: length and width must be positive, got {length} and {width}", key="--set"
        )
    if not 0.0 < section < min(length, width):
        raise SpecError(
            f"rect-frame: section must lie in (0, min(length, width)), got {section}", key="--set"
        )
    points, directions = rect_frame_hinges(length, width, section, cuts, faces)
    names = default_joint_names(len(points))
    meta = {
        "linkage": "rect-frame",
        "length": length,
        "width": width,
        "section": section,
        "cuts": cuts,
        "faces": faces,
        "hinge_faces": resolve_faces(cuts, faces),
        "hinge_sites": [name for name, _, _ in hinge_sites(cuts)],
        "convention": "hinge-lines",
        "points": frame_points(length, width, cuts),
    }
    label = f"rectangular frame {length:g} x {width:g}, cuts {cuts or 'none'}, faces {meta['hinge_faces']}"
    return Mechanism.single_loop(label, names, line_twist(points, directions), meta=meta)


register(
    LinkageEntry(
        name="rect-frame",
        build=rect_frame,
        summary="Guest-type rectangular frames: mitred square rods, sides cut at mid-length, door hinges in or out",
        params={
            "length": Param(2.0, "length", "long side (along x) of the rods' centre-line rectangle", low=0.0),
            "width": Param(1.0, "length", "short side (along y) of the rods' centre-line rectangle", low=0.0),
            "section": Param(0.1, "length", "side of the rods' square section", low=0.0),
            "cuts": Param(
                GUEST_CUTS,
                "text",
                'the sides cut at mid-length: letters from N, E, S, W, e.g. "EW" (Guest\'s frame)',
                pattern="[NESW]{0,4}",
            ),
            "faces": Param(
                "auto",
                "text",
                '"auto" (corners in, mid-sides out) or one letter i/o per hinge, e.g. "oiioii"',
                pattern="auto|[io]{4,8}",
            ),
        },
    )
)
