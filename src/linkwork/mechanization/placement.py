"""Pivot placement inside the shape: where a body's pivots may go, and the binary links found there.

With ``ground_region = "inside"`` a link's pivots and the link itself must lie inside every target profile, each
in its pose (:mod:`linkwork.mechanization.inside`). Rather than choose pivots and reject those that leave, the
links are sought where they are allowed:

* a pivot is a point fixed in a body (the ground, or a chain body), given where it is on profile 1. It is
  *admissible* when, in every profile's pose, it lies inside that profile: the set ``A = ∩_j D_j^-1(P_j)``, each
  profile ``P_j`` pulled back into the body's profile-1 frame by the body's displacement ``D_j``. For the ground
  (``D_j`` the identity) it is the region inside every profile; since ``D_1`` is the identity, ``A`` lies in
  ``P_1``. It is sampled on a square grid over ``P_1``, kept a small :data:`CLEARANCE` from every outline.
* an RR link from an admissible moving pivot ``m`` to an admissible anchor pivot ``c`` must keep its length
  over the profiles. With three profiles every ``m`` has exactly one centre, the circumcentre of its three
  positions seen from the anchor (rigid-body guidance, McCarthy ch. 4), and every ``c`` one circle point, by
  kinematic inversion; both are tried from the samples of their own body and kept when the other pivot is
  admissible too. With more profiles the centre is the least-squares one (its structural error the spread of
  the length it would need). Besides these, pairs of samples whose length spreads by at most the structural
  error limit are tried (open chains only: see :func:`inside_links`).
* the link itself must lie inside every profile in its pose: its two ends inside (admissible pivots) and the
  segment between them crossing no edge of the outline (:func:`segments_inside`); when the body is placed through
  a revolute chain joint, the link must transmit through it as the search requires (:func:`transmissions`).

What is found is ranked exact links first, the deepest inside first (an inexact link's pivots also keep
:data:`SLACK` times its structural error from every outline), and thinned so that no two links are nearly the
same (the search varies one link at a time: twins waste its attempts).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.geometry.polygon import contains
from linkwork.geometry.se2 import relative
from linkwork.mechanization.chain import ShapeChain
from linkwork.mechanization.guidance import Dyad
from linkwork.mechanization.inside import distance_to_outline
from linkwork.mechanization.options import MechanizeOptions

Array = NDArray[np.float64]
Mask = NDArray[np.bool_]

#: Grid points over profile 1 sampled for a body's admissible pivots (about this many inside profile 1).
GRID_POINTS = 3000

#: A pivot keeps at least this fraction of the profiles' largest extent from every outline (rounding-sized
#: moves of the traced mechanism must not take it out).
CLEARANCE = 1e-3

#: An inexact link's pivots keep this many times its structural error from every outline besides the clearance:
#: the traced mechanism reaches the profiles off the chain's poses by about the links' structural errors
#: (amplified by the bodies they place; :data:`linkwork.mechanization.verify.SHAPE_ALLOWANCE` bounds the shape
#: error at five times the largest).
SLACK = 1.0

#: Links returned per body and anchor (after thinning).
LINKS = 80

#: Two links are twins when both their pivots are within this fraction of the size of each other's.
TWIN = 0.02

#: A link shorter than this fraction of the size is no link (its pivots coincide).
SHORTEST = 0.05

#: A structural error up to this fraction of the size counts as exact (rounding in the circumcentre).
EXACT = 1e-9


@dataclass(frozen=True)
class Admissible:
    """A body's admissible pivots: ``points`` ``(k, 2)`` in its profile-1 frame, sampled ``spacing`` apart."""

    points: Array
    spacing: float


def moved(poses: ArrayLike, points: ArrayLike) -> Array:
    """``(p, k, 2)`` the points ``(k, 2)`` of a body (profile-1 frame) in each of its ``(p, 3)`` poses."""
    g = np.asarray(poses, dtype=float)
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    c, s = np.cos(g[:, 2])[:, None], np.sin(g[:, 2])[:, None]
    x = c * pts[None, :, 0] - s * pts[None, :, 1] + g[:, 0, None]
    y = s * pts[None, :, 0] + c * pts[None, :, 1] + g[:, 1, None]
    return np.stack([x, y], axis=2)


def inside_all(
    targets: tuple[Array, ...], poses: ArrayLike, points: ArrayLike, clearance: float = 0.0
) -> Mask:
    """``(k,)`` True where a body point ``(k, 2)`` lies inside every profile in that profile's pose (``poses``
    ``(p, 3)`` the body's displacements), at least ``clearance`` from every outline."""
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    world = moved(poses, pts)
    ok = np.ones(len(pts), dtype=bool)
    for poly, w in zip(targets, world, strict=True):
        ok[ok] = contains(poly, w[ok])
        if clearance > 0.0 and np.any(ok):
            ok[ok] = distance_to_outline(poly, w[ok]) >= clearance
    return ok


def admissible(
    targets: tuple[Array, ...], poses: ArrayLike, size: float, count: int = GRID_POINTS
) -> Admissible:
    """The admissible pivots of a body with displacements ``poses`` ``(p, 3)`` (row 0 the identity): a square
    grid of about ``count`` points over profile 1, those inside every profile in its pose (with
    :data:`CLEARANCE`)."""
    first = np.asarray(targets[0], dtype=float)
    lo, hi = first.min(axis=0), first.max(axis=0)
    area = abs(_area(first)) or float(np.prod(hi - lo))
    spacing = math.sqrt(area / count) if area > 0.0 else float(np.max(hi - lo)) / math.sqrt(count)
    xs = np.arange(lo[0] + spacing / 2, hi[0], spacing)
    ys = np.arange(lo[1] + spacing / 2, hi[1], spacing)
    grid = np.array([(x, y) for x in xs for y in ys]).reshape(-1, 2)
    keep = contains(first, grid) if len(grid) else np.zeros(0, dtype=bool)
    grid = grid[keep]
    ok = inside_all(targets, poses, grid, CLEARANCE * size) if len(grid) else keep[keep]
    return Admissible(grid[ok], spacing)


def _area(polygon: Array) -> float:
    """Signed area of the closed polygon (shoelace)."""
    x, y = polygon[:, 0], polygon[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def segments_inside(polygon: ArrayLike, p: ArrayLike, q: ArrayLike) -> Mask:
    """``(k,)`` True where the segment from ``p[i]`` to ``q[i]`` (``(k, 2)`` each) lies inside the closed
    polygon: both ends inside, and no edge of the polygon crossed, nor touched at a vertex, between them."""
    poly = np.asarray(polygon, dtype=float)
    a, b = poly, np.roll(poly, -1, axis=0)
    p_, q_ = np.atleast_2d(np.asarray(p, dtype=float)), np.atleast_2d(np.asarray(q, dtype=float))
    ok = contains(poly, p_) & contains(poly, q_)
    if not np.any(ok):
        return ok
    pp, qq = p_[ok][:, None, :], q_[ok][:, None, :]

    def side(u: Array, v: Array, w: Array) -> Array:
        return np.asarray(
            (v[..., 0] - u[..., 0]) * (w[..., 1] - u[..., 1])
            - (v[..., 1] - u[..., 1]) * (w[..., 0] - u[..., 0])
        )

    d1, d2 = side(pp, qq, a[None]), side(pp, qq, b[None])
    d3, d4 = side(a[None], b[None], pp), side(a[None], b[None], qq)
    # a crossing, or the segment through a vertex (d1 or d2 zero with the vertex between the ends): out
    cross = (d1 * d2 <= 0.0) & (d3 * d4 < 0.0)
    ok[ok] = ~np.any(cross, axis=1)
    return ok


def links_inside(
    targets: tuple[Array, ...], anchor_poses: Array, body_poses: Array, centres: Array, circles: Array
) -> Mask:
    """``(k,)`` True where the link from anchor pivot ``centres[i]`` (anchor's profile-1 frame) to moving pivot
    ``circles[i]`` (body's) lies inside every profile in its pose, ends included."""
    ca, mb = moved(anchor_poses, centres), moved(body_poses, circles)
    ok = np.ones(len(centres), dtype=bool)
    for j, poly in enumerate(targets):
        if np.any(ok):
            ok[ok] = segments_inside(poly, ca[j][ok], mb[j][ok])
    return ok


def depths(targets: tuple[Array, ...], poses: Array, points: Array) -> Array:
    """``(k,)`` how deep each body point lies inside the profiles: the smallest distance to an outline over the
    profiles, each in its pose (negative when it is outside one)."""
    world = moved(poses, points)
    out = np.full(len(points), np.inf)
    for poly, w in zip(targets, world, strict=True):
        d = distance_to_outline(poly, w)
        out = np.minimum(out, np.where(contains(poly, w), d, -d))
    return out


def circumcentres(points: Array) -> Array:
    """``(k, 2)`` the centres of the circles through three points ``(k, 3, 2)`` (NaN where collinear)."""
    a = 2.0 * (points[:, 1:] - points[:, :1])  # (k, 2, 2)
    b = np.sum(points[:, 1:] ** 2, axis=2) - np.sum(points[:, :1] ** 2, axis=2)  # (k, 2)
    det = a[:, 0, 0] * a[:, 1, 1] - a[:, 0, 1] * a[:, 1, 0]
    scale = np.max(np.abs(points - points[:, :1]), axis=(1, 2))
    good = np.abs(det) > 1e-13 * np.maximum(scale, 1e-300) ** 2
    safe = np.where(good, det, 1.0)
    x = (b[:, 0] * a[:, 1, 1] - b[:, 1] * a[:, 0, 1]) / safe
    y = (a[:, 0, 0] * b[:, 1] - a[:, 1, 0] * b[:, 0]) / safe
    out = np.column_stack([x, y])
    out[~good] = np.nan
    return out


def centres(rel: Array, circles: Array) -> Array:
    """``(k, 2)`` the centre point of every circle point ``(k, 2)`` for the relative poses ``rel`` ``(p, 3)``:
    the circumcentre of its positions (p = 3), else the least-squares solution of the equal-distance equations
    ``2 (W_j - W_1) . c = |W_j|^2 - |W_1|^2`` (McCarthy ch. 4; as :func:`linkwork.mechanization.guidance.centre_point`
    before its refinement)."""
    w = np.transpose(moved(rel, circles), (1, 0, 2))  # (k, p, 2)
    if w.shape[1] == 3:
        return circumcentres(w)
    a = 2.0 * (w[:, 1:] - w[:, :1])
    b = np.sum(w[:, 1:] ** 2, axis=2) - np.sum(w[:, :1] ** 2, axis=2)
    ata = np.einsum("kpi,kpj->kij", a, a)
    atb = np.einsum("kpi,kp->ki", a, b)
    det = ata[:, 0, 0] * ata[:, 1, 1] - ata[:, 0, 1] * ata[:, 1, 0]
    good = np.abs(det) > 1e-14 * np.maximum(np.einsum("kii->k", ata), 1e-300) ** 2
    safe = np.where(good, det, 1.0)
    x = (atb[:, 0] * ata[:, 1, 1] - atb[:, 1] * ata[:, 0, 1]) / safe
    y = (ata[:, 0, 0] * atb[:, 1] - ata[:, 1, 0] * atb[:, 0]) / safe
    out = np.column_stack([x, y])
    out[~good] = np.nan
    return out


def transmissions(
    anchor_poses: Array, body_poses: Array, centres_: Array, circles: Array, joint: Array
) -> Array:
    """``(k, p)`` the signed sine of the transmission angle of every link ``centres_[i]`` (anchor) -
    ``circles[i]`` (body) placing the body with the revolute chain joint at ``joint`` (body's profile-1 frame):
    the angle at the moving pivot between the link and the arm to the joint, on every profile."""
    link = moved(body_poses, circles) - moved(anchor_poses, centres_)  # (p, k, 2)
    arm = moved(body_poses, circles) - moved(body_poses, np.asarray(joint, dtype=float))
    cross = link[..., 0] * arm[..., 1] - link[..., 1] * arm[..., 0]
    norms = np.maximum(np.linalg.norm(link, axis=2) * np.linalg.norm(arm, axis=2), 1e-300)
    return np.asarray((cross / norms).T)


def inverse(rel: Array) -> Array:
    """The poses of the anchor seen from the body (kinematic inversion), ``(p, 3)``."""
    c, s = np.cos(rel[:, 2]), np.sin(rel[:, 2])
    x = -(c * rel[:, 0] + s * rel[:, 1])
    y = -(-s * rel[:, 0] + c * rel[:, 1])
    return np.column_stack([x, y, -rel[:, 2]])


def spreads(rel: Array, circles: Array, centres_: Array) -> tuple[Array, Array]:
    """The length on profile 1 and its spread over the profiles of every link ``circles[i]`` - ``centres_[i]``."""
    w = np.transpose(moved(rel, circles), (1, 0, 2))
    d = np.linalg.norm(w - centres_[:, None, :], axis=2)
    return d[:, 0], np.ptp(d, axis=1)


@dataclass(frozen=True)
class Placement:
    """What the search of one body and anchor found: ``links`` ``[(moving pivot, dyad)]`` ranked (exact first,
    then by structural error) and thinned, and the admissible pivots of the body and the anchor it searched."""

    links: list[tuple[Array, Dyad]]
    body: Admissible
    anchor: Admissible


def inside_links(
    targets: tuple[Array, ...],
    body_poses: Array,
    anchor_poses: Array,
    rel: Array,
    size: float,
    *,
    longest: float,
    structural: float,
    exact_only: bool = False,
    regions: tuple[Admissible, Admissible] | None = None,
    placing: Array | None = None,
    min_sine: float = 0.0,
) -> Placement:
    """RR links from ``anchor`` to ``body`` with both pivots admissible and the link inside every profile in its
    pose (the module docstring).

    Parameters
    ----------
    targets
        The ``p`` target profiles.
    body_poses, anchor_poses
        ``(p, 3)`` displacements of the body and of the anchor (zeros for the ground).
    rel
        ``(p, 3)`` the body's poses seen from the anchor (``relative(anchor_poses, body_poses)``).
    size
        The profiles' largest extent.
    longest
        The longest link allowed.
    structural
        The largest structural error allowed (the spread of the length over the profiles).
    exact_only
        Only links exact to rounding: a closed or fixed-end chain closes its own loop, and an inexact link there
        does not follow the chain's profiles.
    regions
        The admissible pivots of the body and of the anchor when already known (:func:`admissible`).
    placing
        ``(2,)`` the revolute chain joint (body's profile-1 frame) that with the link places the body, if any:
        links are kept only where they transmit through it, the sine of the angle between the link and the arm
        from the joint to the moving pivot at least ``min_sine`` and of one sign (one assembly mode) on every
        profile (:func:`transmissions`).
    """
    if regions is None:
        regions = (admissible(targets, body_poses, size), admissible(targets, anchor_poses, size))
    body, anchor = regions
    empty = Placement([], body, anchor)
    if len(body.points) == 0 or len(anchor.points) == 0:
        return empty
    tol = EXACT * size if exact_only else structural + EXACT * size
    circles, centres_ = [], []
    # every admissible moving pivot with its centre; every admissible anchor pivot with its circle point
    c = centres(rel, body.points)
    circles.append(body.points)
    centres_.append(c)
    m = centres(inverse(rel), anchor.points)
    circles.append(m)
    centres_.append(anchor.points)
    if not exact_only:
        mm, cc = _near_pairs(rel, body.points, anchor.points, tol)
        circles.append(mm)
        centres_.append(cc)
    circle, centre = np.vstack(circles), np.vstack(centres_)
    finite = np.all(np.isfinite(circle), axis=1) & np.all(np.isfinite(centre), axis=1)
    circle, centre = circle[finite], centre[finite]
    length, spread = spreads(rel, circle, centre)
    ok = (spread <= tol) & (length <= longest) & (length >= SHORTEST * size)
    circle, centre, length, spread = circle[ok], centre[ok], length[ok], spread[ok]
    # both pivots admissible (a centre or circle point computed from the other may not be) and the link inside
    if placing is not None:
        sines = transmissions(anchor_poses, body_poses, centre, circle, placing)
        ok = np.all(np.abs(sines) >= min_sine, axis=1) & (
            np.all(sines > 0, axis=1) | np.all(sines < 0, axis=1)
        )
        circle, centre, length, spread = circle[ok], centre[ok], length[ok], spread[ok]
    # the link inside every profile (the crossing test, cheap), then its pivots clear of every outline
    ok = links_inside(targets, anchor_poses, body_poses, centre, circle)
    circle, centre, length, spread = circle[ok], centre[ok], length[ok], spread[ok]
    margin = np.minimum(depths(targets, body_poses, circle), depths(targets, anchor_poses, centre))
    margin -= SLACK * spread
    ok = margin >= CLEARANCE * size
    circle, centre, length, spread, margin = circle[ok], centre[ok], length[ok], spread[ok], margin[ok]
    # exact links first, then the rest; the deepest inside first in each (the traced mechanism reaches the
    # profiles a little off the chain's poses when any link is inexact)
    order = np.lexsort((-margin, spread > EXACT * size))
    kept = _thinned(circle[order], centre[order], TWIN * size, LINKS)
    links = [
        (
            circle[order][i].copy(),
            Dyad(
                circle[order][i].copy(),
                centre[order][i].copy(),
                float(length[order][i]),
                float(spread[order][i]),
            ),
        )
        for i in kept
    ]
    return Placement(links, body, anchor)


#: Samples of each body tried in pairs (every pair: their product is the work).
PAIR_SAMPLES = 400


def _near_pairs(rel: Array, circles: Array, anchors: Array, tol: float) -> tuple[Array, Array]:
    """Pairs of admissible samples ``(circle point, anchor pivot)`` whose length spreads by at most ``tol``: each
    circle point with the anchor pivot that keeps its length best, and each anchor pivot with its best circle
    point."""
    m = circles[:: max(1, len(circles) // PAIR_SAMPLES)]
    c = anchors[:: max(1, len(anchors) // PAIR_SAMPLES)]
    w = moved(rel, m)  # (p, k, 2)
    d = np.linalg.norm(w[:, :, None, :] - c[None, None, :, :], axis=3)  # (p, k, n)
    spread = np.ptp(d, axis=0)
    # for every circle point its best anchor pivot, and for every anchor pivot its best circle point
    rows = np.arange(len(m))
    cols = np.arange(len(c))
    i = np.concatenate([rows, np.argmin(spread, axis=0)])
    n = np.concatenate([np.argmin(spread, axis=1), cols])
    ok = spread[i, n] <= tol
    return m[i[ok]], c[n[ok]]


def _thinned(circles: Array, centres_: Array, twin: float, most: int) -> list[int]:
    """Indices of at most ``most`` links in the given order, skipping any whose pivots are both within ``twin``
    of a kept link's."""
    kept: list[int] = []
    for i in range(len(circles)):
        if kept:
            dm = np.linalg.norm(circles[kept] - circles[i], axis=1)
            dc = np.linalg.norm(centres_[kept] - centres_[i], axis=1)
            if np.any((dm < twin) & (dc < twin)):
                continue
        kept.append(i)
        if len(kept) >= most:
            break
    return kept


def chain_links(
    chain: ShapeChain, body: str, anchor: str, options: MechanizeOptions, via: str | None = None
) -> list[tuple[Array, Dyad]]:
    """:func:`inside_links` for ``body`` of ``chain`` guided from ``anchor`` (``"ground"`` or a body), within the
    options' link-length and structural-error limits; exact links only unless the chain is open (a closed or
    fixed-end chain closes its own loop). With ``via``, the chain joint that with the link places the body, only
    links transmitting through it above ``options.min_transmission`` (a revolute joint; a slide is not screened
    here)."""
    g_body, g_anchor = chain.motion(body), chain.motion(anchor)
    joint = next((j for j in chain.joints if j.name == via), None)
    placing = joint.point if joint is not None and joint.kind == "R" else None
    regions = (_admissible_of(chain, body), _admissible_of(chain, anchor))
    found = inside_links(
        chain.targets,
        g_body,
        g_anchor,
        relative(g_anchor, g_body),
        chain.size,
        longest=options.link_limit(chain.size),
        structural=options.structural_limit(chain.size),
        exact_only=chain.kind != "open",
        regions=regions,
        placing=placing,
        min_sine=math.sin(options.min_transmission),
    )
    return found.links


#: The admissible pivots of the bodies of the chains searched last, by ``(id(chain), body)`` with the chain kept
#: (an id is only unique while its object lives): a body's region does not depend on the anchor it is guided from.
_REGIONS: dict[tuple[int, str], tuple[ShapeChain, Admissible]] = {}


def _admissible_of(chain: ShapeChain, body: str) -> Admissible:
    """:func:`admissible` for ``body`` of ``chain`` (``"ground"`` too), computed once per chain and body."""
    key = (id(chain), body)
    hit = _REGIONS.get(key)
    if hit is not None and hit[0] is chain:
        return hit[1]
    if len(_REGIONS) > 64:
        _REGIONS.clear()
    region = admissible(chain.targets, chain.motion(body), chain.size)
    _REGIONS[key] = (chain, region)
    return region
