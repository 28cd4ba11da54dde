"""Loop closure, Jacobian and Hessian of a :class:`Mechanism`: the readable numpy reference.

For a loop with factors ``exp(s_1 xi_1 q_1) ... exp(s_k xi_k q_k)`` (product ``P``):

* the closure residual is the twist ``log(P)`` (zero exactly when the loop closes; to first order it is the
  paper's skew part of ``F`` and translation of Eq. (27));
* Jacobian column ``i`` is the joint twist carried to the base frame, ``s_i Ad(g_{i-1}) xi_i`` with ``g_{i-1}`` the
  product of the factors before it, so that ``dP P^-1 = sum_i J_i dq_i`` (Eq. (21) in twist form): O(k) per loop;
* the second derivative at a closed configuration is ``d2 log P / dq_j dq_i = [J_j, J_i] / 2`` for ``j`` before
  ``i`` in the loop, from the Lie bracket (Baker-Campbell-Hausdorff), exact and without finite differences.

The compiled kernels in :mod:`linkwork.kinematics.kernels` compute the same quantities; tests check they agree.

References
----------
W. W. Gan, S. Pellegrino, Proc. IMechE Part C 220 (2006), Eqs. (21), (27).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from linkwork.geometry import adjoint, bracket, exp_se3, log_se3
from linkwork.kinematics.mechanism import Array, Mechanism, spanning_tree


def loop_products(mech: Mechanism, q: ArrayLike) -> list[Array]:
    """The 4x4 product around every loop at joint displacements ``q``; identity when the loop closes."""
    q = np.asarray(q, dtype=float)
    out = []
    for loop in mech.loops:
        g = np.eye(4)
        for j, s in zip(loop.joints, loop.signs, strict=True):
            g = g @ exp_se3(s * mech.twists[j] * q[j])
        out.append(g)
    return out


def closure_residual(mech: Mechanism, q: ArrayLike) -> Array:
    """Stacked closure residual ``(n_equations,)``: the kept rows of ``log(P)`` for every loop."""
    rows = list(mech.rows)
    parts = [log_se3(P)[rows] for P in loop_products(mech, q)]
    return np.concatenate(parts) if parts else np.zeros(0)


def _loop_columns(mech: Mechanism, q: Array) -> list[tuple[list[int], Array]]:
    """Per loop: joint indices in loop order and their signed spatial twists ``(k, 6)`` at ``q``."""
    out = []
    for loop in mech.loops:
        g = np.eye(4)
        cols = []
        for j, s in zip(loop.joints, loop.signs, strict=True):
            cols.append(s * adjoint(g) @ mech.twists[j])
            g = g @ exp_se3(s * mech.twists[j] * q[j])
        out.append((list(loop.joints), np.array(cols)))
    return out


def jacobian(mech: Mechanism, q: ArrayLike) -> Array:
    """Closure Jacobian ``(n_equations, n_joints)``: ``dP P^-1 = J dq`` loop by loop (Eq. (21))."""
    q = np.asarray(q, dtype=float)
    rows = list(mech.rows)
    r = len(rows)
    J = np.zeros((mech.n_equations, mech.n_joints))
    for k, (joints, cols) in enumerate(_loop_columns(mech, q)):
        for j, col in zip(joints, cols, strict=True):
            J[k * r : (k + 1) * r, j] += col[rows]
    return J


def hessian(mech: Mechanism, q: ArrayLike) -> Array:
    """Second derivatives ``(n_equations, n_joints, n_joints)`` of the closure residual at a closed ``q``.

    ``H[:, j, i] = [J_j, J_i] / 2`` for joint ``j`` before joint ``i`` in a loop (Lie bracket), symmetric.
    Exact where the loops close; elsewhere it is the Hessian of ``P`` in the right-trivialised sense.
    """
    q = np.asarray(q, dtype=float)
    rows = list(mech.rows)
    r = len(rows)
    n = mech.n_joints
    H = np.zeros((mech.n_equations, n, n))
    for k, (joints, cols) in enumerate(_loop_columns(mech, q)):
        for a in range(len(joints)):
            for b in range(a + 1, len(joints)):
                half = 0.5 * bracket(cols[a], cols[b])[rows]
                H[k * r : (k + 1) * r, joints[a], joints[b]] += half
                H[k * r : (k + 1) * r, joints[b], joints[a]] += half
    return H


def reduce(mech: Mechanism, matrix: Array) -> Array:
    """Columns (and, for a Hessian, both joint axes) summed over each coupling group: derivatives in ``u``."""
    C = mech.coupling_matrix()
    if matrix.ndim == 2:
        return matrix @ C
    return np.einsum("eij,ia,jb->eab", matrix, C, C)


def body_poses(
    mech: Mechanism, *, q: ArrayLike | None = None, angles: ArrayLike | None = None
) -> dict[str, Array]:
    """Displacement of every body from the reference (4x4), along a spanning tree from the first body (the
    ground, when there is one).

    Give exactly one of ``angles``, the joint values users read (a row of ``Trace.angles``, ``offsets + q``), or
    ``q``, the displacements from the reference. Both are keyword-only: a bare array would leave it to the
    caller to remember the reference offsets, and forgetting them is silently wrong.
    """
    if (q is None) == (angles is None):
        raise TypeError("body_poses takes exactly one of angles= (joint values) or q= (displacements)")
    q = np.asarray(q, dtype=float) if angles is None else mech.q_from_angles(angles)
    if not mech.bodies:
        return {}
    root, edges = body_tree(mech)
    poses = {root: np.eye(4)}
    for body, j, other, s in edges:
        poses[other] = poses[body] @ exp_se3(s * mech.twists[j] * q[j])
    return poses


def body_tree(mech: Mechanism) -> tuple[str, list[tuple[str, int, str, int]]]:
    """The spanning tree along which body poses are chained: its root (:attr:`Mechanism.ground`) and its edges ``(body, joint, other, sign)`` in breadth-first order, ``other`` reached from
    ``body`` through ``joint`` (``sign`` -1 when the joint is walked from its second body to its first)."""
    root = mech.ground
    if root is None:
        raise ValueError(f"{mech.name}: no bodies, so no body tree (a loop given by its twists alone)")
    return root, spanning_tree(mech.joint_bodies, root)


def spatial_twists(mech: Mechanism, q: ArrayLike, poses: dict[str, Array] | None = None) -> Array:
    """Joint twists ``(n, 6)`` in the base frame at displacement ``q`` (each carried by its body's pose)."""
    poses = body_poses(mech, q=q) if poses is None else poses
    return np.array(
        [adjoint(poses[a]) @ mech.twists[j] for j, (a, _b) in enumerate(mech.joint_bodies)]
    ).reshape(mech.n_joints, 6)
