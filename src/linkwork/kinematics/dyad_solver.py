"""Compiled closed-form positions of a planar mechanism made of a driver and dyads, with the rows a trace reports.

A planar mechanism that decomposes into a driver (one joint from the fixed body) and a sequence of dyads (Assur
groups of class II: two bodies, three joints, each dyad attached to bodies already placed) is solved at every
drive value without iterating: each dyad is a circle-circle (RRR), circle-line (RRP, PRR), line-line (PRP) or
rotating-line (RPR) intersection, the root taken on the side of the start configuration (its assembly mode).
At every point the planar closure residual and Jacobian are evaluated (the kept rows ``(omega_z, v_x, v_y)`` of
:func:`linkwork.kinematics.kernels.closure_pass`, in SE(2) arithmetic), and from them what the predictor-corrector
records: the singular values (one-sided Jacobi on the triangular factor of a Householder QR of ``J^T``), the
tangent (the QR's last column, oriented continuously) and the signed test function of
:mod:`linkwork.kinematics.march`, ``det([U_r^T J; t])``, which for a Jacobian of full row rank is
``det(U_r) det(R) s det(Q)``.

The kernel gives up (returns a non-zero status) wherever the predictor-corrector's bookkeeping would act: a dyad
without a real solution or near its limit (a fold of the drive), a rank ratio below the local-minimum threshold
(a bifurcation or a higher-dimensional component nearby), a sign change of the test function, a joint limit, a
closed path before the target; the caller then traces with the predictor-corrector as before.

Body poses are planar displacements from the reference ``x -> R x + t``, kept as ``(cos, sin, t_x, t_y)``; a joint between bodies ``a`` (before)
and ``b`` (after) satisfies ``g_b = g_a exp(xi q)`` (:func:`linkwork.kinematics.closure.body_poses`).

References
----------
W. W. Gan, S. Pellegrino, Proc. IMechE Part C 220 (2006), Eqs. (21), (23).
R. L. Norton, *Design of Machinery*, Ch. 4 (closed-form position analysis of four-bars and slider-cranks).
"""

from __future__ import annotations

import numpy as np

from linkwork.kernel_cache import kernel
from linkwork.kinematics.kernels import log_coefficient
from linkwork.kinematics.small_svd import orthonormalise

#: Joint kinds in ``joint_int[:, 0]``.
REVOLUTE, PRISMATIC = 0, 1
#: Statuses returned by :func:`closed_form_path` (0: the target reached cleanly).
CLEAN, NO_SOLUTION, NEAR_SINGULAR, SIGN_CHANGE, CLOSED, LIMIT, JUMP, UNSUPPORTED = 0, 1, 2, 3, 4, 5, 6, 7
#: Settings array layout of :func:`closed_form_path`.
S_STEP, S_TARGET, S_STEPS, S_HMAX, S_DET_BASIS, S_MIN_RATIO, S_MIN_DRIVE, S_MIN_MARGIN = (
    0,
    1,
    2,
    3,
    4,
    5,
    6,
    7,
)
N_SETTINGS = 8
#: Points per block of the closed form's second and third passes (their scratch stays in the cache).
BLOCK = 64


@kernel(inline="always")
def wrap_angle(x: float) -> float:
    """``x`` wrapped onto ``[-pi, pi)`` (compiled copy of :func:`linkwork.geometry.angles.wrap`); a value already
    in the range is returned as it is (exactly, and without the floating-point modulo's cost)."""
    if -np.pi <= x < np.pi:
        return x
    return (x + np.pi) % (2.0 * np.pi) - np.pi


@kernel(inline="always")
def apply_pose(poses: np.ndarray, body: int, x: float, y: float) -> tuple[float, float]:
    """The point ``(x, y)`` of ``body`` (reference coordinates) where the body's pose ``(cos, sin, tx, ty)``
    puts it."""
    c, s = poses[body, 0], poses[body, 1]
    return c * x - s * y + poses[body, 2], s * x + c * y + poses[body, 3]


@kernel(inline="always")
def set_pose(
    poses: np.ndarray, body: int, c: float, s: float, x: float, y: float, X: float, Y: float
) -> None:
    """Pose of ``body`` turned by the rotation ``(c, s)`` and taking its reference point ``(x, y)`` to ``(X, Y)``."""
    poses[body, 0] = c
    poses[body, 1] = s
    poses[body, 2] = X - (c * x - s * y)
    poses[body, 3] = Y - (s * x + c * y)


@kernel(inline="always")
def set_pose_turning(poses, body, x, y, X, Y, ux, uy, vx, vy):
    """Pose of ``body`` taking its reference point ``(x, y)`` to ``(X, Y)`` and turning the reference vector
    ``(ux, uy)`` onto the direction of ``(vx, vy)``."""
    scale = 1.0 / np.sqrt((ux * ux + uy * uy) * (vx * vx + vy * vy))
    set_pose(poses, body, (ux * vx + uy * vy) * scale, (ux * vy - uy * vx) * scale, x, y, X, Y)


@kernel(inline="always")
def place_driven(joint_int, joint_geo, drive, driven, q, poses):
    """Pose of the body the drive joint moves, the other body of the drive joint being fixed (identity pose)."""
    sign = 1.0 if joint_int[drive, 2] == driven else -1.0  # g_after = g_before exp(xi q)
    if joint_int[drive, 0] == REVOLUTE:
        phi = sign * joint_geo[drive, 2] * q
        px, py = joint_geo[drive, 0], joint_geo[drive, 1]
        set_pose(poses, driven, np.cos(phi), np.sin(phi), px, py, px, py)
    else:
        set_pose(
            poses, driven, 1.0, 0.0, 0.0, 0.0, sign * q * joint_geo[drive, 0], sign * q * joint_geo[drive, 1]
        )


@kernel(inline="always")
def guide_line(joint_geo, poses, j, known, px, py):
    """The line a point ``(px, py)`` of the body that prismatic joint ``j`` joins to ``known`` runs on: its point
    and unit direction where ``known``'s pose puts them (the two bodies keep one orientation)."""
    X, Y = apply_pose(poses, known, px, py)
    c, s = poses[known, 0], poses[known, 1]
    dx, dy = joint_geo[j, 0], joint_geo[j, 1]
    return X, Y, c * dx - s * dy, s * dx + c * dy


@kernel()
def place_dyad(joint_int, joint_geo, dyad, mode, poses, min_margin):
    """Place the two bodies of one dyad ``(j1, j2, j3, K1, B1, B2, K2)`` in closed form; returns a status.

    ``mode`` is the sign that picks the start's assembly mode. ``min_margin`` is the smallest relative distance
    from the dyad's limit (a double root) accepted; below it the dyad is too near a fold to trust a closed form
    where the predictor-corrector would meet the fold.
    """
    j1, j2, j3, K1, B1, B2, K2 = dyad[0], dyad[1], dyad[2], dyad[3], dyad[4], dyad[5], dyad[6]
    k1, k2, k3 = joint_int[j1, 0], joint_int[j2, 0], joint_int[j3, 0]
    if k2 == REVOLUTE:
        # The middle point p2 (shared by B1 and B2) on a circle or a line from each side.
        p2x, p2y = joint_geo[j2, 0], joint_geo[j2, 1]
        if k1 == REVOLUTE and k3 == REVOLUTE:  # RRR: two circles
            p1x, p1y, p3x, p3y = joint_geo[j1, 0], joint_geo[j1, 1], joint_geo[j3, 0], joint_geo[j3, 1]
            L1s = (p2x - p1x) ** 2 + (p2y - p1y) ** 2
            L2s = (p2x - p3x) ** 2 + (p2y - p3y) ** 2
            X1, Y1 = apply_pose(poses, K1, p1x, p1y)
            X3, Y3 = apply_pose(poses, K2, p3x, p3y)
            Dx, Dy = X3 - X1, Y3 - Y1
            d2 = Dx * Dx + Dy * Dy
            if d2 == 0.0:
                return NO_SOLUTION
            d = np.sqrt(d2)
            a = (L1s - L2s + d2) / (2.0 * d)
            h2 = L1s - a * a
            if h2 < 0.0:
                return NO_SOLUTION
            h = np.sqrt(h2)
            if h * h < min_margin * min_margin * L1s:
                return NEAR_SINGULAR
            X2 = X1 + (a * Dx - mode * h * Dy) / d
            Y2 = Y1 + (a * Dy + mode * h * Dx) / d
            set_pose_turning(poses, B1, p1x, p1y, X1, Y1, p2x - p1x, p2y - p1y, X2 - X1, Y2 - Y1)
            set_pose_turning(poses, B2, p3x, p3y, X3, Y3, p2x - p3x, p2y - p3y, X2 - X3, Y2 - Y3)
            return CLEAN
        if k1 == PRISMATIC and k3 == PRISMATIC:  # PRP: two lines
            Ax, Ay, ax, ay = guide_line(joint_geo, poses, j1, K1, p2x, p2y)
            Cx, Cy, cx, cy = guide_line(joint_geo, poses, j3, K2, p2x, p2y)
            det = ax * cy - ay * cx
            if abs(det) < min_margin:
                return NEAR_SINGULAR
            s1 = ((Cx - Ax) * cy - (Cy - Ay) * cx) / det
            X2, Y2 = Ax + s1 * ax, Ay + s1 * ay
            set_pose(poses, B1, poses[K1, 0], poses[K1, 1], p2x, p2y, X2, Y2)
            set_pose(poses, B2, poses[K2, 0], poses[K2, 1], p2x, p2y, X2, Y2)
            return CLEAN
        # RRP or PRR: a circle about the revolute side's pivot and the prismatic side's line.
        if k1 == REVOLUTE:
            jr, Kr, Br, jp, Kp, Bp = j1, K1, B1, j3, K2, B2
        else:
            jr, Kr, Br, jp, Kp, Bp = j3, K2, B2, j1, K1, B1
        prx, pry = joint_geo[jr, 0], joint_geo[jr, 1]
        Ls = (p2x - prx) ** 2 + (p2y - pry) ** 2
        Xr, Yr = apply_pose(poses, Kr, prx, pry)
        Qx, Qy, ex, ey = guide_line(joint_geo, poses, jp, Kp, p2x, p2y)
        b = ex * (Qx - Xr) + ey * (Qy - Yr)
        c = (Qx - Xr) ** 2 + (Qy - Yr) ** 2 - Ls
        disc = b * b - c
        if disc < 0.0:
            return NO_SOLUTION
        if disc < min_margin * min_margin * Ls:
            return NEAR_SINGULAR
        s = -b + mode * np.sqrt(disc)
        X2, Y2 = Qx + s * ex, Qy + s * ey
        set_pose_turning(poses, Br, prx, pry, Xr, Yr, p2x - prx, p2y - pry, X2 - Xr, Y2 - Yr)
        set_pose(poses, Bp, poses[Kp, 0], poses[Kp, 1], p2x, p2y, X2, Y2)
        return CLEAN
    if k1 == REVOLUTE and k3 == REVOLUTE:  # RPR: B1 and B2 turn together; B2's pivot on B1's line
        p1x, p1y, p3x, p3y = joint_geo[j1, 0], joint_geo[j1, 1], joint_geo[j3, 0], joint_geo[j3, 1]
        # The slide's direction in B1 (the before body of j2 may be either dyad body: a line is a line).
        dx, dy = joint_geo[j2, 0], joint_geo[j2, 1]
        h0 = dx * (p3y - p1y) - dy * (p3x - p1x)  # signed distance of the line from p1, constant in B1
        X1, Y1 = apply_pose(poses, K1, p1x, p1y)
        X3, Y3 = apply_pose(poses, K2, p3x, p3y)
        Dx, Dy = X3 - X1, Y3 - Y1
        rho2 = Dx * Dx + Dy * Dy
        along2 = rho2 - h0 * h0
        if along2 < 0.0 or rho2 == 0.0:
            return NO_SOLUTION
        if along2 < min_margin * min_margin * rho2:
            return NEAR_SINGULAR
        along = mode * np.sqrt(along2)
        # The turn takes the line's direction d (at angle psi from D in B1's frame) onto D's direction:
        # e^{i phi} = (D / rho) conj(d) conj(e^{i psi}), e^{i psi} = (along + i h0) / rho.
        cx, cy = Dx * dx + Dy * dy, Dy * dx - Dx * dy  # D conj(d)
        c = (cx * along + cy * h0) / rho2
        s = (cy * along - cx * h0) / rho2
        set_pose(poses, B1, c, s, p1x, p1y, X1, Y1)
        set_pose(poses, B2, c, s, p3x, p3y, X3, Y3)
        return CLEAN
    return UNSUPPORTED


@kernel(inline="always")
def joint_values(joint_int, joint_geo, poses, q_prev, q, drive, drive_q):
    """Every joint's displacement from its bodies' poses (revolute ones continued from ``q_prev``), the drive's
    set to ``drive_q``; returns the largest change of a joint (the drive's wrapped for a revolute drive, as its
    value read back from the poses would be)."""
    jump = 0.0
    for j in range(joint_int.shape[0]):
        if j == drive:
            q[j] = drive_q
            step = drive_q - q_prev[j]
            jump = max(jump, abs(wrap_angle(step) if joint_int[j, 0] == REVOLUTE else step))
            continue
        a, b = joint_int[j, 1], joint_int[j, 2]
        ca, sa = poses[a, 0], poses[a, 1]
        if joint_int[j, 0] == REVOLUTE:  # R_a^T R_b = Rz(omega_z q)
            c = ca * poses[b, 0] + sa * poses[b, 1]
            s = ca * poses[b, 1] - sa * poses[b, 0]
            raw = joint_geo[j, 2] * np.arctan2(s, c)
            q[j] = q_prev[j] + wrap_angle(raw - q_prev[j])
        else:  # R_a^T (t_b - t_a) = q d
            tx, ty = poses[b, 2] - poses[a, 2], poses[b, 3] - poses[a, 3]
            q[j] = joint_geo[j, 0] * (ca * tx + sa * ty) + joint_geo[j, 1] * (-sa * tx + ca * ty)
        jump = max(jump, abs(q[j] - q_prev[j]))
    return jump


@kernel(inline="always")
def planar_closure(flat, q, residual, jac, m, E):
    """Planar closure residual ``(omega_z, v_x, v_y)`` of ``log(P)`` per loop and its ``(E, m)`` Jacobian in the
    unknowns, for ``flat = (twists, loop_joint, loop_sign, loop_ptr, groups)``.

    :func:`linkwork.kinematics.kernels.closure_pass` with rows ``(2, 3, 4)`` for twists in the plane, in SE(2):
    columns ``s Ad(g) xi`` (G&P Eq. (21)), the residual the twist ``log(g)`` of the loop product (Eq. (23)).
    ``m`` and ``E`` are the Jacobian's sizes (literal constants at a call site for one loop: the loops unroll).
    """
    twists, loop_joint, loop_sign, loop_ptr, groups = flat
    for e in range(E):
        for c in range(m):
            jac[e, c] = 0.0
    for k in range(E // 3):
        cg, sg, px, py = 1.0, 0.0, 0.0, 0.0
        for idx in range(loop_ptr[k], loop_ptr[k + 1]):
            j = loop_joint[idx]
            sign = float(loop_sign[idx])
            w = sign * twists[j, 2]
            vx, vy = sign * twists[j, 3], sign * twists[j, 4]
            g = groups[j]
            if g >= 0:  # Ad(g) xi: (w, R v + p x (0, 0, w))
                jac[3 * k, g] += w
                jac[3 * k + 1, g] += cg * vx - sg * vy + py * w
                jac[3 * k + 2, g] += sg * vx + cg * vy - px * w
            theta = q[j]
            if w != 0.0:  # exp: rotation by w theta, translation (I - R)(w x v) (w . v = 0 in the plane)
                ce, se = np.cos(w * theta), np.sin(w * theta)
                ax, ay = -w * vy, w * vx
                ex = ax - (ce * ax - se * ay)
                ey = ay - (se * ax + ce * ay)
            else:
                ce, se = 1.0, 0.0
                ex, ey = vx * theta, vy * theta
            px += cg * ex - sg * ey
            py += sg * ex + cg * ey
            cg, sg = cg * ce - sg * se, sg * ce + cg * se
        # log of the planar motion (as kernels.log_rigid): angle, then v = p - (w x p)/2 + D w x (w x p)
        t = np.arctan2(sg, cg)
        D = log_coefficient(abs(t))
        residual[3 * k] = t
        residual[3 * k + 1] = px + 0.5 * t * py - D * t * t * px
        residual[3 * k + 2] = py - 0.5 * t * px - D * t * t * py


@kernel(inline="always")
def qr_of_transpose(jac, M, beta, m, E):
    """Householder QR of ``J^T (m, E)`` in place in ``M`` (reflectors below the diagonal and in ``beta``, ``R``
    on and above it); returns ``det(Q)`` (``-1`` per reflection applied). ``m, E``: the sizes (literal
    constants at a call site for one loop, so that the loops unroll)."""
    for a in range(m):
        for e in range(E):
            M[a, e] = jac[e, a]
    det_q = 1.0
    for k in range(E):
        norm = 0.0
        for a in range(k, m):
            norm += M[a, k] * M[a, k]
        norm = np.sqrt(norm)
        if norm == 0.0:
            beta[k] = 0.0
            continue
        alpha = -norm if M[k, k] >= 0.0 else norm
        M[k, k] -= alpha  # the reflector v = x - alpha e_k, kept in place
        vv = 0.0
        for a in range(k, m):
            vv += M[a, k] * M[a, k]
        beta[k] = 2.0 / vv
        for c in range(k + 1, E):
            dot = 0.0
            for a in range(k, m):
                dot += M[a, k] * M[a, c]
            dot *= beta[k]
            for a in range(k, m):
                M[a, c] -= dot * M[a, k]
        # alpha onto the diagonal (R), the reflector's first entry into beta's second half.
        M[k, k], alpha = alpha, M[k, k]
        beta[E + k] = alpha
        det_q = -det_q
    return det_q


@kernel(inline="always")
def null_vector(M, beta, t, m, E):
    """``t = Q e_m``: the last column of the QR's ``Q`` (the null vector of ``J`` when it has full row rank)."""
    for a in range(m):
        t[a] = 0.0
    t[m - 1] = 1.0
    for k in range(E - 1, -1, -1):
        if beta[k] == 0.0:
            continue
        dot = beta[E + k] * t[k]
        for a in range(k + 1, m):
            dot += M[a, k] * t[a]
        dot *= beta[k]
        t[k] -= dot * beta[E + k]
        for a in range(k + 1, m):
            t[a] -= dot * M[a, k]


@kernel(inline="always")
def jacobi_sweeps(W, V, E):
    """One-sided Jacobi rotations (Hestenes) on the columns of ``W (E, E)``, applied to ``V`` too; returns the
    number of sweeps.

    Each pair whose cosine exceeds 1e-15 is rotated to orthogonality. The sweeps stop after one in which no
    pair's cosine exceeded 1e-8: Jacobi converges quadratically, so after such a sweep the columns are
    orthogonal to about 1e-16 (a rotation of one pair moves another pair's cosine by at most the product of
    two cosines of that sweep), and the column norms are the singular values to round-off; without a warm start
    (or on a hard case) it goes on to at most 60 sweeps.

    The rotation of a pair with squared norms ``alpha``, ``beta`` and inner product ``gamma`` is the classical
    one (``tan = sign(zeta) / (|zeta| + sqrt(1 + zeta^2))``, ``zeta = (beta - alpha) / (2 gamma)``), written
    with ``d = beta - alpha``, ``r = sqrt(d^2 + 4 gamma^2)``, ``D = |d| + r`` as ``cos = D / sqrt(2 r D)``,
    ``sin = 2 gamma sign(d) / sqrt(2 r D)``: two square roots and one division in a row instead of five slow
    operations (the rotations of a sweep depend on each other, so their latency is the cost).
    """
    for sweep in range(60):
        wide = False
        for p in range(E - 1):
            for r in range(p + 1, E):
                alpha, beta, gamma = 0.0, 0.0, 0.0
                for a in range(E):
                    alpha += W[a, p] * W[a, p]
                    beta += W[a, r] * W[a, r]
                    gamma += W[a, p] * W[a, r]
                gg, ab = gamma * gamma, alpha * beta
                if gg > 1e-16 * ab:
                    wide = True
                if gg <= 1e-30 * ab:
                    continue
                d = beta - alpha
                root = np.sqrt(d * d + 4.0 * gg)
                big = abs(d) + root
                inv = 1.0 / np.sqrt(2.0 * root * big)
                cos = big * inv
                sin = (2.0 * gamma if d >= 0.0 else -2.0 * gamma) * inv
                for a in range(E):
                    wp, wr = W[a, p], W[a, r]
                    W[a, p] = cos * wp - sin * wr
                    W[a, r] = sin * wp + cos * wr
                    vp, vr = V[a, p], V[a, r]
                    V[a, p] = cos * vp - sin * vr
                    V[a, r] = sin * vp + cos * vr
        if not wide:
            return sweep + 1
    return 60


@kernel(inline="always")
def singular_values(M, W, V, sigma):
    """:func:`triangle_singular_values` with the size read from ``M`` (``E = M.shape[1]``): the descending
    singular values of the upper triangle of ``M[:E]``, warm-started from ``V`` (updated in place)."""
    triangle_singular_values(M, W, V, sigma, M.shape[1])


@kernel(inline="always")
def triangle_singular_values(M, W, V, sigma, E):
    """Singular values (descending) of the triangular factor ``R`` (upper triangle of ``M[:E]``, ``E`` columns)
    by one-sided Jacobi rotations (Hestenes): the columns of ``W = R V`` are made orthogonal; their norms are the
    values.

    ``V`` (orthogonal, updated in place) is the previous point's right singular vectors: along a path they change
    little, so ``R V`` starts nearly orthogonal and one sweep or two finish it. It is re-orthonormalised first
    (Gram-Schmidt), so that rounding does not build up over a long path. ``E`` is a literal constant at a call
    site for one loop (the loops unroll).
    """
    orthonormalise(V, E)
    for a in range(E):
        for c in range(E):
            acc = 0.0
            for b in range(a, E):
                acc += M[a, b] * V[b, c]
            W[a, c] = acc
    jacobi_sweeps(W, V, E)
    for c in range(E):
        acc = 0.0
        for a in range(E):
            acc += W[a, c] * W[a, c]
        sigma[c] = np.sqrt(acc)
    for c in range(1, E):  # descending, by insertion (a handful of values)
        x = sigma[c]
        a = c - 1
        while a >= 0 and sigma[a] < x:
            sigma[a + 1] = sigma[a]
            a -= 1
        sigma[a + 1] = x


@kernel(inline="always")
def jacobian_rows(flat, q, work, m, E):
    """At joint values ``q``: the closure residual and Jacobian, the Householder QR of ``J^T`` and the tangent
    (``Q``'s last column), into ``work = (res, jac, M, beta, t)``; returns ``det(Q) det(R)`` (``R`` is the
    upper triangle of ``M[:E]``). ``m, E`` are the sizes (literal constants for one loop: the loops unroll)."""
    res, jac, M, beta, t = work
    planar_closure(flat, q, res, jac, m, E)
    det = qr_of_transpose(jac, M, beta, m, E)
    null_vector(M, beta, t, m, E)
    for e in range(E):
        det *= M[e, e]
    return det


@kernel(inline="always")
def warm_singular_values(R, W, V, history, sigma, E):
    """:func:`triangle_singular_values` of the triangle ``R`` warm-started from the right singular vectors
    extrapolated from the last three points (``V``, then ``history = (V_1, V_2)`` one and two points back):
    ``3 V - 3 V_1 + V_2`` (re-orthonormalised there). Along equal steps it is off by the third difference only,
    a few 1e-9 at a thousandth of a radian a step, and one Jacobi sweep mostly finishes the values."""
    V_1, V_2 = history
    for a in range(E):
        for c in range(E):
            x, x1 = V[a, c], V_1[a, c]
            V[a, c] = 3.0 * (x - x1) + V_2[a, c]
            V_2[a, c] = x1
            V_1[a, c] = x
    triangle_singular_values(R, W, V, sigma, E)


@kernel()
def closed_form_path(flat, plan, run):
    """The paper-mode path of a driver-and-dyads mechanism from its reference, in closed form, with its rows.

    ``flat = (twists, loop_joint, loop_sign, loop_ptr, groups)``: the closure arrays (every joint its own
    unknown). ``plan = (joint_int (n, 3): kind, before body, after body; joint_geo (n, 3): revolute point and
    omega_z, or prismatic direction; dyads (k, 7): j1, j2, j3, K1, B1, B2, K2; modes (k,); head: drive joint,
    driven body, number of bodies)``. ``run = (settings (N_SETTINGS,), t0 (m,), lo (m,), hi (m,), periodic (m,))``.

    Returns ``(count, status, u, sigma, res, tau, s)``: rows ``0 .. count - 1`` (row 0 the start), status
    :data:`CLEAN` when the target was reached, otherwise why the closed form gave up at row ``count``.

    Three passes over the points (the last two a block of :data:`BLOCK` points at a time), each a short loop,
    give what one pass point by point would: the positions (dyads and joint values, up to the
    first point where a dyad has no solution or a joint jumps); at each of those points the Jacobian, its QR and
    the tangent; then, point by point, the singular values (warm-started from the point before), the tangent's
    orientation, the test function and every check, in the order of the one-pass loop, so the same point ends
    the path with the same status.
    """
    groups = flat[4]
    joint_int, joint_geo, dyads, modes, head = plan
    settings, t0, lo, hi, periodic = run
    n = joint_int.shape[0]
    m = t0.shape[0]
    E = 3 * (flat[3].shape[0] - 1)
    steps = int(settings[S_STEPS])
    h, target, hmax = settings[S_STEP], settings[S_TARGET], settings[S_HMAX]
    min_ratio, min_drive, min_margin = settings[S_MIN_RATIO], settings[S_MIN_DRIVE], settings[S_MIN_MARGIN]
    det_basis = settings[S_DET_BASIS]
    drive, driven = head[0], head[1]
    g_drive = groups[drive]
    out_u = np.zeros((steps + 1, m))
    out_sigma = np.zeros((steps + 1, E))
    out_res = np.zeros(steps + 1)
    out_tau = np.zeros(steps + 1)
    out_s = np.zeros(steps + 1)
    # Pass 1: positions. Rows 0 .. last are placed; ``ended`` says why row last + 1 could not be (CLEAN: none).
    poses = np.zeros((head[2], 4))
    for b in range(head[2]):
        poses[b, 0] = 1.0  # the fixed body keeps the identity; every other body is placed at every point
    q = np.zeros(n)
    q_prev = np.zeros(n)
    last, ended = steps, CLEAN
    for k in range(1, steps + 1):
        drive_q = q_prev[drive] + h if k < steps else target
        place_driven(joint_int, joint_geo, drive, driven, drive_q, poses)
        for i in range(dyads.shape[0]):
            status = place_dyad(joint_int, joint_geo, dyads[i], modes[i], poses, min_margin)
            if status != CLEAN:
                ended = status
                break
        if (
            ended == CLEAN
            and joint_values(joint_int, joint_geo, poses, q_prev, q, drive, drive_q) > 0.5 * np.pi
        ):
            ended = JUMP
        if ended != CLEAN:
            last = k - 1
            break
        for j in range(n):
            out_u[k, groups[j]] = q[j]
            q_prev[j] = q[j]
    # Passes 2 and 3, a block of points at a time (the block's scratch stays in the cache).
    tri = np.empty((BLOCK, E, E))
    tangents = np.empty((BLOCK, m))
    work = (np.empty(E), np.empty((E, m)), np.empty((m, E)), np.empty(2 * E), np.empty(m))
    M, t = work[2], work[4]
    V = np.eye(E)  # the right singular vectors, carried from point to point
    history = (np.eye(E), np.eye(E))
    W = np.empty((E, E))
    sig = np.empty(E)
    t_prev = t0.copy()
    far = 0.0
    for first in range(0, last + 1, BLOCK):
        stop = min(first + BLOCK, last + 1)
        # Pass 2: at every point of the block, the Jacobian's triangle R, the tangent and det(Q) det(R).
        for k in range(first, stop):
            i = k - first
            for j in range(n):
                q[j] = out_u[k, groups[j]]
            if E == 3:  # one loop (a four-bar, a slider-crank): sizes known, the small loops unroll
                out_tau[k] = jacobian_rows(flat, q, work, 4, 3)
            else:
                out_tau[k] = jacobian_rows(flat, q, work, m, E)
            acc = 0.0
            for e in range(E):
                acc += work[0][e] * work[0][e]
                for c in range(E):
                    tri[i, e, c] = M[e, c]
            out_res[k] = np.sqrt(acc)
            for a in range(m):
                tangents[i, a] = t[a]
        # Pass 3: point by point, singular values, orientation, test function and the checks.
        for k in range(first, stop):
            i = k - first
            if E == 3:
                warm_singular_values(tri[i], W, V, history, sig, 3)
            else:
                warm_singular_values(tri[i], W, V, history, sig, E)
            dot = 0.0
            for a in range(m):
                dot += tangents[i, a] * t_prev[a]
            orient = -1.0 if dot < 0.0 else 1.0
            tau = det_basis * out_tau[k] * orient
            t_drive = tangents[i, g_drive]
            # Where the predictor-corrector would do more than step: hand over to it.
            if sig[E - 1] < min_ratio * sig[0] or abs(t_drive) < min_drive:
                return k, NEAR_SINGULAR, out_u, out_sigma, out_res, out_tau, out_s
            if k > 0 and (orient * t_drive) * h <= 0.0:
                return k, NEAR_SINGULAR, out_u, out_sigma, out_res, out_tau, out_s
            if k > 0 and tau * out_tau[k - 1] < 0.0:
                return k, SIGN_CHANGE, out_u, out_sigma, out_res, out_tau, out_s
            dist = 0.0
            wrapped = 0.0
            for g in range(m):
                x = out_u[k, g]
                if x < lo[g] or x > hi[g]:
                    return k, LIMIT, out_u, out_sigma, out_res, out_tau, out_s
                du = x - out_u[k - 1, g] if k > 0 else 0.0
                dist += du * du
                x = wrap_angle(x) if periodic[g] else x
                wrapped += x * x
            for a in range(m):
                t_prev[a] = orient * tangents[i, a]
            for e in range(E):
                out_sigma[k, e] = sig[e]
            out_tau[k] = tau
            out_s[k] = out_s[k - 1] + np.sqrt(dist) if k > 0 else 0.0
            if 0 < k < steps:  # the march's closed-path test (the target's step ends the march before it)
                d = np.sqrt(wrapped)
                far = max(far, d)
                if far > 4.0 * hmax and d < 1.5 * abs(h):
                    return k, CLOSED, out_u, out_sigma, out_res, out_tau, out_s
    if ended != CLEAN:
        return last + 1, ended, out_u, out_sigma, out_res, out_tau, out_s
    return steps + 1, CLEAN, out_u, out_sigma, out_res, out_tau, out_s
