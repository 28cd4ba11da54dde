"""Every joint's extremes along a traced branch, located on the path, so that a branch's ``range`` is each joint's
true swing and not only what its rows sampled.

The tracer locates the folds of the drive (``Trace.folds``): where the drive turns back. Any other joint turns back
between rows too (a crank-rocker's rocker, every coupler angle), and its extreme value lies between two rows: the
rows of a 2-degree trace miss it by up to about ``h^2 / 8`` times the joint's curvature along the path (a rocker's
swing 7e-4 deg short). Here each joint's turning points are found where its increment from row to row changes
sign, and located as a fold of that joint (:func:`linkwork.kinematics.classify.locate_fold`, the bisection the
tracer's folds use: each trial point corrected onto the path, the tangent's component of the joint's unknown
changing sign across the bracket). A point that cannot be corrected onto the path leaves the rows' extreme as it
was, so a range is never narrower than its rows'.

The points are located in the frame the tracer traced the rows in: a linkage far from its own frame is traced as
its twin in its own frame (:mod:`linkwork.kinematics.own_frame`), and its turning points are located on that twin
too, with the tolerances the twin was traced with, then reported in the user's units. In the raw frame the
closure Jacobian's revolute columns carry moments about a far origin while a prismatic column does not: a
slider-crank with a 1000 mm crank placed 1e5 mm from the origin has singular values 1.9e5 .. 3.6e-3 there (1 ..
0.3 in its own frame), the located points' corrector stalled at 7e-10 mm (round-off of coordinates 1e5 mm large)
and, with the Jacobian that ill-conditioned, that left the point off the path by 7.7e-5 mm along the slider;
placed 1e7 mm away no point was corrected at all.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from linkwork.kinematics.classify import locate_fold
from linkwork.kinematics.jit import select_backend
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.normalization import length_scale
from linkwork.kinematics.own_frame import arguments_in_own_frame, own_frame, twin
from linkwork.kinematics.rank import DEFAULT, Tolerances, numerical_rank
from linkwork.kinematics.stops import StopReason
from linkwork.kinematics.trace_result import Trace
from linkwork.kinematics.workspace import Workspace

Array = NDArray[np.float64]

NOISE = 1e-9
"""Increments of an unknown below this times its largest along the branch, or below :data:`STILL` (radians, or
the linkage's own length), are round-off, not motion: their sign changes are not turning points."""
STILL = 1e-10
"""See :data:`NOISE`."""
SEAM = 1e-9
"""How close (radians, or lengths over the linkage's length scale) a branch's last row must come to its first,
modulo whole turns, to be taken as back at its start (:func:`_back_at_start`)."""
SMOOTH = 0.9
"""The least cosine between a back-at-start branch's tangents at its last and first rows for its seam to be looked
across (:func:`joint_extremes`)."""
LONGEST = 2.0 * np.pi
"""The longest bracket located: two rows a turn apart in the step's metric (radians). Between rows far apart (a few
long equal steps) a trial point's hyperplane may meet the path more than once; a point found is kept only if it
lies beyond its bracket's rows by less than the bracket's length, so a range is never narrower than the rows'
(a crank-rocker's rocker in 4 to 36 equal steps of a turn: its swing to 4e-11 deg; in 2 or 3 steps, rows 180 and
120 deg apart, the swing is not always found and the rows' extreme is kept)."""


def branch_rows(trace: Trace, branch: int) -> NDArray[np.int64]:
    """The row indices of ``branch`` in the order of its steps."""
    rows = np.flatnonzero(trace.branch == branch)
    return rows[np.argsort(trace.step[rows], kind="stable")]


def joint_extremes(trace: Trace, branch: int) -> Array:
    """``(K, n)`` joint values (radians, or lengths) at the located turning points of every free joint on
    ``branch``, strictly between its first and last rows (the drive's folds too: ``Trace.folds`` has them). On a
    closed path the step across its closing row (last row, then the first step again) is looked at too; a point
    found there carries only its own joint's values, the others ``nan`` (they may lie a turn beyond the rows)."""
    user = trace.mechanism
    rows = branch_rows(trace, branch)
    n = user.n_joints
    if len(rows) < 3 or user.n_unknowns == 0:
        return np.zeros((0, n))
    backend = select_backend()
    # located where the tracer traced the rows: a linkage far from its own frame in its twin there (lengths in
    # the linkage's own length, moments about its hinge centre), reported back in the user's units
    frame = own_frame(user)
    mech = twin(user) if frame.used else user
    joint_scale = frame.joint_scale if frame.used else np.ones(n)
    length = 1.0 if frame.used else length_scale(user, kernels=backend)
    u = mech.u_from_q(mech.q_from_angles(trace.angles[rows] * joint_scale))
    ws: Workspace | None = None
    prismatic = np.array(
        [any(mech.joint_types[j] == "P" for j in members) for members in mech.group_members()], dtype=bool
    )
    weight = np.where(prismatic, 1.0 / length, 1.0) if prismatic.any() else None
    n_rows = len(u)
    tol = _tolerances(trace, user, length)
    # a closed path's net change over the loop (a full turn of a joint that turns round)
    period = u[-1] - u[0]
    back = any(b.id == branch and b.end_kind == StopReason.CLOSED for b in trace.branches)
    if back or _back_at_start(period, prismatic, length):
        # a closed path goes on past its last row as from its first: a turning point in the closing step or the
        # first step has its bracket across the seam, if the path passes the start smoothly (not at a crossing,
        # where the branch may come back along another curve)
        ws = Workspace.of(mech, backend)
        t_end, t_start = (
            _tangent(ws, u[-1], u[-1] - u[-2], tol, weight),
            _tangent(ws, u[0], u[1] - u[0], tol, weight),
        )
        w = np.ones(len(period)) if weight is None else weight
        if (
            t_end is not None
            and t_start is not None
            and float((w * t_end) @ (w * t_start))
            > SMOOTH * float(np.linalg.norm(w * t_end) * np.linalg.norm(w * t_start))
        ):
            u = np.vstack([u, u[1] + period])
    closed = len(u) > n_rows
    du = np.diff(u, axis=0)
    found = []
    for g in range(mech.n_unknowns):
        step = du[:, g]
        big = float(np.max(np.abs(step), initial=0.0))
        if big == 0.0:
            continue
        scale = 1.0 if weight is None else 1.0 / weight[g]
        sign = np.where(np.abs(step) > max(NOISE * big, STILL * scale), np.sign(step), 0.0)
        moving = np.flatnonzero(sign != 0.0)
        # consecutive moving increments of opposite signs: the joint turned back between them
        turns = moving[1:][sign[moving[1:]] * sign[moving[:-1]] < 0.0]
        seam = closed and abs(period[g]) > max(NOISE * big, STILL * scale)
        for k in turns:
            if seam and k + 1 >= n_rows:
                continue  # a joint that turns round: its values past the seam are a turn away
            before = int(moving[np.searchsorted(moving, k) - 1])  # the moving increment before it
            # the bracket's rows: the joint moved one way after row a, the other way before row b
            a, b = before, k + 1
            chord = u[b] - u[a]
            if float(np.linalg.norm(chord if weight is None else chord * weight)) > LONGEST:
                continue
            ws = ws if ws is not None else Workspace.of(mech, backend)
            t_a, t_b = _tangent(ws, u[a], chord, tol, weight), _tangent(ws, u[b], chord, tol, weight)
            if t_a is None or t_b is None or np.sign(t_a[g]) == np.sign(t_b[g]):
                continue
            point = locate_fold(ws, u[a], t_a, u[b], t_b, g, tol, weight)
            # the turning point is beyond every row of its bracket, by less than the bracket's length
            inner = u[a : b + 1, g]
            beyond = (point[g] - inner.max()) if sign[before] > 0 else (inner.min() - point[g])
            if point is not u[a] and -1e-12 * big <= beyond <= float(np.abs(chord).sum()):
                angles = mech.angles_from_q(mech.q_from_u(point)) / joint_scale
                if b >= n_rows:
                    # across the seam: only this joint's value is its own (it does not turn round); the others
                    # may lie a turn beyond the branch's rows
                    angles = np.where(np.isin(np.arange(n), mech.group_members()[g]), angles, np.nan)
                found.append(angles)
    return np.array(found).reshape(-1, n)


def joint_ranges(trace: Trace, branch: int | None = None) -> dict[str, tuple[float, float]]:
    """``{joint: (min, max)}`` over ``branch`` (radians, or lengths; ``None``: every branch): its rows, the drive's
    folds and every joint's located turning points (:func:`joint_extremes`)."""
    ids = np.unique(trace.branch) if branch is None else [branch]
    parts = [trace.angles[np.isin(trace.branch, ids)]]
    parts += [f.angles[None, :] for f in trace.folds if f.branch in ids]
    parts += [joint_extremes(trace, int(b)) for b in ids]
    values = np.concatenate(parts)
    return {
        name: (float(np.nanmin(values[:, j])), float(np.nanmax(values[:, j])))
        for j, name in enumerate(trace.mechanism.joint_names)
    }


def _back_at_start(period: Array, prismatic: NDArray[np.bool_], length: float) -> bool:
    """Whether a branch whose unknowns changed by ``period`` from its first row to its last is back where it
    started (a paper trace of one full turn ends on its target, not "closed"): every revolute unknown a whole
    number of turns away, every prismatic one where it was (over the linkage's ``length``), to :data:`SEAM`."""
    turns = period - 2.0 * np.pi * np.round(period / (2.0 * np.pi))
    off = np.where(prismatic, period / length, turns)
    return bool(np.all(np.abs(off) <= SEAM))


def _tolerances(trace: Trace, user: Mechanism, length: float) -> Tolerances:
    """The tolerances of the corrector that traced ``trace`` of ``user``: the defaults, with its closure tolerance
    (play) if it had one; for a linkage traced in its own frame, those the tracer gave its twin
    (:func:`~linkwork.kinematics.own_frame.arguments_in_own_frame`: lengths in the linkage's own length, a stall
    accepted at the round-off its file's coordinates carry); otherwise their round-off levels scaled to the
    linkage's own ``length`` as the tracer scales them (:meth:`~linkwork.kinematics.rank.Tolerances.at_length`),
    so that a point a large linkage's corrector closes to its own round-off is accepted here too."""
    closure = trace.stats.closure_tol
    closure_tol = None if closure <= DEFAULT.closure else closure
    if own_frame(user).used:
        _, _, tol, closure_own = arguments_in_own_frame(user, None, None, DEFAULT, closure_tol)
        return tol if closure_own is None else tol.with_closure(closure_own)
    tol = DEFAULT if closure_tol is None else DEFAULT.with_closure(closure_tol)
    return tol.at_length(length)


def _tangent(
    ws: Workspace, u: Array, along: Array, tol: Tolerances, weight: Array | None = None
) -> Array | None:
    """The path's unit tangent at ``u`` oriented along ``along`` in the step's metric (``weight``: 1 for an
    angle, ``1 / L`` for a length; ``None``: all 1); ``None`` where it is not one line (the Jacobian's rank as the
    tracer reads a row, :func:`~linkwork.kinematics.rank.numerical_rank` with its tolerances ``tol``: a
    spherical four-bar placed 1e8 from the origin carries the round-off of its file's coordinates into its own
    frame, ``sigma_4 / sigma_1 = 2.4e-9`` where it is zero, with a gap of 1e8 above it, and a fixed level of
    1e-10 saw no line there). In the plain metric a slider in a small unit (a large length) outweighs every
    angle, and next to its turning point the chord's slider component would orient both ends' tangents alike,
    hiding the turn."""
    _, _, jac = ws.evaluate(u)
    _, s, vt = np.linalg.svd(jac)
    if vt.shape[0] - numerical_rank(s, tol) != 1:
        return None
    t = vt[-1]
    w2 = 1.0 if weight is None else np.asarray(weight) ** 2
    return t if float(t @ (w2 * along)) >= 0.0 else -t
