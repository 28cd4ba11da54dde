"""Planar mechanisms as a driver and a sequence of dyads: the decomposition, and the closed-form paper-mode path.

A planar mechanism whose body graph decomposes into the drive joint (from a body taken as fixed) and dyads (Assur
groups of class II, RRR, RRP, PRR, PRP and RPR: two bodies and three joints, attached to bodies already placed)
has closed-form positions at every drive value, as pylinkage and textbooks solve four-bars and slider-cranks. For
such a mechanism traced in the paper's mode (equal steps of the drive to a target), :func:`closed_form_rows`
gives the rows the predictor-corrector would record (joint values, singular values of the Jacobian, residual, test
function, arclength) without iterating, keeping the start's assembly mode; it returns ``None`` wherever the
predictor-corrector has more to do (near a fold or a bifurcation, a joint limit, a closed path before the target,
a mechanism that is not of this kind), and the tracer then runs the predictor-corrector as before.
"""

from __future__ import annotations

import math
import types
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from linkwork.kinematics import dyad_solver
from linkwork.kinematics.dyad_solver import (
    CLEAN,
    N_SETTINGS,
    PRISMATIC,
    REVOLUTE,
    S_DET_BASIS,
    S_HMAX,
    S_LOOSE,
    S_MIN_DRIVE,
    S_MIN_MARGIN,
    S_MIN_RATIO,
    S_STEP,
    S_STEPS,
    S_TARGET,
)
from linkwork.kinematics.march import MAX_PARTS, PART_SLACK
from linkwork.kinematics.marcher import MarchSettings
from linkwork.kinematics.mechanism import PLANAR_ROWS, Mechanism
from linkwork.kinematics.trace_result import arclength_weights, has_file_arclength

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: How far from planar a twist may be (omega off the plane's normal, v off the plane) and still be solved here.
PLANAR_TOL = 1e-12
#: A dyad whose assembly mode at the start is this close to its limit (relative) is left to the tracer.
START_MARGIN = 1e-9
#: Smallest |drive component| of the unit tangent the closed form keeps: near a fold of the drive the
#: predictor-corrector's long predictor steps decide what happens, so the tracer takes over there.
MIN_DRIVE = 0.05
#: Smallest relative distance of a dyad from its limit (a double root) accepted at a point.
MIN_MARGIN = 1e-6


@dataclass(frozen=True)
class DyadPlan:
    """A planar mechanism as a driver and dyads, in the arrays the compiled solver reads.

    ``joint_int (n, 3)``: kind (:data:`~linkwork.kinematics.dyad_solver.REVOLUTE` or ``PRISMATIC``), before and
    after body; ``joint_geo (n, 3)``: a revolute joint's point and ``omega_z`` (+1 or -1), a prismatic joint's
    unit direction and 0; ``dyads (k, 7)``: ``j1, j2, j3, K1, B1, B2, K2`` (joint ``j1`` from placed body ``K1``
    to ``B1``, ``j2`` between ``B1`` and ``B2``, ``j3`` from ``B2`` to placed ``K2``) in solving order; ``modes
    (k,)`` the sign picking each dyad's assembly mode of the start; ``head``: the drive joint, the body it moves
    and the number of bodies; ``offsets (n,)`` every joint's value at the reference (the solver reports
    ``offsets + q``).
    """

    joint_int: IntArray
    joint_geo: Array
    dyads: IntArray
    modes: Array
    head: IntArray
    offsets: Array

    def arrays(self) -> tuple[IntArray, Array, IntArray, Array, IntArray, Array]:
        """The plan tuple of :func:`~linkwork.kinematics.dyad_solver.closed_form_path`."""
        return self.joint_int, self.joint_geo, self.dyads, self.modes, self.head, self.offsets


def joint_geometry(mech: Mechanism) -> tuple[IntArray, Array] | None:
    """``(kinds, geometry)`` of every joint of a mechanism whose twists lie in the plane (``None`` otherwise):
    a revolute joint's point ``(x, y)`` and ``omega_z``, a prismatic joint's direction ``(x, y)`` and 0."""
    kinds: list[int] = []
    geo: list[tuple[float, float, float]] = []
    for kind, (w0, w1, w2, v0, v1, v2) in zip(mech.joint_types, mech.twists.tolist(), strict=True):
        if abs(v2) > PLANAR_TOL or abs(w0) > PLANAR_TOL or abs(w1) > PLANAR_TOL:
            return None
        if kind == "R":
            if abs(abs(w2) - 1.0) > PLANAR_TOL:
                return None
            kinds.append(REVOLUTE)
            geo.append((-v1 / w2, v0 / w2, w2))  # v = p x omega for a hinge through p
        else:
            if abs(w2) > PLANAR_TOL or abs(math.hypot(v0, v1) - 1.0) > PLANAR_TOL:
                return None
            kinds.append(PRISMATIC)
            geo.append((v0, v1, 0.0))
    return np.array(kinds, dtype=np.int64), np.array(geo, dtype=float).reshape(len(geo), 3)


def dyad_plan(mech: Mechanism, drive: int) -> DyadPlan | None:
    """The decomposition of ``mech`` into the drive joint ``drive`` and dyads, or ``None`` when it has none.

    The drive joint's first body (the ground when it is one of its bodies) is held fixed; then, repeatedly, a
    joint between two bodies not yet placed, each joined by exactly one joint to placed bodies, forms a dyad. The
    mechanism qualifies when this places every body using every joint once, every joint is its own unknown,
    every twist lies in the plane and no dyad is at its limit at the start.
    """
    n = mech.n_joints
    if not mech.planar or tuple(mech.rows) != PLANAR_ROWS or len(mech.joint_bodies) != n:
        return None
    if sorted(mech.groups.tolist()) != list(range(n)):
        return None  # coupled or fixed joints: not a driver and dyads
    geometry = joint_geometry(mech)
    if geometry is None:
        return None
    kinds, geo = geometry
    names = list(mech.bodies) or sorted({b for pair in mech.joint_bodies for b in pair})
    index = {name: i for i, name in enumerate(names)}
    ends = [(index[a], index[b]) for a, b in mech.joint_bodies]
    fixed, driven = ends[drive]
    if names[driven] == mech.ground:
        fixed, driven = driven, fixed
    placed, used = {fixed, driven}, {drive}
    dyads: list[tuple[int, ...]] = []
    while len(placed) < len(names):
        dyad = _next_dyad(ends, placed, used)
        if dyad is None:
            return None
        dyads.append(dyad)
        placed |= {dyad[4], dyad[5]}
        used |= set(dyad[:3])
    if len(used) != n:
        return None  # a joint between placed bodies: over-constrained
    joint_int = np.array([[kinds[j], a, b] for j, (a, b) in enumerate(ends)], dtype=np.int64)
    modes = [_start_mode(kinds, geo, dyad) for dyad in dyads]
    if any(mode is None for mode in modes):
        return None
    return DyadPlan(
        joint_int=joint_int,
        joint_geo=geo,
        dyads=np.array(dyads, dtype=np.int64).reshape(len(dyads), 7),
        modes=np.array(modes, dtype=float),
        head=np.array([drive, driven, len(names)], dtype=np.int64),
        offsets=np.array(mech.offsets, dtype=float),
    )


def _frozen_plan(mech: Mechanism, drive: int) -> DyadPlan | None:
    """:func:`dyad_plan` with read-only arrays (kept on the mechanism by :func:`closed_form_rows`)."""
    plan = dyad_plan(mech, drive)
    if plan is not None:
        for a in plan.arrays():
            a.flags.writeable = False
    return plan


def _next_dyad(ends: Sequence[tuple[int, int]], placed: set[int], used: set[int]) -> tuple[int, ...] | None:
    """A dyad ``(j1, j2, j3, K1, B1, B2, K2)`` attached to ``placed`` bodies through unused joints, if any."""
    for j2, (b1, b2) in enumerate(ends):
        if j2 in used or b1 in placed or b2 in placed:
            continue
        between = [j for j, e in enumerate(ends) if j not in used and set(e) == {b1, b2}]
        side1 = [j for j, e in enumerate(ends) if j not in used and b1 in e and (set(e) - {b1}) <= placed]
        side3 = [j for j, e in enumerate(ends) if j not in used and b2 in e and (set(e) - {b2}) <= placed]
        if len(between) == 1 and len(side1) == 1 and len(side3) == 1:
            j1, j3 = side1[0], side3[0]
            k1 = ends[j1][0] if ends[j1][1] == b1 else ends[j1][1]
            k2 = ends[j3][0] if ends[j3][1] == b2 else ends[j3][1]
            return (j1, j2, j3, k1, b1, b2, k2)
    return None


def _start_mode(kinds: IntArray, geo: Array, dyad: tuple[int, ...]) -> float | None:
    """The sign that picks the start's assembly mode in :func:`~linkwork.kinematics.dyad_solver.place_dyad`
    (``None``: the dyad is at its limit at the start, or of a kind not solved in closed form)."""
    j1, j2, j3 = dyad[:3]
    k1, k2, k3 = kinds[j1], kinds[j2], kinds[j3]
    p1, p2, p3 = geo[j1, :2], geo[j2, :2], geo[j3, :2]
    if k2 == REVOLUTE and k1 == REVOLUTE and k3 == REVOLUTE:
        a, b = p3 - p1, p2 - p1
        value, size = float(a[0] * b[1] - a[1] * b[0]), float(np.linalg.norm(a) * np.linalg.norm(b))
    elif k2 == REVOLUTE and k1 == PRISMATIC and k3 == PRISMATIC:
        return 1.0
    elif k2 == REVOLUTE:
        jr, jp = (j1, j3) if k1 == REVOLUTE else (j3, j1)
        offset = p2 - geo[jr, :2]
        value, size = float(geo[jp, :2] @ offset), float(np.linalg.norm(offset))
    elif k1 == REVOLUTE and k3 == REVOLUTE:
        offset = p3 - p1
        value, size = float(geo[j2, :2] @ offset), float(np.linalg.norm(offset))
    else:
        return None
    if not abs(value) > START_MARGIN * size:
        return None
    return 1.0 if value > 0.0 else -1.0


def _basis_sign(mech: Mechanism, basis: Array) -> float:
    """The sign of ``det(basis)`` (which orients the test function), once per mechanism and basis: the tracer
    passes the start's basis, the same array on every trace of the mechanism (LAPACK's determinant of a 6 x 6
    matrix is a few microseconds, a tenth of the Python of a trace)."""
    return mech.derived(
        ("closed-form basis sign", basis.shape, basis.tobytes()),
        lambda: 1.0 if np.linalg.det(basis) >= 0.0 else -1.0,
    )


class ClosedFormRows(NamedTuple):
    """The rows of a paper-mode path that :func:`closed_form_rows` solved, one per point (row 0 the start): the
    compiled solver's own arrays, each C-contiguous and writeable, handed to the ``Trace`` without copies (a named
    tuple: built once a trace, in a third of a frozen dataclass's time).

    ``angles (N, n)`` the joint values (joint order, reference offsets included), ``sigma (N, k)`` the singular
    values (descending), ``residual``, ``test`` (the signed test function), ``arclength`` ``(N,)``;
    ``full_rank``: every row has its full rank ``k`` by the quick test of
    :func:`linkwork.kinematics.rank.all_full_rank` (False: the caller counts the ranks row by row);
    ``file_arclength`` ``(N,)`` the arclength in file units (``Trace.arclength_in_file_units``), where a row has
    parts; ``None`` where the rows' chords give it (no prismatic unknown, or every row one step).
    """

    angles: Array
    sigma: Array
    residual: Array
    test: Array
    arclength: Array
    full_rank: bool
    file_arclength: Array | None


def closed_form_rows(
    mech: Mechanism,
    kernels: object,
    drive: int,
    settings: MarchSettings,
    steps: int,
    t0: Array,
    basis: Array,
) -> ClosedFormRows | None:
    """The rows of a paper-mode trace (``steps`` equal steps of joint ``drive`` to ``settings.target``) in closed
    form, or ``None`` when the predictor-corrector must trace it (see the module's docstring).

    ``kernels`` is the tracer's kernel choice (the closed form is compiled only when the tracer's kernels are);
    ``t0`` the start's tangent and ``basis`` the start's range basis (its determinant orients the march's test
    function).
    """
    compiled = getattr(kernels, "compiled", isinstance(kernels, types.ModuleType))  # a backend, or the module
    if not compiled or settings.target is None or steps < 1:
        return None  # plain-Python kernels while numba's cache is cold: the tracer as before
    if settings.r_path != mech.n_equations or mech.n_unknowns != mech.n_equations + 1:
        return None
    arrays = mech.derived(("closed-form arrays", drive), lambda: _path_arrays(mech, drive))
    if arrays is None:
        return None
    tol = settings.tol
    # The settings that hold for every trace of the mechanism from this start with these tolerances are kept;
    # the call's own (its step, target, number of steps and longest step) are written into a copy.
    fixed = mech.derived(
        ("closed-form settings", basis.shape, basis.tobytes(), tol.local_min, tol.loose),
        lambda: _fixed_settings(mech, basis, tol.local_min, tol.loose),
    )
    # A step longer than max_step (the drive's part of it, in the step's metric) is solved at points no further
    # apart than that, as the march takes it in parts (march.march): the rows kept are every ``parts``-th, and a
    # gap of the path between two rows (where the drive turns back and comes round again) is met, not jumped.
    weight = 1.0 if settings.weight is None else float(settings.weight[settings.drive])
    parts = min(
        MAX_PARTS, max(1, math.ceil(abs(settings.target / steps) * weight / settings.max_step - PART_SLACK))
    )
    run = fixed.copy()
    run[S_STEP] = settings.target / (steps * parts)
    run[S_TARGET] = settings.target
    run[S_STEPS] = steps * parts
    run[S_HMAX] = settings.max_step
    periodic = np.ascontiguousarray(settings.periodic, dtype=np.bool_)
    _count, status, angles, sigma, res, tau, s, full_rank = dyad_solver.closed_form_path(
        arrays[0], arrays[1], (run, np.ascontiguousarray(t0, dtype=float), settings.lo, settings.hi, periodic)
    )
    if status != CLEAN:
        return None
    # The solver's arclength is the running sum of the chords between its points, no longer apart than a part
    # (the march's parts). With a slider, the same in file units (trace_result.arclength_weights) where a row
    # has parts, from every point before the rows are kept; rows without parts leave it to
    # io.results.file_arclength, whose chord ratios are then exact (each row's increment is its chord), so a
    # trace of many short rows (the planar benchmark's) does no more work. A twin in its own frame: both in its
    # user's units. Nothing for a linkage of hinges only.
    file_s = None
    if has_file_arclength(mech):
        weights = arclength_weights(mech)
        if np.any(weights[0] != 1.0):
            s = _chord_sums(angles, weights[0][mech.groups])
        if parts > 1:
            file_s = _chord_sums(angles, weights[1][mech.groups])
    if parts > 1:
        angles, sigma, res, tau, s = (np.ascontiguousarray(a[::parts]) for a in (angles, sigma, res, tau, s))
        file_s = None if file_s is None else np.ascontiguousarray(file_s[::parts])
    k = settings.n_sigma
    if k != sigma.shape[1]:  # (the path's rank is the number of equations: never taken)
        sigma, full_rank = np.ascontiguousarray(sigma[:, :k]), False
    # The kernel's test holds every row to rank k; numerical_rank agrees with a floor at or below loose.
    return ClosedFormRows(angles, sigma, res, tau, s, bool(full_rank) and tol.floor <= tol.loose, file_s)


def _chord_sums(angles: Array, weight: Array) -> Array:
    """``(N,)``: the running sum of the chords between consecutive rows of ``angles (N, n)`` with each joint's
    value weighted by ``weight (n,)`` (0 at row 0)."""
    step = angles[1:] - angles[:-1]
    step *= weight
    step *= step
    out = np.empty(len(angles))
    out[0] = 0.0
    np.sqrt(step.sum(axis=1), out=out[1:])
    np.cumsum(out[1:], out=out[1:])
    return out


def _fixed_settings(mech: Mechanism, basis: Array, local_min: float, loose: float) -> Array:
    """The settings vector of :func:`~linkwork.kinematics.dyad_solver.closed_form_path` with what does not change
    from one trace to the next written (the start's basis sign, the tolerances, :data:`MIN_DRIVE` and
    :data:`MIN_MARGIN`) and zeros in the call's own entries; read-only (:func:`closed_form_rows` copies it)."""
    values = [0.0] * N_SETTINGS
    values[S_DET_BASIS] = _basis_sign(mech, basis)
    values[S_MIN_RATIO] = local_min
    values[S_MIN_DRIVE] = MIN_DRIVE
    values[S_MIN_MARGIN] = MIN_MARGIN
    values[S_LOOSE] = loose
    fixed = np.array(values, dtype=float)
    fixed.flags.writeable = False
    return fixed


def _path_arrays(
    mech: Mechanism, drive: int
) -> tuple[tuple[NDArray[Any], ...], tuple[NDArray[Any], ...]] | None:
    """The mechanism and plan tuples of :func:`~linkwork.kinematics.dyad_solver.closed_form_path` for the drive
    joint ``drive`` (read-only arrays; ``None`` when ``mech`` is not a driver and dyads): kept on the mechanism
    by :func:`closed_form_rows`, which then builds only the settings and the start's tangent a call."""
    plan = mech.derived(("dyad plan", drive), lambda: _frozen_plan(mech, drive))
    if plan is None:
        return None
    twists, lj, ls, lp, _, groups = mech.kernel_arrays
    return (twists, lj, ls, lp, groups), plan.arrays()
