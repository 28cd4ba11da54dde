"""Everything inside the shape: how far a binary link's pivots, or the link itself, leave the target profiles.

With ``ground_region = "inside"`` every pivot of an added link, fixed and moving, must lie inside the profile in
that profile's pose, and the link (the straight segment between its pivots) must not cross the outline: a wing
whose linkage pokes out of its skin cannot be built. Each profile is closed by the straight line from its last
point to its first (an airfoil outline with an open trailing edge is closed there), as for the fixed pivots
(:class:`linkwork.mechanization.options.GroundRegion`).

How far a point is outside is its distance to the outline (0 inside); a link leaves by the largest such
distance of its points (sampled densely, and a segment that crosses the outline between samples leaves by at
least a rounding-sized amount, so it is never taken for inside).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.geometry.polygon import contains
from linkwork.mechanization.assemble import Design
from linkwork.mechanization.options import MechanizeOptions
from linkwork.mechanization.verify import Verification, link_pivots, loaded_mechanism, verify

Array = NDArray[np.float64]

#: Points sampled along a link, ends included, to measure how far it leaves an outline.
LINK_SAMPLES = 33


def distance_to_outline(polygon: ArrayLike, points: ArrayLike) -> Array:
    """``(n,)`` the distance from each point to the closed polygon's boundary."""
    poly = np.asarray(polygon, dtype=float)
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    a = poly
    b = np.roll(poly, -1, axis=0)
    ab = b - a
    length2 = np.maximum(np.sum(ab * ab, axis=1), 1e-300)
    t = np.clip(np.einsum("ekd,kd->ek", pts[:, None, :] - a[None], ab) / length2, 0.0, 1.0)
    nearest = a[None] + t[..., None] * ab[None]
    return np.asarray(np.min(np.linalg.norm(pts[:, None, :] - nearest, axis=2), axis=1))


def outside_by(polygon: ArrayLike, points: ArrayLike) -> Array:
    """``(n,)`` how far each point lies outside the closed polygon: 0 inside, else its distance to the outline."""
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    out = np.zeros(len(pts))
    outside = ~contains(polygon, pts)
    if np.any(outside):
        out[outside] = distance_to_outline(polygon, pts[outside])
    return out


def _crosses(polygon: Array, p: Array, q: Array) -> bool:
    """Whether the segment ``p q`` properly crosses an edge of the closed polygon."""
    a = polygon
    b = np.roll(polygon, -1, axis=0)

    def side(u: Array, v: Array, w: Array) -> Array:
        return np.asarray(
            (v[..., 0] - u[..., 0]) * (w[..., 1] - u[..., 1])
            - (v[..., 1] - u[..., 1]) * (w[..., 0] - u[..., 0])
        )

    d1, d2 = side(p, q, a), side(p, q, b)
    d3, d4 = side(a, b, p), side(a, b, q)
    return bool(np.any((d1 * d2 < 0.0) & (d3 * d4 < 0.0)))


def link_outside_by(polygon: ArrayLike, p: ArrayLike, q: ArrayLike) -> float:
    """How far the segment from ``p`` to ``q`` leaves the closed polygon (0 when it lies inside)."""
    poly = np.asarray(polygon, dtype=float)
    p_, q_ = np.asarray(p, dtype=float), np.asarray(q, dtype=float)
    samples = p_ + np.linspace(0.0, 1.0, LINK_SAMPLES)[:, None] * (q_ - p_)
    depth = float(np.max(outside_by(poly, samples)))
    if depth == 0.0 and _crosses(poly, p_, q_):
        # it slips out and back between two samples: by less than a sample spacing, but out
        depth = max(float(np.linalg.norm(q_ - p_)) / (LINK_SAMPLES - 1) / 8.0, 1e-12)
    return depth


@dataclass(frozen=True)
class Leaving:
    """The worst place a link leaves the shape: ``part`` (``"anchor pivot"``, ``"moving pivot"`` or ``"link"``),
    the 0-based ``profile`` and ``by`` how much (a length; 0 when everything is inside)."""

    part: str
    profile: int
    by: float

    def describe(self, link: str) -> str:
        """``the moving pivot of D3 leaves profile 4 by 0.0123`` (1-based profile)."""
        return f"the {self.part} of {link} leaves profile {self.profile + 1} by {self.by:.3g}"


def leaving(targets: tuple[Array, ...], anchor: Array, moving: Array) -> Leaving:
    """How a link whose anchor and moving pivots are at ``anchor`` and ``moving`` ``(p, 2)`` on the ``p``
    profiles leaves the target profiles (each in its own pose): the worst of its pivots and the link between."""
    worst = Leaving("moving pivot", 0, 0.0)
    for j, poly in enumerate(targets):
        a, m = outside_by(poly, np.array([anchor[j], moving[j]]))
        for part, by in (("anchor pivot", float(a)), ("moving pivot", float(m))):
            if by > worst.by:
                worst = Leaving(part, j, by)
        if a == 0.0 and m == 0.0:
            by = link_outside_by(poly, anchor[j], moving[j])
            if by > worst.by:
                worst = Leaving("link", j, by)
    return worst


def is_inside(targets: tuple[Array, ...], anchor: Array, moving: Array) -> bool:
    """Whether both pivots and the link lie inside every target profile, each in its pose (see :func:`leaving`)."""
    for j, poly in enumerate(targets):
        if not np.all(contains(poly, np.array([anchor[j], moving[j]]))):
            return False
        if link_outside_by(poly, anchor[j], moving[j]) > 0.0:
            return False
    return True


def traced_leaving(design: Design, check: Verification) -> tuple[str, Leaving] | None:
    """The link of ``design`` that leaves the shape furthest on the poses its traced mechanism takes on the
    profiles (``check.states``), and how: ``None`` when every pivot and link lies inside every profile there.

    The candidates were screened on the chain's poses; with a least-squares link the traced mechanism reaches a
    profile a little off them, and ``mechanization.json``'s ``profiles[k].pivots`` are where it is then.
    """
    mech = loaded_mechanism(design)
    targets = design.chain.targets
    at = [link_pivots(design, mech, state.values) for state in check.states]
    worst: tuple[str, Leaving] | None = None
    for link in design.links:
        if (
            link.kind == "PR"
        ):  # a slider's guide point is no pivot (its guide was screened on the chain's poses)
            continue
        ends = [pivots[link.name] for pivots in at]
        leaves = leaving(targets[: len(ends)], np.array([e[0] for e in ends]), np.array([e[1] for e in ends]))
        if leaves.by > 0.0 and (worst is None or leaves.by > worst[1].by):
            worst = (link.name, leaves)
    return worst


def verified(design: Design, options: MechanizeOptions) -> Verification:
    """:func:`linkwork.mechanization.verify.verify`, and with ``ground_region = "inside"`` a design that passes
    is rejected (defect ``"inside"``, the link to replace as its culprit) when a pivot or link leaves a profile on
    the traced poses (:func:`traced_leaving`)."""
    check = verify(design)
    if not check.passed or options.region_of(design.chain.targets, design.chain.size).kind != "inside":
        return check
    worst = traced_leaving(design, check)
    if worst is None:
        return check
    name, leaves = worst
    return replace(
        check,
        passed=False,
        defect="inside",
        reason=f"outside the shape: {leaves.describe(name)}",
        culprit=name,
    )
