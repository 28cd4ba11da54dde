"""Tracing a mechanism's motion: the predictor-corrector of Secs. 4-6 of Gan & Pellegrino (2006), branch by branch.

:func:`trace` checks the request, starts the :class:`~linkwork.kinematics.marcher.BranchMarcher` on the start's
branch (and, with ``branches=True``, on the other direction and every branch queued at a bifurcation point) and
assembles the :class:`~linkwork.kinematics.trace_result.Trace`. Every branch ends with a reason: a target reached
(landing exactly on it), a closed path (revolute angles modulo a full turn), a joint limit (landed on), a fold of
the drive (paper mode), no progress, a step budget, a corrector failure, a known bifurcation point, or the entry
into a higher-dimensional component.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import replace
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from linkwork.errors import LinkworkError, RigidStartError, SpecError
from linkwork.interrupts import stop_text
from linkwork.kinematics import kernels
from linkwork.kinematics.bifurcation import branch_tangents
from linkwork.kinematics.classify import classify_point, component_dimension
from linkwork.kinematics.closure import hessian, reduce
from linkwork.kinematics.dyads import ClosedFormRows, closed_form_rows
from linkwork.kinematics.jit import Backend, select_backend
from linkwork.kinematics.marcher import FOLD_START, BranchMarcher, MarchSettings, leading_sign
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.own_frame import arguments_in_own_frame, own_frame, trace_from_own_frame, twin
from linkwork.kinematics.rank import DEFAULT, Tolerances, numerical_rank, numerical_ranks
from linkwork.kinematics.records import record
from linkwork.kinematics.stops import End, StopReason
from linkwork.kinematics.trace_arguments import check_trace_arguments, check_trace_subject
from linkwork.kinematics.trace_result import Branch, Trace, has_file_arclength
from linkwork.kinematics.trace_stats import TraceStats
from linkwork.kinematics.workspace import Workspace
from linkwork.progress import Progress

Array = NDArray[np.float64]

_MAX_TURN = np.radians(10.0)
"""The default ``max_turn`` of :func:`trace`, and its cosine (the settings' ``cos_turn``), computed once."""
_COS_MAX_TURN = float(np.cos(_MAX_TURN))
_TARGET_TEXT = StopReason.TARGET.text
"""The end reason of a branch that reached its target (read once: ``StopReason.text`` hashes the enum)."""


def trace(
    mech: Mechanism,
    drive: str | int | None = None,
    until: tuple[str | int, float] | None = None,
    steps: int | None = None,
    *,
    max_step: float = np.radians(2.0),
    min_step: float = 1e-9,
    max_turn: float = _MAX_TURN,
    max_steps: int = 5000,
    branches: bool = False,
    limits: Mapping[str, tuple[float, float]] | None = None,
    tol: Tolerances = DEFAULT,
    closure_tol: float | None = None,
    progress: Progress | None = None,
) -> Trace:
    """Trace the motion of ``mech`` from its start (reference) configuration.

    Parameters
    ----------
    mech
        The mechanism; its reference configuration is the start and must close.
    drive
        The joint that orients the path and counts the steps (default: the target's joint, else the first free
        joint).
    until
        ``(joint, value)``: stop exactly when that joint reaches ``value`` (radians, or length for a prismatic
        joint).
    steps
        Paper mode: ``steps`` equal steps of the drive from its start value to ``until`` (Sec. 5 uses 200);
        otherwise adaptive arclength steps no longer than ``max_step``.
    branches
        Locate bifurcations and trace every branch in both directions; without it bifurcations are still
        located and reported, and the path goes straight on through them.
    limits
        Joint limits ``{name: (low, high)}`` (joint values: radians, or lengths for a prismatic joint); a branch
        ends with the reason ``limit <name>`` when one is passed.
    closure_tol
        Accept a least-squares closure within this (``Tolerances.with_closure``; default ``tol.closure``); the
        largest misfit met is ``stats.max_misfit``.

    A target that is not reached (the path closes or folds back first, or ends for another reason) does not
    raise: ``stats.unmet`` then says why in one line (the command line exits with code 3 on it).
    """
    check_trace_subject(mech, branches, progress)
    check_trace_arguments(until, steps, max_step, min_step, max_turn, max_steps, limits, closure_tol)
    # Plain Python numbers from here on: a numpy int32 or float32 would make numba compile the kernels again.
    max_step, min_step, max_steps = float(max_step), float(min_step), int(max_steps)
    steps = None if steps is None else int(steps)
    if max_turn is not _MAX_TURN:
        max_turn = float(max_turn)
    m = mech.n_unknowns
    if m == 0:
        raise LinkworkError(f"{mech.name}: every joint is fixed; nothing can move")
    d_joint, d_unknown, target = _drive_and_target(mech, drive, until, steps)
    if steps is not None and steps > max_steps:  # the target is `steps` steps away: never within the budget
        raise SpecError(
            f"steps ({steps}, --steps) equal drive steps to until need more than the step budget max_steps "
            f"({max_steps}, --max-steps); expected steps <= max_steps"
        )
    # The kernels of the whole trace, chosen once (compiled or loaded before the clock starts, or plain Python).
    backend = select_backend(warm_up=warm_up)
    started = time.perf_counter()
    if own_frame(mech).used:  # far from its own frame: decided in it (see linkwork.kinematics.own_frame)
        return _trace_in_own_frame(
            mech, drive, until, steps, limits, tol, closure_tol, backend, started, max_step=max_step,
            min_step=min_step, max_turn=max_turn, max_steps=max_steps, branches=branches, progress=progress,
        )  # fmt: skip
    tol = tol if closure_tol is None else tol.with_closure(closure_tol)
    start = _path_start(
        mech, backend, tol
    )  # (its rank and tangent do not use the corrector's round-off levels)
    tol = _at_scale(mech, tol, backend)
    r_path = start.r_path
    sign = 1.0
    if target is not None:
        sign = 1.0 if target >= 0 else -1.0
    # A fresh array either way (the kept tangent is read-only and shared; the kernels get a writeable one).
    crossing = start.crossing
    if crossing is None:
        t_start = start.tangent * _start_direction(start.components, d_unknown, sign)
    else:  # branches cross at the start: branch 0 leaves along the one that moves the drive most
        pick = crossing[int(np.argmax(np.abs(crossing[:, d_unknown])))]
        t_start = pick * _start_direction(tuple(pick.tolist()), d_unknown, sign)
    lo, hi = _limits_in_unknowns(mech, limits) if limits else (start.lo, start.hi)
    cos_turn = _COS_MAX_TURN if max_turn is _MAX_TURN else float(np.cos(max_turn))
    settings = record(
        MarchSettings, drive=d_unknown, target=target, min_step=min_step, max_step=max_step, cos_turn=cos_turn,
        r_path=r_path, n_sigma=start.n_sigma, periodic=start.periodic, lo=lo, hi=hi, tol=tol, drive_joint=d_joint,
        weight=_step_weights(mech, backend),
    )  # fmt: skip
    paper = steps is not None
    basis0 = start.basis  # read-only (the start's, shared): the marches get copies
    if paper and steps is not None and steps <= max_steps:
        # A planar driver-and-dyads mechanism: the same rows in closed form, unless a singular point is near.
        rows = closed_form_rows(mech, backend, d_joint, settings, steps, t_start, basis0)
        if rows is not None:
            if progress is not None:
                progress(steps, max_steps)
            return _closed_form_trace(mech, d_joint, rows, steps, settings, started, until, backend)
    marcher = BranchMarcher(
        mech, settings, max_steps, switch_branches=branches, progress=progress, kernels=backend,
        workspace=Workspace.of(mech, backend),
    )  # fmt: skip
    h_start = (target / steps) if (paper and target is not None and steps) else max_step / 4.0
    if crossing is not None:
        return _trace_from_crossing(
            mech, d_joint, marcher, (t_start, basis0.copy()), branches, paper, until, started, h_start
        )
    # Paper mode keeps the sign: equal drive steps towards a target below the start value are negative.
    n0, end0 = marcher.run_branch(
        0, np.zeros(m), t_start, basis0.copy(), paper=paper, h0=h_start, stop_at_known=False
    )
    if _closed_away_from_target(mech, settings, paper, end0) and not marcher.stop_requested():
        # The first step moved the drive towards the target, but round the closed path it turned whole turns
        # away from it: going round the other way, the drive's values are those of this path less its turns, so
        # the target is on the path that way (one turn below the start of a crank turning up when it first moved
        # down). Traced again in the other direction, from scratch.
        marcher = BranchMarcher(
            mech, settings, max_steps, switch_branches=branches, progress=progress, kernels=backend,
            workspace=Workspace.of(mech, backend),
        )  # fmt: skip
        t_start = -t_start
        n0, end0 = marcher.run_branch(
            0, np.zeros(m), t_start, basis0.copy(), paper=paper, h0=h_start, stop_at_known=False
        )
    marcher.branches.append(Branch.ended(0, None, None, 1, n0, end0))
    if branches and target is None and end0.kind != StopReason.CLOSED and not marcher.stop_requested():
        # The start is in the middle of its branch: trace the other direction too.
        n1, end1 = marcher.run_branch(
            1, np.zeros(m), -t_start, basis0.copy(), paper=False, h0=max_step / 4.0, stop_at_known=True
        )
        marcher.branches.append(Branch.ended(1, None, None, -1, n1, end1))
    marcher.follow_queue()
    return _assemble(mech, d_joint, marcher, tol, started, paper, until)


def _trace_from_crossing(
    mech: Mechanism,
    d_joint: int,
    marcher: BranchMarcher,
    leave: tuple[Array, Array],
    branches: bool,
    paper: bool,
    until: tuple[str | int, float] | None,
    started: float,
    h_start: float,
) -> Trace:
    """A trace whose start is a crossing of one-parameter branches (a parallelogram four-bar laid flat, at its
    change point): the start is located as point 0 (classified there: a bifurcation, its other branch tangents
    queued with ``branches``); branch 0 leaves it along ``leave = (t_start, range basis)`` (in paper mode in equal drive steps, the
    march keeping the tangent it starts with at a singular row; otherwise as a queued branch leaves its point),
    with ``branches`` and no target branch 1 the other way (unless branch 0 came back round to the start), then
    the queue."""
    m, tol = mech.n_unknowns, marcher.cfg.tol
    t_start, basis = leave
    u0 = np.zeros(m)
    point = classify_point(mech, marcher.ws, 0, 0, 0, u0, 0.0, marcher.cfg)
    marcher.start_at_point(point, t_start)
    if paper:
        n0, end0 = marcher.run_branch(
            0, u0, t_start.copy(), basis, paper=True, h0=h_start, stop_at_known=False
        )
    else:
        left = marcher.leave_point(0, u0, t_start, point.id)
        if left is None:
            n0, end0 = 0, marcher.end(StopReason.NOT_LEFT, StopReason.NOT_LEFT.text, u0, None, point.id)
        else:
            n0, end0 = left
    marcher.branches.append(Branch.ended(0, None, None, 1, n0, end0))
    back = end0.kind == StopReason.CLOSED or end0.point == point.id  # round a closed path to the start
    if branches and marcher.cfg.target is None and not back and not marcher.stop_requested():
        left = marcher.leave_point(1, u0, -t_start, point.id)
        if left is None:
            n1, end1 = 0, marcher.end(StopReason.NOT_LEFT, StopReason.NOT_LEFT.text, u0, None, point.id)
        else:
            n1, end1 = left
        marcher.branches.append(Branch.ended(1, None, None, -1, n1, end1))
    marcher.follow_queue()
    return _assemble(mech, d_joint, marcher, tol, started, paper, until, start_rank=point.rank)


def _start_direction(components: tuple[float, ...], drive: int, sign: float) -> float:
    """+1 or -1: the way to leave the start along its unit null vector ``components``, so that the drive moves
    towards ``sign`` (its target's side).

    At a fold of the drive (its component below :data:`~linkwork.kinematics.marcher.FOLD_START`: a slider-crank's
    slider at a dead centre) the drive stays put to first order and moves the same way in both directions, so
    neither is towards the target; the one taken is then the one along which the first unknown that moves
    increases (:func:`~linkwork.kinematics.marcher.leading_sign`: the SVD's sign is round-off's)."""
    if abs(components[drive]) < FOLD_START:
        return float(leading_sign(np.array(components), drive, FOLD_START))
    return -1.0 if components[drive] * sign < 0 else 1.0


def _trace_in_own_frame(
    mech: Mechanism,
    drive: str | int | None,
    until: tuple[str | int, float] | None,
    steps: int | None,
    limits: Mapping[str, tuple[float, float]] | None,
    tol: Tolerances,
    closure_tol: float | None,
    backend: Backend,
    started: float,
    **options: Any,
) -> Trace:
    """:func:`trace` of ``mech`` through its twin in its own frame (:mod:`linkwork.kinematics.own_frame`): the
    arguments checked on ``mech`` (errors in the user's units), the start's closure too, then traced as the twin
    and reported back in the user's units with the user's singular values (``closure_tol``: the call's, in the user's unit)."""
    _limits_in_unknowns(mech, limits)  # refused in the user's units
    user_tol = tol if closure_tol is None else tol.with_closure(closure_tol)
    r0 = start_point(mech, backend)[0]
    if r0 > user_tol.start_slack * user_tol.closure:
        raise LinkworkError(f"{mech.name}: the start does not close (residual {r0:.3g}); assemble it first")
    until_own, limits_own, tol_own, closure_own = arguments_in_own_frame(
        mech, until, limits, tol, closure_tol
    )
    result = trace(
        twin(mech),
        drive,
        until_own,
        steps,
        limits=limits_own,
        tol=tol_own,
        closure_tol=closure_own,
        **options,
    )
    out = trace_from_own_frame(mech, result, Workspace.of(mech, backend), user_tol.closure)
    unmet = out.stats.unmet
    if until is not None and unmet is not None:  # the verdict's line again, in the user's units
        first = out.branches[0]
        end = End(first.end_kind or StopReason.BUDGET, first.end_reason, first.end_joint, first.end_value)
        on_branch = [out.angles[out.branch == 0], *[f.angles[None, :] for f in out.folds if f.branch == 0]]
        unmet = target_verdict(mech, until, end, np.concatenate(on_branch))
    return replace(out, stats=replace(out.stats, unmet=unmet, seconds=time.perf_counter() - started))


def start_point(mech: Mechanism, backend: Backend) -> tuple[float, Array, Array, Array]:
    """The closure residual at ``mech``'s start (its reference, ``u = 0``) and the SVD ``U, sigma, V^T`` of its
    Jacobian there, evaluated by ``backend``'s kernels: once per mechanism and backend (read-only arrays)."""

    def evaluate() -> tuple[float, Array, Array, Array]:
        r0, _, jac0 = Workspace.of(mech, backend).evaluate(np.zeros(mech.n_unknowns))
        U0, s0, Vt0 = np.linalg.svd(jac0)
        for a in (U0, s0, Vt0):
            a.flags.writeable = False
        return r0, U0, s0, Vt0

    return mech.derived(("trace start", backend.compiled), evaluate)


class PathStart(NamedTuple):
    """What every trace of one mechanism takes from its start, for one backend and tolerances (the start closes
    and its mobility is one): the path's rank ``r_path`` (the range basis's width), the number of singular values
    ``n_sigma``, the start's null vector ``tangent`` (``V^T[-1]``, not yet oriented; its ``components`` as Python
    floats, for the test that orients it), the range ``basis`` (the first ``r_path`` columns of ``U``,
    C-contiguous), which unknowns are ``periodic`` and the bounds ``lo, hi`` of a trace without limits (the arrays
    of :func:`_periodic` and :func:`_limits_in_unknowns`), all read-only: one look-up a call instead of five.
    ``crossing``: at a start where one-parameter branches cross, their tangents (the path's rank is theirs)."""

    r_path: int
    n_sigma: int
    tangent: Array
    components: tuple[float, ...]
    basis: Array
    periodic: NDArray[np.bool_]
    lo: Array
    hi: Array
    crossing: Array | None = None  # at a crossing start: the branches' tangents (rows), one of which is taken


def _path_start(mech: Mechanism, backend: Backend, tol: Tolerances) -> PathStart:
    """The :class:`PathStart` of ``mech``, checked (a start that does not close, is rigid or has a mobility above
    one raises, on every call: nothing is kept then), once per mechanism, backend and tolerances."""

    def build() -> PathStart:
        r0, U0, s0, Vt0 = start_point(mech, backend)
        if r0 > tol.start_slack * tol.closure:
            raise LinkworkError(
                f"{mech.name}: the start does not close (residual {r0:.3g}); assemble it first"
            )
        r_path, crossing = _path_rank(mech, s0, mech.n_unknowns, tol, backend)
        if crossing is not None:
            crossing.flags.writeable = False
        elif (
            tol.closure <= DEFAULT.closure
        ):  # (with play in the hinges a small obstruction is what play takes up)
            obstruction = _second_order_obstruction(mech, U0, Vt0, r_path)
            if obstruction > SHAKY:
                raise RigidStartError(
                    f"{mech.name}: the start is rigid to second order, a shaky structure (Jacobian rank {r_path}: "
                    f"mobility 1 to first order, but along that motion the loops open at second order, "
                    f"{obstruction:.2g} of the Hessian's scale): it cannot move from there",
                    order=2,
                )
        basis = np.ascontiguousarray(U0[:, :r_path])
        basis.flags.writeable = False
        lo, hi = _limits_in_unknowns(mech, None)
        tangent = Vt0[-1]  # read-only, as Vt0
        return PathStart(
            r_path, len(s0), tangent, tuple(tangent.tolist()), basis, _periodic(mech), lo, hi, crossing
        )

    # Keyed by the tolerances' value; the default ones (a module constant) by identity, saving the hash of
    # their twenty-odd fields on almost every call.
    key = ("path start", backend.compiled) if tol is DEFAULT else ("path start", backend.compiled, tol)
    return mech.derived(key, build)


def _length(mech: Mechanism, backend: Backend) -> float:
    """The linkage's own length ``L`` (:func:`~linkwork.kinematics.normalization.length_scale`, the RMS distance
    of its hinge lines from their centre), once per mechanism, evaluated by the trace's ``backend``."""

    def build() -> float:
        from linkwork.kinematics.normalization import length_scale

        return length_scale(mech, kernels=backend)

    return mech.derived("length scale", build)


def _at_scale(mech: Mechanism, tol: Tolerances, backend: Backend) -> Tolerances:
    """``tol`` with the corrector's round-off levels scaled to the linkage's own length ``L``: ``exact * L`` when
    ``L < 1``, ``roundoff * L`` when ``L > 1``.

    ``exact`` bounds the closure residual, whose translation part is a length: a loop a thousandth of the unit in
    size closed to ``1e-12`` is closed only to ``1e-9`` of its size (a crank-rocker of 4 mm written in metres
    was 1.2e-8 deg off the closed form, 8.4e-7 deg at 40 um). Scaled, the corrector goes on to the loop's own
    round-off; the rotation part (radians) is then held tighter than it needs, which costs at most an iteration.
    For a linkage larger than unity the residual's round-off floor grows as ``L``: a residual that stalls below
    ``roundoff * exact * L`` (not ``roundoff * exact``) is accepted, or a Bennett linkage of size 1e6 could not be
    traced (its floor is about 1e-10). ``closure`` (play in the hinges, a length the user gives) is not scaled
    (:meth:`~linkwork.kinematics.rank.Tolerances.at_length`, once per mechanism and tolerances)."""
    return mech.derived(
        ("tolerances at scale", tol), lambda: tol.at_length(_length(mech, backend))
    )  # once per mechanism and tolerances


def _step_weights(mech: Mechanism, backend: Backend) -> Array:
    """Each unknown's weight in the step control's metric, once per mechanism: 1 for an angle, ``1 / L`` for a
    length (a prismatic unknown), ``L`` the linkage's own length
    (:func:`~linkwork.kinematics.normalization.length_scale`, the RMS distance of its hinge lines from their
    centre: it scales with the linkage and does not move with it), so that the step sequence is the same in any
    length unit and wherever the linkage stands. Read-only."""

    def build() -> Array:
        weight = np.ones(mech.n_unknowns)
        prismatic = [k for k, j in enumerate(mech.first_joints) if mech.joint_types[j] != "R"]
        if prismatic:
            weight[prismatic] = 1.0 / _length(mech, backend)
        weight.flags.writeable = False
        return weight

    return mech.derived("step weights", build)


def _periodic(mech: Mechanism) -> NDArray[np.bool_]:
    """Which unknowns are revolute (compared modulo a turn), read-only, once per mechanism."""

    def build() -> NDArray[np.bool_]:
        periodic = np.array([mech.joint_types[j] == "R" for j in mech.first_joints], dtype=np.bool_)
        periodic.flags.writeable = False
        return periodic

    return mech.derived("periodic unknowns", build)


def _closed_away_from_target(mech: Mechanism, settings: MarchSettings, paper: bool, end: End) -> bool:
    """Whether an adaptive first branch closed without reaching its target, having turned its (revolute) drive by
    whole turns away from it: the target is then on the path the other way round (see :func:`trace`)."""
    target = settings.target
    if paper or target is None or end.kind != StopReason.CLOSED or end.value is None or end.joint is None:
        return False
    if not settings.periodic[settings.drive]:
        return False
    turned = end.value - float(mech.offsets[mech.index(end.joint)])  # the drive's unknown at the end
    return abs(turned) > np.pi and turned * target < 0.0


def _drive_and_target(
    mech: Mechanism, drive: str | int | None, until: tuple[str | int, float] | None, steps: int | None
) -> tuple[int, int, float | None]:
    """The drive joint, its unknown and the target in the unknowns (checked against each other and ``steps``)."""
    if until is not None and drive is None:
        drive = until[0]  # (then the target's joint is the drive: looked up once)
    if drive is None:
        drive = mech.joint_names[int(np.flatnonzero(mech.groups >= 0)[0])]
    d_joint, d_unknown, d_offset = _joint(mech, drive)
    if d_unknown < 0:
        raise SpecError(f"the drive joint {mech.joint_names[d_joint]} is fixed; choose a free joint")
    target = None
    if until is not None:
        t_joint, t_unknown, t_offset = (
            (d_joint, d_unknown, d_offset) if until[0] is drive else _joint(mech, until[0])
        )
        if t_joint != d_joint and t_unknown != d_unknown:
            raise SpecError(
                f"until names joint {mech.joint_names[t_joint]} but the drive is {mech.joint_names[d_joint]}; "
                "they must be the same joint (or coupled)"
            )
        target = float(until[1]) - t_offset
    if steps is not None and (target is None or steps < 1):
        raise SpecError("steps (the paper's equal drive steps) needs until=(joint, value) and steps >= 1")
    return d_joint, d_unknown, target


def _joint(mech: Mechanism, joint: str | int) -> tuple[int, int, np.float64]:
    """A joint's index, its unknown (``-1``: fixed) and its offset (the value at the reference, a numpy scalar):
    :meth:`Mechanism.index`, ``groups`` and ``offsets`` read once per mechanism and joint name (an unknown name
    raises on every call; a joint given by index is looked up afresh)."""

    def build() -> tuple[int, int, np.float64]:
        j = mech.index(joint)
        return j, int(mech.groups[j]), mech.offsets[j]

    return mech.derived(("joint", joint), build) if isinstance(joint, str) else build()


def _path_rank(
    mech: Mechanism, sigma: Array, m: int, tol: Tolerances, backend: Backend
) -> tuple[int, Array | None]:
    """The path's rank from the start (its singular values ``sigma``, by the ``backend``'s kernels: once per
    mechanism, backend and tolerances) and, where the start is a crossing of one-parameter branches (rank one
    below theirs, mobility 2 there, two or more real branch tangents), the branch tangents (rows, in the
    unknowns; the path's rank is then one above the start's); refuses a rigid start or one of mobility above one
    (saying so when the start is a singular point of one-parameter branches that cannot be traced from)."""
    r_path = mech.derived(("start rank", backend.compiled, tol), lambda: numerical_rank(sigma, tol))
    mobility = m - r_path
    if mobility == 0:
        raise RigidStartError(
            f"{mech.name}: the start is rigid (Jacobian rank {r_path} = number of unknowns, smallest singular "
            f"value {sigma[-1] / sigma[0]:.2e} of the largest); an over-constrained loop needs its exact geometry "
            "to move: give its parameters to full precision, or accept play in the hinges (closure_tol / "
            "--closure-tol)",
            order=1,
        )
    tangents = _start_lines(mech, backend, tol, m) if mobility > 1 else None
    lines = None if tangents is None else len(tangents)
    if lines is not None and lines >= 2 and mobility == 2:
        return r_path + 1, tangents  # a crossing of one-parameter branches: traced from it, along one of them
    if lines == 0:
        raise RigidStartError(
            f"{mech.name}: the start is rigid, an isolated configuration (Jacobian rank {r_path} here, {m} "
            "unknowns, but no direction along which the loop stays closed to second order): it cannot move "
            "from there",
            order=2,
        )
    if lines is not None and lines >= 2:
        raise LinkworkError(
            f"{mech.name}: the start is a singular point where {lines} one-parameter branches cross (Jacobian "
            f"rank {r_path} here, {r_path + 1} beside it; mobility one, not {mobility}); a trace starts on one "
            "branch: give a start a little away from it (one joint moved by a degree, e.g. --set theta=...) "
            "and the path is traced through this point, located as a bifurcation"
        )
    if mobility > 1:
        raise LinkworkError(
            f"{mech.name}: mobility {mobility} at the start (rank {r_path}, {m} unknowns); the tracer follows "
            "one-parameter paths: couple or fix joints (couple=..., fixed=... / --couple A=C=E)"
        )
    return r_path, None


SHAKY = 1e-6
"""A start whose second-order obstruction (:func:`_second_order_obstruction`) is above this is rigid: the
built-ins' (over-constrained loops that move) are below 1e-15, a shaky frame's (Guest's ``rect-frame`` with faces
``oiiooi``) 0.6."""


def _second_order_obstruction(mech: Mechanism, U0: Array, Vt0: Array, r_path: int) -> float:
    """How far a start of mobility one to first order is from moving at second order: ``max_l |l^T H(t, t)|``
    over the left null vectors ``l`` of the Jacobian (rows ``U0[:, r_path:]``) with ``t`` its null vector and
    ``H`` the closure's Hessian in the unknowns (:func:`~linkwork.kinematics.closure.hessian`, exact at a
    closed point), relative to ``H``'s largest entry; 0 where the Jacobian has full row rank (no condition).

    A curve ``u(s) = s t + s^2 w / 2 + ...`` through the start keeps the loops closed to second order only if
    ``J w + H(t, t) = 0``, which has a solution only if ``H(t, t)`` is in the range of ``J``: its part along
    the left null space is the obstruction (Connelly and Servatius, shaky frameworks; the second-order test of
    :func:`~linkwork.kinematics.bifurcation.branch_tangents` on one direction)."""
    if r_path >= U0.shape[0] or mech.n_unknowns - r_path != 1:
        return 0.0
    H = reduce(mech, hessian(mech, np.zeros(mech.n_joints)))
    scale = float(np.abs(H).max(initial=0.0))
    if scale == 0.0:
        return 0.0
    t = Vt0[-1]
    return float(np.abs(np.einsum("el,eab,a,b->l", U0[:, r_path:], H, t, t)).max()) / scale


def _start_lines(mech: Mechanism, backend: Backend, tol: Tolerances, m: int) -> Array | None:
    """At a start whose rank says mobility above one: ``None`` where the configuration space has dimension 2 or
    more there (a mobility the tracer cannot follow), else the one-parameter branches passing through it (its
    real branch tangents, rows in the unknowns: none for an isolated, rigid point; 2 or more where branches
    cross)."""
    ws = Workspace.of(mech, backend)
    u = np.zeros(m)
    if component_dimension(ws, u, tol) >= 2:
        return None
    return np.asarray(branch_tangents(mech, ws, u, tol)[0], dtype=float)


def _limits_in_unknowns(
    mech: Mechanism, limits: Mapping[str, tuple[float, float]] | None
) -> tuple[Array, Array]:
    """Joint limits ``{name: (low, high)}`` (joint values) as bounds on the unknowns (from the start), read-only
    (the same arrays for every trace without limits)."""
    if not limits:
        return mech.derived("no limits", lambda: _unbounded(mech.n_unknowns))
    lo, hi = _unbounded(mech.n_unknowns)
    lo.flags.writeable = hi.flags.writeable = True
    for name, (a, b) in limits.items():
        j = mech.index(name)
        if not a < b:
            raise SpecError(
                f"limit {mech.joint_names[j]}: the low end {a:g} must be below the high end {b:g}"
            )
        g = mech.groups[j]
        if g < 0:
            raise SpecError(f"limit {mech.joint_names[j]}: the joint is fixed")
        value = mech.offsets[j]
        if not a <= value <= b:
            raise SpecError(f"limit {mech.joint_names[j]}: the start value is outside [{a:g}, {b:g}]")
        lo[g], hi[g] = max(lo[g], a - value), min(hi[g], b - value)
    lo.flags.writeable = hi.flags.writeable = False
    return lo, hi


def _unbounded(m: int) -> tuple[Array, Array]:
    """Read-only bounds ``(-inf, inf)`` on ``m`` unknowns."""
    lo, hi = np.full(m, -np.inf), np.full(m, np.inf)
    lo.flags.writeable = hi.flags.writeable = False
    return lo, hi


def _assemble(
    mech: Mechanism,
    d_joint: int,
    marcher: BranchMarcher,
    tol: Tolerances,
    started: float,
    paper: bool,
    until: tuple[str | int, float] | None,
    start_rank: int | None = None,
) -> Trace:
    """The :class:`Trace` of everything the marcher collected, with each branch's mobility and the verdict on
    the target; ``start_rank`` the start's own rank where it is not the path's (a crossing start: lower)."""
    rows = marcher.rows
    U = np.concatenate(rows.u)
    sigma = np.concatenate(rows.sigma)
    # every row's rank, as the marcher computed it (the closed-form rows come without)
    compiled = marcher.ws.kernels.compiled
    if len(rows.rank) == len(rows.sigma):
        ranks = np.concatenate(rows.rank)
    else:
        ranks = numerical_ranks(sigma, tol, compiled)
    branch = np.concatenate(rows.branch)
    angles = _angles(mech, U, compiled)
    m = mech.n_unknowns
    branch_list = [
        replace(
            br,
            mobility=_branch_mobility(m - (ranks if len(marcher.branches) == 1 else ranks[branch == br.id])),
        )
        for br in marcher.branches
    ]
    unmet = None
    if until is not None:
        first = branch_list[0]
        end = End(first.end_kind or StopReason.BUDGET, first.end_reason, first.end_joint, first.end_value)
        if end.kind != StopReason.TARGET:  # reached: no verdict to write (target_verdict says None)
            on_branch = [angles[branch == 0], *[f.angles[None, :] for f in marcher.folds if f.branch == 0]]
            unmet = target_verdict(mech, until, end, np.concatenate(on_branch))
    residual = np.concatenate(rows.res)
    r_start = marcher.cfg.r_path if start_rank is None else start_rank
    s = np.concatenate(rows.s)  # the two arclengths (marcher.Chunk.s)
    stats = TraceStats(
        start_rank=r_start,
        start_mobility=m - r_start,
        mode="paper" if paper else "adaptive",
        closure_tol=tol.closure,
        max_misfit=float(max(marcher.max_misfit, float(np.max(residual)))),
        sign_changes_without_rank_drop=marcher.spurious,
        branches_not_retraced=marcher.retraced,
        has_target=until is not None,
        unmet=unmet,
        points=len(U),
        seconds=time.perf_counter() - started,
        stopped=stop_text(marcher.interrupted) if marcher.interrupted else None,
    )
    return Trace(
        mechanism=mech,
        drive=mech.joint_names[d_joint],
        angles=angles,
        sigma=sigma,
        residual=residual,
        branch=branch,
        step=np.concatenate(rows.step),
        arclength=np.ascontiguousarray(s[:, 0]),
        test=np.concatenate(rows.tau),
        rank=ranks,
        bifurcations=tuple(marcher.found),
        branches=tuple(branch_list),
        stats=stats,
        folds=tuple(marcher.folds),
        arclength_in_file_units=np.ascontiguousarray(s[:, 1]) if has_file_arclength(mech) else None,
    )


def _closed_form_trace(
    mech: Mechanism,
    d_joint: int,
    rows: ClosedFormRows,
    steps: int,
    settings: MarchSettings,
    started: float,
    until: tuple[str | int, float] | None,
    backend: Backend,
) -> Trace:
    """The :class:`Trace` of a paper-mode path the closed form gave: what :func:`_assemble` makes of one branch
    of ``steps`` steps ending on the target, with no point, fold or misfit besides its rows, built without a
    marcher and without copying the rows (the closed form's own arrays: its joint values and its verdict on the
    ranks come from the compiled solver's pass that stores the rows)."""
    tol = settings.tol
    sigma, residual = rows.sigma, rows.residual
    m = mech.n_unknowns
    count = len(sigma)
    if rows.full_rank:  # usual: the closed form keeps off singular points
        ranks = np.empty(count, dtype=np.int64)
        ranks.fill(sigma.shape[1])  # (np.full's Python wrapper costs half as much again)
        mobility = m - sigma.shape[1]  # _branch_mobility of a constant
    else:
        ranks = numerical_ranks(sigma, tol, backend.compiled)
        mobility = _branch_mobility(m - ranks)
    j = mech.first_joints[settings.drive]  # as BranchMarcher.end reports the drive at the last point
    # The three records are built by `record` (every field at once, Branch's and TraceStats' defaults written
    # out): the same instances as their constructors make, in under half the time.
    branch = record(
        Branch, id=0, parent=None, bifurcation=None, direction=1, steps=steps, end_reason=_TARGET_TEXT,
        mobility=mobility, end_kind=StopReason.TARGET, end_joint=mech.joint_names[j],
        end_value=float(rows.angles[-1, j]), end_point=None,
    )  # fmt: skip
    stats = record(
        TraceStats, start_rank=settings.r_path, start_mobility=m - settings.r_path, mode="paper",
        closure_tol=tol.closure, max_misfit=float(max(0.0, float(np.maximum.reduce(residual)))),
        sign_changes_without_rank_drop=0, branches_not_retraced=0, has_target=until is not None, unmet=None,
        points=count, seconds=time.perf_counter() - started, stopped=None,
    )  # fmt: skip
    return record(
        Trace, mechanism=mech, drive=mech.joint_names[d_joint], angles=rows.angles, sigma=sigma,
        residual=residual, branch=np.zeros(count, dtype=np.int64), step=np.arange(count, dtype=np.int64),
        arclength=rows.arclength, test=rows.test, rank=ranks, bifurcations=(), branches=(branch,), stats=stats,
        folds=(), arclength_in_file_units=rows.file_arclength,
    )  # fmt: skip


def _angles(mech: Mechanism, U: Array, compiled: bool = False) -> Array:
    """``(N, n)`` joint values of the unknowns ``U (N, m)``: ``angles_from_q(q_from_u(U))`` (``compiled``: by
    the compiled kernel, the same sums in one pass)."""
    groups = mech.groups
    if not mech.derived("every joint free", lambda: bool(groups.min() >= 0)):
        return mech.angles_from_q(mech.q_from_u(U))
    if not compiled:
        return U[:, groups] + mech.offsets  # q_from_u is a gather
    out = np.empty((len(U), mech.n_joints))
    kernels.joint_values(np.ascontiguousarray(U), groups, mech.offsets, out)
    return out


def _branch_mobility(mobility: NDArray[np.int64]) -> int:
    """The mobility that holds along a branch: the most frequent value over its points (ends excluded)."""
    inner = mobility[1:-1] if len(mobility) > 2 else mobility
    return int(np.argmax(np.bincount(inner)))  # the smallest of equally frequent values


def target_verdict(mech: Mechanism, until: tuple[str | int, float], end: End, angles: Array) -> str | None:
    """Why the target of ``until`` was not reached on the first branch (``end``: how it ended; ``angles``: its
    points and folds), in one line (``None`` when it was)."""
    if end.kind == StopReason.TARGET:
        return None
    j = mech.index(until[0])
    name = mech.joint_names[j]
    revolute = mech.joint_types[j] == "R"

    lo, hi = float(np.min(angles[:, j])), float(np.max(angles[:, j]))
    unit = np.degrees if revolute else float
    # Two decimals (six digits for a length), or as many more as it takes for the target not to read as an end of
    # the range it is outside (a target 1e-6 deg beyond a rocker's extreme: "never reaches 93.86 ... [-93.86, 93.86]").
    places = next(
        (
            k
            for k in range(2, 13)
            if all(
                f"{float(unit(v)):.{k}f}" != f"{float(unit(until[1])):.{k}f}"
                for v in (lo, hi)
                if v != until[1]
            )
        ),
        12,
    )

    def show(x: float) -> str:
        deg = float(np.degrees(x))
        if not revolute:
            return f"{x:.{max(6, places + 1)}g}"
        return f"{deg:.{places}f} deg" if abs(deg) < 1e6 else f"{deg:.6g} deg"

    span = (
        f"[{np.degrees(lo):.{places}f}, {np.degrees(hi):.{places}f}] deg"
        if revolute
        else f"[{show(lo)}, {show(hi)}]"
    )
    if end.kind in (StopReason.CLOSED, StopReason.TURNING):
        why = "" if end.kind == StopReason.CLOSED else f" (it turns back near {show(float(angles[-1, j]))})"
        return f"{name} never reaches {show(until[1])} on this path{why}: its range is {span}"
    budget, _, why = end.text.partition(": ")
    if end.kind == StopReason.BUDGET and budget == StopReason.BUDGET.text and why:  # foreseen at a closure
        return f"{name} cannot reach {show(until[1])} within the step budget (max_steps, --max-steps): {why}"
    return f"{name} did not reach {show(until[1])}: the path ended with '{end.text}' (range so far {span})"


WARM_UP_DH = (  # Bennett's linkage (twists 45 and 75 deg, a / sin(alpha) = 1) at theta_A = 60 deg
    (1.0471975511965974, 0.7853981633974483),
    (2.799865397326153, 1.3089969389957472),
    (-1.0471975511965974, 0.7853981633974483),
    (-2.799865397326153, 1.3089969389957472),
)
"""``(theta, alpha)`` of the warm-up's loop: the start angles of Bennett's closed form (as ``lw.load("bennett")``
builds it), link lengths ``sin(alpha)``."""


def warm_up() -> None:
    """Run every tracing kernel with the argument types a trace uses: adaptive traces of a Bennett linkage with a
    target (and its normalised condition ratio), without one and up to a joint limit, and a paper-mode trace."""
    import math

    from linkwork.kinematics.chains import from_dh

    params = [{"theta": t, "d": 0.0, "a": math.sin(al), "alpha": al} for t, al in WARM_UP_DH]
    mech, _ = from_dh("Bennett linkage", params, joint_names=("A", "B", "C", "D"))
    a, start = mech.joint_names[0], float(mech.offsets[0])
    trace(mech, until=(a, start + 0.3)).condition()  # the normalised ratio's Jacobian kernel too
    trace(mech, until=(a, start + 0.3), steps=4)
    trace(mech, max_steps=8, max_step=math.radians(5.0))
    trace(mech, max_steps=20, limits={a: (start - 1.0, start + 0.05)})  # a limit: the marcher's own correct()
    planar = _warm_up_four_bar()  # the closed-form dyad solver of planar paper-mode traces
    trace(planar, until=("A", float(planar.offsets[0]) + 0.3), steps=4)


def _warm_up_four_bar() -> Mechanism:
    """A planar four-bar (ground 2, crank 1, coupler 2.5, rocker 2; crank at 60 deg, open assembly) for
    :func:`warm_up`: the closed-form dyad solver runs on planar mechanisms only."""
    theta = np.radians(60.0)
    b, d = np.array([np.cos(theta), np.sin(theta)]), np.array([2.0, 0.0])
    gap = float(np.linalg.norm(d - b))
    e = (d - b) / gap
    along = (2.5**2 - 2.0**2 + gap**2) / (2.0 * gap)
    c = b + along * e + np.sqrt(2.5**2 - along**2) * np.array([-e[1], e[0]])
    th3, th4 = np.arctan2(c[1] - b[1], c[0] - b[0]), np.arctan2(c[1] - d[1], c[0] - d[0])
    z = (0.0, 0.0, 1.0)
    joints = [
        {"name": "A", "bodies": ("ground", "crank"), "point": (0.0, 0.0), "direction": z, "value": theta},
        {"name": "B", "bodies": ("crank", "coupler"), "point": b, "direction": z, "value": th3 - theta},
        {"name": "C", "bodies": ("coupler", "rocker"), "point": c, "direction": z, "value": th4 - th3},
        {"name": "D", "bodies": ("ground", "rocker"), "point": d, "direction": z, "value": th4},
    ]
    return Mechanism.from_joints("four-bar", joints, planar=True)
