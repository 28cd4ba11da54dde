"""The closure misfit along a path: the least weighted closure residual over the other joints, drive held.

For an imperfect mechanism (perturbed twists) and the nominal path ``u_k`` (unknowns at point ``k``), the misfit
at ``k`` is ``min |T r(u)|`` over the unknowns ``u`` in the plane through ``u_k`` normal to the nominal path's
tangent: where the drive parameterises the path this is the drive held, to first order exactly (the Jacobian
annihilates the tangent, so every plane transverse to it gives the same least residual to first order), and unlike
holding the drive it stays well posed at a fold of the drive, where the path turns back; ``r`` is the stacked loop logarithm (closure residual, Eq. (23) in twist form) and ``T`` the weight
of :mod:`linkwork.studies.scale` at point ``k`` (moments about the centre of the hinge lines there), so the misfit is
a length in the linkage's units, whichever body is the ground. Every loop is taken in the ground's frame, the
frame of that centre (the loops of :func:`linkwork.kinematics.ground_frame.ground_frame_arrays`: a loop that does
not pass through the ground is conjugated by its tree path from it, ``log(A P A^-1) = Ad_A log P``, and its
columns, the exact derivative of that product, are its joints' axes where they are). It is solved by Gauss-Newton
(normal equations, Cholesky, with backtracking), warm-started along the path from the solutions' offsets from the
nominal path at the last three drive values, extrapolated (each refined by its last, unevaluated Gauss-Newton
step): one evaluation usually ends a solve. The compiled batch kernel runs many samples and all drive values in
one call.

References
----------
W. W. Gan, S. Pellegrino, Proc. IMechE Part C 220 (2006), Eqs. (21), (23).
"""

from __future__ import annotations

import numpy as np

from linkwork.kernel_cache import kernel
from linkwork.kinematics.kernels import cholesky_in_place, cholesky_solve, closure_pass, expand, work_arrays


@kernel()
def weighted_closure(
    mech: tuple[np.ndarray, ...], q: np.ndarray, T: np.ndarray, residual: np.ndarray, jac: np.ndarray
) -> None:
    """Weighted closure residual ``T log(P)`` (kept rows, per loop) and its Jacobian in the unknowns, in place:
    :func:`linkwork.kinematics.kernels.closure_pass` (columns ``s Ad(g) xi``, Eq. (21)) with the weight ``T``."""
    matrices, vectors = work_arrays()
    closure_pass(mech, q, T, residual, jac, matrices, vectors)


@kernel(inline="always")
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
    cholesky_in_place(A, 0.0, 1e-150)  # a zero pivot (a singular point) kept finite
    cholesky_solve(A, b, dy)


@kernel(inline="always")
def _on_plane(u_path: np.ndarray, normal: np.ndarray, k: int, y: np.ndarray, u: np.ndarray) -> None:
    """``u = u_k + Q_k y``: the unknowns at offset ``y`` in the plane normal to the nominal path at point ``k``."""
    for a in range(u.shape[0]):
        acc = u_path[k, a]
        for c in range(y.shape[0]):
            acc += normal[k, a, c] * y[c]
        u[a] = acc


@kernel(inline="always")
def _warm_start(u_path: np.ndarray, normal: np.ndarray, k: int, offsets: np.ndarray, y: np.ndarray) -> None:
    """``y = Q_k^T e``: the solutions' offset from the path ``e``, extrapolated to point ``k`` and carried into its
    plane; ``offsets[i]`` is the offset at point ``k - 1 - i`` (a polynomial through the last three: the offset
    changes smoothly along the path, so the guess is close enough that one evaluation usually ends the solve)."""
    have = min(k, 3)
    for c in range(y.shape[0]):
        acc = 0.0
        for a in range(u_path.shape[1]):
            if have == 3:
                e = 3.0 * offsets[0, a] - 3.0 * offsets[1, a] + offsets[2, a]
            elif have == 2:
                e = 2.0 * offsets[0, a] - offsets[1, a]
            else:
                e = offsets[0, a]
            acc += normal[k, a, c] * e
        y[c] = acc


@kernel(inline="always")
def _in_plane(J: np.ndarray, normal: np.ndarray, k: int, Jy: np.ndarray) -> None:
    """``Jy = J Q_k``: the Jacobian in the plane's coordinates."""
    for e in range(J.shape[0]):
        for c in range(Jy.shape[1]):
            acc = 0.0
            for a in range(J.shape[1]):
                acc += J[e, a] * normal[k, a, c]
            Jy[e, c] = acc


@kernel(inline="always")
def _predicted_gain(Jy: np.ndarray, dy: np.ndarray) -> float:
    """``|Jy dy|^2``: how much the step lowers ``|r|^2``, to first order."""
    gain = 0.0
    for e in range(Jy.shape[0]):
        acc = 0.0
        for c in range(dy.shape[0]):
            acc += Jy[e, c] * dy[c]
        gain += acc * acc
    return gain


@kernel(inline="always")
def _cross_add(a: np.ndarray, b: np.ndarray, out: np.ndarray, o: int) -> None:
    """``out[o:o + 3] += a x b`` (3-vectors)."""
    out[o + 0] += a[1] * b[2] - a[2] * b[1]
    out[o + 1] += a[2] * b[0] - a[0] * b[2]
    out[o + 2] += a[0] * b[1] - a[1] * b[0]


@kernel(inline="always")
def _ad(w: np.ndarray, v: np.ndarray, z: np.ndarray, out: np.ndarray) -> None:
    """``out = ad_X z`` for ``X = (w, v)``: ``(w x z_w, v x z_w + w x z_v)``."""
    out[:] = 0.0
    _cross_add(w, z[0:3], out, 0)
    _cross_add(v, z[0:3], out, 3)
    _cross_add(w, z[3:6], out, 3)


@kernel(inline="always")
def _loop_twist(
    r: np.ndarray, base: int, T: np.ndarray, rows: np.ndarray, x: np.ndarray, z: np.ndarray
) -> None:
    """The loop's weighted residual (rows ``base ..`` of ``r``) into ``z`` (6 entries, the rows not kept zero) and
    its twist ``X = T^-1 z`` into ``x``: ``omega = z_w / L``, ``v = z_v - T21 omega``."""
    length = T[0, 0]
    z[:] = 0.0
    for e in range(rows.shape[0]):
        z[rows[e]] = r[base + e]
    for i in range(3):
        x[i] = z[i] / length
    for i in range(3):
        x[3 + i] = z[3 + i] - (T[3 + i, 0] * x[0] + T[3 + i, 1] * x[1] + T[3 + i, 2] * x[2])


@kernel(inline="always")
def _log_gradient(r: np.ndarray, T: np.ndarray, rows: np.ndarray, work: np.ndarray, rg: np.ndarray) -> None:
    """``rg = M^T r`` per loop, ``M = T (I - ad_X / 2) T^-1`` the map :func:`_log_jacobian` applies to the columns
    (``X = T^-1 r``): ``J^T rg`` is then the gradient of ``|T log P|^2 / 2`` that :func:`_log_jacobian`'s columns
    give (``(M J)^T r``), from one vector a loop instead of every column. Gauss-Newton with the twist columns'
    normal matrix and this gradient stops where the true gradient is zero, the least residual, as
    :func:`_log_jacobian` does (the normal matrix errs by ``O(|X|)``: the steps converge linearly at that rate,
    and ``|X|`` is the misfit itself). Used where the loops are not mixed (one loop: the Monte Carlo's hexagon),
    where ``J`` is then left as it is. ``T^T = [[L I, T21^T], [0, I]]``, ``ad_X^T y = (-(w x y_w) - v x y_v, -(w
    x y_v))``, ``T^-T = [[I / L, -T21^T / L], [0, I]]``."""
    x, z, z1 = work[0], work[1], work[2]
    nrows = rows.shape[0]
    length = T[0, 0]
    for loop in range(r.shape[0] // nrows):
        base = loop * nrows
        _loop_twist(r, base, T, rows, x, z)
        w, v = x[0:3], x[3:6]
        for i in range(3):  # z1 = T^T r
            z1[i] = length * z[i] + T[3, i] * z[3] + T[4, i] * z[4] + T[5, i] * z[5]
            z1[3 + i] = z[3 + i]
        for i in range(6):  # z = (I - ad_X / 2)^T z1 = z1 + (w x z1_w + v x z1_v, w x z1_v) / 2
            z[i] = 0.0
        _cross_add(w, z1[0:3], z, 0)
        _cross_add(v, z1[3:6], z, 0)
        _cross_add(w, z1[3:6], z, 3)
        for i in range(6):
            z[i] = z1[i] + 0.5 * z[i]
        for i in range(3):  # T^-T z
            z[i] = (z[i] - (T[3, i] * z[3] + T[4, i] * z[4] + T[5, i] * z[5])) / length
        for e in range(nrows):
            rg[base + e] = z[rows[e]]


@kernel(inline="always")
def _log_jacobian(r: np.ndarray, J: np.ndarray, T: np.ndarray, rows: np.ndarray, work: np.ndarray) -> None:
    """Turn ``J`` (the loop's twist columns, weighted: the derivative of ``T log P`` only where ``P = I``) into the
    derivative of ``T log P`` itself, in place: ``T dexp^-1_X T^-1 J`` with ``X = log P = T^-1 r`` per loop and
    ``dexp^-1_X = I - ad_X / 2 + ad_X^2 / 12 - ...`` (the spatial form), applied column by column through cross
    products. The first-order term is kept: the columns' error left, ``|X|^2 / 12``, moves the least residual by
    a fourth-order amount (below 1e-12 relative at misfits of 1e-2 of the linkage's size).

    Gauss-Newton on the twist columns alone stops where ``J^T r = 0``, not at the least ``|r|``: for an imperfect
    loop whose misfit is ``X`` the two differ at second order (4e-7 relative on an offset slider-crank at
    tolerances of 1e-3, against the 1e-8 the solve promises). A planar loop's kept rows are closed under ``ad_X``
    (its residual and columns have no out-of-plane part), so the kept rows suffice. ``T`` is
    ``[[L I, 0], [T21, I]]`` (:func:`linkwork.studies.scale.weight`); ``work`` a ``(3, 6)`` work array.
    """
    x, z, z1 = work[0], work[1], work[2]
    nrows = rows.shape[0]
    length = T[0, 0]
    for loop in range(r.shape[0] // nrows):
        base = loop * nrows
        _loop_twist(r, base, T, rows, x, z)  # X = T^-1 (weighted residual)
        w, v = x[0:3], x[3:6]
        for a in range(J.shape[1]):
            z[:] = 0.0
            for e in range(nrows):
                z[rows[e]] = J[base + e, a]
            for i in range(3):
                z[i] = z[i] / length
            for i in range(3):
                z[3 + i] -= T[3 + i, 0] * z[0] + T[3 + i, 1] * z[1] + T[3 + i, 2] * z[2]
            _ad(w, v, z, z1)
            for i in range(6):
                z[i] -= 0.5 * z1[i]
            for i in range(3):
                z[3 + i] += T[3 + i, 0] * z[0] + T[3 + i, 1] * z[1] + T[3 + i, 2] * z[2]
            for i in range(3):
                z[i] = z[i] * length
            for e in range(nrows):
                J[base + e, a] = z[rows[e]]


@kernel(inline="always")
def _mix_loops(
    r: np.ndarray, J: np.ndarray, cycles: np.ndarray, nrows: int, rb: np.ndarray, Jb: np.ndarray
) -> None:
    """``r``, ``J`` with their loop blocks combined by ``cycles`` (:func:`linkwork.studies.scale.loop_weights`), in
    place: the loops' rows made orthonormal over the cycle space, so that the stacked residual's size does not
    depend on which cycle basis (which ground body) the body graph gave. Nothing to do for one loop."""
    n_loops = cycles.shape[0]
    if n_loops < 2:
        return
    for e in range(r.shape[0]):
        loop, row = e // nrows, e % nrows
        acc = 0.0
        for other in range(n_loops):
            acc += cycles[loop, other] * r[other * nrows + row]
        rb[e] = acc
        for a in range(J.shape[1]):
            acc = 0.0
            for other in range(n_loops):
                acc += cycles[loop, other] * J[other * nrows + row, a]
            Jb[e, a] = acc
    for e in range(r.shape[0]):
        r[e] = rb[e]
        for a in range(J.shape[1]):
            J[e, a] = Jb[e, a]


@kernel()
def misfit_along_path(
    mech: tuple[np.ndarray, ...],
    path: tuple[np.ndarray, np.ndarray, np.ndarray],
    T: np.ndarray,
    max_iter: int,
    out: np.ndarray,
) -> None:
    """Misfit ``out (K,)`` of one imperfect mechanism ``mech`` (the mechanism tuple of
    :mod:`~linkwork.kinematics.kernels`, with its perturbed twists) at every nominal path point of ``path =
    (u_path (K, m), normal, cycles)`` (the loops' rows combined by ``cycles``: :func:`_mix_loops`).

    At point ``k`` the unknowns move in the plane normal to the nominal path, ``u = u_k + Q_k y`` with
    ``normal[k] = Q_k (m, m - 1)`` orthonormal: the drive held wherever it parameterises the path, and still a
    well-posed problem at a fold of the drive. ``T (K, 6, 6)`` is the weight at every point (its centre moves with
    the linkage: :func:`linkwork.studies.scale.weights_along`).
    """
    u_path, normal, cycles = path
    loop_ptr, rows, groups = mech[3], mech[4], mech[5]
    K, m = u_path.shape
    p = normal.shape[2]
    E = (loop_ptr.shape[0] - 1) * rows.shape[0]
    q = np.empty(groups.shape[0])
    r = np.empty(E)
    J = np.empty((E, m))
    Jy = np.empty((E, p))
    dy = np.empty(p)
    matrices, vectors = work_arrays()
    A = np.empty((p, p))
    b = np.empty(p)
    y = np.zeros(p)
    y_old = np.zeros(p)
    u = np.empty(m)
    log_work = np.empty((3, 6))
    mixed_r = np.empty(E)
    mixed_J = np.empty((E, m))
    rg = np.empty(E)  # the residual the step's gradient is taken of (see _log_gradient)
    mixed = cycles.shape[0] >= 2
    offsets = np.zeros((3, m))  # the solutions' offsets from the path at the last three points, newest first
    for k in range(K):
        if k > 0:
            _warm_start(u_path, normal, k, offsets, y)
        best = np.inf
        halvings = 0
        gain = np.inf  # what the last step was predicted to gain
        refined = False
        for _ in range(max_iter):
            _on_plane(u_path, normal, k, y, u)
            expand(u, groups, q)
            closure_pass(mech, q, T[k], r, J, matrices, vectors)
            if mixed:  # the loops' columns mapped one by one, then combined
                _log_jacobian(r, J, T[k], rows, log_work)
                _mix_loops(r, J, cycles, rows.shape[0], mixed_r, mixed_J)
                rg[:] = r
            else:  # the same gradient from one vector a loop
                _log_gradient(r, T[k], rows, log_work, rg)
            norm = np.sqrt(np.sum(r * r))
            if norm > best * (1.0 + 1e-10) and gain <= 1e-6 * best * best:
                break  # a step predicted to gain next to nothing came out worse: round-off; best is the minimum
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
            _in_plane(J, normal, k, Jy)
            _solve_normal(Jy, rg, dy, A, b)
            # The step lowers |r|^2 by |Jy dy|^2 to first order: when that is below 1e-8 |r|^2 the misfit is
            # known to 1e-8 relative already, and a further evaluation would not change it.
            gain = _predicted_gain(Jy, dy)
            if gain <= 1e-8 * norm * norm:
                # The misfit is ``best``; the next points start from this solution refined by the step (not
                # evaluated), so that their extrapolated start is accurate.
                for c in range(p):
                    y[c] = y_old[c] + dy[c]
                refined = True
                break
            step = 0.0
            for c in range(p):
                y[c] += dy[c]
                step = max(step, abs(dy[c]))
            if step < 1e-15:
                break
        _on_plane(u_path, normal, k, y if refined else y_old, u)
        for a in range(m):
            offsets[2, a], offsets[1, a] = offsets[1, a], offsets[0, a]
            offsets[0, a] = u[a] - u_path[k, a]
        out[k] = best


@kernel(nogil=True)  # nogil: a Dask worker keeps talking to its scheduler while a chunk computes
def misfit_batch(
    twists: np.ndarray,
    path: tuple[np.ndarray, np.ndarray, np.ndarray],
    loops: tuple[np.ndarray, ...],
    T: np.ndarray,
    max_iter: int,
) -> np.ndarray:
    """``(S, K)`` misfits of ``S`` imperfect mechanisms ``twists (S, n, 6)`` along the nominal path ``path =
    (u_path, normal, cycles)`` (``cycles`` the loops' weights, :func:`linkwork.studies.scale.loop_weights`);
    ``loops = (loop_joint, loop_sign, loop_ptr, rows, groups)`` (the mechanism tuple without
    its twists, its loops taken from the ground: :func:`linkwork.kinematics.ground_frame.ground_frame_arrays`);
    weights ``T (K, 6, 6)``, one per point."""
    S = twists.shape[0]
    out = np.empty((S, path[0].shape[0]))
    loop_joint, loop_sign, loop_ptr, rows, groups = loops
    for s in range(S):
        misfit_along_path(
            (twists[s], loop_joint, loop_sign, loop_ptr, rows, groups), path, T, max_iter, out[s]
        )
    return out
