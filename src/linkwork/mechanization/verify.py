"""Verification of a mechanized design with the kinematic core: DOF from the Jacobian rank, then a trace.

For one degree of freedom the drive is traced from profile 1 (the reference configuration) to the drive value
of every later profile, exactly as ``linkwork trace mechanism.toml --drive D --until D=value`` does, and the
design is rejected with the reason when

* **order defect**: the drive's values on the profiles are not monotonic, or the drive turns back on the way;
* **branch defect**: the path meets a singular configuration (a bifurcation, or a drop of the Jacobian rank)
  between profiles, or the corrector fails;
* **circuit defect**: at a profile's drive value the mechanism is in another assembly mode than the profile's
  configuration (the traced joint values differ from the chain's).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from linkwork.geometry.angles import wrap
from linkwork.geometry.se2 import apply, pose_of
from linkwork.kinematics.closure import body_poses, closure_residual, jacobian
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.normalization import NearMobility, near_mobility
from linkwork.kinematics.rank import numerical_rank
from linkwork.kinematics.stops import StopReason
from linkwork.kinematics.trace_result import Trace
from linkwork.kinematics.tracer import trace
from linkwork.mechanization.assemble import Design
from linkwork.mechanization.chain import turned

Array = NDArray[np.float64]

#: A traced configuration matches the profile's when every joint agrees to this (radians or length / size).
SAME_CONFIGURATION = 1e-6

#: With least-squares links, the traced mechanism is accepted on a profile when its shape error is at most the
#: joined chain's plus this many times the largest structural error of its links (a link's error is amplified by
#: the lever of the bodies it places; the shape error is reported beside the joined chain's either way).
SHAPE_ALLOWANCE = 5.0

#: A profile's configuration closes the loops when the closure residual's norm is below this (times the size).
CLOSES = 1e-9


@dataclass(frozen=True)
class ProfileState:
    """The mechanism on one profile.

    Attributes
    ----------
    drive_value
        The drive's displacement from profile 1 (radians, or a length for a prismatic drive).
    values
        ``(n,)`` every joint's displacement from profile 1 as traced (radians or lengths).
    e_max
        Largest distance from the mechanism's chain to the target profile.
    deviation
        Largest difference between the traced joint values and the chain's (0 for an exact design).
    """

    drive_value: float
    values: Array
    e_max: float
    deviation: float


@dataclass(frozen=True)
class Verification:
    """The outcome of :func:`verify`.

    ``defect`` is ``None`` when the design passes, else ``"dof"``, ``"order"``, ``"branch"``, ``"circuit"``,
    ``"closure"``, ``"frozen"`` (a rigid group of bodies that the profiles deform) or (set by the search with ``ground_region = "inside"``) ``"inside"``, with ``reason`` one line; ``culprit`` names the body or link to change. ``traced`` is ``False``
    when the motion was not traced (more than one DOF: the tracer follows one-parameter paths); a design that
    passes untraced says so in ``reason`` (``"not traced: dof 2 ..."``).
    """

    passed: bool
    defect: str | None
    reason: str
    dof: int
    rank: int
    drive: str
    states: tuple[ProfileState, ...] = ()
    max_condition: float = float("nan")
    culprit: str | None = None
    paths: tuple[Trace, ...] = field(default=())
    traced: bool = True


def loaded_mechanism(design: Design) -> Mechanism:
    """The mechanism of ``design``, built in memory exactly as ``linkwork trace`` reads the written
    ``mechanism.toml`` (the spec reader builds it with the same :meth:`Mechanism.from_joints` from the same joint
    points; tested against a written and read-back file)."""
    return design.mechanism()


#: A design whose links leave the chain rigid but for a hair is refused as the spec reader refuses its file
#: (``linkwork.io.spec``: a closure misfit above this per radian of the near-motion).
NEAR_MOBILE_MISFIT = 1e-12


def _near_rigid(mech: Mechanism) -> NearMobility | None:
    """The near-motion of a design that the spec reader would refuse (rigid but for a hair), else ``None``."""
    near = near_mobility(mech)
    return near if near is not None and near.misfit > NEAR_MOBILE_MISFIT else None


@dataclass(frozen=True)
class PathEnd:
    """How a traced path from one profile to the next ended, as the verification reads it.

    ``kind`` is ``"target"`` (reached the drive value asked for), ``"turning"`` (the drive turned back: a dead
    centre), ``"failed"`` (the corrector failed), ``"bifurcation"``, ``"budget"`` (step budget), ``"closed"``
    or ``"other"``; ``text`` is the tracer's words for people.
    """

    kind: str
    text: str


#: How the verification reads each of the tracer's stop reasons (the rest, a joint limit, no progress, a known
#: point or a component, are "other").
_END_KINDS = {
    StopReason.TARGET: "target",
    StopReason.TURNING: "turning",
    StopReason.FAILED: "failed",
    StopReason.SIGN_CHANGE: "bifurcation",
    StopReason.BUDGET: "budget",
    StopReason.CLOSED: "closed",
}


def path_end(path: Trace) -> PathEnd:
    """How the first branch of ``path`` ended, from its structured end (``Branch.end_kind``, a
    :class:`~linkwork.kinematics.stops.StopReason`): the one place mechanization reads a tracer's end; the
    branch's sentence is kept for people."""
    branch = path.branches[0]
    kind = "other" if branch.end_kind is None else _END_KINDS.get(branch.end_kind, "other")
    return PathEnd(kind, branch.end_reason)


def chain_displacements(design: Design, mech: Mechanism, values: Array) -> dict[str, Array]:
    """``(x, y, angle)`` displacement of every body of the mechanism at joint displacements ``values``."""
    poses = body_poses(mech, q=values)
    return {name: pose_of(g[np.ix_([0, 1, 3], [0, 1, 3])]) for name, g in poses.items()}


def _difference(mech: Mechanism, a: Array, b: Array, size: float) -> Array:
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    revolute = np.array([t == "R" for t in mech.joint_types])
    d = np.where(revolute, wrap(d), d / size)
    return np.abs(d)


#: A defect found on the way: ``(defect, reason, culprit)``.
_Defect = tuple[str, str, str | None]


@dataclass(frozen=True)
class _Checker:
    """What every check of one design needs: the mechanism as ``linkwork trace`` reads it, every joint's value
    on every profile (the chain's), the Jacobian's rank and the DOF at profile 1, and the drive's index."""

    design: Design
    mech: Mechanism
    ideal: Array
    rank: int
    dof: int
    d: int

    @classmethod
    def of(cls, design: Design, mech: Mechanism) -> _Checker:
        """The checker of ``design`` assembled as ``mech``; rank from the Jacobian's singular values."""
        sigma = np.linalg.svd(jacobian(mech, np.zeros(mech.n_joints)), compute_uv=False)
        rank = numerical_rank(sigma)
        d = list(mech.joint_names).index(design.drive)
        return cls(design, mech, design.ideal_values(), rank, mech.n_unknowns - rank, d)

    def state(self, values: Array, j: int) -> ProfileState:
        """The mechanism at joint values ``values`` measured against profile ``j``."""
        chain = self.design.chain
        disp = chain_displacements(self.design, self.mech, values)
        e = float(np.max(chain.errors(disp, j)))
        dev = float(np.max(_difference(self.mech, values, self.ideal[j], chain.size)))
        return ProfileState(float(values[self.d]), np.asarray(values, dtype=float), e, dev)

    def show(self, value: float) -> str:
        """A drive value as printed: degrees for a revolute drive, the length for a prismatic one."""
        return f"{math.degrees(value):.4g} deg" if self.mech.joint_types[self.d] == "R" else f"{value:.4g}"

    def failed(
        self,
        defect: str,
        reason: str,
        *,
        states: tuple[ProfileState, ...] = (),
        max_condition: float = float("nan"),
        culprit: str | None = None,
        paths: tuple[Trace, ...] = (),
        traced: bool = True,
    ) -> Verification:
        """A failed verification, with what was found before the defect."""
        drive = self.design.drive
        return Verification(
            False, defect, reason, self.dof, self.rank, drive, states, max_condition, culprit, paths, traced
        )


def verify(design: Design, *, max_step: float = math.radians(2.0), max_steps: int = 1500) -> Verification:
    """Check a design: DOF from the Jacobian rank; for one DOF, trace the drive through every profile in order.

    With more than one DOF nothing is traced (``traced`` is ``False``): every profile's configuration must close
    the loops (residual below ``CLOSES`` times the size) where the Jacobian keeps its rank; ``max_condition`` is
    then the largest condition number at the profiles.

    Parameters
    ----------
    design
        The mechanized chain.
    max_step
        Largest tracing step (radians), as ``linkwork trace --max-step`` (default 2 degrees).
    max_steps
        Step budget of each trace (a passing design's path is the same as with the CLI's larger budget).
    """
    mech = loaded_mechanism(design)
    near = _near_rigid(mech)
    if near is not None:
        # the spec reader's assembly check: the links make the chain rigid but for a hair (a near-singular design)
        reason = (
            f"branch defect: the joint lines are rigid by a hair, not mobile: smallest singular value "
            f"{near.relative:.3g} of the largest, joints {', '.join(near.joints)}"
        )
        return Verification(False, "branch", reason, 0, 0, design.drive)
    check = _Checker.of(design, mech)
    if check.dof != design.dof:
        return check.failed(
            "dof",
            f"the mechanism has {check.dof} degrees of freedom (Jacobian rank {check.rank}), expected {design.dof}",
        )
    if check.dof != 1:
        return _untraced(check)
    return _traced(check, max_step, max_steps)


def _untraced(check: _Checker) -> Verification:
    """Several DOF: the tracer follows one-parameter paths, so nothing is traced, and the report says so; what
    is checked is that every profile's configuration closes the loops with the Jacobian's full rank."""
    chain, mech, rank = check.design.chain, check.mech, check.rank
    max_cond = 1.0
    for j in range(chain.count):
        residual = float(np.linalg.norm(closure_residual(mech, check.ideal[j])))
        if residual > CLOSES * max(chain.size, 1.0):
            return check.failed(
                "closure",
                f"the configuration of profile {j + 1} does not close the loops (residual {residual:.3g}): "
                "least-squares links are only verified by tracing, with one DOF",
                traced=False,
            )
        spectrum = np.linalg.svd(jacobian(mech, check.ideal[j]), compute_uv=False)
        at = numerical_rank(spectrum)
        if at > 0:
            max_cond = max(max_cond, float(spectrum[0] / spectrum[at - 1]))
        if at < rank:
            return check.failed(
                "branch",
                f"branch defect: the Jacobian loses rank at profile {j + 1} ({at} < {rank})",
                traced=False,
            )
    fixed = tuple(check.state(check.ideal[j], j) for j in range(chain.count))
    note = (
        f"not traced: dof {check.dof} (the tracer follows one-parameter paths; checked: every profile's "
        "configuration closes the loops with full Jacobian rank)"
    )
    return Verification(True, None, note, check.dof, rank, check.design.drive, fixed, max_cond, traced=False)


def _traced(check: _Checker, max_step: float, max_steps: int) -> Verification:
    """One DOF: the drive must be monotonic over the profiles; trace it from each profile's drive value to the
    next's, and stop at the first order, branch or circuit defect."""
    design, mech, d = check.design, check.mech, check.d
    # the drive values the mechanism is expected at: the chain's, or the fitted configurations' (pivot_fit)
    v = check.design.expected_values()[:, d]
    steps = np.diff(v)
    if not (np.all(steps > 0) or np.all(steps < 0)):
        order = ", ".join(f"{x:.4g}" for x in (np.degrees(v) if mech.joint_types[d] == "R" else v))
        return check.failed(
            "order",
            f"order defect: the drive {design.drive} is not monotonic over the profiles ({order})",
            culprit="drive",
        )
    frozen = _frozen(check)
    if frozen is not None:
        return check.failed(*frozen[:2], culprit=frozen[2])
    states: list[ProfileState] = [check.state(np.zeros(mech.n_joints), 0)]
    paths: list[Trace] = []
    max_cond = 1.0
    structural = max((link.structural_error for link in design.links), default=0.0)
    refine = structural > 1e-9 * design.chain.size
    for j in range(1, design.chain.count):
        path, st, found = _reach(check, j, float(v[j]), max_step, max_steps, judge=not refine)
        if found is None and refine:
            path, st, found = _best_setting(check, j, v, path, st, max_step, max_steps)
        paths.append(path)
        max_cond = max(max_cond, path.max_condition_raw)  # raw, like the untraced check
        if found is not None:
            defect, reason, culprit = found
            return check.failed(
                defect,
                reason,
                states=tuple(states),
                max_condition=max_cond,
                culprit=culprit,
                paths=tuple(paths),
            )
        assert st is not None
        states.append(st)
    return Verification(
        True, None, "", check.dof, check.rank, design.drive, tuple(states), max_cond, None, tuple(paths)
    )


#: A chain joint is frozen when the mechanism's motion at profile 1 moves it less than this (relative to the
#: joint moving most) while the chain's step to profile 2 moves it by more than :data:`MOVES` (relative).
FROZEN = 1e-7
MOVES = 1e-3


def _frozen(check: _Checker) -> _Defect | None:
    """A rigid sub-assembly: chain joints that the profiles move but the mechanism's one motion at profile 1 does
    not (links anchored so that a group of bodies is rigid among itself; the DOF is elsewhere). Such a design can
    only follow profiles that do not change that group's shape."""
    mech, design = check.mech, check.design
    if mech.n_unknowns != mech.n_joints:
        return None
    vt = np.linalg.svd(jacobian(mech, np.zeros(mech.n_joints)))[2]
    tangent = np.abs(vt[-1])
    n = len(design.chain.joints)
    step = np.abs(check.design.expected_values()[1] - check.design.expected_values()[0])[:n]
    if not np.any(step > 0) or not np.any(tangent > 0):
        return None
    still = (tangent[:n] <= FROZEN * tangent.max()) & (step > MOVES * step.max())
    if not np.any(still):
        return None
    names = [jt.name for jt, s in zip(design.chain.joints, still, strict=True) if s]
    bodies = {b for jt in design.chain.joints if jt.name in names for b in jt.bodies}
    blamed = [link.name for link in design.links if link.body in bodies or link.anchor in bodies]
    return (
        "frozen",
        f"frozen: the links make a rigid group of the chain: joint{'s' if len(names) > 1 else ''} "
        f"{', '.join(names)} cannot move, but the profiles move {'them' if len(names) > 1 else 'it'}",
        blamed[-1] if blamed else None,
    )


def _reach(
    check: _Checker, j: int, value: float, max_step: float, max_steps: int, *, judge: bool = True
) -> tuple[Trace, ProfileState | None, _Defect | None]:
    """Trace the drive from profile 1 to ``value`` and judge the mechanism there against profile ``j``: the
    path, the state (``None`` after a path defect) and the defect found, if any (the circuit only with
    ``judge``)."""
    design = check.design
    path = trace(
        check.mech, drive=design.drive, until=(design.drive, value), max_step=max_step, max_steps=max_steps
    )
    found = _path_defect(check, path, j, value)
    if found is not None:
        return path, None, found
    st = check.state(path.angles[-1], j)
    return path, st, _circuit_defect(check, path, st, j) if judge else None


#: The drive setting of a profile is refined to this fraction of the drive's step between profiles.
SETTING_TOLERANCE = 1e-3

#: At most this many traces refine one profile's drive setting.
SETTING_TRACES = 14


def _best_setting(
    check: _Checker,
    j: int,
    v: Array,
    path: Trace,
    st: ProfileState | None,
    max_step: float,
    max_steps: int,
) -> tuple[Trace, ProfileState | None, _Defect | None]:
    """Least-squares links put no configuration of the mechanism exactly on a profile: the drive setting of
    profile ``j`` is the one, between the midpoints to the neighbouring profiles' settings, where the traced
    mechanism's shape error against profile ``j`` is smallest (a bounded scalar minimisation, each value traced
    from profile 1). The designer sets the actuator there; the order of the profiles along the drive is kept."""
    from scipy.optimize import minimize_scalar

    assert st is not None
    before = 0.5 * (v[j - 1] + v[j])
    after = 0.5 * (v[j] + v[j + 1]) if j + 1 < len(v) else v[j] + 0.5 * (v[j] - v[j - 1])
    lo, hi = sorted((float(before), float(after)))
    tried: dict[float, tuple[Trace, ProfileState | None, _Defect | None]] = {float(v[j]): (path, st, None)}

    def error(t: float) -> float:
        if t not in tried:
            tried[t] = _reach(check, j, t, max_step, max_steps, judge=False)
        reached = tried[t]
        ok = reached[1] is not None and reached[2] is None
        return reached[1].e_max if ok else 1e3 * check.design.chain.size  # type: ignore[union-attr]

    best = minimize_scalar(
        error,
        bounds=(lo, hi),
        method="bounded",
        options={"xatol": SETTING_TOLERANCE * (hi - lo), "maxiter": SETTING_TRACES},
    )
    t = float(best.x)
    if error(t) < st.e_max:
        path, st, _ = tried[t]
    assert st is not None
    return path, st, _circuit_defect(check, path, st, j)


def _path_defect(check: _Checker, trace: Trace, j: int, target: float) -> _Defect | None:
    """A branch or order defect on the path from profile 1 to the drive value ``target`` of profile ``j + 1``
    (0-based ``j``)."""
    design, d, drive = check.design, check.d, check.design.drive
    where = f"between profiles {j} and {j + 1}" if j == 1 else f"before profile {j + 1}"
    end = path_end(trace)
    if trace.bifurcations:
        b = trace.bifurcations[0]
        return (
            "branch",
            f"branch defect: a singular configuration (rank {b.rank}) {where}, drive {drive} = {check.show(b.angles[d])}",
            _culprit(design, check.mech, trace),
        )
    if np.any(trace.rank < check.rank):
        k = int(np.flatnonzero(trace.rank < check.rank)[0])
        return (
            "branch",
            f"branch defect: the Jacobian loses rank {where}, drive {drive} = {check.show(trace.angles[k, d])}",
            _culprit(design, check.mech, trace),
        )
    dv = np.diff(trace.angles[:, d])
    if np.any(dv * np.sign(target) < -1e-12):
        # a dead centre on the way: the drive turns back (the trace may then wander until its budget)
        k = int(np.flatnonzero(dv * np.sign(target) < -1e-12)[0])
        return (
            "order",
            f"order defect: the drive {drive} turns back {where} at {check.show(trace.angles[k, d])} (a dead centre)"
            + (f"; the trace then {end.text}" if end.kind != "target" else ""),
            _culprit(design, check.mech, trace),
        )
    if end.kind != "target":
        defect = "order" if end.kind == "turning" else "branch"
        return (
            defect,
            f"{defect} defect: the trace {where} stopped ({end.text}) before the drive {drive} reached {check.show(target)}",
            _culprit(design, check.mech, trace),
        )
    return None


def _circuit_defect(check: _Checker, trace: Trace, st: ProfileState, j: int) -> _Defect | None:
    """A circuit defect at profile ``j``'s drive value: the mechanism in another assembly mode than the chain
    (least-squares links: judged by the shape, as the profile's configuration is not on the mechanism)."""
    design, chain = check.design, check.design.chain
    start = signed_transmissions(design, check.mech, np.zeros(check.mech.n_joints))
    now = signed_transmissions(design, check.mech, st.values)
    flipped = [name for name, sine in now.items() if sine * start[name] < 0.0]
    if flipped:
        return (
            "circuit",
            f"circuit defect: on profile {j + 1} link {flipped[0]} is in the other assembly mode than on profile 1",
            flipped[0],
        )
    structural = max((link.structural_error for link in design.links), default=0.0)
    if structural > 1e-9 * chain.size:
        allowed = chain.joined_errors[j] + SHAPE_ALLOWANCE * structural
        if st.e_max <= allowed + 1e-9 * chain.size:
            return None
        return (
            "circuit",
            f"shape error {st.e_max:.3g} on profile {j + 1} at its best drive setting, more than the joined "
            f"chain's {chain.joined_errors[j]:.3g} + {SHAPE_ALLOWANCE:g} x the largest structural error "
            f"{structural:.3g} (too far from the profile to be on it)",
            max(design.links, key=lambda link: link.structural_error).name,
        )
    if st.deviation <= SAME_CONFIGURATION:
        return None
    worst = check.mech.joint_names[
        int(np.argmax(_difference(check.mech, trace.angles[-1], check.ideal[j], chain.size)))
    ]
    return (
        "circuit",
        f"circuit defect: at the drive value of profile {j + 1} the mechanism is in another assembly mode "
        f"(joint {worst} differs)",
        _circuit_culprit(design, check.mech, trace.angles[-1], j),
    )


def _circuit_culprit(design: Design, mech: Mechanism, values: Array, j: int) -> str | None:
    """The first added link (in build order) whose moving body is not where the profile puts it."""
    disp = chain_displacements(design, mech, values)
    tol = SAME_CONFIGURATION * design.chain.size
    for link in design.links:
        ideal = design.chain.body(link.body).displacements[j]
        if (
            np.max(np.abs(disp[link.body][:2] - ideal[:2])) > tol
            or abs(wrap(disp[link.body][2] - ideal[2])) > 1e-6
        ):
            return link.name
    return design.links[0].name if design.links else None


def link_pivots(design: Design, mech: Mechanism, values: Array) -> dict[str, Array]:
    """``(2, 2)`` the world positions of every binary link's two pivots at joint displacements ``values``: the
    anchor pivot (on the ground or on the anchor body; a slider's guide point) and the moving pivot (on the
    body)."""
    disp = chain_displacements(design, mech, values)
    out: dict[str, Array] = {}
    for link in design.links:
        anchor = apply(disp[link.anchor], link.centre)
        out[link.name] = np.array([anchor, apply(disp[link.body], link.circle)])
    return out


def link_transmissions(design: Design, mech: Mechanism, values: Array) -> dict[str, float]:
    """Sine of every RR link's (and PR slider's) transmission angle at joint displacements ``values`` (0: a dead
    centre).

    The angle at the moving pivot between the link and the line to the point that, with the link, places the
    body: the body's chain joint ``via``, or the other root link's moving pivot.
    """
    return {name: abs(s) for name, s in signed_transmissions(design, mech, values).items()}


def signed_transmissions(design: Design, mech: Mechanism, values: Array) -> dict[str, float]:
    """The transmission sines of :func:`link_transmissions` with their sign: the side of the line from the
    placing point to the moving pivot the link lies on, i.e. the assembly mode of the dyad (it changes only
    through a dead centre, sine 0)."""
    disp = chain_displacements(design, mech, values)
    joints = {jt.name: jt for jt in design.chain.joints}
    links = {link.name: link for link in design.links}
    out: dict[str, float] = {}
    for link in design.links:
        if link.kind not in ("RR", "PR") or link.via is None:
            continue
        m = apply(disp[link.body], link.circle)
        if link.kind == "PR":  # the guide reacts along its normal
            assert link.direction is not None
            d = turned(disp[link.anchor], link.direction)
            u = np.array([-d[1], d[0]])
        else:
            c = apply(disp[link.name], link.centre)
            u = (m - c) / max(float(np.linalg.norm(m - c)), 1e-300)
        if link.via in joints:
            jt = joints[link.via]
            if jt.kind == "P":
                assert jt.direction is not None
                d = turned(disp[jt.other(link.body)], jt.direction)
                out[link.name] = float(u @ d)
                continue
            pj = apply(disp[link.body], jt.point)
        else:
            partner = links[link.via]
            pj = apply(disp[link.body], partner.circle)
        r = m - pj
        nr = float(np.linalg.norm(r))
        out[link.name] = float(u @ np.array([-r[1], r[0]]) / nr) if nr > 0 else 0.0
    return out


def _culprit(design: Design, mech: Mechanism, trace: Trace) -> str | None:
    """The RR link nearest a dead centre on the path (at the drive's turning point when there is one, among the
    links that move there with the drive held: :func:`moving_links`)."""
    d = mech.index(design.drive)
    drive = trace.angles[:, d]
    turn = np.flatnonzero(np.diff(np.sign(np.diff(drive))) != 0)
    rows = [int(turn[0]) + 1] if turn.size else range(0, len(drive), max(1, len(drive) // 40))
    moving = moving_links(design, mech, trace.angles[rows[0]]) if turn.size else set()
    worst, name = math.inf, None
    for k in rows:
        for link, s in link_transmissions(design, mech, trace.angles[k]).items():
            if (not moving or link in moving) and s < worst:
                worst, name = s, link
    return name


#: A joint moves in the motion with the drive held when its rate is above this fraction of the fastest.
MOVING = 1e-3


def moving_links(design: Design, mech: Mechanism, values: Array) -> set[str]:
    """The binary links that move at a dead centre of the drive (``values``) with the drive held: the motion
    (the right singular vector of the closure Jacobian without the drive's column, G&P Eq. (21), for its
    smallest singular value) moves only the group that is singular there and what it carries. The links placed
    before that group stand still; a dead centre inside an Assur group of more than two bodies (a triad), which
    no dyad's transmission angle shows, is found by this."""
    d = mech.index(design.drive)
    j = np.delete(jacobian(mech, values), d, axis=1)
    if j.shape[1] == 0:
        return set()
    v = np.insert(np.linalg.svd(j)[2][-1], d, 0.0)
    rate = np.abs(v) / max(float(np.max(np.abs(v))), 1e-300)
    names = design.joint_names()
    index = {n: k for k, n in enumerate(names)}
    return {
        link.name
        for link in design.links
        if any(rate[index[n]] > MOVING for n in link.joint_names() if n in index)
    }
