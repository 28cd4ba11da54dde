"""A mechanism at a glance, for notebooks: a one-line summary (``repr``) and an HTML card with its joints and bodies
as tables and a small SVG drawing of the start configuration (no JavaScript, no matplotlib, a few kB).

Every name a user wrote (the mechanism's, a joint's, a body's) is escaped before it enters the HTML.
"""

from __future__ import annotations

import html
import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from linkwork.viz.palette import colour

if TYPE_CHECKING:
    from linkwork.kinematics.mechanism import Mechanism

DRAWING_PX = 220
"""Width and height of the card's drawing (CSS pixels)."""

MAX_ROWS = 40
"""Rows of the joints table shown before it is cut (a hoop of 100 rods lists its first 40)."""

MAX_NAME = 60
"""The longest mechanism name a summary shows whole."""

_TYPES = {"R": "revolute", "P": "prismatic"}


def summary(mech: Mechanism) -> str:
    """One line: name, joints by type and name, bodies, loops, planar or spatial, couplings and fixed joints."""
    kinds = sorted(set(mech.joint_types))
    joints = " and ".join(f"{mech.joint_types.count(k)} {_TYPES.get(k, k)}" for k in kinds)
    names = (
        ", ".join(mech.joint_names)
        if mech.n_joints <= 12
        else f"{mech.joint_names[0]} ... {mech.joint_names[-1]}"
    )
    extra = ["couplings " + ", ".join(_couplings(mech))] if _couplings(mech) else []
    fixed = [mech.joint_names[j] for j in np.flatnonzero(mech.groups < 0)]
    if fixed:
        extra.append("fixed " + ", ".join(fixed))
    loops = f"{len(mech.loops)} loop{'s' if len(mech.loops) != 1 else ''}"
    parts = [
        f"{joints} joints ({names})",
        f"{len(mech.bodies)} bodies",
        loops,
        "planar" if mech.moves_in_plane else "spatial",
    ]
    name = mech.name if len(mech.name) <= MAX_NAME else mech.name[: MAX_NAME - 3] + "..."
    return f"<Mechanism {name!r}: " + "; ".join(parts + extra) + ">"


def _couplings(mech: Mechanism) -> list[str]:
    """Each group of coupled joints as ``A=C=E``."""
    return [
        "=".join(mech.joint_names[j] for j in members) for members in mech.group_members() if len(members) > 1
    ]


def _start(mech: Mechanism, j: int) -> str:
    """Joint ``j``'s start value in file units (degrees, or a length)."""
    value = float(mech.offsets[j])
    return f"{math.degrees(value):.6g} deg" if mech.joint_types[j] == "R" else f"{value:.6g}"


def _vector(x: NDArray[np.float64]) -> str:
    """``(x, y, z)`` with 4 significant digits, round-off next to zero shown as 0."""
    return "(" + ", ".join(f"{0.0 if abs(v) < 5e-13 else v:.4g}" for v in x) + ")"


def card(mech: Mechanism) -> str:
    """The HTML card (``Mechanism._repr_html_``): summary, a drawing, the joints and bodies tables."""
    from linkwork.kinematics.positions import joint_points

    esc = html.escape
    points = joint_points(mech)
    rows = []
    for j in range(min(mech.n_joints, MAX_ROWS)):
        before, after = mech.joint_bodies[j] if mech.joint_bodies else ("", "")
        direction = mech.twists[j, :3] if mech.joint_types[j] == "R" else mech.twists[j, 3:]
        rows.append(
            "<tr>"
            + "".join(
                f"<td>{esc(str(cell))}</td>"
                for cell in (
                    mech.joint_names[j],
                    _TYPES.get(mech.joint_types[j], mech.joint_types[j]),
                    f"{before} \u2192 {after}",
                    _vector(points[j]),
                    _vector(direction),
                    _start(mech, j),
                )
            )
            + "</tr>"
        )
    if mech.n_joints > MAX_ROWS:
        rows.append(f"<tr><td colspan='6'>... {mech.n_joints - MAX_ROWS} more joints</td></tr>")
    head = "".join(f"<th>{h}</th>" for h in ("joint", "type", "bodies", "point", "direction", "start"))
    body_rows = "".join(
        f"<tr><td>{esc(b)}</td><td>{esc(', '.join(_body_joints(mech, b)))}</td></tr>"
        for b in mech.bodies[:MAX_ROWS]
    )
    cell = "style='vertical-align: top; padding-right: 1em'"
    return (
        f"<div class='linkwork-mechanism'><p><code>{esc(summary(mech))}</code></p>"
        f"<table><tr><td {cell}>{drawing(mech, points)}</td>"
        f"<td {cell}><table><thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table></td>"
        f"<td {cell}><table><thead><tr><th>body</th><th>joints</th></tr></thead><tbody>{body_rows}</tbody></table>"
        "</td></tr></table></div>"
    )


def _body_joints(mech: Mechanism, body: str) -> list[str]:
    return [mech.joint_names[j] for j, pair in enumerate(mech.joint_bodies) if body in pair]


def _projected(mech: Mechanism, points: NDArray[np.float64]) -> NDArray[np.float64]:
    """Drawing coordinates: x, y for a mechanism moving in that plane, an isometric view (from (1, -1, 1))
    otherwise."""
    if mech.moves_in_xy:
        return points[:, :2].copy()
    c, s = math.cos(math.radians(30.0)), math.sin(math.radians(30.0))
    x, y, z = points.T
    return np.column_stack([(x + y) * c, z + (y - x) * s])


def drawing(mech: Mechanism, points: NDArray[np.float64] | None = None) -> str:
    """An inline SVG of the start configuration: each body a line through its joints (ground dashed), each joint
    a circle labelled with its name."""
    from linkwork.kinematics.positions import joint_points

    points = joint_points(mech) if points is None else points
    xy = _projected(mech, points)
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    span = float(max(hi[0] - lo[0], hi[1] - lo[1], 1e-9))
    pad = 22.0
    scale = (DRAWING_PX - 2 * pad) / span
    centre = (lo + hi) / 2
    px = (xy - centre) * scale * np.array([1.0, -1.0]) + DRAWING_PX / 2  # y up on the page

    def at(k: int) -> str:
        return f"{px[k, 0]:.1f},{px[k, 1]:.1f}"

    shapes = []
    for b, body in enumerate(mech.bodies):
        ks = [j for j, pair in enumerate(mech.joint_bodies) if body in pair]
        if len(ks) < 2:
            continue
        ground = body == mech.ground
        style = "stroke='#888' stroke-dasharray='4 3'" if ground else f"stroke='{colour(b)}'"
        closed = len(ks) > 2
        tag = "polygon" if closed else "polyline"
        shapes.append(
            f"<{tag} points='{' '.join(at(k) for k in ks)}' fill='none' {style} stroke-width='2.5'>"
            f"<title>{html.escape(body)}</title></{tag}>"
        )
    for j, name in enumerate(mech.joint_names):
        shapes.append(
            f"<circle cx='{px[j, 0]:.1f}' cy='{px[j, 1]:.1f}' r='4' fill='white' stroke='black'/>"
            f"<text x='{px[j, 0] + 6:.1f}' y='{px[j, 1] - 6:.1f}' font-size='11' font-family='sans-serif'>"
            f"{html.escape(name)}</text>"
        )
    view = "planar, x right, y up" if mech.moves_in_xy else "isometric view"
    return (
        f"<svg xmlns='http://www.w3.org/2000/svg' width='{DRAWING_PX}' height='{DRAWING_PX}' "
        f"viewBox='0 0 {DRAWING_PX} {DRAWING_PX}' role='img'><title>{html.escape(mech.name)} at its start "
        f"({view})</title>{''.join(shapes)}</svg>"
    )
