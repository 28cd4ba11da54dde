"""Tracing a linkage in its own frame, so that where it stands and the unit it is written in decide nothing.

The tracer's rank decisions (the path's rank at the start, the rank of every row, the local minima of
``sigma_r / sigma_1`` that may be singular points, a located minimum's verdict) read ratios of the closure
Jacobian's singular values. On the raw Jacobian (joint twists ``(w, v)`` with moments ``v`` about the base frame's
origin, in the file's length unit) those ratios change with placement and unit: Goldberg's linkage written in
thousandths and moved 42 units from the origin has ``sigma_4 / sigma_1 = 9.8e-8`` where the same linkage at the
origin in its own unit has ``6e-2``, and five singular points were reported where there is none.

So a linkage whose raw frame is far from its own is traced as its **twin in its own frame**: moments about its
hinge centre ``c`` and lengths in its scale ``L`` at the start (:func:`~linkwork.kinematics.normalization.
hinge_centre`, the point nearest to all revolute hinge lines and their RMS distance from it), that is every
revolute twist ``(w, v)`` becomes ``(w, (v - c x w) / L)`` and a prismatic joint's displacement is measured in
``L``. The twin is the same linkage (a rigid change of origin and a change of unit): its path is the user's path,
joint for joint. Under a rigid motion or a change of unit of the user's linkage, ``c`` moves with it and ``L``
scales with it, so the twin is the same up to a rotation, and so are its singular values and every decision taken
on them (the Jacobian of the twin is ``A^-1 J`` with ``A = [[I, 0], [[c]x, L I]]`` per loop, fixed for the
trace). What the trace reports is the user's again: joint values (prismatic ones times ``L``), and the singular
values and residuals of the user's own Jacobian at every row and point (``Trace.sigma`` means one thing
whichever frame decided the ranks).

A frame already close to the linkage's own (``cond(A) <= OWN_FRAME_GATE``: every built-in, between 1.5 and 4.6)
is traced as it is: the ratios differ from the twin's by at most that factor, far inside the margins of the rank
decisions (``local_min = 1e-2`` against ``loose = 1e-5``), and its trace costs nothing more.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from linkwork.kinematics.mechanism import Array, Mechanism
from linkwork.kinematics.normalization import hinge_centre
from linkwork.kinematics.rank import Tolerances
from linkwork.kinematics.trace_result import ARCLENGTH_WEIGHTS, Bifurcation, Trace, arclength_weights
from linkwork.kinematics.workspace import Workspace

OWN_FRAME_GATE = 10.0
"""A linkage whose frame map ``A`` (see the module's docstring) has a condition number above this is traced in
its own frame; below it, the raw ratios are within this factor of the twin's."""


ROUNDOFF_CARRIED = 100.0
"""In the twin, a residual that stalls below this many times the round-off the file's coordinates carry into it
(``eps (|c| + L) / L``) is accepted as closed: Hedgepeth's hoop in thousandths 42 units from the origin carries
3e-11 of its size and stalled at 1.4e-9 (raw) before its path closed."""


@dataclass(frozen=True)
class OwnFrame:
    """A linkage's own frame: its hinge ``centre (3,)`` and ``length`` at the start, the condition number ``kappa``
    of the map between the raw Jacobian's rows and the twin's, and how each joint's value (``joint_scale (n,)``)
    and each unknown (``unknown_scale (m,)``) is measured in the twin: 1 for an angle, ``1 / length`` for a
    length."""

    centre: Array
    length: float
    kappa: float
    joint_scale: Array
    unknown_scale: Array

    @property
    def used(self) -> bool:
        """Whether a trace goes through the twin (the raw frame is too far from the linkage's own)."""
        return self.kappa > OWN_FRAME_GATE


def own_frame(mech: Mechanism) -> OwnFrame:
    """The :class:`OwnFrame` of ``mech`` at its start, once per mechanism."""

    def build() -> OwnFrame:
        centre, length = hinge_centre(mech.twists, mech.joint_types)
        cross = np.array(
            [[0.0, -centre[2], centre[1]], [centre[2], 0.0, -centre[0]], [-centre[1], centre[0], 0.0]]
        )
        frame_map = np.eye(6)
        frame_map[3:, :3] = cross
        frame_map[3:, 3:] *= length
        kappa = float(np.linalg.cond(frame_map))
        prismatic = np.array([t != "R" for t in mech.joint_types], dtype=bool)
        joint_scale = np.where(prismatic, 1.0 / length, 1.0)
        unknown_scale = joint_scale[list(mech.first_joints)] if mech.n_unknowns else np.zeros(0)
        for a in (centre, joint_scale, unknown_scale):
            a.flags.writeable = False
        return OwnFrame(centre, float(length), kappa if math.isfinite(kappa) else math.inf, joint_scale,
                        unknown_scale)  # fmt: skip

    return mech.derived("own frame", build)


def twin(mech: Mechanism) -> Mechanism:
    """``mech`` written in its own frame (moments about its hinge centre, lengths in its scale), once per
    mechanism: the twin's own frame is the identity and its length scale 1 (kept on it, so a trace of the twin
    neither goes through a twin again nor rescales its tolerances)."""

    def build() -> Mechanism:
        frame = own_frame(mech)
        c, length = frame.centre, frame.length
        w, v = mech.twists[:, :3], mech.twists[:, 3:]
        revolute = np.array([t == "R" for t in mech.joint_types], dtype=bool)
        moments = np.where(revolute[:, None], (v - np.cross(c, w)) / length, v)
        points = mech.hinge_points
        if len(points):
            points = (points - c) / length
        copy = replace(
            mech,
            twists=np.concatenate([w, moments], axis=1),
            offsets=mech.offsets * frame.joint_scale,
            hinge_points=points,
        )
        m = copy.n_unknowns
        copy.derived("length scale", lambda: 1.0)
        copy.derived(
            "own frame",
            lambda: OwnFrame(np.zeros(3), 1.0, 1.0, np.ones(copy.n_joints), np.ones(m)),
        )
        # its trace's arclengths in the user's units: a twin's length is 1 / unknown_scale of the user's
        weights = arclength_weights(mech) / frame.unknown_scale
        weights.flags.writeable = False
        copy.derived(ARCLENGTH_WEIGHTS, lambda: weights)
        return copy

    return mech.derived("own frame twin", build)


def arguments_in_own_frame(
    mech: Mechanism,
    until: tuple[str | int, float] | None,
    limits: Mapping[str, tuple[float, float]] | None,
    tol: Tolerances,
    closure_tol: float | None,
) -> tuple[tuple[str | int, float] | None, dict[str, tuple[float, float]] | None, Tolerances, float | None]:
    """A trace's ``until``, ``limits`` and tolerances for the twin of ``mech`` (checked on ``mech`` already):
    lengths divided by the linkage's own length, the start's closure checked already (so not again on the twin,
    whose start carries the raw start's residual in its own unit), and a stalled residual accepted at the
    round-off the file's coordinates carry (:data:`ROUNDOFF_CARRIED`)."""
    frame = own_frame(mech)
    scale = frame.joint_scale
    if until is not None:
        until = (until[0], float(until[1]) * float(scale[mech.index(until[0])]))
    if limits:
        limits = {
            name: (a * float(scale[mech.index(name)]), b * float(scale[mech.index(name)]))
            for name, (a, b) in limits.items()
        }
    else:
        limits = None
    play = tol.closure > tol.exact  # a length the user gave (play in the hinges): in the linkage's unit too
    closure = tol.closure / frame.length if play else tol.closure
    # The twin's geometry carries the file's round-off: coordinates |c| from the origin hold each number to
    # eps |c|, which is eps (|c| + L) / L of the linkage's size, and a residual stalling at a hundred times that
    # is closed (as `roundoff` accepts a hundred times the round-off of a loop of unit size).
    carried = np.finfo(float).eps * (float(np.linalg.norm(frame.centre)) + frame.length) / frame.length
    roundoff = max(tol.roundoff, ROUNDOFF_CARRIED * carried / max(closure, tol.exact))
    tol = replace(tol, start_slack=math.inf, closure=closure, roundoff=roundoff)
    if closure_tol is not None:
        closure_tol = closure_tol / frame.length
    return until, limits, tol, closure_tol


def trace_from_own_frame(mech: Mechanism, result: Trace, ws: Workspace, closure: float) -> Trace:
    """The user's :class:`Trace` of ``mech`` from the trace ``result`` of its twin: joint values back in the
    user's units, the singular values and residuals of ``mech``'s own Jacobian (``ws``: its workspace) at every
    row and point; ranks, steps, branches and points as the twin decided them.
    ``closure`` is the closure tolerance the trace used, in the user's unit. ``stats.unmet`` is the twin's line
    (its numbers in the twin's units when the target is a length): the tracer writes it again."""
    frame = own_frame(mech)
    joint_back = 1.0 / frame.joint_scale
    unknown_back = 1.0 / frame.unknown_scale
    angles = result.angles * joint_back
    U = mech.u_from_q(mech.q_from_angles(angles))
    sigma, residual = _raw_rows(ws, U, result.sigma.shape[1])
    # (the twin's arclengths are the user's already: its march measured them so, trace_result.arclength_weights)
    points = tuple(_point_back(mech, ws, b, joint_back, unknown_back) for b in result.bifurcations)
    folds = tuple(
        replace(f, value=f.value * float(joint_back[mech.index(result.drive)]), angles=f.angles * joint_back)
        for f in result.folds
    )
    branches = tuple(
        br
        if br.end_joint is None or br.end_value is None
        else replace(br, end_value=br.end_value * float(joint_back[mech.index(br.end_joint)]))
        for br in result.branches
    )
    misfit = max([float(np.max(residual, initial=0.0)), *(p.residual for p in points)])
    stats = replace(result.stats, closure_tol=closure, max_misfit=misfit)
    return replace(
        result, mechanism=mech, angles=angles, sigma=sigma, residual=residual,
        bifurcations=points, branches=branches, stats=stats, folds=folds,
    )  # fmt: skip


def _raw_rows(ws: Workspace, U: Array, k: int) -> tuple[Array, Array]:
    """The singular values ``(N, k)`` and closure residuals ``(N,)`` of the user's Jacobian at the unknowns
    ``U (N, m)``: each row's Jacobian evaluated once, their singular values in one batched SVD (a closed path's
    last row, at its first row's unknowns, gets the first row's values exactly)."""
    residual = np.empty(len(U))
    jacobians = np.empty((len(U), *ws.jac.shape))
    arrays, evaluate = ws.kernel_arrays(), ws.kernels.evaluate
    U = np.ascontiguousarray(U, dtype=float)
    for i in range(len(U)):  # the kernel writes each row's Jacobian in place
        residual[i] = evaluate(arrays, U[i], ws.q, ws.res, jacobians[i])
    sigma = np.linalg.svd(jacobians, compute_uv=False)[:, :k] if len(U) else np.zeros((0, k))
    return np.ascontiguousarray(sigma), residual


def _point_back(
    mech: Mechanism, ws: Workspace, point: Bifurcation, joint_back: Array, unknown_back: Array
) -> Bifurcation:
    """A located point of the twin in the user's units, with the user's singular values and residual there."""
    u = point.u * unknown_back
    r, _, jac = ws.evaluate(u)
    sigma = np.asarray(np.linalg.svd(jac, compute_uv=False)[: len(point.sigma)], dtype=np.float64)
    return replace(
        point, u=u, angles=point.angles * joint_back, sigma=sigma, residual=float(r),
        tangents=_directions(point.tangents, joint_back), tangents_u=_directions(point.tangents_u, unknown_back),
    )  # fmt: skip


def _directions(tangents: Array, back: Array) -> NDArray[np.float64]:
    """Unit tangents of the twin as unit tangents in the user's coordinates (lengths scaled back)."""
    if tangents.size == 0 or np.all(back == 1.0):
        return tangents.copy()
    t = tangents * back
    norms = np.linalg.norm(t, axis=-1, keepdims=True)
    return np.divide(t, norms, out=t.copy(), where=norms > 0.0)
