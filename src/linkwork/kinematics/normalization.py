"""A closure Jacobian normalised by the linkage itself, so that its condition ratio means something.

The paper's robustness criterion (Gan & Pellegrino 2006, Sec. 5) is the ratio of the largest to the smallest
non-zero singular value of the closure Jacobian along the path. On the raw Jacobian (joint twists ``(omega, v)``
with moments ``v`` about the base frame's origin, in the file's length unit) that ratio changes when the linkage
is moved away from the origin, turned, or drawn in another unit. Here the Jacobian is rewritten so that it does
not:

* **Moments about the linkage's own centre** ``c``: the point nearest to all revolute hinge lines in the least-
  squares sense, ``c = argmin sum_i d(c, line_i)^2`` (solve ``sum_i (I - w_i w_i^T) (c - p_i) = 0`` with ``p_i``
  any point of line ``i``; minimum-norm when the lines are all parallel, where the moments do not depend on the
  free coordinate of ``c``). ``c`` depends only on the lines, not on the points written for them.
* **Lengths in the linkage's own scale** ``L``: the RMS distance from ``c`` to the revolute hinge lines (1 when
  they all pass through ``c``, as in a spherical linkage, where every moment about ``c`` vanishes).
* Translation rows divided by ``L``, and a prismatic joint's coordinate measured in ``L`` (its column stays the
  unit direction ``(0, d)``): the normalised Jacobian is dimensionless.
* **Loop rows orthonormal over the cycle space** (:func:`cycle_metric`): a mechanism of several loops gives the
  same singular values whichever cycle basis its body graph (and so the order of its joints) produced.

Every loop is measured in one frame, the ground's (:mod:`linkwork.kinematics.ground_frame`): a loop that does not
pass through the ground body is taken from the ground, so its columns are its joints' axes where they are, not
where the motion of the loop's own first body has carried them back to. ``c`` and ``L`` are taken from the hinge
lines at the configuration itself (the joint axes in the ground's frame there), so that holding another body as
the ground (relabelling the joints of a loop, or naming another body of a multi-loop mechanism ``ground``) also
leaves the ratio unchanged: the frames of two grounds differ by the rigid motion between those bodies, the same for
every loop, and the cycle bases by a unimodular ``M`` (above). Under a rigid motion ``g = [R, t]`` every column
becomes ``Ad(g) xi``, ``c`` becomes ``g c`` and ``L`` is kept, so the normalised columns become ``(R w, R v_c /
L)``: an orthogonal map of the rows, and the singular values are unchanged. Scaling every length by ``s`` scales
``v_c`` and ``L`` alike. Relabelling permutes columns (and may change the cycle basis, see above). Tests:
``tests/studies/test_every_body_as_ground.py`` (random Watt and Stephenson six-bars, planar and spherical, and
Goldberg's two Bennett loops, with every body as the ground).

The trace's own rows (``Trace.sigma``, path.csv) are the singular values of the loops as the tracer takes them,
each from its own first body; only the normalised ratio reads them in the ground's frame.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from linkwork.kinematics.ground_frame import ground_frame_closure, joint_axes
from linkwork.kinematics.jit import Backend, select_backend
from linkwork.kinematics.mechanism import Array, Mechanism
from linkwork.kinematics.rank import DEFAULT, Tolerances, numerical_rank


def hinge_centres(axes: ArrayLike, joint_types: Sequence[str]) -> tuple[Array, Array]:
    """Centres ``c (N, 3)`` and length scales ``L (N,)`` of the revolute hinge lines of ``axes (N, n, 6)``.

    ``axes`` are unit twists ``(w, v)`` with ``v = p x w``. Rows that are all zero (joints in no loop) and
    prismatic joints are left out. Without any revolute line the centre is the origin and the scale 1.
    """
    axes = np.asarray(axes, dtype=float)
    revolute = np.array([t == "R" for t in joint_types])
    w, v = axes[..., :3], axes[..., 3:]
    ww = np.sum(w * w, axis=-1)
    use = revolute[None, :] & (ww > 1e-24)
    scale = np.where(use, 1.0 / np.sqrt(np.where(use, ww, 1.0)), 0.0)
    w = w * scale[..., None]
    p = np.cross(w, v * scale[..., None])  # the point of each line nearest the origin
    P = np.eye(3) - w[..., :, None] * w[..., None, :]  # (N, n, 3, 3) projector across each line
    P = P * use[..., None, None]
    A = P.sum(axis=1)
    b = np.einsum("knij,knj->ki", P, p)
    c = np.einsum("kij,kj->ki", np.linalg.pinv(A, rcond=1e-9), b)
    d = np.einsum("knij,knj->kni", P, c[:, None, :] - p)
    count = np.maximum(use.sum(axis=1), 1)
    L = np.sqrt(np.sum(d * d, axis=(1, 2)) / count)
    spread = 1.0 + np.max(np.abs(p), axis=(1, 2), initial=0.0)
    L = np.where((L > 1e-12 * spread) & (use.sum(axis=1) > 0), L, 1.0)
    return c, L


def hinge_centre(axes: ArrayLike, joint_types: Sequence[str]) -> tuple[Array, float]:
    """Centre ``c (3,)`` and length scale ``L`` of the revolute hinge lines among ``axes (n, 6)``."""
    c, L = hinge_centres(np.asarray(axes, dtype=float)[None], joint_types)
    return c[0], float(L[0])


def _full_jacobians(mech: Mechanism, q: Array, kernels: Backend | None = None) -> Array:
    """Unreduced closure Jacobians ``(N, 6 * loops, n)`` at displacements ``q (N, n)``, every loop in the ground's
    frame (:func:`linkwork.kinematics.ground_frame.ground_frame_closure`), by ``kernels`` (default: chosen now;
    a trace passes the backend it chose for the whole call)."""
    return ground_frame_closure(mech, q, kernels)[1]


def _tracer_jacobian(mech: Mechanism, q: Array) -> Array:
    """The unreduced closure Jacobian ``(6 * loops, n)`` at displacements ``q (n,)`` of the loops as the tracer
    takes them (each from its own first body: :attr:`Mechanism.kernel_arrays`), all six rows."""
    joints, signs, ptr = mech.loop_arrays()
    n = mech.n_joints
    jac = np.zeros((6 * len(mech.loops), n))
    rows, groups = np.arange(6, dtype=np.int64), np.arange(n, dtype=np.int64)
    mechanism = (np.ascontiguousarray(mech.twists), joints, signs, ptr, rows, groups)
    select_backend().closure_jacobian(
        mechanism, np.ascontiguousarray(q, dtype=float), n, np.zeros(len(jac)), jac
    )
    return jac


def cycle_metric(mech: Mechanism) -> Array:
    """``W = (Z Z^T)^(-1/2)`` for the signed loop-joint incidence ``Z (loops, n)``: loop rows made orthonormal.

    Another cycle basis is ``Z' = M Z`` with ``M`` unimodular, and its Jacobian rows are combined by ``M``;
    ``W' M = Q W`` with ``Q`` orthogonal, so the rows ``W J`` have the same singular values whichever basis the
    body graph gave. For a single loop of ``n`` joints ``W = 1 / sqrt(n)``.
    """
    Z = np.zeros((len(mech.loops), mech.n_joints))
    for k, loop in enumerate(mech.loops):
        for j, sign in zip(loop.joints, loop.signs, strict=True):
            Z[k, j] += sign
    values, vectors = np.linalg.eigh(Z @ Z.T)
    return (vectors / np.sqrt(np.maximum(values, 1e-300))) @ vectors.T


def normalized_jacobians(mech: Mechanism, angles: ArrayLike) -> Array:
    """:func:`normalized_jacobian` at every row of ``angles (N, n)``: ``(N, n_equations, n_unknowns)``."""
    values = np.atleast_2d(np.asarray(angles, dtype=float))
    jac = _full_jacobians(mech, values - mech.offsets)
    n_loops = len(mech.loops)
    c, L = hinge_centres(joint_axes(mech, jac), mech.joint_types)
    N, _, n = jac.shape
    blocks = jac.reshape(N, n_loops, 6, n)
    w, v = blocks[:, :, :3, :], blocks[:, :, 3:, :]
    moments = (v - np.cross(c[:, None, :, None], w, axis=2)) / L[:, None, None, None]
    blocks = np.concatenate([w, moments], axis=2)
    prismatic = np.array([t == "P" for t in mech.joint_types])
    blocks[..., prismatic] *= L[:, None, None, None]
    blocks = np.einsum("kl,Nlrn->Nkrn", cycle_metric(mech), blocks)
    kept = blocks[:, :, list(mech.rows), :].reshape(N, n_loops * len(mech.rows), n)
    return kept @ mech.coupling_matrix()


def normalized_jacobian(mech: Mechanism, angles: ArrayLike) -> Array:
    """The reduced closure Jacobian ``(n_equations, n_unknowns)`` at joint values ``angles`` (radians), normalised,
    every loop in the ground's frame (:mod:`linkwork.kinematics.ground_frame`).

    Moments about :func:`hinge_centre` of the joint axes there, lengths in its scale ``L``; the rows kept and the
    coupling reduction are those of the raw Jacobian (:func:`linkwork.kinematics.closure.jacobian`).
    """
    return normalized_jacobians(mech, np.asarray(angles, dtype=float)[None])[0]


def hinge_centres_along(mech: Mechanism, angles: ArrayLike) -> tuple[Array, Array]:
    """Centre ``c (N, 3)`` and length scale ``L (N,)`` of the revolute hinge lines at every row of joint values
    ``angles (N, n)`` (:func:`hinge_centres` of the joint axes in the ground's frame there,
    :func:`linkwork.kinematics.ground_frame.joint_axes`): the same physical point whichever body is the ground,
    since the axes there are carried by the poses of their bodies."""
    values = np.atleast_2d(np.asarray(angles, dtype=float))
    jac = _full_jacobians(mech, values - mech.offsets)
    return hinge_centres(joint_axes(mech, jac), mech.joint_types)


def length_scale(mech: Mechanism, angles: ArrayLike | None = None, kernels: Backend | None = None) -> float:
    """The linkage's own length ``L`` (RMS distance of the revolute hinge lines from their centre) at ``angles``.

    ``angles`` default to the reference configuration (``mech.offsets``); ``kernels`` the backend to evaluate with
    (default: chosen now).
    """
    values = mech.offsets if angles is None else np.asarray(angles, dtype=float)
    jac = _full_jacobians(mech, np.atleast_2d(values - mech.offsets), kernels)
    return float(hinge_centres(joint_axes(mech, jac), mech.joint_types)[1][0])


def robustness_ratio(sigma: ArrayLike, rank: int) -> float:
    """Largest over smallest non-zero singular value (Sec. 5): ``sigma[0] / sigma[rank - 1]``; NaN for rank 0."""
    s = np.asarray(sigma, dtype=float)
    if rank <= 0 or s[rank - 1] <= 0.0:
        return float("nan")
    return float(s[0] / s[rank - 1])


def condition_ratios(mech: Mechanism, angles: ArrayLike, rank: ArrayLike, chunk: int = 2048) -> Array:
    """``(N,)`` normalised robustness ratio at every row of ``angles (N, n)``, with the numerical ``rank (N,)``."""
    values = np.atleast_2d(np.asarray(angles, dtype=float))
    ranks = np.asarray(rank, dtype=np.int64).reshape(len(values))
    out = np.full(len(values), np.nan)
    for start in range(0, len(values), chunk):
        part = slice(start, start + chunk)
        sigma = np.linalg.svd(normalized_jacobians(mech, values[part]), compute_uv=False)
        out[part] = [robustness_ratio(s, int(r)) for s, r in zip(sigma, ranks[part], strict=True)]
    return out


NEAR_MOBILE = 1e-3
"""A rigid start whose smallest normalised singular value is below this fraction of the largest is near-mobile."""


@dataclass(frozen=True)
class NearMobility:
    """A start that is rigid only by a hair: the loops would move if the smallest singular value were zero.

    ``relative`` is that singular value over the largest (normalised Jacobian); ``misfit`` the closure residual
    (2-norm of the stacked loop logarithms, as the tracer measures it) that the near-motion leaves, to first
    order, when its most-moving joint turns by one radian; ``joints`` the joints that move in it.
    """

    relative: float
    misfit: float
    joints: tuple[str, ...]


def near_mobility(
    mech: Mechanism, angles: ArrayLike | None = None, tol: Tolerances = DEFAULT
) -> NearMobility | None:
    """Diagnose link geometry that is almost, but not, mobile (an over-constrained loop typed with rounded lines).

    At ``angles`` (default: the reference configuration) the numerical rank of the normalised Jacobian leaves
    no motion, yet its smallest singular value is below ``NEAR_MOBILE`` times the largest: the hinge lines are a
    rounding away from a mobile linkage (a generic rigid loop has a ratio of order 0.1). ``None`` when the start
    is mobile or clearly rigid.
    """
    values = mech.offsets if angles is None else np.asarray(angles, dtype=float)
    J = normalized_jacobian(mech, values)
    m = J.shape[1]
    if m == 0 or J.shape[0] < m:
        return None
    _, s, Vt = np.linalg.svd(J)
    if s[0] <= 0.0 or numerical_rank(s, tol) < m or s[m - 1] >= NEAR_MOBILE * s[0]:
        return None
    C = mech.coupling_matrix()
    motion = C @ Vt[m - 1] / np.max(np.abs(C @ Vt[m - 1]))  # the near-motion, largest joint moving 1 rad
    joints = tuple(name for name, x in zip(mech.joint_names, motion, strict=True) if abs(x) > 0.1)
    jac = _tracer_jacobian(mech, values - mech.offsets)
    raw = jac.reshape(len(mech.loops), 6, -1)[:, list(mech.rows), :].reshape(-1, mech.n_joints)
    return NearMobility(float(s[m - 1] / s[0]), float(np.linalg.norm(raw @ motion)), joints)
