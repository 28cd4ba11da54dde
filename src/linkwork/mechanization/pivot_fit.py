"""Every link's pivots fitted jointly to the profiles: more than five profiles, least-squares links.

With six or more profiles no binary link guides its body exactly (:mod:`linkwork.mechanization.guidance`); each
least-squares link is fitted alone, and the mechanism they make is not on any later profile: it takes the
configuration its rigid links allow, and a link's structural error is amplified by the lever of the bodies it
places (links each fitted within 0.005 can leave the mechanism 0.05 off a profile the chain joins within 0.002).
What the designer wants is the mechanism's shape error, so it is what is minimised here, over every
link's pivots at once (S13 Sec. 7: the least-squares synthesis of Murray et al., with the mechanism's own
configurations as unknowns):

* unknowns: every RR link's two pivots (the anchor pivot in the anchor's profile-1 frame, the moving pivot in
  the body's), and on every profile after the first every body's pose ``(x, y, angle)``;
* residuals: the chain's points against the profile's target points (the shape error), and, weighted by
  :data:`CONSTRAINT_WEIGHT`, the chain's joints holding (a revolute joint's two points one point, a straight arc
  slide's bodies parallel and on their line), every link keeping its profile-1 length (the mechanism starts on
  profile 1, exactly as joined), and every link's structural error within the limit (a hinge);
* sliders (PR) and a linear actuator keep their pivots: a slider holds its moving pivot on its guide line (one
  constraint), an actuator adds none.

The problem is sparse (a profile's residuals depend on that profile's poses and on the pivots), which
:func:`scipy.optimize.least_squares` uses for its finite differences. The fit is only a proposal: the design it
returns is verified by tracing like any other (order, branch and circuit defects, the shape error at each
profile's best drive setting), and the candidate checks (link length, ground region, transmission angle,
assembly mode, structural error) are made again on the fitted links.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from linkwork.mechanization.assemble import Design
from linkwork.mechanization.chain import ShapeChain, track
from linkwork.mechanization.guidance import positions
from linkwork.mechanization.inside import leaving
from linkwork.mechanization.options import GroundRegion

Array = NDArray[np.float64]

#: Weight of the constraint residuals (joints hold, links keep their length) against the shape residuals: a
#: shape residual of ``r`` leaves a constraint violated by about ``r / CONSTRAINT_WEIGHT**2``.
CONSTRAINT_WEIGHT = 1e3

#: Two links between the same two bodies keep their moving pivots at least this far apart (times the size), as
#: the search's candidates do.
APART = 0.1

#: Function evaluations of one fit (each a few milliseconds; the Jacobian's grouped finite differences not counted).
EVALUATIONS = 200


class _Layout:
    """Where every unknown sits in the vector ``x``: the fitted links' pivots, then each later profile's poses."""

    def __init__(
        self, design: Design, least: float, longest: float = math.inf, region: GroundRegion | None = None
    ) -> None:
        chain = design.chain
        self.least = least
        self.longest = longest
        self.box: tuple[Array, Array] | None = None
        if region is not None and region.kind != "inside":
            xmin, ymin, xmax, ymax = region.bounds()
            inset = 1e-6 * chain.size
            self.box = (np.array([xmin, ymin]) + inset, np.array([xmax, ymax]) - inset)
        self.joints = {jt.name: jt for jt in chain.joints}
        self.names = {link.name: k for k, link in enumerate(design.links)}
        self.chain = chain
        self.links = design.links
        self.fitted = [k for k, link in enumerate(design.links) if link.kind == "RR"]
        self.bodies = [b.name for b in chain.bodies]
        self.index = {name: i for i, name in enumerate(self.bodies)}
        self.index["ground"] = len(self.bodies)
        self.n_pivots = 4 * len(self.fitted)
        self.per_profile = 3 * len(self.bodies)
        self.p = chain.count
        self.twins = [
            (a, b)
            for i, a in enumerate(self.fitted)
            for b in self.fitted[i + 1 :]
            if {design.links[a].anchor, design.links[a].body}
            == {design.links[b].anchor, design.links[b].body}
        ]

    def start(self) -> Array:
        x = [np.concatenate([self.links[k].centre, self.links[k].circle]) for k in self.fitted]
        for j in range(1, self.p):
            x.append(np.concatenate([self.chain.body(b).displacements[j] for b in self.bodies]))
        return np.concatenate(x) if x else np.zeros(0)

    def pivots(self, x: Array) -> dict[int, tuple[Array, Array]]:
        return {k: (x[4 * i : 4 * i + 2], x[4 * i + 2 : 4 * i + 4]) for i, k in enumerate(self.fitted)}

    def poses(self, x: Array, j: int) -> dict[str, Array]:
        """Every body's pose on profile ``j`` (row 0 fixed at the identity), and the ground's."""
        if j == 0:
            out = {b: np.zeros(3) for b in self.bodies}
        else:
            a = self.n_pivots + (j - 1) * self.per_profile
            out = {b: x[a + 3 * i : a + 3 * i + 3] for i, b in enumerate(self.bodies)}
        out["ground"] = np.zeros(3)
        return out

    def at(self, body: str) -> int:
        """The index of ``body`` (the ground last) in the poses of :func:`_poses`."""
        return self.index[body]

    def pose_columns(self, j: int, body: str) -> list[int]:
        if body == "ground" or j == 0:
            return []
        a = self.n_pivots + (j - 1) * self.per_profile + 3 * self.index[body]
        return [a, a + 1, a + 2]


def _poses(layout: _Layout, x: Array) -> Array:
    """``(p, bodies + 1, 3)`` every body's pose on every profile (profile 1 the identity), the ground last."""
    g = np.zeros((layout.p, len(layout.bodies) + 1, 3))
    g[1:, :-1, :] = x[layout.n_pivots :].reshape(layout.p - 1, len(layout.bodies), 3)
    return g


def _track(g: Array, body: int, point: Array) -> Array:
    """``(p, 2)`` the point (profile-1 coordinates) of body ``body`` on every profile at the poses ``g``."""
    pose = g[:, body]
    c, s = np.cos(pose[:, 2]), np.sin(pose[:, 2])
    return np.column_stack(
        [c * point[0] - s * point[1] + pose[:, 0], s * point[0] + c * point[1] + pose[:, 1]]
    )


def _turn(g: Array, body: int, direction: Array) -> Array:
    """``(p, 2)`` a direction of body ``body`` turned with it on every profile."""
    a = g[:, body, 2]
    c, s = np.cos(a), np.sin(a)
    return np.column_stack([c * direction[0] - s * direction[1], s * direction[0] + c * direction[1]])


def _normal(d: Array) -> Array:
    return np.column_stack([-d[:, 1], d[:, 0]])


def _transmissions(layout: _Layout, g: Array, pivots: dict[int, tuple[Array, Array]], k: int) -> Array:
    """``(p,)`` the signed transmission sine of RR link ``k`` on every profile at the poses ``g`` with the fitted
    ``pivots`` (as :func:`linkwork.mechanization.verify.signed_transmissions`: the angle at the moving pivot
    between the link and the line to the point that, with the link, places the body)."""
    link = layout.links[k]
    c, m = pivots.get(k, (link.centre, link.circle))
    body = layout.at(link.body)
    mw = _track(g, body, m)
    u = mw - _track(g, layout.at(link.anchor), c)
    u /= np.maximum(np.linalg.norm(u, axis=1, keepdims=True), 1e-300)
    joint = layout.joints.get(link.via or "")
    if joint is not None and joint.kind == "P":
        assert joint.direction is not None
        return np.sum(u * _turn(g, layout.at(joint.other(link.body)), joint.direction), axis=1)
    if joint is not None:
        pj = _track(g, body, joint.point)
    else:
        partner = layout.names[link.via or ""]
        pj = _track(g, body, pivots.get(partner, (link.centre, layout.links[partner].circle))[1])
    r = mw - pj
    nr = np.maximum(np.linalg.norm(r, axis=1), 1e-300)
    return np.sum(u * _normal(r), axis=1) / nr


def _residual(layout: _Layout, x: Array, limit: float) -> Array:
    chain = layout.chain
    pivots = layout.pivots(x)
    w = CONSTRAINT_WEIGHT
    g = _poses(layout, x)
    cons: list[Array] = []  # (p, rows) the constraints on every profile
    for jt in chain.joints:
        a, b = layout.at(jt.bodies[0]), layout.at(jt.bodies[1])
        if jt.kind == "R":
            cons.append(_track(g, a, jt.point) - _track(g, b, jt.point))
        else:
            assert jt.direction is not None
            gap = _track(g, b, jt.point) - _track(g, a, jt.point)
            turn = np.remainder(g[:, b, 2] - g[:, a, 2] + math.pi, 2 * math.pi) - math.pi
            cons.append(np.column_stack([turn, np.sum(gap * _normal(_turn(g, a, jt.direction)), axis=1)]))
    for k, link in enumerate(layout.links):
        a, b = layout.at(link.anchor), layout.at(link.body)
        if k in pivots:
            c, m = pivots[k]
            length = np.linalg.norm(_track(g, b, m) - _track(g, a, c), axis=1) - np.linalg.norm(m - c)
            cons.append(length[:, None])
        elif link.kind == "PR":
            assert link.direction is not None
            gap = _track(g, b, link.circle) - _track(g, a, link.centre)
            cons.append(np.sum(gap * _normal(_turn(g, a, link.direction)), axis=1)[:, None])
    held = np.hstack(cons) if cons else np.zeros((layout.p, 0))
    out: list[Array] = []
    for j in range(1, layout.p):
        poses = {name: g[j, i] for i, name in enumerate(layout.bodies)}
        poses["ground"] = g[j, -1]
        out.append((chain.points(poses, j) - chain.targets[j]).ravel())
        out.append(w * held[j])
    hinge: list[float] = []
    for k, link in enumerate(layout.links):
        if link.via is None or link.kind != "RR":
            continue
        sines = _transmissions(layout, g, pivots, k)
        hinge.extend(np.maximum(0.0, layout.least - sines * math.copysign(1.0, sines[0])))
    for k1, k2 in layout.twins:
        # two links between the same bodies stay apart (merged, they would be one link: a singular design)
        apart = float(np.linalg.norm(pivots[k1][1] - pivots[k2][1]))
        hinge.append(max(0.0, APART * chain.size - apart))
    for k, (c, m) in pivots.items():
        # the candidate rules: a link no longer than the limit, a fixed pivot in the ground region's box
        hinge.append(max(0.0, float(np.linalg.norm(m - c)) - layout.longest))
        if layout.box is not None and layout.links[k].anchor == "ground":
            lo, hi = layout.box
            hinge.extend(np.maximum(0.0, np.concatenate([lo - c, c - hi])))
    for k, (c, m) in pivots.items():
        link = layout.links[k]
        need = np.linalg.norm(
            positions(chain.motion(link.body), m) - positions(chain.motion(link.anchor), c), axis=1
        )
        hinge.extend(np.maximum(0.0, np.abs(need[1:] - need[0]) - 0.5 * limit))
    out.append(w * np.asarray(hinge, dtype=float))
    return np.concatenate(out)


def _sparsity(layout: _Layout, limit: float) -> NDArray[np.int8]:
    """Which unknowns each residual depends on (for grouped finite differences)."""
    chain = layout.chain
    n = layout.n_pivots + (layout.p - 1) * layout.per_profile
    rows: list[NDArray[np.int8]] = []
    pivots = {k: i for i, k in enumerate(layout.fitted)}

    def row(cols: list[int]) -> NDArray[np.int8]:
        r = np.zeros(n, dtype=np.int8)
        r[cols] = 1
        return r

    for j in range(1, layout.p):
        every = [c for b in layout.bodies for c in layout.pose_columns(j, b)]
        npts = len(chain.targets[j]) * 2
        rows.extend(row(every) for _ in range(npts))  # the points depend on the bodies' poses only
        for jt in chain.joints:
            cols = layout.pose_columns(j, jt.bodies[0]) + layout.pose_columns(j, jt.bodies[1])
            rows.extend([row(cols), row(cols)])
        for k, link in enumerate(layout.links):
            cols = layout.pose_columns(j, link.anchor) + layout.pose_columns(j, link.body)
            if k in pivots:
                rows.append(row(cols + list(range(4 * pivots[k], 4 * pivots[k] + 4))))
            elif link.kind == "PR":
                rows.append(row(cols))
    for k, link in enumerate(layout.links):
        if link.via is None or link.kind != "RR":
            continue
        cols = []
        for other in (k, layout.names.get(link.via, -1)):
            if other in pivots:
                cols += list(range(4 * pivots[other], 4 * pivots[other] + 4))
        for j in range(layout.p):
            every = [c for b in layout.bodies for c in layout.pose_columns(j, b)] if j else []
            rows.append(row(cols + every))
    for a, b in layout.twins:
        rows.append(
            row(list(range(4 * pivots[a], 4 * pivots[a] + 4)) + list(range(4 * pivots[b], 4 * pivots[b] + 4)))
        )
    for k in layout.fitted:
        cols = list(range(4 * pivots[k], 4 * pivots[k] + 4))
        rows.append(row(cols))
        if layout.box is not None and layout.links[k].anchor == "ground":
            rows.extend(row(cols) for _ in range(4))
    for k in layout.fitted:
        i = pivots[k]
        rows.extend(row(list(range(4 * i, 4 * i + 4))) for _ in range(layout.p - 1))
    return np.array(rows, dtype=np.int8)


def fit_pivots(
    design: Design,
    structural_limit: float,
    min_transmission: float,
    link_limit: float = math.inf,
    region: GroundRegion | None = None,
    *,
    evaluations: int = EVALUATIONS,
) -> Design:
    """``design`` with every RR link's pivots moved to bring the mechanism nearest every profile (least squares
    over the profiles, the mechanism's configurations as unknowns); each link's structural error recomputed in
    the chain's own poses and kept within ``structural_limit``, every RR link's transmission angle above
    ``min_transmission`` (radians) in its assembly mode of profile 1, no link longer than ``link_limit``, every
    fixed pivot on the ground in the box of ``region`` (:func:`fits` checks the region itself after); at most
    ``evaluations`` evaluations of the residuals (not counting the Jacobian's). Unverified: trace it."""
    from scipy.optimize import least_squares

    layout = _Layout(design, math.sin(min_transmission), link_limit, region)
    if not layout.fitted or layout.p < 3:
        return design
    x0 = layout.start()
    sparsity = _sparsity(layout, structural_limit)
    sol = least_squares(
        lambda x: _residual(layout, x, structural_limit),
        x0,
        jac_sparsity=sparsity,
        method="trf",
        x_scale="jac",
        max_nfev=evaluations,
    )
    fitted = {b: np.array([layout.poses(sol.x, j)[b] for j in range(layout.p)]) for b in layout.bodies}
    return replace(with_pivots(design, layout.pivots(sol.x)), fitted=fitted)


def fits(design: Design, link_limit: float, region: GroundRegion) -> str | None:
    """Why the fitted ``design`` breaks a candidate rule (a link longer than ``link_limit`` or shorter than a
    thousandth of the size, a ground pivot outside ``region``; with ``ground_region = "inside"`` a pivot or the
    link leaving a profile in the chain's pose), or ``None``. (Transmission, assembly mode and
    structural error are kept by the fit's hinges and checked again by the verification.)"""
    size = design.chain.size
    for link in design.links:
        if link.kind != "RR":
            continue
        if not link.length <= link_limit or link.length < 1e-3 * size:
            return f"the fitted link {link.name} is {link.length:.4g} long (allowed 1e-3 x {size:.4g} to {link_limit:.4g})"
        if region.kind == "inside":
            chain = design.chain
            out = leaving(
                chain.targets,
                track(chain.motion(link.anchor), link.centre),
                track(chain.motion(link.body), link.circle),
            )
            if out.by > 0.0:
                return f"the fitted link {link.name} leaves the shape by {out.by:.3g}"
        elif link.anchor == "ground" and not bool(region.contains(link.centre)[0]):
            c = link.centre
            return (
                f"the fitted link {link.name}'s fixed pivot ({c[0]:.4g}, {c[1]:.4g}) leaves the ground region"
            )
    return None


def with_pivots(design: Design, pivots: dict[int, tuple[Array, Array]]) -> Design:
    """``design`` with the pivots of links ``k`` replaced, each link's structural error recomputed (the spread
    of the distance between its pivots in the chain's own poses)."""
    chain: ShapeChain = design.chain
    links = list(design.links)
    for k, (c, m) in pivots.items():
        link = links[k]
        need = np.linalg.norm(track(chain.motion(link.body), m) - track(chain.motion(link.anchor), c), axis=1)
        links[k] = replace(
            link, centre=np.array(c, float), circle=np.array(m, float), structural_error=float(np.ptp(need))
        )
    return replace(design, links=tuple(links))
