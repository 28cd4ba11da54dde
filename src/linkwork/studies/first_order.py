"""The first-order prediction of the misfit from the nominal Jacobian: one linear map per path point.

Moving hinge line ``j`` by a small rigid displacement ``d`` (a twist) turns its twist into ``Ad(exp d) xi_j``, so
its loop factor becomes ``D exp(s xi_j q_j) D^-1`` and the loop product changes by
``dP P^-1 = Ad(g_{j-1}) (I - Ad(exp(s xi_j q_j))) d`` (``g_{j-1}`` the product of the factors before it, as in
Eq. (21)). A tilt ``t`` about the unit vector ``e`` normal to the line through its point ``p`` is
``d = t (e, p x e)``; a shift ``s`` along ``e`` is ``d = s (0, e)``. Stacked over joints this is
``B_k`` (equations x 4n) at path point ``k``, and the weighted residual of the imperfect loop is, to first order,
``T (J_k dx + B_k delta)``. The least residual over the joint motions ``dx`` normal to the path (or with the drive
held: ``J_k`` annihilates the tangent, so both reach the same range) leaves the part of ``T B_k delta`` outside the
range of ``T J_k``: with ``N_k`` an orthonormal basis of the left null space of ``T J_k``, the predicted misfit is
``|N_k^T T B_k delta|``. The paper's Sec. 5 ratio measures how close
``J_k`` is to losing rank; ``N_k`` is exactly what the hinge errors project on.

References
----------
W. W. Gan, S. Pellegrino, Proc. IMechE Part C 220 (2006), Eq. (21).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from linkwork.geometry import adjoint, exp_se3
from linkwork.kernel_cache import kernel
from linkwork.kinematics.ground_frame import ground_frame_loops
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import numerical_rank
from linkwork.studies.imperfections import HingeLines

Array = NDArray[np.float64]


def hinge_derivative_twists(lines: HingeLines) -> Array:
    """``(n, 4, 6)`` the displacement twist ``d`` of a unit tilt about ``e1``, ``e2`` and a unit shift along
    ``e1``, ``e2`` of every hinge line."""
    n = lines.points.shape[0]
    d = np.zeros((n, 4, 6))
    for a, e in enumerate((lines.e1, lines.e2)):
        d[:, a, :3] = e
        moment = np.cross(lines.points, e)
        d[:, a, 3:] = np.where(lines.revolute[:, None], moment, 0.0)
        d[:, 2 + a, 3:] = np.where(lines.revolute[:, None], e, 0.0)
    return d


def linearised_closure(mech: Mechanism, q: Array, lines: HingeLines, T: Array) -> tuple[Array, Array]:
    """Weighted Jacobian ``T J`` ``(E, m)`` (unknowns) and hinge-error matrix ``T B`` ``(E, 4n)`` at ``q``, every
    loop taken from the ground (:func:`linkwork.kinematics.ground_frame.ground_frame_loops`: a joint on a loop's
    tree path adds to it twice, and its two terms cancel where the loops close)."""
    rows = list(mech.rows)
    r = len(rows)
    n = mech.n_joints
    dtw = hinge_derivative_twists(lines)
    J = np.zeros((mech.n_equations, n))
    B = np.zeros((mech.n_equations, n, 4))
    for k, loop in enumerate(ground_frame_loops(mech)):
        g = np.eye(4)
        for j, s in zip(loop.joints, loop.signs, strict=True):
            ad_g = adjoint(g)
            factor = exp_se3(s * mech.twists[j] * q[j])
            J[k * r : (k + 1) * r, j] += (T @ (s * ad_g @ mech.twists[j]))[rows]
            change = ad_g @ (np.eye(6) - adjoint(factor))
            B[k * r : (k + 1) * r, j, :] += (T @ change @ dtw[j].T)[rows]
            g = g @ factor
    return J @ mech.coupling_matrix(), B.reshape(mech.n_equations, 4 * n)


def sensitivity_maps(
    mech: Mechanism,
    u_path: Array,
    lines: HingeLines,
    T: Array,
    length: float = 1.0,
    cycles: Array | None = None,
) -> tuple[Array, Array]:
    """Per path point: the map ``G_k = N_k^T T_k B_k`` padded to ``(K, E, 4n)`` (zero rows beyond the left null
    space), and ``(K, m, m - 1)`` an orthonormal basis ``Q_k`` of the plane normal to the path's tangent (the last
    right singular vector), in which the misfit is minimised. ``T`` is one weight ``(6, 6)`` or one per point
    ``(K, 6, 6)`` (:func:`linkwork.studies.scale.weights_along`).

    "Normal" is measured with a slider's travel in the linkage's length ``length`` (the misfit's ``L``) and the
    angles in radians, so that the plane, and with it the misfit beyond first order, does not depend on the length
    unit the linkage is written in (the tangent itself does not; the plane normal to it in raw unknowns did, for a
    linkage with a prismatic joint). ``cycles`` combine the loops' rows as the misfit does
    (:func:`linkwork.studies.scale.loop_weights`; none: as they are)."""
    K = u_path.shape[0]
    E = mech.n_equations
    m = mech.n_unknowns
    G = np.zeros((K, E, 4 * mech.n_joints))
    normal = np.zeros((K, m, m - 1))
    metric = unknown_metric(mech, length)
    mix = np.eye(E) if cycles is None else np.kron(cycles, np.eye(len(mech.rows)))
    for k in range(K):
        J, B = linearised_closure(mech, mech.q_from_u(u_path[k]), lines, T[k] if T.ndim == 3 else T)
        J, B = mix @ J, mix @ B
        U, sigma, Vt = np.linalg.svd(J, full_matrices=True)
        rank = numerical_rank(sigma)
        if np.all(metric == 1.0):
            normal[k] = Vt[: m - 1].T
        else:
            # the plane {x : t . M x = 0} (M = metric^2, t the tangent) in an orthonormal basis of its own
            _, _, Wt = np.linalg.svd((metric**2 * Vt[m - 1])[None, :], full_matrices=True)
            normal[k] = Wt[1:].T
        N = U[:, rank:]
        G[k, : N.shape[1], :] = N.T @ B
    return G, normal


def unknown_metric(mech: Mechanism, length: float) -> Array:
    """``(m,)`` the size of one unit of each unknown in the linkage's own measure: 1 for an angle (radians),
    ``1 / length`` for a slider's travel (a length)."""
    metric = np.ones(mech.n_unknowns)
    for j, kind in enumerate(mech.joint_types):
        group = int(mech.groups[j])
        if kind == "P" and group >= 0:
            metric[group] = 1.0 / length
    return metric


@kernel(fastmath=True)
def _first_order_kernel(G: np.ndarray, rows: np.ndarray, delta: np.ndarray) -> np.ndarray:
    # fastmath lets the compiler vectorise the dot products; each sample still runs the same instructions
    # whatever its chunk, so its numbers do not depend on the chunking.
    S, P = delta.shape
    K = G.shape[0]
    out = np.empty((S, K))
    for s in range(S):
        d = delta[s]
        for k in range(K):
            total = 0.0
            for e in range(rows[k]):
                g = G[k, e]
                acc = 0.0
                for p in range(P):
                    acc += g[p] * d[p]
                total += acc * acc
            out[s, k] = np.sqrt(total)
    return out


def first_order_misfit(G: Array, errors: Array) -> Array:
    """``(S, K)`` predicted misfits ``|G_k delta_s|`` of hinge errors ``errors (S, n, 4)``.

    A compiled loop over the non-zero rows of each ``G_k`` (the left null space is small), each sample on its own,
    so that a sample's numbers never depend on how many others share its chunk.
    """
    S = errors.shape[0]
    P = G.shape[2]
    used = np.any(G != 0.0, axis=2)  # (K, E): the rows of each G_k inside its left null space
    rows = np.where(used.any(axis=1), used.shape[1] - np.argmax(used[:, ::-1], axis=1), 0).astype(np.int64)
    delta = np.ascontiguousarray(errors.reshape(S, P))
    return _first_order_kernel(np.ascontiguousarray(G), rows, delta)
