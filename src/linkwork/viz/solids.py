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
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.geometry.fit import kabsch
from linkwork.kinematics.closure import body_poses
from linkwork.kinematics.mechanism import Mechanism

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Colours (hex) of the drawing styles.
ROD_COLORS = ("#4878a8", "#d08a3c")  # two rod types / long and short sides
BAR_COLORS = ("#4878a8", "#d08a3c", "#5a9e5a", "#b8534f", "#8a6fb0", "#8c7a5b", "#c27aa9", "#6f8f9f")
PIN_COLOR = "#5c5c5c"

#: Relative sizes (fractions of the mechanism's scale).
ROD_WIDTH = 0.2  # Hedgepeth rod: side of the triangle section / rod length
BAR_RADIUS = 0.035
PIN_RADIUS = 0.05
PIN_MARGIN = 0.12  # pin overhang beyond the bars it joins
SEGMENTS = 12  # sides of a round bar or pin


@dataclass(frozen=True)
class Mesh:
    """A closed triangle mesh.

    Attributes
    ----------
    vertices
        ``(V, 3)`` coordinates.
    faces
        ``(F, 3)`` vertex indices, counter-clockwise seen from outside (outward normals).
    color
        Fill colour, a hex string ``"#rrggbb"``.
    kind
        ``"rod"`` (a shaped link of a built-in linkage), ``"bar"`` (a link drawn as bars), or ``"pin"``.
    name
        The body's name (rods, bars) or the joint's name (pins).
    """

    vertices: Array
    faces: IntArray
    color: str = BAR_COLORS[0]
    kind: str = "bar"
    name: str = ""

    def __post_init__(self) -> None:
        vertices = np.asarray(self.vertices, dtype=float)
        faces = np.asarray(self.faces, dtype=np.int64)
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise ValueError(f"Expected vertices of shape (V, 3), got {vertices.shape}")
        if faces.ndim != 2 or faces.shape[1] != 3:
            raise ValueError(f"Expected faces of shape (F, 3), got {faces.shape}")
        object.__setattr__(self, "vertices", vertices)
        object.__setattr__(self, "faces", faces)

    def transformed(self, T: ArrayLike) -> Mesh:
        """The mesh moved by the 4x4 rigid transform ``T``."""
        T = np.asarray(T, dtype=float)
        return replace(self, vertices=self.vertices @ T[:3, :3].T + T[:3, 3])

    @property
    def triangles(self) -> Array:
        """``(F, 3, 3)`` corner coordinates of every face."""
        return self.vertices[self.faces]

    @property
    def volume(self) -> float:
        """Signed volume by the divergence theorem (positive for outward-oriented closed meshes)."""
        a, b, c = (self.vertices[self.faces[:, k]] for k in range(3))
        return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


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


def signed_volume(mesh: Mesh) -> float:
    """Signed volume of a closed mesh (divergence theorem); same as ``mesh.volume``."""
    return mesh.volume


def edge_counts(mesh: Mesh) -> tuple[int, int]:
    """``(bad_undirected, bad_directed)``: edges not shared by exactly two faces, and directed edges repeated.

    Both are zero for a closed, consistently oriented mesh (each edge used once in each direction).
    """
    f = mesh.faces
    directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    undirected = np.sort(directed, axis=1)
    _, counts = np.unique(undirected, axis=0, return_counts=True)
    _, dcounts = np.unique(directed, axis=0, return_counts=True)
    return int(np.sum(counts != 2)), int(np.sum(dcounts != 1))


# --------------------------------------------------------------------------------------------------------
# primitives


def cut_prism(
    section: ArrayLike, axis: ArrayLike, start: tuple[Array, Array], end: tuple[Array, Array]
) -> Array:
    """Vertices ``(2k, 3)`` of a prism: edges through the ``section`` points along ``axis``, cut by two planes.

    ``start`` and ``end`` are ``(point, normal)`` planes. The first ``k`` vertices lie on the start plane, the
    next ``k`` on the end plane, in section order. Faces come from :func:`prism_faces`.
    """
    section = np.asarray(section, dtype=float)
    u = np.asarray(axis, dtype=float)
    out = []
    for point, normal in (start, end):
        t = ((point - section) @ normal) / float(u @ normal)
        out.append(section + t[:, None] * u)
    return np.concatenate(out)


def prism_faces(k: int) -> IntArray:
    """Faces of a prism from :func:`cut_prism` whose section is counter-clockwise about the axis."""
    faces = []
    for i in range(1, k - 1):
        faces.append((0, i + 1, i))  # start cap, normal against the axis
        faces.append((k, k + i, k + i + 1))  # end cap
    for i in range(k):
        j = (i + 1) % k
        faces.append((i, j, k + j))
        faces.append((i, k + j, k + i))
    return np.array(faces, dtype=np.int64)


def cylinder(a: ArrayLike, b: ArrayLike, radius: float, segments: int = SEGMENTS, **fields: str) -> Mesh:
    """A closed round bar (a ``segments``-sided prism) from ``a`` to ``b``."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    u = b - a
    length = float(np.linalg.norm(u))
    u = u / length if length > 0 else np.array([0.0, 0.0, 1.0])
    e1, e2 = _perpendiculars(u)
    t = 2.0 * np.pi * np.arange(segments) / segments
    section = a + radius * (np.cos(t)[:, None] * e1 + np.sin(t)[:, None] * e2)  # CCW about u
    vertices = cut_prism(section, u, (a, u), (a + max(length, 1e-12 * radius) * u, u))
    return Mesh(vertices, prism_faces(segments), **fields)


def _merge(meshes: list[Mesh], **fields: str) -> Mesh:
    """Several closed meshes as one (their union as a set of faces)."""
    vertices, faces, offset = [], [], 0
    for m in meshes:
        vertices.append(m.vertices)
        faces.append(m.faces + offset)
        offset += len(m.vertices)
    return Mesh(np.concatenate(vertices), np.concatenate(faces), **fields)


def _perpendiculars(u: Array) -> tuple[Array, Array]:
    """Two unit vectors completing ``u`` to a right-handed frame ``(e1, e2, u)``."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(helper, u)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(u, e1)


def _project(x: Array, p: Array, d: Array) -> Array:
    """Foot of ``x`` on the line ``(p, d)``."""
    return p + ((x - p) @ d) * d


def _unit(x: Array) -> Array:
    return x / np.linalg.norm(x)


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
        designed = _hedgepeth_design(mech)
    elif style == "hedgepeth-rods":
        designed = _hedgepeth_rods_design(mech)
    elif style == "guest-frame":
        designed = _guest_design(mech)
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
        bodies[body] = _merge(parts, color=color, kind="bar", name=body)
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


def _rod_frames(mech: Mechanism) -> list[Array]:
    """Frames of the paper's rod chain at the mechanism's reference values: ``F[k]`` has joint ``k`` on its z-axis.

    Factor ``k`` is ``C_k Rz(theta_k)`` (Eq. (12)); joint ``k``'s axis is the z-axis after ``C_k``.
    """
    from linkwork.geometry import rot_z
    from linkwork.kinematics.chains import rod_transform

    g = np.eye(4)
    frames = []
    for k, rod in enumerate(mech.meta["rods"]):
        g = g @ rod_transform(rod["phi"], rod["omega"], rod["psi"], rod["v"])
        frames.append(g.copy())
        g = g @ rot_z(mech.offsets[k])
    return frames


def _hedgepeth_design(mech: Mechanism) -> tuple[dict[str, Mesh], list[Mesh], Array, Array] | None:
    """Hedgepeth's triangular rods in the rod chain's own frame (Sec. 3, Fig. 5).

    Body ``link{i}`` (after joint ``i``) is the rod from joint ``i``'s frame origin to joint ``i+1``'s along its
    apex line. Its section is an isosceles triangle, apex on the apex line, apex angle ``alpha1 = 2 pi / n``,
    equal sides along the half-lines ``h_i``, ``h_{i+1}``: the hinge axes projected across the rod, with
    alternating signs so that the n sections tile a regular n-gon around the bundle's axis (Fig. 5(a)).
    """
    n = mech.n_joints
    frames = _rod_frames(mech)
    if np.max(np.abs(frames[-1] @ _rz(mech.offsets[-1]) - np.eye(4))) > 1e-6:
        return None
    origins = np.array([F[:3, 3] for F in frames])
    axes = np.array([F[:3, 2] for F in frames])
    lengths = np.linalg.norm(np.roll(origins, -1, axis=0) - origins, axis=1)
    width = ROD_WIDTH * float(np.median(lengths))
    bodies: dict[str, Mesh] = {}
    for i in range(n):
        a, b = i, (i + 1) % n
        if mech.joint_bodies[a][1] != mech.joint_bodies[b][0]:
            return None
        body = mech.joint_bodies[a][1]
        o0, o1 = origins[a], origins[b]
        u = _unit(o1 - o0)
        h0 = _unit(axes[a] - (axes[a] @ u) * u) * (1.0 if a % 2 == 0 else -1.0)
        h1 = _unit(axes[b] - (axes[b] @ u) * u) * (1.0 if b % 2 == 0 else -1.0)
        if np.cross(h0, h1) @ u < 0:  # keep the section counter-clockwise about the axis
            h0, h1 = h1, h0
        bisector = _unit(h0 + h1)
        side_normal = np.cross(u, bisector)  # normal of the rod's plane of symmetry
        planes = []
        for origin, z in ((o0, axes[a]), (o1, axes[b])):
            m = np.cross(z, side_normal)  # contains z; normal in the plane of symmetry
            planes.append((origin, _unit(m)))
        section = np.array([o0, o0 + width * h0, o0 + width * h1])
        vertices = cut_prism(section, u, planes[0], planes[1])
        color = ROD_COLORS[i % 2]
        bodies[body] = Mesh(vertices, prism_faces(3), color=color, kind="rod", name=body)
    pins = []
    for j in range(n):
        half = 0.5 * width * axes[j]
        pins.append(
            cylinder(
                origins[j] - half,
                origins[j] + half,
                0.12 * width,
                color=PIN_COLOR,
                kind="pin",
                name=mech.joint_names[j],
            )
        )
    bodies = {name: bodies[name] for name in mech.bodies}
    return bodies, pins, origins, axes


def _hedgepeth_rods_design(mech: Mechanism) -> tuple[dict[str, Mesh], list[Mesh], Array, Array] | None:
    """The mitred triangular rods of :mod:`linkwork.linkages.hedgepeth_rods`, in the folded bundle.

    Rod ``i`` is the prism of isosceles section (apex on the apex line, equal sides ``width`` at ``+-180/n``
    from the section's axis) between the mitre planes ``x cos(beta) +- y sin(beta) = ...`` of its body frame; the
    pins run along the hinge edges from the apex to the base corner of the end section.
    """
    from linkwork.linkages.hedgepeth_rods import hinge_edge, rod_frame, start_face_sign

    n = int(mech.meta.get("n", mech.n_joints))
    if n != mech.n_joints or len(mech.bodies) != n:
        return None
    width = float(mech.meta.get("width", ROD_WIDTH))
    beta = np.pi / n
    corner = width * np.array([np.sin(beta), np.cos(beta)])
    bodies: dict[str, Mesh] = {}
    points, axes = np.zeros((n, 3)), np.zeros((n, 3))
    pins = []
    for i in range(n):
        F = rod_frame(n, i)
        R, o = F[:3, :3], F[:3, 3]
        section = (
            o + np.array([[0.0, 0.0, 0.0], [0.0, corner[0], corner[1]], [0.0, -corner[0], corner[1]]]) @ R.T
        )
        start = (o, R @ np.array([np.cos(beta), np.sin(beta), 0.0]))
        end = (o + R[:, 0], R @ np.array([np.cos(beta), -np.sin(beta), 0.0]))
        vertices = cut_prism(section, R[:, 0], start, end)
        bodies[mech.joint_bodies[i][1]] = Mesh(
            vertices, prism_faces(3), color=ROD_COLORS[i % 2], kind="rod", name=mech.joint_bodies[i][1]
        )
        sign = start_face_sign(i)
        edge = R @ hinge_edge(n, sign)
        length = width / float(hinge_edge(n, sign) @ np.array([0.0, 0.0, 1.0])) * np.cos(beta)
        points[i], axes[i] = o, -sign * edge
        pins.append(
            cylinder(
                o, o + length * edge, 0.06 * width, color=PIN_COLOR, kind="pin", name=mech.joint_names[i]
            )
        )
    bodies = {name: bodies[name] for name in mech.bodies}
    return bodies, pins, points, axes


def _rz(angle: float) -> Array:
    from linkwork.geometry import rot_z

    return rot_z(angle)


def _guest_design(mech: Mechanism) -> tuple[dict[str, Mesh], list[Mesh], Array, Array] | None:
    """Guest's frame flat in z = 0: diamond-section rods, mitred corners, short sides cut at y = 0 (Sec. 6)."""
    from linkwork.linkages.guest import HINGE_SITES, JOINTS, guest_hinges

    if mech.joint_names != JOINTS:
        return None
    length, width, section = (float(mech.meta[k]) for k in ("length", "width", "section"))
    points, directions = guest_hinges(length, width, section)
    h = section / np.sqrt(2.0)
    ez = np.array([0.0, 0.0, 1.0])

    def site(k: int) -> tuple[Array, Array]:
        sx, sy = HINGE_SITES[k]
        centre = np.array([sx * length / 2.0, sy * width / 2.0, 0.0])
        normal = np.array([0.0, 1.0, 0.0]) if sy == 0 else _unit(np.array([sy, -sx, 0.0]))  # cut / mitre
        return centre, normal

    bodies: dict[str, Mesh] = {}
    for i in range(6):
        a, b = i, (i + 1) % 6
        body = mech.joint_bodies[a][1]
        (c0, n0), (c1, n1) = site(a), site(b)
        u = _unit(c1 - c0)
        e1 = np.cross(ez, u)  # horizontal, across the rod
        # Section diagonals horizontal and vertical; counter-clockwise about u (e1, ez, -e1, -ez).
        diamond = np.array([c0 + h * e1, c0 + h * ez, c0 - h * e1, c0 - h * ez])
        vertices = cut_prism(diamond, u, (c0, n0), (c1, n1))
        color = ROD_COLORS[0] if i in (1, 4) else ROD_COLORS[1]  # long sides, half short sides
        bodies[body] = Mesh(vertices, prism_faces(4), color=color, kind="rod", name=body)
    pins = []
    for j in range(6):
        # The hinge runs along an edge of the cut, from a horizontal vertex (z = 0) to the top one (z = h).
        d = directions[j] if directions[j][2] > 0 else -directions[j]
        top = points[j] + d * (h / d[2])
        mid = 0.5 * (points[j] + top)
        half = 0.6 * np.linalg.norm(top - points[j]) * d
        pins.append(
            cylinder(mid - half, mid + half, 0.12 * section, color=PIN_COLOR, kind="pin", name=JOINTS[j])
        )
    bodies = {name: bodies[name] for name in mech.bodies}
    return bodies, pins, points, directions
