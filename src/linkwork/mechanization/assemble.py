"""Assembly: the chain plus its binary links as one planar :class:`~linkwork.kinematics.mechanism.Mechanism`.

The reference configuration of the mechanism is profile 1 (every joint at displacement 0 there), so the spec
file written by :func:`spec_text` starts on profile 1 and ``linkwork trace`` runs it as it is. Every joint's
displacement on every profile (the *ideal* configurations, where the chain sits exactly as joined) is known
from the bodies' displacements; the verification compares the traced motion with them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from linkwork.geometry.se2 import pose_matrix, pose_of, relative
from linkwork.kinematics.mechanism import Mechanism
from linkwork.mechanization.chain import ShapeChain, track

Array = NDArray[np.float64]


@dataclass(frozen=True)
class BinaryLink:
    """An RR dyad (binary link), a PR slider on a guide, or an RPR actuator added to the chain.

    Attributes
    ----------
    name
        ``D1``, ``D2``, ... (dyads) or ``A1`` (prismatic actuator).
    kind
        ``"RR"``, ``"PR"`` (a slider on a straight guide of the anchor, pivoted to the body) or ``"RPR"``.
    anchor
        The body the fixed end is pivoted on (``"ground"`` or a chain body).
    body
        The chain body the moving end is pivoted on.
    centre
        ``(2,)`` the anchor pivot (the centre point) on profile 1; for a slider, where it is on its guide then.
    circle
        ``(2,)`` the moving pivot (the circle point) on profile 1.
    structural_error
        How far the moving pivot's positions are from one circle about ``centre`` (0 for an exact dyad).
    transmission
        Smallest transmission angle over the profiles, radians (90 degrees is best).
    via
        The chain joint (or, for the root's four-bar, the other link) that with this link places the body.
    direction
        ``(2,)`` a slider's guide direction (unit, anchor frame on profile 1); ``None`` for the others.
    """

    name: str
    kind: str
    anchor: str
    body: str
    centre: Array
    circle: Array
    structural_error: float = 0.0
    transmission: float = math.pi / 2
    via: str | None = None
    direction: Array | None = None

    @property
    def length(self) -> float:
        """Link length (RR), the actuator's length on profile 1 (RPR), 0 for a slider (PR)."""
        if self.kind == "PR":
            return 0.0
        return float(np.linalg.norm(self.circle - self.centre))

    def to_dict(self) -> dict[str, object]:
        """JSON-ready: lengths as given, angles in degrees; ``ground_pivot`` is ``None`` when the anchor is a
        moving body (``fixed_pivot`` is then the anchor pivot on profile 1)."""
        return {
            "name": self.name,
            "type": self.kind,
            "anchor": self.anchor,
            "body": self.body,
            "ground_pivot": [float(v) for v in self.centre] if self.anchor == "ground" else None,
            "fixed_pivot": [float(v) for v in self.centre],
            "moving_pivot": [float(v) for v in self.circle],
            "length": self.length,
            "structural_error": float(self.structural_error),
            "transmission_deg": math.degrees(self.transmission),
            "guide_direction": [float(v) for v in self.direction] if self.direction is not None else None,
            "via": self.via,
            "joints": self.joint_names(),
        }

    def joint_names(self) -> list[str]:
        """The link's joints, anchor side first."""
        if self.kind == "RR":
            return [f"{self.name}a", f"{self.name}m"]
        if self.kind == "PR":
            return [f"{self.name}s", f"{self.name}m"]
        return [f"{self.name}a", f"{self.name}s", f"{self.name}m"]


@dataclass(frozen=True)
class Design:
    """A mechanized chain: the chain, the binary links, and the drive joint(s).

    Attributes
    ----------
    chain
        The shape chain.
    links
        The binary links added, in the order they were chosen.
    drive
        The name of the driven joint.
    dof
        The degrees of freedom asked for.
    notes
        How the design was found (root body, candidates tried, ...).
    fitted
        With pivots fitted jointly to the profiles (:mod:`linkwork.mechanization.pivot_fit`): every chain body's
        ``(p, 3)`` displacement on every profile where the fitted mechanism is expected to be (near, not on, the
        chain's); ``None`` when the links are placed on the chain's own poses.
    """

    chain: ShapeChain
    links: tuple[BinaryLink, ...]
    drive: str
    dof: int = 1
    name: str = "mechanized chain"
    notes: tuple[str, ...] = field(default=())
    fitted: Mapping[str, Array] | None = field(default=None, compare=False)

    def displacements(self, *, fitted: bool = False) -> dict[str, Array]:
        """``(p, 3)`` displacement of every body (chain bodies and link bodies) on every profile: the chain's, or
        with ``fitted`` where the fitted mechanism is expected (:attr:`fitted`, when there is one)."""
        p = self.chain.count
        disp: dict[str, Array] = {"ground": np.zeros((p, 3))}
        disp.update({b.name: b.displacements for b in self.chain.bodies})
        if fitted and self.fitted is not None:
            disp.update(self.fitted)
        for link in self.links:
            disp.update(_link_displacements(link, disp[link.anchor], disp[link.body]))
        return disp

    def joint_specs(self) -> list[dict[str, object]]:
        """Joints for :meth:`Mechanism.from_joints` (profile-1 positions): the chain's, then every link's in
        :meth:`BinaryLink.joint_names` order."""
        out: list[dict[str, object]] = []
        for jt in self.chain.joints:
            direction = _AXIS if jt.kind == "R" else [float(v) for v in jt.direction]  # type: ignore[union-attr]
            out.append(
                _joint(jt.name, jt.kind, jt.bodies, [float(jt.point[0]), float(jt.point[1])], direction)
            )
        for link in self.links:
            out += _link_joints(link)
        return out

    def mechanism(self) -> Mechanism:
        """The planar mechanism, reference configuration = profile 1."""
        return Mechanism.from_joints(self.name, self.joint_specs(), planar=True, meta={"form": "mechanism"})

    def joint_names(self) -> list[str]:
        """Joint names in mechanism order."""
        return [str(j["name"]) for j in self.joint_specs()]

    def ideal_values(self) -> Array:
        """``(p, n)`` every joint's displacement on every profile (radians or lengths), joints in order, with the
        chain on the profile as joined."""
        return self._values(self.displacements())

    def expected_values(self) -> Array:
        """``(p, n)`` every joint's displacement on every profile where the mechanism is expected: the fitted
        configurations (:attr:`fitted`), else :meth:`ideal_values`."""
        return self._values(self.displacements(fitted=True))

    def _values(self, disp: dict[str, Array]) -> Array:
        cols = []
        for spec in self.joint_specs():
            pair: list[str] = spec["bodies"]  # type: ignore[assignment]
            rel = relative(disp[pair[0]], disp[pair[1]])
            if spec["type"] == "R":
                v = np.unwrap(rel[:, 2])
            else:
                v = rel[:, :2] @ np.asarray(spec["direction"], dtype=float)
            cols.append(v - v[0])
        return np.column_stack(cols)


def _link_displacements(link: BinaryLink, ga: Array, gb: Array) -> dict[str, Array]:
    """``(p, 3)`` displacements of a link's bodies (the slider ``<name>``, the dyad ``<name>``, or the actuator's
    cylinder ``<name>c`` and rod ``<name>r``) when its anchor moves by ``ga`` and its body by ``gb``."""
    p = len(ga)
    # the moving pivot and fixed pivot as seen from the anchor (profile-1 coordinates)
    m = track(relative(ga, gb), link.circle)
    d = m - link.centre
    if link.kind == "PR":
        assert link.direction is not None
        travel = (m - m[0]) @ link.direction
        slide = np.column_stack([np.outer(travel, link.direction), np.zeros(p)])
        return {link.name: _compose(ga, slide)}
    phi = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    rot = np.array([ga_pose(link.centre, a) for a in phi - phi[0]])
    if link.kind == "RR":
        return {link.name: _compose(ga, rot)}
    dist = np.linalg.norm(d, axis=1)
    u0 = d[0] / dist[0]
    slide = np.column_stack([np.outer(dist - dist[0], u0), np.zeros(p)])
    rod = np.array([_then(r, s) for r, s in zip(rot, slide, strict=True)])
    return {f"{link.name}c": _compose(ga, rot), f"{link.name}r": _compose(ga, rod)}


def ga_pose(centre: Array, angle: float) -> Array:
    """Displacement ``(x, y, angle)`` of a rotation by ``angle`` about ``centre``."""
    c, s = math.cos(angle), math.sin(angle)
    t = centre - np.array([c * centre[0] - s * centre[1], s * centre[0] + c * centre[1]])
    return np.array([t[0], t[1], angle])


#: The axis of every revolute joint of a planar mechanism.
_AXIS = [0.0, 0.0, 1.0]


def _joint(
    name: str, kind: str, bodies: Sequence[str], point: list[float], direction: list[float]
) -> dict[str, object]:
    """One joint entry of :meth:`Design.joint_specs`."""
    return {"name": name, "type": kind, "bodies": list(bodies), "point": point, "direction": list(direction)}


def _link_joints(link: BinaryLink) -> list[dict[str, object]]:
    """The joints of a binary link, anchor side first: a slider's guide ``<name>s`` and pivot ``<name>m``, an RR
    dyad's pivots ``<name>a`` and ``<name>m``, an actuator's pivot ``<name>a``, stroke ``<name>s`` (cylinder
    ``<name>c`` to rod ``<name>r``) and pivot ``<name>m``."""
    c, m = [float(v) for v in link.centre], [float(v) for v in link.circle]
    n = link.name
    if link.kind == "PR":
        assert link.direction is not None
        guide = [float(v) for v in link.direction]
        return [
            _joint(f"{n}s", "P", [link.anchor, n], c, guide),
            _joint(f"{n}m", "R", [n, link.body], m, _AXIS),
        ]
    if link.kind == "RR":
        return [
            _joint(f"{n}a", "R", [link.anchor, n], c, _AXIS),
            _joint(f"{n}m", "R", [n, link.body], m, _AXIS),
        ]
    u = (link.circle - link.centre) / link.length
    cyl, rod = f"{n}c", f"{n}r"
    return [
        _joint(f"{n}a", "R", [link.anchor, cyl], c, _AXIS),
        _joint(f"{n}s", "P", [cyl, rod], c, [float(u[0]), float(u[1])]),
        _joint(f"{n}m", "R", [rod, link.body], m, _AXIS),
    ]


def _then(first: Array, second: Array) -> Array:
    """``first`` composed with ``second`` (``second`` applied first, both displacements)."""
    return pose_of(pose_matrix(first) @ pose_matrix(second))


def _compose(outer: Array, inner: Array) -> Array:
    return np.array([_then(a, b) for a, b in zip(outer, inner, strict=True)])


def spec_text(design: Design) -> str:
    """The ``[mechanism]`` spec file (TOML) of the design, starting on profile 1, with a header."""
    from linkwork.io.spec import dump_spec

    text = dump_spec(design.mechanism())
    header = [
        f"# {design.name}: mechanized shape-changing chain written by linkwork mechanize.",
        "# Bodies s<e> are M-segments; s<e>a / s<e>b are the first and last pieces of C-segment e, joined by the",
        "# arc slide S<e> (a revolute joint at the centre of the arc = a curved prismatic joint; prismatic when",
        "# the arc is straight). J<i> joins segments i and i + 1. D<k> are the added binary links (D<k>a the",
        "# fixed pivot, D<k>m the moving pivot; a slider D<k> has D<k>s on its guide), A<k> prismatic actuators.",
        "# The start is profile 1.",
        f"# drive: {design.drive}  (see mechanization.json for its value on every profile)",
    ]
    return "\n".join(header) + "\n" + text
