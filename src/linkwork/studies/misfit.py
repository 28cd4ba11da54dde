"""The closure misfit along a path: the least weighted closure residual over the other joints, drive held.

For an imperfect mechanism (perturbed twists) and the nominal path ``u_k`` (unknowns at point ``k``), the misfit
at ``k`` is ``min |T r(u)|`` over the unknowns ``u`` in the plane through ``u_k`` normal to the nominal path's
tangent: where the drive parameterises the path this is the drive held, to first order exactly (the Jacobian
annihilates the tangent, so every plane transverse to it gives the same least residual to first order), and unlike
holding the drive it stays well posed at a fold of the drive, where the path turns back; ``r`` is the stacked loop logarithm (closure residual, Eq. (23) in twist form) and ``T`` the weight
of :mod:`linkwork.studies.scale`, so the misfit is a length in the linkage's units. It is solved by Gauss-Newton
(normal equations, Cholesky, with backtracking), warm-started along the path from the previous drive value's
solution shifted by the nominal step. The compiled batch kernel runs many samples and all drive values in one call.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from linkwork.kinematics.kernels import exp_unit_twist, expand, log_rigid


@njit(cache=True)
def weighted_closure(
    twists: np.ndarray,
    q: np.ndarray,
    loop_joint: np.ndarray,
    loop_sign: np.ndarray,
    loop_ptr: np.ndarray,
    rows: np.ndarray,
    groups: np.ndarray,
    T: np.ndarray,
    residual: np.ndarray,
    jac: np.ndarray,
) -> None:
    """Weighted closure residual ``T log(P)`` (kept rows, per loop) and its Jacobian in the unknowns, in place.

    As :func:`linkwork.kinematics.kernels.closure_jacobian` (columns ``s Ad(g) xi``, Eq. (21)), with every
    6-vector mapped by ``T`` before the rows are kept.
    """
    scratch = np.empty((5, 3, 3))
    vectors = np.empty((5, 6))
    _weighted_closure(
        twists, q, loop_joint, loop_sign, loop_ptr, rows, groups, T, residual, jac, scratch, vectors
    )


@njit(cache=True)
def _weighted_closure(
    twists: np.ndarray,
    q: np.ndarray,
    loop_joint: np.ndarray,
    loop_sign: np.ndarray,
    loop_ptr: np.ndarray,
    rows: np.ndarray,
    groups: np.ndarray,
    T: np.ndarray,
    residual: np.ndarray,
    jac: np.ndarray,
    scratch: np.ndarray,
    vectors: np.ndarray,
) -> None:
    """:func:`weighted_closure` with its work arrays given (``scratch (5, 3, 3)``, ``vectors (5, 6)``)."""
    nrows = rows.shape[0]
    jac[:, :] = 0.0
    Rg = scratch[0]
    Re = scratch[1]
    Rn = scratch[2]
    pg = vectors[0, :3]
    pe = vectors[0, 3:]
    w = vectors[1, :3]
    v = vectors[1, 3:]
    col = vectors[2]
    lg = vectors[3]
    for k in range(loop_ptr.shape[0] - 1):
        for i in range(3):
            for c in range(3):
                Rg[i, c] = 1.0 if i == c else 0.0
            pg[i] = 0.0
        for idx in range(loop_ptr[k], loop_ptr[k + 1]):
            j = loop_joint[idx]
            s = float(loop_sign[idx])
            for i in range(3):
                w[i] = s * twists[j, i]
                v[i] = s * twists[j, 3 + i]
            g = groups[j]
            if g >= 0:
                for i in range(3):
                    col[i] = Rg[i, 0] * w[0] + Rg[i, 1] * w[1] + Rg[i, 2] * w[2]
                    col[3 + i] = Rg[i, 0] * v[0] + Rg[i, 1] * v[1] + Rg[i, 2] * v[2]
                col[3] += pg[1] * col[2] - pg[2] * col[1]
                col[4] += pg[2] * col[0] - pg[0] * col[2]
                col[5] += pg[0] * col[1] - pg[1] * col[0]
                for r in range(nrows):
                    acc = 0.0
                    for c in range(6):
                        acc += T[rows[r], c] * col[c]
                    jac[k * nrows + r, g] += acc
            exp_unit_twist(w, v, q[j], Re, pe)
            for i in range(3):
                for c in range(3):
                    Rn[i, c] = Rg[i, 0] * Re[0, c] + Rg[i, 1] * Re[1, c] + Rg[i, 2] * Re[2, c]
            for i in range(3):
                pg[i] += Rg[i, 0] * pe[0] + Rg[i, 1] * pe[1] + Rg[i, 2] * pe[2]
            for i in range(3):
                for c in range(3):
                    Rg[i, c] = Rn[i, c]
        log_rigid(Rg, pg, lg)
        for r in range(nrows):
            acc = 0.0
            for c in range(6):
                acc += T[rows[r], c] * lg[c]
            residual[k * nrows + r] = acc


@njit(cache=True)
def _solve_normal(Jy: np.ndarray, r: np.ndarray, dy: np.ndarray, A: np.ndarray, b: np.ndarray) -> None:
    """Gauss-Newton step ``dy``: ``(A + mu I) dy = -Jy^T r`` with ``A = Jy^T Jy`` by Cholesky (``A``, ``b`` are
    work arrays); ``mu`` a tiny regularisation that keeps singular points finite."""
    m = Jy.shape[1]
    for a in range(m):
        for c in range(a, m):
            acc = 0.0
            for e in range(Jy.shape[0]):
                acc += Jy[e, a] * Jy[e, c]
            A[a, c] = acc
            A[c, a] = acc
        acc = 0.0
        for e in range(Jy.shape[0]):
            acc += Jy[e, a] * r[e]
        b[a] = -acc
    top = 0.0
    for a in range(m):
        top = max(top, A[a, a])
    mu = 1e-14 * top + 1e-300
    for a in range(m):
        A[a, a] += mu
    # Cholesky A = L L^T in place (lower triangle), then two triangular solves.
    for a in range(m):
        for c in range(a + 1):
            acc = A[a, c]
            for k in range(c):
                acc -= A[a, k] * A[c, k]
            if a == c:
                A[a, a] = np.sqrt(acc) if acc > 0.0 else 1e-150
            else:
                A[a, c] = acc / A[c, c]
    for a in range(m):
        acc = b[a]
        for k in range(a):
            acc -= A[a, k] * dy[k]
        dy[a] = acc / A[a, a]
    for a in range(m - 1, -1, -1):
        acc = dy[a]
        for k in range(a + 1, m):
            acc -= A[k, a] * dy[k]
        dy[a] = acc / A[a, a]


@njit(cache=True)
def misfit_along_path(
    twists: np.ndarray,
    u_path: np.ndarray,
    normal: np.ndarray,
    loop_joint: np.ndarray,
    loop_sign: np.ndarray,
    loop_ptr: np.ndarray,
    rows: np.ndarray,
    groups: np.ndarray,
    T: np.ndarray,
    max_iter: int,
    out: np.ndarray,
) -> None:
    """Misfit ``out (K,)`` of one imperfect mechanism at every nominal path point ``u_path (K, m)``.

    At point ``k`` the unknowns move in the plane normal to the nominal path, ``u = u_k + Q_k y`` with
    ``normal[k] = Q_k (m, m - 1)`` orthonormal: the drive held wherever it parameterises the path, and still a
    well-posed problem at a fold of the drive.
    """
    K, m = u_path.shape
    p = normal.shape[2]
    E = (loop_ptr.shape[0] - 1) * rows.shape[0]
    q = np.empty(groups.shape[0])
    r = np.empty(E)
    J = np.empty((E, m))
    Jy = np.empty((E, p))
    dy = np.empty(p)
    scratch = np.empty((5, 3, 3))
    vectors = np.empty((5, 6))
    A = np.empty((p, p))
    b = np.empty(p)
    y = np.zeros(p)
    y_old = np.zeros(p)
    u = np.empty(m)
    for k in range(K):
        if k > 0:
            # Warm start: the previous point's offset from the path, carried into this point's normal plane.
            for c in range(p):
                acc = 0.0
                for a in range(m):
                    acc += normal[k, a, c] * (u[a] - u_path[k - 1, a])
                y[c] = acc
        best = np.inf
        halvings = 0
        for _ in range(max_iter):
            for a in range(m):
                acc = u_path[k, a]
                for c in range(p):
                    acc += normal[k, a, c] * y[c]
                u[a] = acc
            expand(u, groups, q)
            _weighted_closure(
                twists, q, loop_joint, loop_sign, loop_ptr, rows, groups, T, r, J, scratch, vectors
            )
            norm = np.sqrt(np.sum(r * r))
            if norm > best * (1.0 + 1e-10) and halvings < 30:
                # The step made things worse: go back half way (Gauss-Newton with backtracking).
                for c in range(p):
                    y[c] = 0.5 * (y[c] + y_old[c])
                halvings += 1
                continue
            converged = best - norm <= 1e-10 * norm
            best = norm
            halvings = 0
            for c in range(p):
                y_old[c] = y[c]
            if converged or norm == 0.0:
                break
            for e in range(E):
                for c in range(p):
                    acc = 0.0
                    for a in range(m):
                        acc += J[e, a] * normal[k, a, c]
                    Jy[e, c] = acc
            _solve_normal(Jy, r, dy, A, b)
            # The step lowers |r|^2 by |Jy dy|^2 to first order: when that is below 1e-8 |r|^2 the misfit is
            # known to 1e-8 relative already, and a further evaluation would not change it.
            gain = 0.0
            for e in range(E):
                acc = 0.0
                for c in range(p):
                    acc += Jy[e, c] * dy[c]
                gain += acc * acc
            if gain <= 1e-8 * norm * norm:
                break
            step = 0.0
            for c in range(p):
                y[c] += dy[c]
                step = max(step, abs(dy[c]))
            if step < 1e-15:
                break
        for a in range(m):
            acc = u_path[k, a]
            for c in range(p):
                acc += normal[k, a, c] * y_old[c]
            u[a] = acc
        out[k] = best


@njit(cache=True)
def misfit_batch(
    twists: np.ndarray,
    u_path: np.ndarray,
    normal: np.ndarray,
    loop_joint: np.ndarray,
    loop_sign: np.ndarray,
    loop_ptr: np.ndarray,
    rows: np.ndarray,
    groups: np.ndarray,
    T: np.ndarray,
    max_iter: int,
) -> np.ndarray:
    """``(S, K)`` misfits of ``S`` imperfect mechanisms ``twists (S, n, 6)`` along the nominal path."""
    S = twists.shape[0]
    out = np.empty((S, u_path.shape[0]))
    for s in range(S):
        misfit_along_path(
            twists[s], u_path, normal, loop_joint, loop_sign, loop_ptr, rows, groups, T, max_iter, out[s]
        )
    return out
