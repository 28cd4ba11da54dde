"""The synthesised chain as rigid bodies and joints, with every body's displacement at every profile.

Bodies and joints (Sec. 7 of Shamsudin et al. 2013, and the design notes):

* an M-segment is one body ``s<e>``;
* a C-segment (a constant-curvature arc whose length changes) is two bodies, ``s<e>a`` carrying its first piece
  and ``s<e>b`` its last, joined by the *arc slide* ``S<e>``: the last piece turns about the centre of the arc's
  circle relative to the first (a curved prismatic joint, i.e. a revolute joint at the centre), or slides along
  the first piece when the arc is straight (a prismatic joint);
* joint ``J<i>`` is the revolute joint between segments ``i`` and ``i + 1``; a joint merged into a compound
  segment (Sec. 6) welds its two bodies into one (``s2b+s3a``);
* a fixed-end chain is pinned to the ground at both ends (``J0`` and ``J<q>``); a closed chain's last body is
  joined to its first by ``J0``.

Displacements are ``(p, 3)`` arrays ``(x, y, angle)`` of the rigid motion that carries a body from where it is on
profile 1 to where it is on profile ``j`` (so row 0 is the identity), the convention of the POE model whose
reference configuration is profile 1. Points of bodies are given where they are on profile 1.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.errors import LinkworkError
from linkwork.geometry.angles import wrap
from linkwork.geometry.se2 import apply, pose_matrix, pose_of, relative
from linkwork.synthesis.result import JoinedProfile, SynthesisResult
from linkwork.synthesis.segment_fit import segment_starts

Array = NDArray[np.float64]

#: Two bodies welded by a merged joint, or a joint's two bodies, must agree to this (relative to the size).
CONSISTENCY = 1e-8


@dataclass(frozen=True)
class ChainBody:
    """One rigid body of the chain.

    Attributes
    ----------
    name
        ``s1``, ``s2a``, ``s2b+s3a``, ...
    displacements
        ``(p, 3)`` from profile 1 to every profile (row 0 the identity).
    outline
        ``(n, 2)`` the chain's points this body carries, on profile 1 (for drawings and candidate pivots).
    """

    name: str
    displacements: Array
    outline: Array


@dataclass(frozen=True)
class ChainJoint:
    """One joint of the chain: revolute ``R`` (point) or prismatic ``P`` (point and direction), on profile 1.

    ``values`` are the joint's displacements from profile 1 on every profile (radians or lengths).
    """

    name: str
    kind: str
    bodies: tuple[str, str]
    point: Array
    direction: Array | None
    values: Array
    role: str


@dataclass(frozen=True)
class ChainSegment:
    """What is needed to draw a segment in any configuration: its kind, bodies and shape."""

    kind: str
    first: str
    last: str
    points: Array
    curvature: float
    turn: float
    pieces: NDArray[np.int64]


@dataclass(frozen=True)
class ShapeChain:
    """The chain of a synthesis result as bodies and joints, posed on every profile.

    Attributes
    ----------
    kind
        ``open``, ``closed`` or ``fixed-end``.
    bodies, joints, segments
        See :class:`ChainBody`, :class:`ChainJoint`, :class:`ChainSegment`.
    targets
        The ``p`` target profiles' points (what the error is measured against).
    size
        The largest extent of the target profiles (a length scale for tolerances and regions).
    joined_errors
        ``(p,)`` ``E_max`` of the joined (or compound) chain on every profile.
    """

    kind: str
    bodies: tuple[ChainBody, ...]
    joints: tuple[ChainJoint, ...]
    segments: tuple[ChainSegment, ...]
    targets: tuple[Array, ...]
    size: float
    joined_errors: Array

    @property
    def count(self) -> int:
        """Number of profiles ``p``."""
        return len(self.targets)

    def body(self, name: str) -> ChainBody:
        """The body called ``name``."""
        for b in self.bodies:
            if b.name == name:
                return b
        raise KeyError(name)

    def mobility(self) -> int:
        """Degrees of freedom of the chain alone (Grubler, planar: 3 per body, -2 per joint)."""
        return 3 * len(self.bodies) - 2 * len(self.joints)

    def points(self, displacements: Mapping[str, ArrayLike], profile: int) -> Array:
        """The chain's points matching the target points of ``profile``, with bodies displaced as given."""
        out: list[Array] = []
        for e, seg in enumerate(self.segments):
            first = np.asarray(displacements[seg.first], dtype=float)
            n = int(seg.pieces[profile])
            if seg.kind == "M":
                pts = apply(first, seg.points)
            else:
                last = np.asarray(displacements[seg.last], dtype=float)
                pts = _arc(seg, first, last, n)
            out.append(pts if e == 0 else pts[1:])
        return np.vstack(out)

    def errors(self, displacements: Mapping[str, ArrayLike], profile: int) -> Array:
        """Point-to-point distances from the chain (displaced) to the target points of ``profile``."""
        return np.linalg.norm(self.points(displacements, profile) - self.targets[profile], axis=1)

    def displacements_at(self, profile: int) -> dict[str, Array]:
        """Every body's displacement on ``profile``."""
        return {b.name: b.displacements[profile] for b in self.bodies}


def _arc(seg: ChainSegment, first: Array, last: Array, n: int) -> Array:
    """``n + 1`` points of a C-segment whose first piece is displaced by ``first`` and last by ``last``."""
    ref = seg.points  # start point, first-piece end, last-piece start, end point, on profile 1
    start = apply(first, ref[0])
    if seg.curvature == 0.0:
        direction = apply(first, ref[1]) - start
        direction /= np.linalg.norm(direction)
        end = apply(last, ref[3])
        length = float((end - start) @ direction)
        return start + np.outer(np.linspace(0.0, 1.0, n + 1), direction * length)
    centre = apply(first, ref[4])
    # rotation of the last piece relative to the first, counted from profile 1's (m_1 - 1) turns
    psi = float(wrap(last[2] - first[2])) + ref[5, 0]
    # the turn may exceed half a revolution between profiles: take the branch nearest this piece count's
    expected = (n - 1) * seg.turn
    psi += 2.0 * math.pi * round((expected - psi) / (2.0 * math.pi))
    sweep = psi + seg.turn  # start vertex to end vertex: one turn more than first piece to last piece
    rel = start - centre
    angles = np.linspace(0.0, sweep, n + 1)
    c, s = np.cos(angles), np.sin(angles)
    return centre + np.column_stack([c * rel[0] - s * rel[1], s * rel[0] + c * rel[1]])


def _frame(origin: Array, towards: Array) -> Array:
    d = towards - origin
    return np.array([origin[0], origin[1], math.atan2(d[1], d[0])])


def build_chain(result: SynthesisResult) -> ShapeChain:
    """The chain of ``result`` (its compound chain when joints were merged) as bodies and joints.

    Raises
    ------
    LinkworkError
        When the joined chain is not consistent with its own bodies (a merged joint that does not hold).
    """
    compound = result.compound
    merged = set(compound.merged) if compound is not None else set()
    profiles: tuple[JoinedProfile, ...] = (
        compound.profiles if compound is not None and merged else result.joined
    )
    design = result.design
    q, p = len(design), len(profiles)
    starts = segment_starts(result.segment_matrix)  # (q, p)
    sm = np.asarray(result.segment_matrix)
    targets = tuple(np.asarray(t.points, dtype=float) for t in result.targets)
    allpts = np.vstack(targets)
    size = float(np.ptp(allpts, axis=0).max()) or 1.0

    def piece(e: int, j: int) -> Array:
        a = int(starts[e, j])
        return profiles[j].points[a : a + int(sm[e, j]) + 1]

    # frames of every part on every profile; a part's displacement is frame_j * frame_1^-1
    parts: list[tuple[str, Array, Array]] = []  # (name, (p, 3) frames, outline on profile 1)
    seg_parts: list[tuple[str, str]] = []
    for e, kind in enumerate(design):
        if kind == "M":
            frames = np.array([_frame(piece(e, j)[0], piece(e, j)[-1]) for j in range(p)])
            parts.append((f"s{e + 1}", frames, piece(e, 0)))
            seg_parts.append((f"s{e + 1}", f"s{e + 1}"))
        else:
            pts0 = piece(e, 0)
            half = len(pts0) // 2
            fa = np.array([_frame(piece(e, j)[0], piece(e, j)[1]) for j in range(p)])
            fb = np.array([_frame(piece(e, j)[-2], piece(e, j)[-1]) for j in range(p)])
            parts.append((f"s{e + 1}a", fa, pts0[: half + 1]))
            parts.append((f"s{e + 1}b", fb, pts0[half:]))
            seg_parts.append((f"s{e + 1}a", f"s{e + 1}b"))
    disp = {
        name: np.array([pose_of(pose_matrix(f[j]) @ np.linalg.inv(pose_matrix(f[0]))) for j in range(p)])
        for name, f, _ in parts
    }
    outline = {name: o for name, _, o in parts}
    # welds of merged joints: union the last part of segment i with the first part of segment i + 1
    owner = {name: name for name, _, _ in parts}
    for i in sorted(merged):
        a, b = seg_parts[i][1], seg_parts[i + 1][0]
        ra, rb = owner[a], owner[b]
        new = f"{ra}+{rb}"
        for k, v in list(owner.items()):
            if v in (ra, rb):
                owner[k] = new
    tol = CONSISTENCY * max(size, 1.0)
    bodies: dict[str, ChainBody] = {}
    for name, _, _ in parts:
        body = owner[name]
        if body in bodies:
            d0, d1 = bodies[body].displacements, disp[name]
            if np.max(np.abs(d0[:, :2] - d1[:, :2])) > tol or np.max(np.abs(wrap(d0[:, 2] - d1[:, 2]))) > tol:
                raise LinkworkError(
                    f"mechanization: the merged joint welding {body} does not hold on every profile"
                )
            bodies[body] = ChainBody(body, d0, np.vstack([bodies[body].outline, outline[name]]))
        else:
            bodies[body] = ChainBody(body, disp[name], outline[name])

    joints: list[ChainJoint] = []

    def add_r(name: str, a: str, b: str, point: Array, role: str) -> None:
        da = bodies[a].displacements if a != "ground" else np.zeros((p, 3))
        db = bodies[b].displacements if b != "ground" else np.zeros((p, 3))
        pa, pb = np.array([apply(x, point) for x in da]), np.array([apply(x, point) for x in db])
        if np.max(np.abs(pa - pb)) > 1e-6 * max(size, 1.0):
            raise LinkworkError(f"mechanization: joint {name} does not stay one point on every profile")
        values = np.unwrap(db[:, 2] - da[:, 2])
        joints.append(ChainJoint(name, "R", (a, b), np.asarray(point, float), None, values - values[0], role))

    segs: list[ChainSegment] = []
    for e, kind in enumerate(design):
        first, last = owner[seg_parts[e][0]], owner[seg_parts[e][1]]
        pts0 = piece(e, 0)
        pieces = sm[e].astype(np.int64)
        if kind == "M":
            segs.append(ChainSegment("M", first, last, pts0, 0.0, 0.0, pieces))
            continue
        seg = result.segments[e]
        kappa = float(seg.curvature or 0.0)
        s_bar = float(seg.piece_length)
        turn = 2.0 * math.asin(float(np.clip(0.5 * kappa * s_bar, -1.0, 1.0)))
        m1 = int(sm[e, 0])
        head = pts0[1] - pts0[0]
        head /= np.linalg.norm(head)
        normal = np.array([-head[1], head[0]])
        name = f"S{e + 1}"
        if kappa == 0.0:
            da, db = bodies[first].displacements, bodies[last].displacements
            rel = relative(da, db)
            values = rel[:, :2] @ head
            joints.append(
                ChainJoint(name, "P", (first, last), pts0[0].copy(), head, values - values[0], "slide")
            )
            centre = pts0[0]
        else:
            # circumcentre of the regular polygon: half a chord along the first piece, then inwards
            centre = pts0[0] + 0.5 * s_bar * head + (0.5 * s_bar / math.tan(0.5 * turn)) * normal
            add_r(name, first, last, centre, "slide")
        ref = np.vstack([pts0[0], pts0[1], pts0[-2], pts0[-1], centre, [(m1 - 1) * turn, 0.0]])
        segs.append(ChainSegment("C", first, last, ref, kappa, turn, pieces))
    firsts = [owner[s[0]] for s in seg_parts]
    lasts = [owner[s[1]] for s in seg_parts]
    j0 = profiles[0].joints
    for i in range(q - 1):
        if i not in merged:
            add_r(f"J{i + 1}", lasts[i], firsts[i + 1], j0[i + 1], "joint")
    if result.problem.kind == "fixed-end":
        add_r("J0", "ground", firsts[0], j0[0], "pin")
        add_r(f"J{q}", lasts[-1], "ground", j0[-1], "pin")
    elif result.problem.kind == "closed":
        add_r("J0", lasts[-1], firsts[0], j0[0], "joint")
    joined_errors = np.array([float(np.max(prof.errors)) for prof in profiles])
    return ShapeChain(
        kind=result.problem.kind,
        bodies=tuple(bodies.values()),
        joints=tuple(joints),
        segments=tuple(segs),
        targets=targets,
        size=size,
        joined_errors=joined_errors,
    )
