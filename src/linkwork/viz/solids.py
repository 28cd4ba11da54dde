"""Solid geometry for drawing a mechanism: one closed triangle mesh per body, and hinge pins, placed from angles.

The meshes are built in the mechanism's **reference configuration** (the assembled configuration its twists
describe) and moved rigidly by :func:`linkwork.kinematics.closure.body_poses`. The style follows
``mech.meta["linkage"]``:

* ``"hedgepeth"``: the paper's rods, prisms of isosceles-triangle section (apex angle ``alpha1 = 360/n``, Eq. (7))
  running along their apex line between the two hinge frames (Gan & Pellegrino 2006, Sec. 3 and Fig. 5). Each
  hinge axis lies in a side face through the apex (a door hinge on that face); each end is cut by the plane through
  the hinge axis whose normal lies in the rod's plane of symmetry, so the end section is an isosceles triangle and
  the cut makes ``180/n`` degrees with the rod (the paper's cut angle). A documented simplification: the paper's
  rods are cut this way too, but its exact door-hinge offsets are not given.
* ``"hedgepeth-rods"``: the same rods as built (:mod:`linkwork.linkages.hedgepeth_rods`): pie-slice sections
  tiling a regular n-gon in the bundle, ends mitred at ``180/n``, each pin along the edge where a mitre meets the
  side face that carries the door hinge.
* ``"guest-frame"``: square-section rods turned 45 degrees (section diagonals horizontal and vertical), corners
  mitred by the vertical bisecting planes, short sides cut by the plane ``y = 0`` (Sec. 6; ``docs/linkages.md``).
* anything else (spec files, Bennett, Bricard, Sarrus, Goldberg, synthesised mechanisms): round bars between the
  consecutive hinge axes of each body along their common normal, plus a hinge pin on every axis.

Every mesh is closed and consistently oriented (outward normals, positive volume); sizes scale with the
mechanism (the median link length). Prismatic joints have no location in a twist: they are drawn through the
centroid of the other joints of their two bodies.

The mesh record and its primitives live in :mod:`linkwork.viz.mesh`, the designed rods of the built-in linkages in
:mod:`linkwork.viz.rod_solids`; their names keep this module's import path too.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping

import numpy as np
from numpy.typing import ArrayLike

from linkwork.geometry.fit import kabsch
from linkwork.kinematics.closure import body_poses
from linkwork.kinematics.mechanism import Mechanism
from linkwork.viz.mesh import (
    BAR_COLORS,
    PIN_COLOR,
    ROD_COLORS,
    SEGMENTS,
    Array,
    IntArray,
    Mesh,
    cut_prism,
    cylinder,
    edge_counts,
    merge,
    prism_faces,
    signed_volume,
)
from linkwork.viz.rod_solids import ROD_WIDTH, guest_design, hedgepeth_design, hedgepeth_rods_design

__all__ = [
    "BAR_COLORS",
    "BAR_RADIUS",
    "PIN_COLOR",
    "PIN_MARGIN",
    "PIN_RADIUS",
    "ROD_COLORS",
    "ROD_WIDTH",
    "SEGMENTS",
    "Array",
    "IntArray",
    "Mesh",
    "bar_segments",
    "body_meshes",
    "common_normal",
    "cut_prism",
    "cylinder",
    "edge_counts",
    "hinge_pins",
    "joint_lines",
    "mechanism_scale",
    "place",
    "posed_meshes",
    "prism_faces",
    "signed_volume",
]

#: Relative sizes (fractions of the mechanism's scale).
BAR_RADIUS = 0.035
PIN_RADIUS = 0.05
PIN_MARGIN = 0.12  # pin overhang beyond the bars it joins


# --------------------------------------------------------------------------------------------------------
# public API


def body_meshes(mech: Mechanism) -> dict[str, Mesh]:
    """One mesh per body of ``mech`` in its reference configuration, keyed by body name (``mech.bodies`` order)."""
    return _drawing(mech)[0]


def hinge_pins(mech: Mechanism) -> list[Mesh]:
    """One small cylinder along every joint axis (reference configuration), in joint order, named by joint."""
    return _drawing(mech)[1]


def posed_meshes(mech: Mechanism, angles: ArrayLike, *, pins: bool = True) -> list[Mesh]:
    """Every body's mesh (``mech.bodies`` order), then the pins (joint order), at the joint values ``angles``.

    ``angles`` are the reported joint values in radians (a row of ``Path.angles``); bodies are placed by
    ``body_poses(mech, angles=angles)``, a pin by the pose of the body after its joint.
    """
    bodies, pin_meshes = _drawing(mech)
    return place(mech, bodies, pin_meshes if pins else [], angles)


def place(mech: Mechanism, bodies: Mapping[str, Mesh], pins: list[Mesh], angles: ArrayLike) -> list[Mesh]:
    """Move precomputed reference meshes (from :func:`body_meshes`, :func:`hinge_pins`) to ``angles``.

    Use it to pose many frames without rebuilding the meshes.
    """
    poses = body_poses(mech, angles=angles)
    out = [mesh.transformed(poses[name]) for name, mesh in bodies.items()]
    by_joint = {name: j for j, name in enumerate(mech.joint_names)}
    for pin in pins:
        j = by_joint[pin.name]
        out.append(pin.transformed(poses[mech.joint_bodies[j][1]]))
    return out


def joint_lines(mech: Mechanism) -> tuple[Array, Array]:
    """Axis lines of the joints at the reference: points ``(n, 3)`` and unit directions ``(n, 3)``.

    A revolute joint's point is its axis' point nearest the origin; a prismatic joint (a direction only) is put
    through the centroid of the revolute axis points of its two bodies.
    """
    n = mech.n_joints
    points, directions = np.zeros((n, 3)), np.zeros((n, 3))
    prismatic = []
    for j in range(n):
        w, v = mech.twists[j, :3], mech.twists[j, 3:]
        if mech.joint_types[j] == "P" or np.linalg.norm(w) < 1e-12:
            directions[j] = v / np.linalg.norm(v)
            prismatic.append(j)
        else:
            w = w / np.linalg.norm(w)
            directions[j] = w
            points[j] = np.cross(w, v)  # foot of the origin on the line (v = p x w)
    revolute = [j for j in range(n) if j not in prismatic]
    for j in prismatic:
        near = [k for k in revolute if set(mech.joint_bodies[k]) & set(mech.joint_bodies[j])]
        pool = near or revolute
        points[j] = points[pool].mean(axis=0) if pool else 0.0
    return points, directions


def common_normal(p1: ArrayLike, d1: ArrayLike, p2: ArrayLike, d2: ArrayLike) -> tuple[Array, Array]:
    """Feet ``(f1, f2)`` of the shortest segment between two lines (point, unit direction).

    Intersecting lines give ``f1 == f2`` (the intersection); parallel lines, whose common normals are all alike,
    give the one through ``p1``.
    """
    p1, d1, p2, d2 = (np.asarray(x, dtype=float) for x in (p1, d1, p2, d2))
    n = np.cross(d1, d2)
    nn = float(n @ n)
    r = p2 - p1
    if nn < 1e-20:  # parallel
        f1 = p1
        return f1, p2 + ((f1 - p2) @ d2) * d2
    t1 = float(np.cross(r, d2) @ n) / nn
    t2 = float(np.cross(r, d1) @ n) / nn
    return p1 + t1 * d1, p2 + t2 * d2


def mechanism_scale(mech: Mechanism) -> float:
    """A length for sizing solids: the median common-normal length between consecutive joints of a body."""
    points, directions = joint_lines(mech)
    lengths = []
    for joints in _body_joints(mech).values():
        for a, b in itertools.pairwise(joints):
            f1, f2 = common_normal(points[a], directions[a], points[b], directions[b])
            lengths.append(np.linalg.norm(f2 - f1))
    lengths_arr = np.array([x for x in lengths if x > 1e-9])
    if lengths_arr.size:
        return float(np.median(lengths_arr))
    spread = np.linalg.norm(points - points.mean(axis=0), axis=1)
    return float(np.median(spread)) if np.any(spread > 1e-9) else 1.0


def bar_segments(mech: Mechanism) -> dict[str, list[tuple[Array, Array]]]:
    """The bars each body is drawn with (reference configuration): ``(start, end)`` points on two joint axes.

    Consecutive joints of a body are joined along their common normal. When the axes meet, the bar runs between
    the neighbouring bars' feet on the two axes (where the pins are); when everything meets in one point (a
    spherical loop), between points one scale length out along each axis.
    """
    points, directions = joint_lines(mech)
    scale = mechanism_scale(mech)
    body_joints = _body_joints(mech)
    raw: dict[str, list[tuple[int, int, Array, Array]]] = {}
    for body, joints in body_joints.items():
        pairs = list(itertools.pairwise(joints))
        if len(joints) > 2:
            pairs.append((joints[-1], joints[0]))
        raw[body] = [
            (a, b, *common_normal(points[a], directions[a], points[b], directions[b])) for a, b in pairs
        ]
    # Feet of the non-degenerate bars on every axis: where a degenerate bar should end instead.
    feet: dict[int, list[Array]] = {j: [] for j in range(mech.n_joints)}
    for segs in raw.values():
        for a, b, f1, f2 in segs:
            if np.linalg.norm(f2 - f1) > 1e-9 * scale:
                feet[a].append(f1)
                feet[b].append(f2)
    out: dict[str, list[tuple[Array, Array]]] = {}
    for body, segs in raw.items():
        bars = []
        for a, b, f1, f2 in segs:
            if np.linalg.norm(f2 - f1) <= 1e-9 * scale:
                f1 = _project(feet[a][0], points[a], directions[a]) if feet[a] else f1
                f2 = _project(feet[b][0], points[b], directions[b]) if feet[b] else f2
                if np.linalg.norm(f2 - f1) <= 1e-9 * scale:
                    f1, f2 = f1 + scale * directions[a], f2 + scale * directions[b]
            bars.append((f1, f2))
        out[body] = bars
    return out


# --------------------------------------------------------------------------------------------------------
# helpers


def _project(x: Array, p: Array, d: Array) -> Array:
    """Foot of ``x`` on the line ``(p, d)``."""
    return p + ((x - p) @ d) * d


def _body_joints(mech: Mechanism) -> dict[str, list[int]]:
    """Joints attached to each body, in joint order, with a single-loop link's joints as (before, after)."""
    out: dict[str, list[int]] = {b: [] for b in mech.bodies}
    for j, (a, b) in enumerate(mech.joint_bodies):
        out[b].append(j)  # this body comes after joint j: j is its proximal joint
        out[a].append(j)
    for body, joints in out.items():
        # A link "after j, before k" reads best as (j, k); keep the order of appearance otherwise.
        prox = [j for j in joints if mech.joint_bodies[j][1] == body]
        dist = [j for j in joints if mech.joint_bodies[j][0] == body]
        out[body] = prox + [j for j in dist if j not in prox]
    return out


# --------------------------------------------------------------------------------------------------------
# styles


def _drawing(mech: Mechanism) -> tuple[dict[str, Mesh], list[Mesh]]:
    """Body meshes and pins in the reference configuration, in the style ``meta["linkage"]`` asks for."""
    style = str(mech.meta.get("linkage", ""))
    designed = None
    if style == "hedgepeth" and "rods" in mech.meta:
        designed = hedgepeth_design(mech)
    elif style == "hedgepeth-rods":
        designed = hedgepeth_rods_design(mech)
    elif style == "guest-frame":
        designed = guest_design(mech)
    if designed is not None:
        placed = _to_reference(mech, *designed)
        if placed is not None:
            return placed
    return _bars(mech)


def _bars(mech: Mechanism) -> tuple[dict[str, Mesh], list[Mesh]]:
    """Round bars along common normals and a pin on every axis spanning the bars' feet on it."""
    scale = mechanism_scale(mech)
    r_bar, r_pin = BAR_RADIUS * scale, PIN_RADIUS * scale
    segments = bar_segments(mech)
    bodies = {}
    for i, body in enumerate(mech.bodies):
        parts = [cylinder(a, b, r_bar) for a, b in segments[body]]
        color = BAR_COLORS[i % len(BAR_COLORS)]
        if not parts:  # a body with a single joint: a stub along its axis
            parts = [cylinder(np.zeros(3), np.array([0.0, 0.0, 1e-3 * scale]), r_bar)]
        bodies[body] = merge(parts, color=color, kind="bar", name=body)
    points, directions = joint_lines(mech)
    feet: dict[int, list[float]] = {j: [] for j in range(mech.n_joints)}
    body_joints = _body_joints(mech)
    for body, segs in segments.items():
        joints = body_joints[body]
        pairs = list(itertools.pairwise(joints))
        if len(joints) > 2:
            pairs.append((joints[-1], joints[0]))
        for (a, b), (fa, fb) in zip(pairs, segs, strict=True):
            feet[a].append(float((fa - points[a]) @ directions[a]))
            feet[b].append(float((fb - points[b]) @ directions[b]))
    pins = []
    margin = PIN_MARGIN * scale
    for j in range(mech.n_joints):
        ts = feet[j] or [0.0]
        lo, hi = min(ts) - margin, max(ts) + margin
        a, b = points[j] + lo * directions[j], points[j] + hi * directions[j]
        radius = r_pin if mech.joint_types[j] == "R" else 1.6 * r_pin
        sides = SEGMENTS if mech.joint_types[j] == "R" else 4
        pins.append(cylinder(a, b, radius, sides, color=PIN_COLOR, kind="pin", name=mech.joint_names[j]))
    return bodies, pins


def _to_reference(
    mech: Mechanism, bodies: dict[str, Mesh], pins: list[Mesh], points: Array, directions: Array
) -> tuple[dict[str, Mesh], list[Mesh]] | None:
    """Carry design-configuration solids to the reference, body by body, by the rigid motion that maps the
    body's two joint lines onto the mechanism's (None if some body's lines do not match rigidly)."""
    ref_points, ref_dirs = joint_lines(mech)
    scale = mechanism_scale(mech)
    body_joints = _body_joints(mech)
    moves: dict[str, Array] = {}
    for body, joints in body_joints.items():
        if len(joints) != 2:
            return None
        a, b = joints
        src = _line_pair_points(points[a], directions[a], points[b], directions[b])
        dst = _line_pair_points(ref_points[a], ref_dirs[a], ref_points[b], ref_dirs[b])
        if src is None or dst is None:
            return None
        T = kabsch(src, dst)
        moved = src @ T[:3, :3].T + T[:3, 3]
        if np.max(np.abs(moved - dst)) > 1e-7 * max(scale, 1.0):
            return None
        moves[body] = T
    out_bodies = {name: mesh.transformed(moves[name]) for name, mesh in bodies.items()}
    out_pins = []
    for j, pin in enumerate(pins):
        out_pins.append(pin.transformed(moves[mech.joint_bodies[j][1]]))
    return out_bodies, out_pins


def _line_pair_points(p1: Array, d1: Array, p2: Array, d2: Array) -> Array | None:
    """Four points fixed to a pair of non-parallel lines: the common normal's feet and a unit step along each."""
    if np.linalg.norm(np.cross(d1, d2)) < 1e-6:
        return None
    f1, f2 = common_normal(p1, d1, p2, d2)
    return np.array([f1, f1 + d1, f2, f2 + d2])
