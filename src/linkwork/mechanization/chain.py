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

    def other(self, body: str) -> str:
        """The joint's body that is not ``body`` (one of its two)."""
        return self.bodies[1] if self.bodies[0] == body else self.bodies[0]


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

    def motion(self, name: str) -> Array:
        """``(p, 3)`` displacements of body ``name`` on every profile (all zero for ``"ground"``)."""
        if name == "ground":
            return np.zeros((self.count, 3))
        return self.body(name).displacements

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


def track(displacements: Array, point: ArrayLike) -> Array:
    """``(p, 2)`` the positions of a body point (profile-1 coordinates) under the body's ``(p, 3)``
    displacements, pose by pose with :func:`~linkwork.geometry.se2.apply`
    (:func:`linkwork.mechanization.guidance.positions` is the vectorised form, equal to rounding)."""
    return np.array([apply(g, point) for g in displacements])


def turned(displacement: Array, direction: ArrayLike) -> Array:
    """A direction of a body (profile-1 coordinates) turned by the body's displacement ``(x, y, angle)``."""
    return apply(np.array([0.0, 0.0, displacement[2]]), direction)


def track_direction(displacements: Array, direction: ArrayLike) -> Array:
    """``(p, 2)`` a direction of a body (profile-1 coordinates) as it turns with the body's ``(p, 3)``
    displacements."""
    return np.array([turned(g, direction) for g in displacements])


@dataclass(frozen=True)
class _Pieces:
    """The joined (or compound) profiles cut into the segments' pieces: ``starts`` and ``counts`` ``(q, p)`` are
    every segment's first point and number of pieces on every profile (the segment matrix)."""

    profiles: tuple[JoinedProfile, ...]
    starts: NDArray[np.int64]
    counts: NDArray[np.int64]

    def piece(self, e: int, j: int) -> Array:
        """The points of segment ``e`` on profile ``j``."""
        a = int(self.starts[e, j])
        return self.profiles[j].points[a : a + int(self.counts[e, j]) + 1]


@dataclass(frozen=True)
class _Part:
    """A segment's rigid part before merged joints weld parts into bodies: its frame on every profile."""

    name: str
    frames: Array
    outline: Array

    def displacements(self) -> Array:
        """``(p, 3)`` from profile 1 to every profile: ``frame_j * frame_1^-1``."""
        first = np.linalg.inv(pose_matrix(self.frames[0]))
        return np.array([pose_of(pose_matrix(f) @ first) for f in self.frames])


def _parts(design: str, pieces: _Pieces) -> tuple[list[_Part], list[tuple[str, str]]]:
    """Every segment's parts (one for an M-segment, first and last piece for a C-segment), and each segment's
    ``(first part, last part)``."""
    p = len(pieces.profiles)
    parts: list[_Part] = []
    seg_parts: list[tuple[str, str]] = []
    for e, kind in enumerate(design):
        pts0 = pieces.piece(e, 0)
        if kind == "M":
            frames = np.array([_frame(pieces.piece(e, j)[0], pieces.piece(e, j)[-1]) for j in range(p)])
            parts.append(_Part(f"s{e + 1}", frames, pts0))
            seg_parts.append((f"s{e + 1}", f"s{e + 1}"))
        else:
            half = len(pts0) // 2
            fa = np.array([_frame(pieces.piece(e, j)[0], pieces.piece(e, j)[1]) for j in range(p)])
            fb = np.array([_frame(pieces.piece(e, j)[-2], pieces.piece(e, j)[-1]) for j in range(p)])
            parts.append(_Part(f"s{e + 1}a", fa, pts0[: half + 1]))
            parts.append(_Part(f"s{e + 1}b", fb, pts0[half:]))
            seg_parts.append((f"s{e + 1}a", f"s{e + 1}b"))
    return parts, seg_parts


def _owners(parts: list[_Part], seg_parts: list[tuple[str, str]], merged: set[int]) -> dict[str, str]:
    """The body owning every part: a merged joint ``i`` welds the last part of segment ``i`` to the first of
    segment ``i + 1`` (``s2b+s3a``)."""
    owner = {part.name: part.name for part in parts}
    for i in sorted(merged):
        ra, rb = owner[seg_parts[i][1]], owner[seg_parts[i + 1][0]]
        new = f"{ra}+{rb}"
        for k, v in list(owner.items()):
            if v in (ra, rb):
                owner[k] = new
    return owner


def _bodies(parts: list[_Part], owner: dict[str, str], size: float) -> dict[str, ChainBody]:
    """The chain's bodies from the welded parts, checking that welded parts move as one.

    Raises
    ------
    LinkworkError
        When a merged joint does not hold on every profile.
    """
    tol = CONSISTENCY * max(size, 1.0)
    bodies: dict[str, ChainBody] = {}
    for part in parts:
        body, disp = owner[part.name], part.displacements()
        if body in bodies:
            d0 = bodies[body].displacements
            if (
                np.max(np.abs(d0[:, :2] - disp[:, :2])) > tol
                or np.max(np.abs(wrap(d0[:, 2] - disp[:, 2]))) > tol
            ):
                raise LinkworkError(
                    f"mechanization: the merged joint welding {body} does not hold on every profile"
                )
            bodies[body] = ChainBody(body, d0, np.vstack([bodies[body].outline, part.outline]))
        else:
            bodies[body] = ChainBody(body, disp, part.outline)
    return bodies


def _revolute(
    name: str, pair: tuple[str, str], point: Array, role: str, bodies: dict[str, ChainBody], size: float
) -> ChainJoint:
    """The revolute joint between two bodies (or a body and ``"ground"``) at ``point`` (profile 1).

    Raises
    ------
    LinkworkError
        When the point of the two bodies does not stay one point on every profile.
    """
    p = len(next(iter(bodies.values())).displacements)
    da, db = (bodies[b].displacements if b != "ground" else np.zeros((p, 3)) for b in pair)
    if np.max(np.abs(track(da, point) - track(db, point))) > 1e-6 * max(size, 1.0):
        raise LinkworkError(f"mechanization: joint {name} does not stay one point on every profile")
    values = np.unwrap(db[:, 2] - da[:, 2])
    return ChainJoint(name, "R", pair, np.asarray(point, float), None, values - values[0], role)


def _c_segment(
    result: SynthesisResult,
    e: int,
    pair: tuple[str, str],
    pieces: _Pieces,
    bodies: dict[str, ChainBody],
    size: float,
) -> tuple[ChainSegment, ChainJoint]:
    """C-segment ``e`` between its first and last body, and its arc slide ``S<e>``: a revolute joint at the
    centre of the arc's circle, or a prismatic joint along the first piece when the arc is straight."""
    first, last = pair
    pts0 = pieces.piece(e, 0)
    seg = result.segments[e]
    kappa = float(seg.curvature or 0.0)
    s_bar = float(seg.piece_length)
    turn = 2.0 * math.asin(float(np.clip(0.5 * kappa * s_bar, -1.0, 1.0)))
    m1 = int(pieces.counts[e, 0])
    head = pts0[1] - pts0[0]
    head /= np.linalg.norm(head)
    normal = np.array([-head[1], head[0]])
    name = f"S{e + 1}"
    if kappa == 0.0:
        rel = relative(bodies[first].displacements, bodies[last].displacements)
        values = rel[:, :2] @ head
        slide = ChainJoint(name, "P", pair, pts0[0].copy(), head, values - values[0], "slide")
        centre = pts0[0]
    else:
        # circumcentre of the regular polygon: half a chord along the first piece, then inwards
        centre = pts0[0] + 0.5 * s_bar * head + (0.5 * s_bar / math.tan(0.5 * turn)) * normal
        slide = _revolute(name, pair, centre, "slide", bodies, size)
    ref = np.vstack([pts0[0], pts0[1], pts0[-2], pts0[-1], centre, [(m1 - 1) * turn, 0.0]])
    pieces_e = pieces.counts[e].astype(np.int64)
    return ChainSegment("C", first, last, ref, kappa, turn, pieces_e), slide


def build_chain(result: SynthesisResult) -> ShapeChain:
    """The chain of ``result`` (its compound chain when joints were merged) as bodies and joints.

    Joints come in this order: the arc slides ``S<e>``, the joints ``J<i>`` between segments, then the pins or
    the closing joint ``J0``.

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
    q = len(design)
    pieces = _Pieces(profiles, segment_starts(result.segment_matrix), np.asarray(result.segment_matrix))
    targets = tuple(np.asarray(t.points, dtype=float) for t in result.targets)
    size = float(np.ptp(np.vstack(targets), axis=0).max()) or 1.0
    parts, seg_parts = _parts(design, pieces)
    owner = _owners(parts, seg_parts, merged)
    bodies = _bodies(parts, owner, size)
    joints: list[ChainJoint] = []
    segs: list[ChainSegment] = []
    for e, kind in enumerate(design):
        pair = (owner[seg_parts[e][0]], owner[seg_parts[e][1]])
        if kind == "M":
            segs.append(
                ChainSegment("M", *pair, pieces.piece(e, 0), 0.0, 0.0, pieces.counts[e].astype(np.int64))
            )
            continue
        seg, slide = _c_segment(result, e, pair, pieces, bodies, size)
        segs.append(seg)
        joints.append(slide)
    firsts = [owner[s[0]] for s in seg_parts]
    lasts = [owner[s[1]] for s in seg_parts]
    j0 = profiles[0].joints
    for i in range(q - 1):
        if i not in merged:
            joints.append(_revolute(f"J{i + 1}", (lasts[i], firsts[i + 1]), j0[i + 1], "joint", bodies, size))
    if result.problem.kind == "fixed-end":
        joints.append(_revolute("J0", ("ground", firsts[0]), j0[0], "pin", bodies, size))
        joints.append(_revolute(f"J{q}", (lasts[-1], "ground"), j0[-1], "pin", bodies, size))
    elif result.problem.kind == "closed":
        joints.append(_revolute("J0", (lasts[-1], firsts[0]), j0[0], "joint", bodies, size))
    return ShapeChain(
        kind=result.problem.kind,
        bodies=tuple(bodies.values()),
        joints=tuple(joints),
        segments=tuple(segs),
        targets=targets,
        size=size,
        joined_errors=np.array([float(np.max(prof.errors)) for prof in profiles]),
    )
