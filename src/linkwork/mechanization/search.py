"""The search for binary links: candidate pivots on the links and on the ground, ranked (Sec. 7).

The chain's bodies are constrained one after another from a *root* body (Assur-group build-up):

* the root is guided by two RR dyads to the ground, a four-bar whose crank is the drive (or, for a fixed-end
  chain, it is already pinned to the ground and its pin is the crank);
* every further body, reached through a chain joint from a body already placed, gets one RR dyad to the ground
  (or to a placed body): with the chain joint it forms an RRR (or RRP) dyad, placed once its neighbour is;
* a body joined to two placed bodies (the far end of a fixed-end or closed chain) needs no link.

For every body the candidate moving pivots are points of the body (its outline, and offsets from it along the
normal); each has its centre point by rigid-body guidance (:mod:`linkwork.mechanization.guidance`); the pivot
pairs are ranked by structural error, the smallest transmission angle over the profiles and the link-length
ratio. Candidates whose fixed pivot leaves the allowed region, whose assembly mode changes between profiles
(the transmission changes sign) or whose transmission angle is below the limit are dropped.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from linkwork.errors import LinkworkError, MechanizationError, SpecError
from linkwork.geometry.se2 import relative
from linkwork.interrupts import requested, stop_text
from linkwork.mechanization import guidance, placement, sliders
from linkwork.mechanization.assemble import BinaryLink
from linkwork.mechanization.chain import ShapeChain, track, track_direction
from linkwork.mechanization.inside import Leaving, leaving
from linkwork.mechanization.options import GroundRegion, MechanizeOptions

Array = NDArray[np.float64]

#: Fixed pivots sampled in the ground region per body (candidates by kinematic inversion).
REGION_SAMPLES = 81

#: With more than five profiles, this many moving pivots per body are moved to fit a circle best.
POLISHED = 12

#: Score lost per unit of structural error relative to the profiles' size: a structural error of 1 % of the
#: size costs as much as 50 degrees of transmission angle (the shape error is what the designer asked for; any
#: transmission above ``min_transmission`` works).
STRUCTURAL_WEIGHT = 5e3


class NoPlan(MechanizationError):
    """No build-up of a root passes the candidate checks; ``near_inside``: the message says how the link that
    came closest to staying inside the shape leaves it (``ground_region = "inside"``)."""

    def __init__(self, message: str, *, near_inside: bool = False) -> None:
        self.near_inside = near_inside
        super().__init__(message)


class PlanStopped(MechanizationError):
    """A SIGINT or SIGTERM held by the command line (:func:`linkwork.interrupts.held_signals`) stopped the
    planning: ranking a body's candidates takes seconds, and a stop should not wait for every body of a plan."""


@dataclass(frozen=True)
class Candidate:
    """A ranked RR dyad for one body: the link, and its score (higher is better)."""

    link: BinaryLink
    score: float
    quality: Array = field(default_factory=lambda: np.zeros(0))
    leaves: Leaving | None = None


@dataclass(frozen=True)
class Step:
    """One body to constrain: the body, the chain joint it is reached through, and its ranked candidates; a body
    that takes two links (``links``) with the body it was placed from, ``hangs_from`` names the body that pair
    hangs from (both links anchored there would make the pair rigid on it)."""

    body: str
    via: str | None
    candidates: tuple[Candidate, ...]
    links: int = 1
    hangs_from: str | None = None


@dataclass(frozen=True)
class Plan:
    """The build-up order and the candidates of every step; ``root_pairs`` rank the root's four-bars.

    ``paired`` are the bodies joined to two placed bodies (a loop's closing body), ``free`` the bodies left
    without a link as extra inputs (DOF above one), ``closing`` the bodies a closing body frees from needing a
    link of their own (:func:`link_slack`): with their chain joints they form an Assur group (an RRR dyad with
    the closing body, or a triad)."""

    root: str
    pinned_root: str | None
    root_pairs: tuple[tuple[Candidate, Candidate, float], ...]
    steps: tuple[Step, ...]
    free: tuple[str, ...]
    paired: tuple[str, ...]
    closing: tuple[str, ...] = ()


def _moving_pivots(chain: ShapeChain, body: str, count: int, offset: float) -> Array:
    """Candidate moving pivots on ``body`` (profile-1 coordinates): outline points and normal offsets."""
    pts = chain.body(body).outline
    if len(pts) < 2:
        return pts.copy()
    idx = np.unique(np.linspace(0, len(pts) - 1, count).round().astype(int))
    length = float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))
    tangent = np.gradient(pts, axis=0)[idx]
    tangent /= np.maximum(np.linalg.norm(tangent, axis=1, keepdims=True), 1e-300)
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])
    out = [pts[idx] + h * offset * length * normal for h in (0.0, 1 / 3, -1 / 3, 2 / 3, -2 / 3, 1.0, -1.0)]
    return np.vstack(out)


#: Points inside the first profile tried as moving pivots of a body (``ground_region = "inside"``).
INTERIOR_SAMPLES = 40


def _interior(chain: ShapeChain, body: str) -> Array:
    """Points inside the first profile near ``body`` (within its length of its outline), profile-1 coordinates."""
    pts = chain.body(body).outline
    length = float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1))) if len(pts) > 1 else chain.size
    first = GroundRegion.inside(chain.targets[:1]).samples(4 * INTERIOR_SAMPLES)
    if len(first) == 0:
        return first.reshape(0, 2)
    near = np.min(np.linalg.norm(first[:, None, :] - pts[None, :, :], axis=2), axis=1)
    close = first[near <= max(length, 0.05 * chain.size)]
    step = max(1, len(close) // INTERIOR_SAMPLES)
    return close[::step]


def _guide(rel: Array, m: Array) -> guidance.Dyad | None:
    """The dyad of moving pivot ``m`` for the relative positions ``rel`` (exact for p = 3)."""
    try:
        return guidance.centre_point(rel, m)
    except LinkworkError:
        return None


def _free_directions(chain: ShapeChain, body: str, via: str | None, m: Array) -> Array | None:
    """``(p, 2)`` the direction the moving pivot may move in when the body's neighbour is held (unit)."""
    if via is None:
        return None
    jt = next(j for j in chain.joints if j.name == via)
    g = chain.body(body).displacements
    p = chain.count
    if jt.kind == "P":
        other = jt.other(body)
        assert jt.direction is not None
        d = track_direction(chain.motion(other), jt.direction)
        return d / np.linalg.norm(d, axis=1, keepdims=True)
    r = track(g, m) - track(g, jt.point)
    n = np.linalg.norm(r, axis=1, keepdims=True)
    if np.any(n < 1e-9 * chain.size):
        return np.full((p, 2), np.nan)
    return np.column_stack([-r[:, 1], r[:, 0]]) / n


def _transmitting(
    chain: ShapeChain,
    body: str,
    via: str | None,
    m: Array,
    kind: str,
    acting: Array,
    options: MechanizeOptions,
) -> Array | None:
    """Signed sine of the transmission angle on every profile of a link with moving pivot ``m`` on ``body``
    (1 when there is no neighbour ``via``), or ``None`` when the link is dropped: its pivot on the neighbour's
    joint, a transmission angle below the limit, or a change of assembly mode (:func:`_accepts`).

    ``acting`` ``(p, 2)`` is the direction in the world of an RR link (``kind`` ``"RR"``), or of a slider's guide
    (``"PR"``), which reacts along its normal (:func:`linkwork.mechanization.sliders.transmission`).
    """
    free = _free_directions(chain, body, via, m)
    if free is None:
        return np.ones(chain.count)
    if np.any(~np.isfinite(free)):
        return None
    s = np.sum(acting * free, axis=1) if kind == "RR" else sliders.transmission(acting, free)
    return s if _accepts(s, options) else None


def body_candidates(
    chain: ShapeChain,
    body: str,
    via: str | None,
    anchors: Sequence[str],
    options: MechanizeOptions,
    name: str = "D",
    *,
    keep_outside: bool = False,
) -> list[Candidate]:
    """Ranked binary links guiding ``body`` relative to each anchor (best first): RR dyads and, as
    ``options.binary_links`` allows, PR sliders.

    With ``ground_region = "inside"`` a link is kept only when its pivots and the link lie inside every profile
    in its pose (:mod:`linkwork.mechanization.inside`); ``keep_outside`` keeps the others too, each with how it
    leaves (``Candidate.leaves``), to say how close the search came.

    Raises
    ------
    PlanStopped
        When a signal is held (:func:`linkwork.interrupts.requested`): the plan being made is given up.
    """
    if requested():
        raise PlanStopped(f"mechanize: {stop_text(requested())} while ranking the links of body {body}")
    region = options.region_of(chain.targets, chain.size)
    out: list[Candidate] = []
    g_body = chain.body(body).displacements
    for anchor in anchors:
        rel = relative(chain.motion(anchor), g_body)
        if options.binary_links in ("revolute", "both"):
            pivots = _pivot_candidates(chain, body, rel, options, region)
            if anchor == "ground":
                pivots += _pivots_from_region(chain, rel, region)
            if region.kind == "inside":  # links sought where their pivots and the link may be
                pivots += placement.chain_links(chain, body, anchor, options, via)
            out += _rr_candidates(chain, body, via, anchor, pivots, options, region, name, keep_outside)
        if options.binary_links in ("prismatic", "both"):
            out += _slider_candidates(chain, body, via, anchor, rel, options, region, name, keep_outside)
    out.sort(key=lambda cand: -cand.score)
    return out


def least_leaving(
    chain: ShapeChain, body: str, via: str | None, anchors: Sequence[str], options: MechanizeOptions
) -> str:
    """With ``ground_region = "inside"``: how the link of ``body`` that comes closest to staying inside leaves
    (for the message when no link stays inside); empty otherwise."""
    if options.region_of(chain.targets, chain.size).kind != "inside":
        return ""
    cands = [c for c in body_candidates(chain, body, via, anchors, options, keep_outside=True) if c.leaves]
    if not cands or any(c.leaves is not None and c.leaves.by == 0.0 for c in cands):
        return ""  # some link stays inside: it failed on other counts, which the message names
    best = min(cands, key=lambda c: c.leaves.by if c.leaves is not None else math.inf)
    assert best.leaves is not None
    link = best.link
    return (
        f"; the link of {body} closest to staying inside ({link.anchor} to {body}, moving pivot "
        f"({link.circle[0]:.4g}, {link.circle[1]:.4g})): {best.leaves.describe('it')}"
    )


def _accepts(s: Array, options: MechanizeOptions) -> bool:
    """Transmission above the limit on every profile, one assembly mode throughout (one sign)."""
    limit = math.sin(options.min_transmission)
    return not (np.any(np.abs(s) < limit) or not (np.all(s > 0) or np.all(s < 0)))


def _smallest_angle(s: Array) -> float:
    """The smallest transmission angle (radians) of the sines ``s`` on every profile."""
    return float(np.arcsin(min(1.0, float(np.min(np.abs(s))))))


def _rr_candidates(
    chain: ShapeChain,
    body: str,
    via: str | None,
    anchor: str,
    pivots: list[tuple[Array, guidance.Dyad]],
    options: MechanizeOptions,
    region: GroundRegion,
    name: str,
    keep_outside: bool = False,
) -> list[Candidate]:
    """RR dyads from their pivots: long, short, outside the region or badly transmitting ones dropped (with
    ``ground_region = "inside"``: any pivot or link leaving a profile, unless ``keep_outside``)."""
    g_body, g_anchor = chain.body(body).displacements, chain.motion(anchor)
    inside = region.kind == "inside"
    out = []
    for m, dyad in pivots:
        c = dyad.centre_point
        r = dyad.radius
        if not np.all(np.isfinite(c)) or r > options.link_limit(chain.size) or r < 1e-3 * chain.size:
            continue
        leaves = None
        if inside:
            leaves = leaving(chain.targets, track(g_anchor, c), track(g_body, m))
            if leaves.by > 0.0 and not keep_outside:
                continue
        elif anchor == "ground" and not bool(region.contains(c)[0]):
            continue
        if dyad.structural_error > options.structural_limit(chain.size) + 1e-9 * chain.size:
            continue
        u = track(g_body, m) - track(g_anchor, c)
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        s = _transmitting(chain, body, via, m, "RR", u, options)
        if s is None:
            continue
        mu = _smallest_angle(s)
        ratio = abs(math.log(r / (0.5 * chain.size)))
        score = math.degrees(mu) - 15.0 * ratio - STRUCTURAL_WEIGHT * dyad.structural_error / chain.size
        link = BinaryLink(name, "RR", anchor, body, c, np.asarray(m, float), dyad.structural_error, mu, via)
        out.append(Candidate(link, score, s, leaves))
    return out


def _slider_candidates(
    chain: ShapeChain,
    body: str,
    via: str | None,
    anchor: str,
    rel: Array,
    options: MechanizeOptions,
    region: GroundRegion,
    name: str,
    keep_outside: bool = False,
) -> list[Candidate]:
    """PR sliders: slider points of the body (exact for three profiles), guides fitted through their positions,
    kept when the slider moves one way, its guide lies in the region (on the ground) and it transmits well
    (with ``ground_region = "inside"``: its guide and its moving pivot inside every profile in its pose)."""
    g_anchor = chain.motion(anchor)
    g_body = chain.body(body).displacements
    inside = region.kind == "inside"
    grid = _moving_pivots(chain, body, max(3, options.candidates // 2), options.link_offset)
    out = []
    for g in grid:
        for v in (np.array([1.0, 0.0]), np.array([0.0, 1.0])):
            for m in sliders.slider_points(rel, g, v * chain.size, reach=options.link_offset):
                start, u, travel, error = sliders.fit_guide(rel, m)
                if (
                    not sliders.monotonic(travel, chain.size)
                    or error > options.structural_limit(chain.size) + 1e-9 * chain.size
                ):
                    continue
                ends = start + np.outer([travel[0], travel[-1]], u)
                leaves = None
                if inside:
                    # the guide, on the anchor, and the moving pivot: inside every profile in its pose
                    leaves = leaving(chain.targets, track(g_anchor, ends[0]), track(g_anchor, ends[1]))
                    pivot = leaving(chain.targets, track(g_body, m), track(g_body, m))
                    leaves = pivot if pivot.by > leaves.by else leaves
                    if leaves.by > 0.0 and not keep_outside:
                        continue
                elif anchor == "ground" and not np.all(region.contains(ends)):
                    continue
                s = _transmitting(chain, body, via, m, "PR", track_direction(g_anchor, u), options)
                if s is None:
                    continue
                mu = _smallest_angle(s)
                score = math.degrees(mu) - STRUCTURAL_WEIGHT * error / chain.size
                link = BinaryLink(name, "PR", anchor, body, start, np.asarray(m, float), error, mu, via, u)
                out.append(Candidate(link, score, s, leaves))
    return out


def _pivot_candidates(
    chain: ShapeChain, body: str, rel: Array, options: MechanizeOptions, region: GroundRegion
) -> list[tuple[Array, guidance.Dyad]]:
    """Moving pivots and their dyads: any point (p <= 3), the circle-point curve (4), Burmester points (5);
    with ``ground_region = "inside"`` also points inside the first profile (where a moving pivot must be)."""
    p = len(rel)
    grid = _moving_pivots(chain, body, options.candidates, options.link_offset)
    if region.kind == "inside":
        grid = np.vstack([grid, _interior(chain, body)])
    out: list[tuple[Array, guidance.Dyad]] = []
    if p <= 3:
        for m in grid:
            d = _guide(rel, m)
            if d is not None:
                out.append((m, d))
    elif p == 4:
        circle, _ = guidance.circle_point_curve(rel, rays=90, origin=grid.mean(axis=0), reach=chain.size)
        for m in circle:
            out.append((m, guidance.centre_point(rel, m)))
    elif p == 5:
        out = [(d.circle_point, d) for d in guidance.burmester_points(rel)]
    else:
        # least squares: every grid point's best circle (fast), then the circle point itself moved to fit best
        # (a small optimisation each) for the few that fit best already
        rough = [(m, d) for m in grid if (d := _guide(rel, m)) is not None]
        rough.sort(key=lambda md: md[1].structural_error)
        out = rough[POLISHED:]
        for m, _ in rough[:POLISHED]:
            d = guidance.fit_circle_point(rel, m)
            out.append((d.circle_point, d))
    return out


def _pivots_from_region(
    chain: ShapeChain, rel: Array, region: GroundRegion
) -> list[tuple[Array, guidance.Dyad]]:
    """Dyads whose fixed pivot is sampled in the ground region: the moving pivot by kinematic inversion.

    Seen from the body, a fixed pivot ``c`` takes the positions of the inverted motion; the moving pivot is the
    centre of the circle through them (exact for three positions, least squares beyond), McCarthy ch. 4.
    """
    inverse = guidance.inverse_poses(rel)
    out: list[tuple[Array, guidance.Dyad]] = []
    for c in region.samples(REGION_SAMPLES):
        try:
            inv = guidance.centre_point(inverse, c)
        except LinkworkError:
            continue
        m = inv.centre_point
        if not np.all(np.isfinite(m)):
            continue
        out.append((m, guidance.Dyad(m, np.asarray(c, dtype=float), inv.radius, inv.structural_error)))
    return out


def _limits(chain: ShapeChain, options: MechanizeOptions) -> str:
    """The link-length and structural-error limits in use, for messages: ``max_link 0.8 (0.59 x the largest
    extent 1.36), structural error 0.068``."""
    longest = options.link_limit(chain.size)
    return (
        f"max_link {longest:.4g} (a length: {longest / chain.size:.3g} x the largest extent {chain.size:.4g}) "
        f"with a structural error at most {options.structural_limit(chain.size):.3g}"
    )


def _adjacent(chain: ShapeChain, body: str) -> list[tuple[str, str]]:
    """``(joint, other body)`` for every chain joint of ``body``."""
    return [(j.name, j.other(body)) for j in chain.joints if body in j.bodies]


def roots(chain: ShapeChain, options: MechanizeOptions) -> list[str]:
    """Bodies to try as the root: the ground-pinned body, the designer's, or every body (longest first)."""
    names = [b.name for b in chain.bodies]
    if options.root is not None and options.root not in names:
        raise SpecError(f"unknown body {options.root!r}; expected one of {', '.join(names)}", key="root")
    pinned = [j for j in chain.joints if "ground" in j.bodies]
    if pinned:
        return [pinned[0].other("ground")]
    if options.root is not None:
        return [options.root]
    return sorted(
        names, key=lambda b: -float(np.sum(np.linalg.norm(np.diff(chain.body(b).outline, axis=0), axis=1)))
    )


def plan(chain: ShapeChain, root: str, options: MechanizeOptions) -> Plan:
    """Order the bodies from ``root`` and rank every body's candidate dyads (``options.anchors`` is
    ``"ground"`` or ``"any"``).

    Raises
    ------
    MechanizationError
        When a body has no acceptable dyad, naming it and the checks.
    """
    pinned = [j for j in chain.joints if "ground" in j.bodies]
    return _plan_from(chain, root, pinned[0].name if pinned else None, options)


def _plan_from(chain: ShapeChain, root: str, pinned_root: str | None, options: MechanizeOptions) -> Plan:
    """The plan with ``root`` guided first."""
    order, paired = _build_up(chain, root)
    # (dof - 1) bodies at the far end stay without a link: their chain joints are the extra inputs
    extra = max(0, options.dof - 1)
    free = tuple(b for b, _ in order[len(order) - extra :]) if extra else ()
    order = order[: len(order) - extra] if extra else order
    slack = link_slack(chain, order, pinned_root, options.dof)
    steps, closing = _steps(chain, root, order, paired, slack, options)
    pairs: list[tuple[Candidate, Candidate, float]] = []
    if pinned_root is None:
        pairs = _root_pairs(chain, root, options)
        if not pairs:
            leaves = least_leaving(chain, root, None, ["ground"], options)
            raise NoPlan(
                f"mechanize: no four-bar guides the root body {root}"
                + leaves
                + "; none through the profiles with its crank turning "
                f"one way and transmission angles above {math.degrees(options.min_transmission):.0f} deg "
                f"and links no longer than {_limits(chain, options)} (try another root, a larger ground region, link "
                "offset or max_link)",
                near_inside=bool(leaves),
            )
    return Plan(root, pinned_root, tuple(pairs), tuple(steps), free, tuple(paired), closing)


def link_slack(chain: ShapeChain, order: Sequence[tuple[str, str]], pinned_root: str | None, dof: int) -> int:
    """How many bodies of the build-up ``order`` need no link of their own.

    A build-up gives the root two links (none when it is pinned to the ground) and every body of ``order`` one;
    the mechanism needs ``M - dof`` (``M`` the chain's Grübler mobility, :meth:`ShapeChain.mobility`: each
    binary link takes one DOF). A loop's closing body, joined to two placed bodies, takes one more DOF than an
    RRR dyad would (``3 - 2 * 2``): a closed chain's or a fixed-end chain's build-up is over-constrained by one,
    and one body of the loop is freed from its link (a generic over-constrained design does not move: the
    verification finds 0 DOF, or rigid but for a hair)."""
    planned = (0 if pinned_root is not None else 2) + len(order)
    return max(0, planned - (chain.mobility() - dof))


def _build_up(chain: ShapeChain, root: str) -> tuple[list[tuple[str, str]], list[str]]:
    """The bodies in build-up order from ``root`` (breadth first) as ``(body, chain joint reached through)``,
    and the bodies joined to two placed bodies, which need no link."""
    placed = ["ground", root]
    order: list[tuple[str, str]] = []
    paired: list[str] = []
    queue = [root]
    while queue:
        body = queue.pop(0)
        for joint, other in _adjacent(chain, body):
            if other in placed:
                continue
            # a body joined to a second placed (or ground-pinned) body closes an RRR dyad with this one
            closing = [(jn, o2) for jn, o2 in _adjacent(chain, other) if o2 != body and o2 in placed]
            placed.append(other)
            queue.append(other)
            if closing:
                paired.append(other)
                continue
            order.append((other, joint))
    return order, paired


def _anchors(chain: ShapeChain, body: str, among: Sequence[str], options: MechanizeOptions) -> list[str]:
    """The ground, and with ``options.anchors == "any"`` the bodies of ``among`` not joined to ``body`` (a link
    beside a chain joint between the same two bodies would make them one)."""
    if options.anchors != "any":
        return ["ground"]
    adjacent = {o for _, o in _adjacent(chain, body)}
    return ["ground"] + [b for b in among if b not in ("ground", body) and b not in adjacent]


@dataclass
class _BuildUp:
    """The state of one build-up (:func:`_steps`): the steps so far, the bodies placed, those skipped."""

    steps: list[Step]
    done: list[str]
    deferred: list[str] = field(default_factory=list)

    def place(self, step: Step, *bodies: str) -> None:
        """Record ``step`` placing ``bodies``."""
        self.steps.append(step)
        self.done += list(bodies)
        for b in bodies:
            if b in self.deferred:
                self.deferred.remove(b)


def _steps(
    chain: ShapeChain,
    root: str,
    order: list[tuple[str, str]],
    paired: Sequence[str],
    slack: int,
    options: MechanizeOptions,
) -> tuple[list[Step], tuple[str, ...]]:
    """Every body's ranked candidates in build-up order, and the bodies a loop's closing body frees from a link.

    A body no dyad from the placed bodies can guide is skipped, then:

    * with ``slack`` (:func:`link_slack`, a closed or fixed-end chain) up to that many skipped bodies need no
      link: with the closing body and the chain joints they form an Assur group (an RRR dyad, or a triad when a
      link joins two of its bodies);
    * a skipped body is retried once later bodies are placed, with links from them too (``anchors = "any"``; a
      body placed after it, or with slack a skipped body, may hold it: the group they form has the DOF count of
      a dyad's);
    * without slack, a body placed from a skipped one may take two links (the pair is placed together), and two
      skipped bodies may hold each other by two links.

    When the closing body frees no skipped body, it frees the last body placed beside it (their chain joints
    make an RRR dyad).

    Raises
    ------
    MechanizationError
        When a body has no acceptable dyad by any of these.
    """
    state = _BuildUp([], ["ground", root])
    joints = {j.name: j for j in chain.joints}
    via_of = dict(order)
    placed_from: dict[str, str] = {}
    for body, via in order:
        anchors = _anchors(chain, body, state.done, options)
        parent = joints[via].other(body)
        placed_from[body] = parent
        if parent in state.deferred and not slack:
            # the body it is placed from had no dyad: this one takes two, and the pair is placed together
            cands = body_candidates(chain, body, None, anchors, options)
            if len(cands) >= 2:
                state.place(Step(body, None, tuple(cands), 2, placed_from.get(parent)), parent, body)
                continue
        cands = body_candidates(chain, body, via, anchors, options)
        if cands:
            state.place(Step(body, via, tuple(cands)), body)
        else:
            state.deferred.append(body)
    # retried with the bodies placed after them (and the other skipped ones) as anchors
    retried = True
    while retried and len(state.deferred) > slack and options.anchors == "any":
        retried = False
        for body in list(state.deferred):
            if len(state.deferred) <= slack:
                break
            # not a body it holds already (the two would take the same links twice); the other skipped bodies
            # only with slack (else two skipped bodies hold each other by a pair of links, below)
            held = {s.body for s in state.steps if any(c.link.anchor == body for c in s.candidates)}
            known = [b for b in (*state.done, *paired, *(state.deferred if slack else ())) if b not in held]
            cands = _retried(chain, body, via_of[body], _anchors(chain, body, known, options), state, options)
            if cands:
                state.place(Step(body, via_of[body], tuple(cands)), body)
                retried = True
    while (
        len(state.deferred) - slack >= 2 and options.anchors == "any"
    ):  # two may hold each other by two links
        first, second = state.deferred[:2]
        if second in {o for _, o in _adjacent(chain, first)}:
            break  # joined already: two links beside the joint would make them one
        pair = body_candidates(chain, first, None, [second], options)
        if len(pair) < 2:
            break
        state.place(Step(state.deferred[0], None, tuple(pair), 2), *state.deferred[:2])
    if len(state.deferred) > slack:
        body = state.deferred[slack]
        leaves = least_leaving(chain, body, None, ["ground"], options)
        raise NoPlan(
            f"mechanize: no dyad can guide body {body} (root {root})"
            + leaves
            + "; not from the bodies placed before it, nor after "
            f"(outside the ground region, longer than {_limits(chain, options)}, a transmission angle below "
            f"{math.degrees(options.min_transmission):.0f} deg or a change of assembly mode between profiles; try "
            "a larger ground region, link offset or max_link)",
            near_inside=bool(leaves),
        )
    closing = list(state.deferred)
    for _ in range(slack - len(closing)):
        freed = _beside_closing(chain, state.steps, paired)
        if freed is None:
            break
        state.steps.remove(freed)
        closing.append(freed.body)
    return state.steps, tuple(closing)


def _retried(
    chain: ShapeChain, body: str, via: str, anchors: Sequence[str], state: _BuildUp, options: MechanizeOptions
) -> list[Candidate]:
    """The candidates of a skipped ``body`` retried: from the bodies placed before it (the ground too) screened for
    their transmission through its chain joint ``via`` as in the build-up; from the others (placed after it, or
    not placed by a dyad: skipped, or a closing body), and from any when the body it is reached from is not placed
    by a dyad, unscreened: the body is then one of a group of more than two bodies solved together (a triad), whose
    motion no dyad's transmission angle describes, and the tracing judges it."""
    parent = next(j for j in chain.joints if j.name == via).other(body)
    placed = [a for a in anchors if a in state.done]
    if parent not in state.done:
        placed = []
    later = [a for a in anchors if a not in placed]
    cands = body_candidates(chain, body, via, placed, options) if placed else []
    cands += body_candidates(chain, body, None, later, options) if later else []
    cands.sort(key=lambda cand: -cand.score)
    return cands


def _beside_closing(chain: ShapeChain, steps: Sequence[Step], paired: Sequence[str]) -> Step | None:
    """The step of the last single-link body placed beside a closing body (freed from its link, it makes an RRR
    dyad with it), else the last single-link step."""
    single = [s for s in steps if s.links == 1]
    beside = {o for p in paired for _, o in _adjacent(chain, p)}
    near = [s for s in single if s.body in beside]
    return near[-1] if near else (single[-1] if single else None)


def _root_pairs(
    chain: ShapeChain, root: str, options: MechanizeOptions
) -> list[tuple[Candidate, Candidate, float]]:
    """Four-bars guiding the root: pairs of dyads ranked by the smaller transmission angle and link ratio."""
    singles = body_candidates(chain, root, None, ["ground"], options)[:60]
    g = chain.body(root).displacements
    out = []
    for i, a in enumerate(singles):
        wa = track(g, a.link.circle)
        if a.link.kind == "RR":
            ca = a.link.centre
            phi = np.unwrap(np.arctan2(wa[:, 1] - ca[1], wa[:, 0] - ca[0]))
            dphi = np.diff(phi)
            if not (np.all(dphi > 1e-6) or np.all(dphi < -1e-6)):
                continue  # the crank must turn one way through the profiles (order); a slider does by choice
        for b in singles[i + 1 :]:
            wb = track(g, b.link.circle)
            coupler = wb - wa
            n = np.linalg.norm(coupler, axis=1)
            if np.any(n < 0.05 * chain.size):
                continue
            perp = np.column_stack([-coupler[:, 1], coupler[:, 0]]) / n[:, None]
            s_b = np.sum(_pull(b.link, wb) * perp, axis=1)  # transmission at the rocker
            s_a = np.sum(_pull(a.link, wa) * perp, axis=1)  # crank against coupler: away from its dead centre
            if not (_accepts(s_a, options) and _accepts(s_b, options)):
                continue
            mu = math.degrees(_smallest_angle(np.concatenate([s_a, s_b])))
            lengths = [link.length for link in (a.link, b.link) if link.kind == "RR"] + [float(n[0])]
            ratio = max(lengths) / min(lengths)
            out.append((a, b, mu - 10.0 * math.log(ratio)))
    out.sort(key=lambda t: -t[2])
    return out[:40]


def _pull(link: BinaryLink, w: Array) -> Array:
    """``(p, 2)`` the unit direction a ground link acts on its moving pivot at positions ``w``: along an RR
    link, along the normal of a slider's guide."""
    if link.kind == "PR":
        assert link.direction is not None
        return np.tile([-link.direction[1], link.direction[0]], (len(w), 1))
    return (w - link.centre) / link.length


def prismatic_actuator(chain: ShapeChain, body: str, options: MechanizeOptions) -> BinaryLink:
    """A linear actuator (RPR) from the ground region to ``body`` whose length changes monotonically.

    Ranked by the stroke relative to the length (larger is better, up to a stroke of half the length), and by
    how squarely the actuator pushes on its pivot's path (the cosine of the angle between the actuator and the
    pivot's motion between profiles).

    Raises
    ------
    MechanizationError
        When no pivot pair on the ground and the body has a monotonic length.
    """
    region = options.region_of(chain.targets, chain.size)
    grid = region.samples(REGION_SAMPLES)
    g = chain.body(body).displacements
    best, best_score = None, -math.inf
    movings = _moving_pivots(chain, body, options.candidates, options.link_offset)
    if region.kind == "inside":
        movings = np.vstack([movings, _interior(chain, body)])
    for m in movings:
        w = track(g, m)
        travel = np.diff(w, axis=0)
        for c in grid:
            length = np.linalg.norm(w - c, axis=1)
            if length.min() < 0.05 * chain.size or length.max() > options.link_limit(chain.size):
                continue
            if region.kind == "inside" and leaving(chain.targets, np.tile(c, (len(w), 1)), w).by > 0.0:
                continue
            dl = np.diff(length)
            if not (np.all(dl > 0) or np.all(dl < 0)):
                continue
            stroke = abs(length[-1] - length[0]) / length.min()
            u = (w[:-1] + w[1:]) / 2 - c
            u /= np.linalg.norm(u, axis=1, keepdims=True)
            t = travel / np.maximum(np.linalg.norm(travel, axis=1, keepdims=True), 1e-300)
            push = float(np.min(np.abs(np.sum(u * t, axis=1))))
            score = min(stroke, 0.5) + push
            if score > best_score:
                best, best_score = (c, m, push), score
    if best is None:
        raise MechanizationError(
            f"mechanize: no linear actuator from the ground region to body {body} changes length one way "
            "through the profiles (enlarge the ground region)"
        )
    c, m, push = best
    return BinaryLink("A1", "RPR", "ground", body, c, m, 0.0, float(np.arcsin(min(1.0, push))))
