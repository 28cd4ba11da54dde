"""Compiled (numba) kernels of the tracing hot loop: closure residual and Jacobian in O(n) per loop, and the
Cholesky solve of the correctors' normal equations.

The closure kernels do, one joint at a time and without temporaries, what :mod:`linkwork.kinematics.closure`
does with numpy; tests check that both agree. A mechanism is passed as one tuple ``mech = (twists, loop_joint,
loop_sign, loop_ptr, rows, groups)`` laid out as in :class:`linkwork.kinematics.mechanism.Mechanism`: ``twists
(n, 6)`` as ``(omega, v)``; loops flattened into ``loop_joint``, ``loop_sign`` and ``loop_ptr``; ``rows`` are the
twist rows kept per loop; ``groups (n,)`` maps each joint to its unknown (``-1`` = fixed).

References
----------
W. W. Gan, S. Pellegrino, Proc. IMechE Part C 220 (2006), Eqs. (21), (23).
"""

from __future__ import annotations

import numpy as np

from linkwork.kernel_cache import kernel


@kernel(inline="always")
def log_coefficient(t: float) -> float:
    """``D(t) = (1 - A / (2 B)) / t^2`` with ``A = sin t / t``, ``B = (1 - cos t) / t^2``: the coefficient of
    ``K^2`` in ``V^-1 = I - K/2 + D K^2``, the inverse of the translation part of a rotation by ``t >= 0`` (the
    logarithm of a rigid motion); its Taylor series where the closed form cancels (truncation < 1e-20)."""
    if t < 1e-2:
        t2 = t * t
        return 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0 + t2 * t2 * t2 / 1209600.0
    A = np.sin(t) / t
    B = (1.0 - np.cos(t)) / (t * t)
    return (1.0 - A / (2.0 * B)) / (t * t)


@kernel(inline="always")
def exp_unit_twist(w: np.ndarray, v: np.ndarray, theta: float, R: np.ndarray, p: np.ndarray) -> None:
    """Write ``exp(xi theta)`` for a unit twist (``|w| = 1`` or ``w = 0``) into ``R (3,3)`` and ``p (3,)``."""
    wx, wy, wz = w[0], w[1], w[2]
    if wx * wx + wy * wy + wz * wz < 0.5:  # prismatic: pure translation along v
        R[0, 0], R[0, 1], R[0, 2] = 1.0, 0.0, 0.0
        R[1, 0], R[1, 1], R[1, 2] = 0.0, 1.0, 0.0
        R[2, 0], R[2, 1], R[2, 2] = 0.0, 0.0, 1.0
        p[0], p[1], p[2] = v[0] * theta, v[1] * theta, v[2] * theta
        return
    s = np.sin(theta)
    c1 = 1.0 - np.cos(theta)
    c = 1.0 - c1
    # Rodrigues: R = I + s K + (1 - c) K^2 with K = hat(w), K^2 = w w^T - I; written out entry by entry (loops
    # with a branch per entry cost numba three times as much).
    R[0, 0] = c1 * wx * wx + c
    R[0, 1] = c1 * wx * wy - s * wz
    R[0, 2] = c1 * wx * wz + s * wy
    R[1, 0] = c1 * wy * wx + s * wz
    R[1, 1] = c1 * wy * wy + c
    R[1, 2] = c1 * wy * wz - s * wx
    R[2, 0] = c1 * wz * wx - s * wy
    R[2, 1] = c1 * wz * wy + s * wx
    R[2, 2] = c1 * wz * wz + c
    # p = (I - R)(w x v) + w (w . v) theta
    a0 = wy * v[2] - wz * v[1]
    a1 = wz * v[0] - wx * v[2]
    a2 = wx * v[1] - wy * v[0]
    wv = wx * v[0] + wy * v[1] + wz * v[2]
    p[0] = a0 - (R[0, 0] * a0 + R[0, 1] * a1 + R[0, 2] * a2) + wx * wv * theta
    p[1] = a1 - (R[1, 0] * a0 + R[1, 1] * a1 + R[1, 2] * a2) + wy * wv * theta
    p[2] = a2 - (R[2, 0] * a0 + R[2, 1] * a1 + R[2, 2] * a2) + wz * wv * theta


@kernel()
def log_rigid(R: np.ndarray, p: np.ndarray, out: np.ndarray) -> None:
    """Write the twist ``log([R, p])`` (6,) into ``out``."""
    cos_t = (R[0, 0] + R[1, 1] + R[2, 2] - 1.0) * 0.5
    if cos_t > 1.0:
        cos_t = 1.0
    elif cos_t < -1.0:
        cos_t = -1.0
    sx = R[2, 1] - R[1, 2]
    sy = R[0, 2] - R[2, 0]
    sz = R[1, 0] - R[0, 1]
    sin_t = 0.5 * np.sqrt(sx * sx + sy * sy + sz * sz)
    t = np.arctan2(sin_t, cos_t)
    if t < 1e-6:
        f = 0.5 + t * t / 12.0
        wx, wy, wz = f * sx, f * sy, f * sz
    elif t > np.pi - 1e-4:
        # Axis from the symmetric part B = (R + R^T)/2 - cos t I = (1 - cos t) u u^T.
        best = 0
        bmax = -1.0
        for i in range(3):
            d = R[i, i] - cos_t
            if d > bmax:
                bmax = d
                best = i
        ux = 0.5 * (R[0, best] + R[best, 0]) - (cos_t if best == 0 else 0.0)
        uy = 0.5 * (R[1, best] + R[best, 1]) - (cos_t if best == 1 else 0.0)
        uz = 0.5 * (R[2, best] + R[best, 2]) - (cos_t if best == 2 else 0.0)
        nrm = np.sqrt(ux * ux + uy * uy + uz * uz)
        ux, uy, uz = ux / nrm, uy / nrm, uz / nrm
        if ux * sx + uy * sy + uz * sz < 0.0:
            ux, uy, uz = -ux, -uy, -uz
        wx, wy, wz = t * ux, t * uy, t * uz
    else:
        f = t / (2.0 * sin_t)
        wx, wy, wz = f * sx, f * sy, f * sz
    out[0], out[1], out[2] = wx, wy, wz
    # v = V^-1 p with V^-1 = I - K/2 + D K^2
    D = log_coefficient(t)
    # K p = w x p, K^2 p = w x (w x p)
    kx = wy * p[2] - wz * p[1]
    ky = wz * p[0] - wx * p[2]
    kz = wx * p[1] - wy * p[0]
    k2x = wy * kz - wz * ky
    k2y = wz * kx - wx * kz
    k2z = wx * ky - wy * kx
    out[3] = p[0] - 0.5 * kx + D * k2x
    out[4] = p[1] - 0.5 * ky + D * k2y
    out[5] = p[2] - 0.5 * kz + D * k2z


@kernel()
def closure_jacobian(
    mech: tuple[np.ndarray, ...], q: np.ndarray, m: int, residual: np.ndarray, jac: np.ndarray
) -> None:
    """Closure residual ``(E,)`` and reduced Jacobian ``(E, m)`` at displacements ``q``, written in place.

    :func:`closure_pass` without a weight, with work arrays of its own (the hot loop of tracing).
    """
    matrices, vectors = work_arrays()
    closure_pass(mech, q, None, residual, jac, matrices, vectors)


@kernel(inline="always")
def closure_pass(
    mech: tuple[np.ndarray, ...],
    q: np.ndarray,
    weight: np.ndarray | None,
    residual: np.ndarray,
    jac: np.ndarray,
    matrices: tuple[np.ndarray, np.ndarray, np.ndarray],
    vectors: tuple[np.ndarray, ...],
) -> None:
    """Closure residual ``W log(P)`` ``(E,)`` and its Jacobian ``(E, m)`` in the unknowns, written in place.

    One pass per loop: running product ``g = [Rg, pg]``, each column ``s Ad(g) xi`` (Eq. (21)), then the factor
    ``exp(s xi q)`` applied to ``g``; the residual is ``log(g)`` at the end (Eq. (23), twist form). Columns of
    coupled joints add up (``J C``); fixed joints contribute no column. ``weight`` ``W (6, 6)`` maps every
    6-vector before its ``rows`` are kept; ``None`` means none (and numba compiles the weighting out).

    Work arrays (:func:`work_arrays`): ``matrices`` three ``(3, 3)``, ``vectors`` four ``(3,)`` then two ``(6,)``.
    Inlined into its callers (numba passes every array as a dozen scalars: a call per evaluation would cost a
    quarter of it).
    """
    twists, loop_joint, loop_sign, loop_ptr, rows, groups = mech
    nrows = rows.shape[0]
    jac[:, :] = 0.0
    Rg, Re, Rn = matrices
    pg, pe, w, v, col, lg = vectors
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
                adjoint_column(Rg, pg, w, v, col)
                if weight is not None:
                    for r in range(nrows):
                        jac[k * nrows + r, g] += weighted_entry(weight, rows[r], col)
                else:
                    for r in range(nrows):
                        jac[k * nrows + r, g] += col[rows[r]]
            exp_unit_twist(w, v, q[j], Re, pe)
            compose(Rg, pg, Re, pe, Rn)
        log_rigid(Rg, pg, lg)
        for r in range(nrows):
            residual[k * nrows + r] = lg[rows[r]] if weight is None else weighted_entry(weight, rows[r], lg)


@kernel(inline="always")
def work_arrays() -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, ...]]:
    """The work arrays of :func:`closure_pass`: ``(Rg, Re, Rn)`` and ``(pg, pe, w, v, column, log)``."""
    matrices = (np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3)))
    vectors = (np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(6), np.empty(6))
    return matrices, vectors


@kernel(inline="always")
def adjoint_column(Rg: np.ndarray, pg: np.ndarray, w: np.ndarray, v: np.ndarray, col: np.ndarray) -> None:
    """``col = Ad(g) xi = (Rg w, Rg v + pg x (Rg w))``: the twist ``xi = (w, v)`` carried to the base frame."""
    for i in range(3):
        col[i] = Rg[i, 0] * w[0] + Rg[i, 1] * w[1] + Rg[i, 2] * w[2]
        col[3 + i] = Rg[i, 0] * v[0] + Rg[i, 1] * v[1] + Rg[i, 2] * v[2]
    col[3] += pg[1] * col[2] - pg[2] * col[1]
    col[4] += pg[2] * col[0] - pg[0] * col[2]
    col[5] += pg[0] * col[1] - pg[1] * col[0]


@kernel(inline="always")
def compose(Rg: np.ndarray, pg: np.ndarray, Re: np.ndarray, pe: np.ndarray, Rn: np.ndarray) -> None:
    """``g <- g e`` in place for rigid motions ``g = [Rg, pg]`` and ``e = [Re, pe]`` (``Rn`` is work space)."""
    for i in range(3):
        for c in range(3):
            Rn[i, c] = Rg[i, 0] * Re[0, c] + Rg[i, 1] * Re[1, c] + Rg[i, 2] * Re[2, c]
    for i in range(3):
        pg[i] += Rg[i, 0] * pe[0] + Rg[i, 1] * pe[1] + Rg[i, 2] * pe[2]
    for i in range(3):
        for c in range(3):
            Rg[i, c] = Rn[i, c]


@kernel(inline="always")
def weighted_entry(weight: np.ndarray, row: int, vector: np.ndarray) -> float:
    """``(W vector)[row]`` for a 6-vector."""
    acc = 0.0
    for c in range(6):
        acc += weight[row, c] * vector[c]
    return acc


@kernel()
def expand(u: np.ndarray, groups: np.ndarray, q: np.ndarray) -> None:
    """Joint displacements ``q (n,)`` from unknowns ``u (m,)``; fixed joints (group -1) stay at 0."""
    for j in range(groups.shape[0]):
        g = groups[j]
        q[j] = u[g] if g >= 0 else 0.0


@kernel(inline="always")
def cholesky_in_place(A: np.ndarray, floor: float, fallback: float) -> bool:
    """Cholesky factor ``A = L L^T`` of a symmetric positive (semi)definite ``A``, written into its lower triangle
    (the lower triangle of ``A`` is all that is read).

    A pivot at or below ``floor`` is replaced by ``fallback`` when that is positive (a singular matrix then still
    gives a finite solve); otherwise the factorisation stops and returns False.
    """
    for a in range(A.shape[0]):
        for c in range(a + 1):
            acc = A[a, c]
            for k in range(c):
                acc -= A[a, k] * A[c, k]
            if a != c:
                A[a, c] = acc / A[c, c]
            elif acc <= floor:
                if fallback <= 0.0:
                    return False
                A[a, a] = fallback
            else:
                A[a, a] = np.sqrt(acc)
    return True


@kernel(inline="always")
def cholesky_solve(L: np.ndarray, b: np.ndarray, x: np.ndarray) -> None:
    """``x`` solving ``L L^T x = b`` by two triangular solves, ``L`` the lower triangle of a Cholesky factor."""
    n = b.shape[0]
    for a in range(n):
        acc = b[a]
        for k in range(a):
            acc -= L[a, k] * x[k]
        x[a] = acc / L[a, a]
    for a in range(n - 1, -1, -1):
        acc = x[a]
        for k in range(a + 1, n):
            acc -= L[k, a] * x[k]
        x[a] = acc / L[a, a]


@kernel()
def joint_values(u: np.ndarray, groups: np.ndarray, offsets: np.ndarray, out: np.ndarray) -> None:
    """Joint values ``out (N, n)`` of the unknowns ``u (N, m)`` at every row, every joint free (``groups >= 0``):
    ``out[k, j] = u[k, groups[j]] + offsets[j]``, what numpy's ``u[:, groups] + offsets`` gives, in one pass
    (without the gather when every joint is its own unknown)."""
    n = groups.shape[0]
    own = u.shape[1] == n
    for j in range(n):
        own = own and groups[j] == j
    if own:
        for k in range(u.shape[0]):
            for j in range(n):
                out[k, j] = u[k, j] + offsets[j]
        return
    for k in range(u.shape[0]):
        for j in range(n):
            out[k, j] = u[k, groups[j]] + offsets[j]


@kernel()
def every_row_full_rank(sigma: np.ndarray, loose: float) -> bool:
    """Whether every row of singular values ``sigma (N, r)`` has ``sigma_1 > 0`` and every ratio
    ``sigma_i / sigma_1`` above ``loose``: then every row's numerical rank is ``r``
    (:func:`linkwork.kinematics.rank.numerical_rank`, with a floor at or below ``loose``). A row's smallest value
    over its first is its smallest ratio (division by a positive number is monotone, also once rounded), so one
    division a row decides it exactly; NaN fails."""
    ok = sigma.shape[1] > 0
    for k in range(sigma.shape[0]):
        first = sigma[k, 0]
        low = first
        for i in range(1, sigma.shape[1]):
            x = sigma[k, i]
            ok &= x == x
            low = x if x < low else low
        ok &= first > 0.0
        ok &= low / first > loose
    return ok


@kernel()
def rank_counts(
    sigma: np.ndarray, loose: float, floor: float, sure: np.ndarray, candidates: np.ndarray
) -> None:
    """For every row of singular values ``sigma (N, r)``: how many ratios ``sigma_i / sigma_1`` are above
    ``loose`` (``sure[k]``) and above ``floor`` (``candidates[k]``), both 0 where ``sigma_1`` is not positive:
    the counts :func:`linkwork.kinematics.rank.numerical_ranks` starts from (the same divisions)."""
    for k in range(sigma.shape[0]):
        first = sigma[k, 0]
        above_loose = 0
        above_floor = 0
        if first > 0.0:
            for i in range(sigma.shape[1]):
                rel = sigma[k, i] / first
                if rel > loose:
                    above_loose += 1
                if rel > floor:
                    above_floor += 1
        sure[k] = above_loose
        candidates[k] = above_floor
