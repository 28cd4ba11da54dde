"""Compiled closed-form positions of a planar mechanism made of a driver and dyads, with the rows a trace reports.

A planar mechanism that decomposes into a driver (one joint from the fixed body) and a sequence of dyads (Assur
groups of class II: two bodies, three joints, each dyad attached to bodies already placed) is solved at every
drive value without iterating: each dyad is a circle-circle (RRR), circle-line (RRP, PRR), line-line (PRP) or
rotating-line (RPR) intersection, the root taken on the side of the start configuration (its assembly mode).
At every point the planar closure residual and Jacobian are evaluated (the kept rows ``(omega_z, v_x, v_y)`` of
:func:`linkwork.kinematics.kernels.closure_pass`, in SE(2) arithmetic), and from them what the predictor-corrector
records: the singular values, the tangent (oriented continuously) and the signed test function of
:mod:`linkwork.kinematics.march`, ``det([U_r^T J; t])``, here ``det(U_r) det([J; t^T])`` (for one loop by
:func:`linkwork.kinematics.planar_rows.one_loop_rows`; for more, a Householder QR of ``J^T``, whose last column is
the tangent, and one-sided Jacobi on its triangle, ``det([J; t^T]) = det(Q) det(R)``).

The work is laid out as passes over all points (structure of arrays: every array's last index is the point), a
block of :data:`BLOCK` points at a time: the drive's poses, each dyad's two bodies, every joint's value, the
closure Jacobian and residual, the rows, the checks. Each pass is a loop over the points with straight-line code
(conditional expressions, no exceptions: ``error_model="numpy"``) on one-dimensional arrays, which LLVM vectorises;
the sines, cosines and arctangents are the branch-free ones of :mod:`linkwork.kinematics.trig` (numba's call the C
library one value at a time). The closure uses each revolute joint's cosine and sine as the bodies' poses give
them, not the sine and cosine of its reported value (they agree to an ulp: the value is read back from them).

The kernel gives up (returns a non-zero status) wherever the predictor-corrector's bookkeeping would act: a dyad
without a real solution or near its limit (a fold of the drive), a rank ratio below the local-minimum threshold
(a bifurcation or a higher-dimensional component nearby), a sign change of the test function, a joint limit, a
closed path before the target; the caller then traces with the predictor-corrector as before.

Body poses are planar displacements from the reference ``x -> R x + t``, kept as ``(cos, sin, t_x, t_y)`` (each
an array over the points); a joint between bodies ``a`` (before) and ``b`` (after) satisfies ``g_b = g_a exp(xi
q)`` (:func:`linkwork.kinematics.closure.body_poses`).

References
----------
W. W. Gan, S. Pellegrino, Proc. IMechE Part C 220 (2006), Eqs. (21), (23).
R. L. Norton, *Design of Machinery*, Ch. 4 (closed-form position analysis of four-bars and slider-cranks).
"""

from __future__ import annotations

import numpy as np

from linkwork.kernel_cache import kernel
from linkwork.kinematics.bidiagonal_rows import LANES
from linkwork.kinematics.kernels import log_coefficient
from linkwork.kinematics.planar_rows import multi_loop_rows, multi_loop_state, one_loop_rows
from linkwork.kinematics.small_svd import orthonormalise
from linkwork.kinematics.trig import SINCOS_LIMIT, atan2, sincos

#: Joint kinds in ``joint_int[:, 0]``.
REVOLUTE, PRISMATIC = 0, 1
#: Statuses returned by :func:`closed_form_path` (0: the target reached cleanly).
CLEAN, NO_SOLUTION, NEAR_SINGULAR, SIGN_CHANGE, CLOSED, LIMIT, JUMP, UNSUPPORTED = 0, 1, 2, 3, 4, 5, 6, 7
#: Internal mark of :func:`closed_form_path`'s scan: a clean point near the start, where the path may close.
NEAR_START = -1
#: Settings array layout of :func:`closed_form_path`.
S_STEP, S_TARGET, S_STEPS, S_HMAX, S_DET_BASIS, S_MIN_RATIO, S_MIN_DRIVE, S_MIN_MARGIN, S_LOOSE = (
    0,
    1,
    2,
    3,
    4,
    5,
    6,
    7,
    8,
)
N_SETTINGS = 9
TWO_PI = 2.0 * np.pi
#: The most points a block of :func:`closed_form_path` holds (a block's arrays stay in the second-level cache;
#: :func:`block_width` shares a path's steps evenly among its blocks).
BLOCK = 256


@kernel(inline="always")
def apply_pose(poses: np.ndarray, body: int, k: int, x: float, y: float) -> tuple[float, float]:
    """The point ``(x, y)`` of ``body`` (reference coordinates) where the body's pose ``(cos, sin, tx, ty)`` at
    point ``k`` puts it."""
    c, s = poses[body, 0, k], poses[body, 1, k]
    return c * x - s * y + poses[body, 2, k], s * x + c * y + poses[body, 3, k]


@kernel(inline="always")
def set_pose(poses, body, k, c, s, x, y, X, Y):
    """Pose of ``body`` at point ``k`` turned by the rotation ``(c, s)`` and taking its reference point ``(x, y)``
    to ``(X, Y)``."""
    poses[body, 0, k] = c
    poses[body, 1, k] = s
    poses[body, 2, k] = X - (c * x - s * y)
    poses[body, 3, k] = Y - (s * x + c * y)


@kernel(inline="always")
def set_pose_turning(poses, body, k, x, y, X, Y, ux, uy, vx, vy):
    """Pose of ``body`` at point ``k`` taking its reference point ``(x, y)`` to ``(X, Y)`` and turning the
    reference vector ``(ux, uy)`` onto the direction of ``(vx, vy)``."""
    scale = 1.0 / np.sqrt((ux * ux + uy * uy) * (vx * vx + vy * vy))
    set_pose(poses, body, k, (ux * vx + uy * vy) * scale, (ux * vy - uy * vx) * scale, x, y, X, Y)


@kernel(inline="always")
def guide_line(joint_geo, poses, j, known, k, px, py):
    """The line a point ``(px, py)`` of the body that prismatic joint ``j`` joins to ``known`` runs on at point
    ``k``: its point and unit direction where ``known``'s pose puts them (the two bodies keep one orientation)."""
    X, Y = apply_pose(poses, known, k, px, py)
    c, s = poses[known, 0, k], poses[known, 1, k]
    dx, dy = joint_geo[j, 0], joint_geo[j, 1]
    return X, Y, c * dx - s * dy, s * dx + c * dy


@kernel(inline="always")
def first_status(status: np.ndarray, k: int, code: int) -> None:
    """Keep the first reason a point failed (the dyads are placed in order; a later one sees NaN or garbage)."""
    status[k] = code if status[k] == CLEAN else status[k]


@kernel(inline="always", error_model="numpy")
def place_driver(joint_int, joint_geo, head, drive_q, poses):
    """Pose of the body the drive joint moves at every point ``k >= 1`` (the other body of the drive joint is
    fixed: identity pose), the drive's values ``drive_q``; the rotation by the branch-free
    :func:`~linkwork.kinematics.trig.sincos` in one vectorised loop."""
    drive, driven = head[0], head[1]
    sign = 1.0 if joint_int[drive, 2] == driven else -1.0  # g_after = g_before exp(xi q)
    K = drive_q.shape[0]
    if joint_int[drive, 0] == REVOLUTE:
        turn = sign * joint_geo[drive, 2]
        px, py = joint_geo[drive, 0], joint_geo[drive, 1]
        for k in range(1, K):
            c, s = sincos(turn * drive_q[k])
            set_pose(poses, driven, k, c, s, px, py, px, py)
        for k in range(1, K):  # beyond the reduction's range: the C library (never on a sane drive)
            if not abs(turn * drive_q[k]) <= SINCOS_LIMIT:
                phi = turn * drive_q[k]
                set_pose(poses, driven, k, np.cos(phi), np.sin(phi), px, py, px, py)
    else:
        dx, dy = sign * joint_geo[drive, 0], sign * joint_geo[drive, 1]
        for k in range(1, K):
            set_pose(poses, driven, k, 1.0, 0.0, 0.0, 0.0, drive_q[k] * dx, drive_q[k] * dy)


@kernel(inline="always", error_model="numpy")
def place_rrr(joint_geo, dyad, mode, poses, min_margin, status):
    """An RRR dyad ``(j1, j2, j3, K1, B1, B2, K2)`` at every point ``k >= 1``: two circles about the placed
    pivots, the root on the side ``mode``; ``status[k]`` set where there is none or it is within ``min_margin``
    (relative) of the double root. Straight-line code: the loop over points vectorises."""
    j1, j2, j3, K1, B1, B2, K2 = dyad[0], dyad[1], dyad[2], dyad[3], dyad[4], dyad[5], dyad[6]
    p1x, p1y, p3x, p3y = joint_geo[j1, 0], joint_geo[j1, 1], joint_geo[j3, 0], joint_geo[j3, 1]
    p2x, p2y = joint_geo[j2, 0], joint_geo[j2, 1]
    L1s = (p2x - p1x) ** 2 + (p2y - p1y) ** 2
    L2s = (p2x - p3x) ** 2 + (p2y - p3y) ** 2
    floor = min_margin * min_margin * L1s
    for k in range(1, poses.shape[2]):
        X1, Y1 = apply_pose(poses, K1, k, p1x, p1y)
        X3, Y3 = apply_pose(poses, K2, k, p3x, p3y)
        Dx, Dy = X3 - X1, Y3 - Y1
        d2 = Dx * Dx + Dy * Dy
        inv_d = 1.0 / np.sqrt(d2)  # one division for the three below
        a = (L1s - L2s + d2) * (0.5 * inv_d)
        h2 = L1s - a * a
        h = np.sqrt(max(h2, 0.0))
        code = NO_SOLUTION if (d2 == 0.0) | (h2 < 0.0) else (NEAR_SINGULAR if h * h < floor else CLEAN)
        first_status(status, k, code)
        X2 = X1 + (a * Dx - mode * h * Dy) * inv_d
        Y2 = Y1 + (a * Dy + mode * h * Dx) * inv_d
        set_pose_turning(poses, B1, k, p1x, p1y, X1, Y1, p2x - p1x, p2y - p1y, X2 - X1, Y2 - Y1)
        set_pose_turning(poses, B2, k, p3x, p3y, X3, Y3, p2x - p3x, p2y - p3y, X2 - X3, Y2 - Y3)


@kernel(inline="always", error_model="numpy")
def place_prp(joint_geo, dyad, poses, min_margin, status):
    """A PRP dyad at every point ``k >= 1``: the middle pivot where the two guide lines cross."""
    j1, j2, j3, K1, B1, B2, K2 = dyad[0], dyad[1], dyad[2], dyad[3], dyad[4], dyad[5], dyad[6]
    p2x, p2y = joint_geo[j2, 0], joint_geo[j2, 1]
    d1x, d1y, d3x, d3y = joint_geo[j1, 0], joint_geo[j1, 1], joint_geo[j3, 0], joint_geo[j3, 1]
    for k in range(1, poses.shape[2]):
        c1, s1, c3, s3 = poses[K1, 0, k], poses[K1, 1, k], poses[K2, 0, k], poses[K2, 1, k]
        Ax, Ay = apply_pose(poses, K1, k, p2x, p2y)  # the guide lines: a point and the unit direction
        Cx, Cy = apply_pose(poses, K2, k, p2x, p2y)
        ax, ay = c1 * d1x - s1 * d1y, s1 * d1x + c1 * d1y
        cx, cy = c3 * d3x - s3 * d3y, s3 * d3x + c3 * d3y
        det = ax * cy - ay * cx
        first_status(status, k, NEAR_SINGULAR if abs(det) < min_margin else CLEAN)
        along = ((Cx - Ax) * cy - (Cy - Ay) * cx) / det
        X2, Y2 = Ax + along * ax, Ay + along * ay
        set_pose(poses, B1, k, c1, s1, p2x, p2y, X2, Y2)
        set_pose(poses, B2, k, c3, s3, p2x, p2y, X2, Y2)


@kernel(inline="always", error_model="numpy")
def place_rrp(joint_int, joint_geo, dyad, mode, poses, min_margin, status):
    """An RRP or PRR dyad at every point ``k >= 1``: a circle about the revolute side's pivot and the prismatic
    side's line."""
    j1, j2, j3, K1, B1, B2, K2 = dyad[0], dyad[1], dyad[2], dyad[3], dyad[4], dyad[5], dyad[6]
    if joint_int[j1, 0] == REVOLUTE:
        jr, Kr, Br, jp, Kp, Bp = j1, K1, B1, j3, K2, B2
    else:
        jr, Kr, Br, jp, Kp, Bp = j3, K2, B2, j1, K1, B1
    p2x, p2y = joint_geo[j2, 0], joint_geo[j2, 1]
    prx, pry = joint_geo[jr, 0], joint_geo[jr, 1]
    Ls = (p2x - prx) ** 2 + (p2y - pry) ** 2
    floor = min_margin * min_margin * Ls
    for k in range(1, poses.shape[2]):
        Xr, Yr = apply_pose(poses, Kr, k, prx, pry)
        Qx, Qy, ex, ey = guide_line(joint_geo, poses, jp, Kp, k, p2x, p2y)
        b = ex * (Qx - Xr) + ey * (Qy - Yr)
        c = (Qx - Xr) ** 2 + (Qy - Yr) ** 2 - Ls
        disc = b * b - c
        first_status(status, k, NO_SOLUTION if disc < 0.0 else (NEAR_SINGULAR if disc < floor else CLEAN))
        s = -b + mode * np.sqrt(max(disc, 0.0))
        X2, Y2 = Qx + s * ex, Qy + s * ey
        set_pose_turning(poses, Br, k, prx, pry, Xr, Yr, p2x - prx, p2y - pry, X2 - Xr, Y2 - Yr)
        set_pose(poses, Bp, k, poses[Kp, 0, k], poses[Kp, 1, k], p2x, p2y, X2, Y2)


@kernel(inline="always", error_model="numpy")
def place_rpr(joint_geo, dyad, mode, poses, min_margin, status):
    """An RPR dyad at every point ``k >= 1``: ``B1`` and ``B2`` turn together, ``B2``'s pivot on ``B1``'s line."""
    j1, j2, j3, K1, B1, B2, K2 = dyad[0], dyad[1], dyad[2], dyad[3], dyad[4], dyad[5], dyad[6]
    p1x, p1y, p3x, p3y = joint_geo[j1, 0], joint_geo[j1, 1], joint_geo[j3, 0], joint_geo[j3, 1]
    # The slide's direction in B1 (the before body of j2 may be either dyad body: a line is a line).
    dx, dy = joint_geo[j2, 0], joint_geo[j2, 1]
    h0 = dx * (p3y - p1y) - dy * (p3x - p1x)  # signed distance of the line from p1, constant in B1
    floor = min_margin * min_margin
    for k in range(1, poses.shape[2]):
        X1, Y1 = apply_pose(poses, K1, k, p1x, p1y)
        X3, Y3 = apply_pose(poses, K2, k, p3x, p3y)
        Dx, Dy = X3 - X1, Y3 - Y1
        rho2 = Dx * Dx + Dy * Dy
        along2 = rho2 - h0 * h0
        near = along2 < floor * rho2
        first_status(
            status, k, NO_SOLUTION if (along2 < 0.0) | (rho2 == 0.0) else (NEAR_SINGULAR if near else CLEAN)
        )
        along = mode * np.sqrt(max(along2, 0.0))
        # The turn takes the line's direction d (at angle psi from D in B1's frame) onto D's direction:
        # e^{i phi} = (D / rho) conj(d) conj(e^{i psi}), e^{i psi} = (along + i h0) / rho.
        cx, cy = Dx * dx + Dy * dy, Dy * dx - Dx * dy  # D conj(d)
        c = (cx * along + cy * h0) / rho2
        s = (cy * along - cx * h0) / rho2
        set_pose(poses, B1, k, c, s, p1x, p1y, X1, Y1)
        set_pose(poses, B2, k, c, s, p3x, p3y, X3, Y3)


@kernel(inline="always", error_model="numpy")
def place_dyads(joint_int, joint_geo, dyads, modes, poses, min_margin, status):
    """Every dyad of the plan at every point ``k >= 1``, in solving order (each a loop over the points); sets
    ``status[k]`` to the first dyad's failure at point ``k`` (:data:`UNSUPPORTED` for a dyad of no solved kind)."""
    for i in range(dyads.shape[0]):
        dyad = dyads[i]
        k1, k2, k3 = joint_int[dyad[0], 0], joint_int[dyad[1], 0], joint_int[dyad[2], 0]
        if k2 == REVOLUTE and k1 == REVOLUTE and k3 == REVOLUTE:
            place_rrr(joint_geo, dyad, modes[i], poses, min_margin, status)
        elif k2 == REVOLUTE and k1 == PRISMATIC and k3 == PRISMATIC:
            place_prp(joint_geo, dyad, poses, min_margin, status)
        elif k2 == REVOLUTE:
            place_rrp(joint_int, joint_geo, dyad, modes[i], poses, min_margin, status)
        elif k1 == REVOLUTE and k3 == REVOLUTE:
            place_rpr(joint_geo, dyad, modes[i], poses, min_margin, status)
        else:
            for k in range(1, poses.shape[2]):
                first_status(status, k, UNSUPPORTED)


@kernel(inline="always", error_model="numpy")
def read_angles(ca, sa, cb, sb, rel, omega, q):
    """A revolute joint between bodies of rotations ``(ca, sa)`` and ``(cb, sb)`` at every point: ``rel = (c,
    s)`` of ``R_a^T R_b``, and (unless ``q`` is empty) ``q[k] = omega atan2(s[k], c[k])`` by the branch-free
    :func:`~linkwork.kinematics.trig.atan2`."""
    c, s = rel[0], rel[1]
    if q.shape[0] == 0:
        for k in range(c.shape[0]):
            c[k] = ca[k] * cb[k] + sa[k] * sb[k]
            s[k] = ca[k] * sb[k] - sa[k] * cb[k]
        return
    for k in range(c.shape[0]):
        ck = ca[k] * cb[k] + sa[k] * sb[k]
        sk = ca[k] * sb[k] - sa[k] * cb[k]
        c[k] = ck
        s[k] = sk
        q[k] = omega * atan2(sk, ck)


@kernel(inline="always", error_model="numpy")
def angle_steps(q, turns, jump):
    """The step of an angle read in ``[-pi, pi]`` into each point ``k >= 1``, wrapped onto ``[-pi, pi)``: ``turns[k]``
    the whole turns the wrapping added (-1, 0, 1), ``jump[k]`` raised to the wrapped step's size where larger;
    returns the number of points with a turn."""
    count = 0
    for k in range(1, q.shape[0]):
        step = q[k] - q[k - 1]
        turn = -1.0 if step >= np.pi else (1.0 if step < -np.pi else 0.0)
        size = abs(step + TWO_PI * turn)
        turns[k] = turn
        jump[k] = size if size > jump[k] else jump[k]
        count += 0 if turn == 0.0 else 1
    return count


@kernel(inline="always", error_model="numpy")
def slide_values(ca, sa, ta, tb, dx, dy, q):
    """``q[k] = d . R_a^T (t_b - t_a)``: a prismatic joint's value along its unit direction ``d = (dx, dy)`` from
    the rotation ``(ca, sa)`` of its before body and both bodies' translations ``ta``, ``tb`` (``(2, K)``)."""
    for k in range(q.shape[0]):
        tx, ty = tb[0, k] - ta[0, k], tb[1, k] - ta[1, k]
        q[k] = dx * (ca[k] * tx + sa[k] * ty) + dy * (-sa[k] * tx + ca[k] * ty)


@kernel(inline="always", error_model="numpy")
def joint_values(joint_int, joint_geo, poses, drive, drive_q, rel, q, jump, carry):
    """Every joint's value at every point from its bodies' poses: ``q[j, k]``; revolute ones continued from
    point to point (each point's step wrapped onto ``[-pi, pi)``), the drive's ``drive_q``. ``rel[j] = (cos,
    sin)`` of a joint's relative rotation ``R_a^T R_b`` (``Rz(omega_z q)`` for a revolute joint, the identity for
    a prismatic one); ``jump[k]``: the largest step of a joint into point ``k >= 1`` (the drive's wrapped for a
    revolute drive), as the point-by-point march reads it.

    ``carry = (start, total, turns)``: each joint's value at point 0 (the last point of the block before), the
    whole turns its angle has made there (updated to the last point's, for the next block), and scratch ``(K,)``.

    The angles come from the branch-free :func:`~linkwork.kinematics.trig.atan2` (vectorised); a revolute
    joint's value is ``raw + 2 pi n`` with ``raw`` the angle read back and ``n`` the count of turns, a running sum
    of the integer steps (so no round-off accumulates along the path).
    """
    start, total, turns = carry
    K = poses.shape[2]
    for j in range(joint_int.shape[0]):
        a, b = joint_int[j, 1], joint_int[j, 2]
        revolute = joint_int[j, 0] == REVOLUTE
        if revolute:  # also the drive's relative rotation (the closure's exp reads it; its value is drive_q)
            angles = q[j, :0] if j == drive else q[j]
            read_angles(poses[a, 0], poses[a, 1], poses[b, 0], poses[b, 1], rel[j], joint_geo[j, 2], angles)
        else:
            rel[j, 0, :] = 1.0
            rel[j, 1, :] = 0.0
        if j == drive:
            q[j, :] = drive_q
            for k in range(1, K):
                step = drive_q[k] - drive_q[k - 1]
                wrapped = step - TWO_PI * np.floor((step + np.pi) * (1.0 / TWO_PI))  # any number of turns
                size = abs(wrapped if revolute else step)
                jump[k] = size if size > jump[k] else jump[k]
        elif revolute:
            n = total[j]
            if angle_steps(q[j], turns, jump) > 0:
                for k in range(1, K):  # the running count of turns (whole numbers: exact)
                    n += turns[k]
                    q[j, k] += TWO_PI * n
            elif n != 0.0:
                for k in range(1, K):
                    q[j, k] += TWO_PI * n
            total[j] = n
        else:
            slide_values(
                poses[a, 0], poses[a, 1], poses[a, 2:], poses[b, 2:], joint_geo[j, 0], joint_geo[j, 1], q[j]
            )
            for k in range(1, K):
                size = abs(q[j, k] - q[j, k - 1])
                jump[k] = size if size > jump[k] else jump[k]
        q[j, 0] = start[j]


@kernel(inline="always", error_model="numpy")
def turn_column(product, col1, col2, rel, sign, w, vx, vy, fresh=False):
    """A revolute loop joint at every point: rows 2 and 3 of its Jacobian column ``Ad(g) xi = (w, R v + p x (0,
    0, w))`` (G&P Eq. (21)) added to ``col1``, ``col2`` (``fresh``: written, as added to zeros), with ``g =
    product = (cos, sin, p_x, p_y)`` the loop's product before the joint, then ``g <- g exp(xi q)``: the rotation
    ``rel = (c, sign s)``, the translation ``(I - R)(w x v)`` (``w . v = 0`` in the plane)."""
    c, s, px, py = product[0], product[1], product[2], product[3]
    rc, rs = rel[0], rel[1]
    ax, ay = -w * vy, w * vx
    if fresh:  # 0 + x, as the sum into zeros gives (a zero's sign included), without reading the column
        for k in range(c.shape[0]):
            ck, sk, xk, yk = c[k], s[k], px[k], py[k]
            col1[k] = 0.0 + (ck * vx - sk * vy + yk * w)
            col2[k] = 0.0 + (sk * vx + ck * vy - xk * w)
            cr, sr = rc[k], sign * rs[k]
            ex = ax - (cr * ax - sr * ay)
            ey = ay - (sr * ax + cr * ay)
            px[k] = xk + (ck * ex - sk * ey)
            py[k] = yk + (sk * ex + ck * ey)
            c[k] = ck * cr - sk * sr
            s[k] = sk * cr + ck * sr
        return
    for k in range(c.shape[0]):
        ck, sk, xk, yk = c[k], s[k], px[k], py[k]
        col1[k] += ck * vx - sk * vy + yk * w
        col2[k] += sk * vx + ck * vy - xk * w
        cr, sr = rc[k], sign * rs[k]
        ex = ax - (cr * ax - sr * ay)
        ey = ay - (sr * ax + cr * ay)
        px[k] = xk + (ck * ex - sk * ey)
        py[k] = yk + (sk * ex + ck * ey)
        c[k] = ck * cr - sk * sr
        s[k] = sk * cr + ck * sr


@kernel(inline="always", error_model="numpy")
def slide_column(product, col1, col2, q, vx, vy, fresh=False):
    """A prismatic loop joint at every point: its Jacobian column's rows 2 and 3 (``R v``) added to ``col1``,
    ``col2`` (``fresh``: written, as added to zeros), then ``g <- g exp(xi q)``: the translation ``v q``."""
    c, s, px, py = product[0], product[1], product[2], product[3]
    if fresh:
        for k in range(c.shape[0]):
            ck, sk = c[k], s[k]
            col1[k] = 0.0 + (ck * vx - sk * vy)
            col2[k] = 0.0 + (sk * vx + ck * vy)
            ex, ey = vx * q[k], vy * q[k]
            px[k] += ck * ex - sk * ey
            py[k] += sk * ex + ck * ey
        return
    for k in range(c.shape[0]):
        ck, sk = c[k], s[k]
        col1[k] += ck * vx - sk * vy
        col2[k] += sk * vx + ck * vy
        ex, ey = vx * q[k], vy * q[k]
        px[k] += ck * ex - sk * ey
        py[k] += sk * ex + ck * ey


@kernel(inline="always", error_model="numpy")
def loop_log(c, s, px, py, angle, share):
    """The twist ``log(g)`` of the loop product at every point (as ``kernels.log_rigid``): the angle ``t``, then
    ``v = p - (w x p)/2 + D w x (w x p)`` with ``D`` by its Taylor series (a closed loop turns by round-off);
    ``share[k]`` its squared norm, ``angle[k] = t``. Returns the number of points where ``|t| >= 1e-2`` (there
    the series does not hold: the caller uses :func:`~linkwork.kinematics.kernels.log_coefficient`)."""
    # A closed loop's product turns by round-off: there atan2(s, c) = s / c to the last bit (fdlibm's atan(z) is
    # z for |z| < 2^-27 and the branch-free atan2 returns it so), one division instead of the arctangent. The
    # arctangent only where some point turns more (a loop that does not close: never after a dyad solve).
    wide = 0
    far = 0
    for k in range(c.shape[0]):
        ck, sk = c[k], s[k]
        far += 0 if (ck > 0.0) & (abs(sk) < 1e-9 * ck) else 1
        t = sk / ck
        t2 = t * t
        D = 1.0 / 12.0 + t2 * (1.0 / 720.0) + t2 * t2 * (1.0 / 30240.0) + t2 * t2 * t2 * (1.0 / 1209600.0)
        x = px[k] + 0.5 * t * py[k] - D * t2 * px[k]
        y = py[k] - 0.5 * t * px[k] - D * t2 * py[k]
        angle[k] = t
        share[k] = t2 + x * x + y * y
    if far == 0:
        return 0
    for k in range(c.shape[0]):
        t = atan2(s[k], c[k])
        t2 = t * t
        # (products by the reciprocals, folded at compile time: no division in the loop)
        D = 1.0 / 12.0 + t2 * (1.0 / 720.0) + t2 * t2 * (1.0 / 30240.0) + t2 * t2 * t2 * (1.0 / 1209600.0)
        x = px[k] + 0.5 * t * py[k] - D * t2 * px[k]
        y = py[k] - 0.5 * t * px[k] - D * t2 * py[k]
        angle[k] = t
        share[k] = t2 + x * x + y * y
        wide += 0 if abs(t) < 1e-2 else 1
    return wide


@kernel(error_model="numpy")
def planar_closure(flat, rel, q, jac, res, scratch):
    """Planar closure residual ``(omega_z, v_x, v_y)`` of ``log(P)`` per loop and its ``(E, m)`` Jacobian in the
    unknowns at every point ``k < K``: ``jac (E, m, K)`` (point index last), ``res (K,)`` the residual's norm;
    ``flat = (twists, loop_joint, loop_sign, loop_ptr, groups)``, ``q (n, K)`` the joint values, ``rel (n, 2,
    K)`` each joint's relative rotation (from :func:`joint_values`); ``scratch = (product (4, K), angle (K,),
    share (K,))``.

    :func:`linkwork.kinematics.kernels.closure_pass` with rows ``(2, 3, 4)`` for twists in the plane, in SE(2):
    columns ``s Ad(g) xi`` (G&P Eq. (21)), the residual the twist ``log(g)`` of the loop product (Eq. (23)). A
    revolute joint's ``exp`` uses the cosine and sine of its relative rotation as the bodies' poses give them,
    which equal those of its reported value to an ulp (the value is read back from them by an ``atan2``): no
    sine or cosine is evaluated here. Each step is one loop over the points on 1-d arrays (straight-line code
    that vectorises). The entries that do not depend on the point (row ``omega_z`` and the zeros) are written by
    :func:`closure_constants`, the others by :func:`closure_columns`.
    """
    fresh = np.empty(flat[1].shape[0], dtype=np.bool_)
    closure_constants(flat, jac, fresh)
    closure_columns(flat, rel, q, jac, res, scratch, fresh)


@kernel(error_model="numpy")
def closure_constants(flat, jac, fresh):
    """The entries of the planar closure Jacobian ``jac (E, m, K)`` that are the same at every point: each loop's
    ``omega_z`` row (``s w`` summed over the loop's joints of each unknown) and zero everywhere else, for
    :func:`closure_columns` to fill in the rest (its rows ``v_x, v_y`` of each loop's columns) at every block of
    points; ``fresh[idx]`` whether loop entry ``idx`` is the first of its loop with its unknown (its column is
    written, the others' added)."""
    twists, loop_joint, loop_sign, loop_ptr, groups = flat
    E = jac.shape[0]
    jac[:] = 0.0
    for loop in range(E // 3):
        for idx in range(loop_ptr[loop], loop_ptr[loop + 1]):
            j = loop_joint[idx]
            g = groups[j]
            seen = False
            for before in range(loop_ptr[loop], idx):
                seen = seen or groups[loop_joint[before]] == g
            fresh[idx] = g >= 0 and not seen
            if g >= 0:
                jac[3 * loop, g, :] += float(loop_sign[idx]) * twists[j, 2]


@kernel(inline="always", error_model="numpy")
def closure_columns(flat, rel, q, jac, res, scratch, fresh):
    """:func:`planar_closure` at a block of points into a ``jac`` whose constant entries
    :func:`closure_constants` wrote (once, for every block): each loop's rows ``v_x, v_y`` (the loop's columns
    only) and the residual ``res``."""
    twists, loop_joint, loop_sign, loop_ptr, groups = flat
    E, K = jac.shape[0], jac.shape[2]
    # the loop product's partial (cos, sin, p_x, p_y); its log's angle and norm
    product, angle, share = scratch
    res[:] = 0.0
    for loop in range(E // 3):
        c, s, px, py = product[0], product[1], product[2], product[3]
        c[:] = 1.0
        s[:] = 0.0
        px[:] = 0.0
        py[:] = 0.0
        for idx in range(loop_ptr[loop], loop_ptr[loop + 1]):
            j = loop_joint[idx]
            sign = float(loop_sign[idx])
            w = sign * twists[j, 2]
            vx, vy = sign * twists[j, 3], sign * twists[j, 4]
            # every joint is its own unknown in a dyad plan; a fixed one would add to a scratch column
            g = groups[j]
            col1, col2 = (jac[3 * loop + 1, g], jac[3 * loop + 2, g]) if g >= 0 else (angle, share)
            if w != 0.0:
                turn_column(product, col1, col2, rel[j], sign, w, vx, vy, fresh[idx])
            else:
                slide_column(product, col1, col2, q[j], vx, vy, fresh[idx])
        if loop_log(c, s, px, py, angle, share) > 0:  # a loop that does not close (never after a dyad solve)
            for k in range(K):
                t = angle[k]
                if abs(t) >= 1e-2:
                    D = log_coefficient(abs(t))
                    x = px[k] + 0.5 * t * py[k] - D * t * t * px[k]
                    y = py[k] - 0.5 * t * px[k] - D * t * t * py[k]
                    share[k] = t * t + x * x + y * y
        res += share
    for k in range(K):
        res[k] = np.sqrt(res[k])


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


@kernel(inline="always")
def rows_at_point(jac, k, M, beta, t, W, V, history, sig, m, E):
    """At point ``k`` of ``jac (E, m, K)``: the Householder QR of ``J^T`` in ``M``, the tangent ``t`` (``Q``'s last
    column) and the singular values ``sig`` (warm-started, :func:`warm_singular_values`); returns
    ``det([J; t^T]) = det(Q) det(R)``. ``m, E``: the sizes (literal constants for one loop: the loops unroll)."""
    det = qr_of_transpose(jac[:, :, k], M, beta, m, E)
    null_vector(M, beta, t, m, E)
    for e in range(E):
        det *= M[e, e]
    warm_singular_values(M, W, V, history, sig, E)
    return det


@kernel()
def rows_at_points(jac, sigma, tangent, raw_tau, begin, state):
    """The rows of :func:`closed_form_path` from the Jacobians ``jac (E, m, K)``, point by point from ``begin``:
    ``sigma (E, K)`` descending, ``tangent (m, K)`` a unit null vector (either sign), ``raw_tau (K,) = det([J;
    t^T])`` for that tangent; returns 0 (the number of points without a clean answer, as the batched one-loop
    kernel reports).

    The singular values by one-sided Jacobi on the triangle of a Householder QR of ``J^T``, warm-started from the
    right singular vectors extrapolated from the last three points: ``state = (V, V_1, V_2)`` (the identity at the
    start), carried from one block of points to the next."""
    E, m, K = jac.shape[0], jac.shape[1], jac.shape[2]
    M, beta, t = np.empty((m, E)), np.empty(2 * E), np.empty(m)
    W = np.empty((E, E))
    V, V_1, V_2 = state
    history = (V_1, V_2)
    sig = np.empty(E)
    for k in range(begin, K):
        if E == 3 and m == 4:  # one loop (a four-bar, a slider-crank): sizes known, the small loops unroll
            raw_tau[k] = rows_at_point(jac, k, M, beta, t, W, V, history, sig, 4, 3)
        else:
            raw_tau[k] = rows_at_point(jac, k, M, beta, t, W, V, history, sig, m, E)
        for e in range(E):
            sigma[e, k] = sig[e]
        for a in range(m):
            tangent[a, k] = t[a]
    return 0


@kernel(inline="always")
def zero_tail(count, code, outs):
    """``(count, code, *outs, False)`` with every output's rows not written set to zero: those after ``count``
    (after ``count + 1`` for :data:`CLOSED`, whose row ``count`` is stored though the path ends before it); the
    full-rank verdict is left False (a path handed over has no rank to report)."""
    out_angles, out_sigma, out_res, out_tau, out_s = outs
    tail = count + 1 if code == CLOSED else count
    out_angles[tail:] = 0.0
    out_sigma[tail:] = 0.0
    out_res[tail:] = 0.0
    out_tau[tail:] = 0.0
    out_s[tail:] = 0.0
    return count, code, out_angles, out_sigma, out_res, out_tau, out_s, False


@kernel(error_model="numpy")
def closed_form_path(flat, plan, run):
    """The paper-mode path of a driver-and-dyads mechanism from its reference, in closed form, with its rows.

    ``flat = (twists, loop_joint, loop_sign, loop_ptr, groups)``: the closure arrays (every joint its own
    unknown). ``plan = (joint_int (n, 3): kind, before body, after body; joint_geo (n, 3): revolute point and
    omega_z, or prismatic direction; dyads (k, 7): j1, j2, j3, K1, B1, B2, K2; modes (k,); head: drive joint,
    driven body, number of bodies; offsets (n,): every joint's value at the reference)``. ``run = (settings
    (N_SETTINGS,), t0 (m,), lo (m,), hi (m,), periodic (m,))``.

    Returns ``(count, status, angles, sigma, res, tau, s, full_rank)``: rows ``0 .. count - 1`` (row 0 the start),
    status :data:`CLEAN` when the target was reached, otherwise why the closed form gave up at row ``count``.
    ``angles (N, n)`` are the joint values (``offsets + q``, joint order: the trace's angles, what numpy's ``u[:,
    groups] + offsets`` gives); ``full_rank`` whether every row of ``sigma`` passes
    :func:`~linkwork.kinematics.kernels.every_row_full_rank` with ``settings[S_LOOSE]`` (False unless CLEAN).

    Passes over all points, each array indexed by the point last (structure of arrays), each pass a loop over
    the points with straight-line bodies that vectorise: the drive's poses, each dyad's two bodies, every joint's
    value (then a scan finds the first point a dyad could not be placed or a joint jumped); the closure residual
    and Jacobian at those points; the tangent, test function and singular values from the Jacobians; then the
    tangent's orientation (a recurrence: a scalar loop of two integer operations a point), every check at every
    point (vectorised, marking the points near the start where the path may close), and a scan in the order of the
    point-by-point march that runs the arclength's sum and the largest distance from the start and stops at the
    first failing or closing point (``far``, the arclength and the orientation carry from point to point), so
    the same point ends the path with the same status. The outputs' rows are written once each (not zero-filled
    first); those after the count are zeroed on an early return.
    """
    groups = flat[4]
    joint_int, joint_geo, dyads, modes, head, offsets = plan
    settings, t0, lo, hi, periodic = run
    n = joint_int.shape[0]
    m = t0.shape[0]
    E = 3 * (flat[3].shape[0] - 1)
    steps = int(settings[S_STEPS])
    h, target, hmax = settings[S_STEP], settings[S_TARGET], settings[S_HMAX]
    min_ratio, min_drive, min_margin = settings[S_MIN_RATIO], settings[S_MIN_DRIVE], settings[S_MIN_MARGIN]
    det_basis, loose = settings[S_DET_BASIS], settings[S_LOOSE]
    drive = head[0]
    g_drive = groups[drive]
    # Not zero-filled: every row up to the count is written; the rows after it are zeroed on return.
    out_angles = np.empty((steps + 1, n))
    out_sigma = np.empty((steps + 1, E))
    out_res = np.empty(steps + 1)
    out_tau = np.empty(steps + 1)
    out_s = np.empty(steps + 1)
    outs = (out_angles, out_sigma, out_res, out_tau, out_s)
    full_rank = E > 0  # every stored row's ratios above loose (kernels.every_row_full_rank), so far
    # A block's arrays: column i is point first - 1 + i; column 0 the block before's last point (the start for
    # the first block), columns 1 .. BLOCK this block's points (past the last point: harmless extrapolation).
    block = block_width(steps)
    C = block + 1
    svd_state = multi_loop_state(E)  # the Jacobi warm start, from block to block (more loops)
    # Every float array of a block is carved from one buffer, at offsets fixed relative to each other and to the
    # rows' state (see carve): their placement no longer depends on the allocator.
    sizes = block_sizes(C, head[2], n, m, E)
    buffer, base = carve_buffer(sizes, svd_state)
    at = base
    drive_q, at = carve(buffer, at, base, 0, C)
    drive_q[:] = 0.0
    flat_poses, at = carve(buffer, at, base, 1, sizes[1])
    poses = flat_poses.reshape((head[2], 4, C))
    poses[:, :, :] = 0.0
    poses[:, 0, :] = 1.0  # the fixed body keeps the identity, every body is the reference at the start
    flat_status, at = carve(buffer, at, base, 20, C)
    status = flat_status.view(np.int64)  # (zeroed at each block)
    flat_rel, at = carve(buffer, at, base, 2, sizes[2])
    rel = flat_rel.reshape((n, 2, C))
    flat_q, at = carve(buffer, at, base, 3, sizes[3])
    q = flat_q.reshape((n, C))
    jump, at = carve(buffer, at, base, 4, C)
    turns, at = carve(buffer, at, base, 5, C)
    turns[:] = 0.0
    carry = (np.zeros(n), np.zeros(n), turns)  # each joint's value at column 0, its whole turns there
    flat_scratch, at = carve(buffer, at, base, 6, sizes[6])
    scratch_b, at = carve(buffer, at, base, 7, C)
    scratch_c, at = carve(buffer, at, base, 8, C)
    scratch = (flat_scratch.reshape((4, C)), scratch_b, scratch_c)
    flat_jac, at = carve(buffer, at, base, 9, sizes[9])
    jac = flat_jac.reshape((E, m, C))
    fresh = np.empty(flat[1].shape[0], dtype=np.bool_)
    closure_constants(flat, jac, fresh)  # the entries the same at every point, once for every block
    res, at = carve(buffer, at, base, 10, C)
    flat_sigma, at = carve(buffer, at, base, 11, sizes[11])
    sigma = flat_sigma.reshape((E, C))
    flat_tangent, at = carve(buffer, at, base, 12, sizes[12])
    tangent = flat_tangent.reshape((m, C))
    raw_tau, at = carve(buffer, at, base, 13, C)
    align, at = carve(buffer, at, base, 14, C)
    dist, at = carve(buffer, at, base, 15, C)
    wrapped, at = carve(buffer, at, base, 16, C)
    outside, at = carve(buffer, at, base, 17, C)
    measures = (align, dist, wrapped, outside)
    flips, at = carve(buffer, at, base, 18, C)  # each point's tangent orientation ...
    taus, at = carve(buffer, at, base, 19, C)  # ... and test function
    far = 0.0
    flipped = 0  # the tangent's orientation is -1 (the one before the block's first point)
    flat_bits, at = carve(buffer, at, base, 21, C)
    turn_bits = flat_bits.view(np.int64)
    near_start = 1.5 * abs(h)  # a path closes where it comes back this near its start
    limits = (min_ratio, min_drive, near_start, hmax, det_basis)
    for first in range(1, steps + 1, block):
        # Positions: the drive's values (a running sum, as the march steps), the bodies' poses, the joints.
        drive_values(drive_q, first, steps, h, target)
        status[:] = CLEAN
        jump[:] = 0.0
        place_driver(joint_int, joint_geo, head, drive_q, poses)
        place_dyads(joint_int, joint_geo, dyads, modes, poses, min_margin, status)
        joint_values(joint_int, joint_geo, poses, drive, drive_q, rel, q, jump, carry)
        size, ended = first_failure(status, jump, min(block, steps + 1 - first))
        for i in range(size + 1, C):  # past the block's last point: its copies (no NaN, no work for the rows)
            rel[:, :, i] = rel[:, :, size]
            q[:, i] = q[:, size]
        # The Jacobians and their rows (the tangent, det([J; t^T]), the singular values), column 0 included.
        closure_columns(flat, rel, q, jac, res, scratch, fresh)
        if E == 3 and m == 4:  # one loop (a four-bar, a slider-crank): batched, vectorised across the points
            one_loop_rows(jac, sigma, tangent, raw_tau)
        else:
            multi_loop_rows(jac, sigma, tangent, raw_tau, 0 if first == 1 else 1, svd_state)
        path_measures(q, groups, tangent, t0, (lo, hi, periodic), measures)
        begin = 0 if first == 1 else 1
        taus[0] = out_tau[first - 1]
        flipped = check_points(
            (sigma, tangent, raw_tau, measures), (flips, taus, turn_bits), status, (first, begin, size, steps),
            g_drive, h, limits, flipped,
        )  # fmt: skip
        stop, code, far = scan_points(status, measures, out_s, (first, begin, size, steps), far, hmax, ended)
        end = stop + 1 if code == CLOSED else stop
        full_rank &= store_rows((q, sigma, res, taus), offsets, outs, first, begin, end, loose)
        if stop <= size:
            return zero_tail(first - 1 + stop, code, outs)
        if ended != CLEAN:
            return zero_tail(first + size, ended, outs)
        # The block's last column is the next block's column 0.
        poses[:, :, 0] = poses[:, :, block]
        drive_q[0] = drive_q[block]
        for j in range(n):
            carry[0][j] = q[j, block]
        sigma[:, 0] = sigma[:, block]
        tangent[:, 0] = tangent[:, block]
        raw_tau[0] = raw_tau[block]
    return steps + 1, CLEAN, out_angles, out_sigma, out_res, out_tau, out_s, full_rank


PAGE = 512
"""Doubles in 4 KiB: two addresses this far apart (or a multiple) look alike to a core's store-to-load forwarding
(4K aliasing: a load waits for an older store to an unrelated address with the same low 12 bits)."""
STAGGER = 24
"""Doubles between the starts of consecutive block arrays, modulo :data:`PAGE` (22 arrays: 192 bytes apart)."""


@kernel(inline="always")
def block_sizes(C, bodies, n, m, E):
    """The sizes of the 22 block arrays of :func:`closed_form_path`, in the order of their ``carve`` indices:
    drive, poses, relative rotations, joint values, jumps, turns, scratch (three), Jacobians, residuals, singular
    values, tangents, raw test function, the four measures, orientations, test function, status, turn bits."""
    rows = (C, bodies * 4 * C, n * 2 * C, n * C, C, C, 4 * C, C, C, E * m * C, C, E * C, m * C)
    return (*rows, C, C, C, C, C, C, C, C, C)  # (numba multiplies no tuple)


@kernel(inline="always")
def carve_buffer(sizes, state):
    """One uninitialised buffer for the block arrays of ``sizes`` (see :func:`carve`), and the offset ``base`` of
    its first: half a page from the rows' ``state`` (modulo a page), wherever the allocator put either. Before,
    each array had its own allocation, and in about one process of four the allocator placed two hot rows 4 KiB
    apart (modulo): the Watt six-bar's turn then took 360 ns a point instead of 260."""
    total = 0
    for size in sizes:
        total += size + 2 * PAGE
    buffer = np.empty(total + 2 * PAGE)
    start = (state.ctypes.data + 8 * (PAGE // 2) - buffer.ctypes.data) % (8 * PAGE) // 8
    return buffer, start


@kernel(inline="always")
def carve(buffer, at, base, index, size):
    """``buffer[begin : begin + size]`` and the offset after it: ``begin`` the first offset at or after ``at``
    that is ``index`` times :data:`STAGGER` past ``base`` modulo a page, so that the block arrays start at distinct
    places within a page (two rows a multiple of 4 KiB apart make a pass over both wait on 4K aliasing)."""
    want = (base + index * STAGGER) % PAGE
    begin = at + (want - at) % PAGE
    return buffer[begin : begin + size], begin + size


@kernel(inline="always")
def block_width(steps):
    """Points a block of a path of ``steps`` steps: the fewest blocks of at most :data:`BLOCK` points, the steps
    shared evenly among them, rounded up to a multiple of the rows' lanes
    (:data:`~linkwork.kinematics.bidiagonal_rows.LANES`: from block to block each lane continues its own points).
    Every pass runs over a whole block, so a last block of a few points in a block of ``BLOCK`` columns cost as
    much as a full one (3600 steps: 15 blocks of 240, not 14 of 256 and one of 16 in 256 columns)."""
    blocks = max(1, -(-steps // BLOCK))
    width = -(-steps // blocks)
    return max(LANES, -(-width // LANES) * LANES)


@kernel(inline="always")
def drive_values(drive_q, first, steps, h, target):
    """The drive's values at the block of points from ``first``: ``drive_q[i]`` at point ``first - 1 + i``, a
    running sum of the step ``h`` from ``drive_q[0]`` (as the march steps), ``target`` at point ``steps``."""
    value = drive_q[0]  # carried in a register, not reloaded from the store before
    for i in range(1, drive_q.shape[0]):
        value = target if first - 1 + i == steps else value + h
        drive_q[i] = value


@kernel(inline="always")
def first_failure(status, jump, size):
    """``(placed, code)``: how many of the block's first ``size`` points were placed cleanly (a dyad solved, no
    joint stepping by more than a quarter turn), and why the next one was not (:data:`CLEAN` if all were)."""
    for i in range(1, size + 1):
        code = JUMP if status[i] == CLEAN and jump[i] > 0.5 * np.pi else status[i]
        if code != CLEAN:
            return i - 1, code
    return size, CLEAN


@kernel(inline="always")
def check_points(rows, orient, status, span, g_drive, h, limits, flipped):
    """Every check at every point of the block, in ``status`` (vectorised); returns the orientation of the
    tangent at the block's last point (1 for -1).

    ``rows = (sigma, tangent, raw_tau, measures)``, ``orient = (flips, taus, turn_bits)`` (written: each point's
    tangent orientation and test function; ``taus[0]`` the point before's), ``span = (first, begin, size,
    steps)``, ``limits = (min_ratio, min_drive, near_start, hmax, det_basis)``.

    The tangent's orientation (continuous from point to point, the start's at row 0), then the test function
    and every check (in the march's order: a rank or drive check, a sign change, a limit); a clean point that
    could close the path (near the start, not the start or the target) is marked :data:`NEAR_START`.
    """
    sigma, tangent, raw_tau, measures = rows
    flips, taus, turn_bits = orient
    first, begin, size, steps = span
    min_ratio, min_drive, near_start, _hmax, det_basis = limits
    align, _dist, wrapped, outside = measures
    E = sigma.shape[0]
    # orient = -1 where align * (the orientation before) < 0, else 1 (at the start, the one before is 1): as
    # bits, flipped = (align < 0) xor (flipped before) where align is neither 0 nor NaN, else 0. The bits in a
    # vectorised loop, the recurrence (two integer operations a point) in a scalar one.
    for i in range(begin, size + 1):
        a = align[i]
        turn_bits[i] = (1 if a < 0.0 else 0) | (2 if (a < 0.0) | (a > 0.0) else 0)
    for i in range(begin, size + 1):
        bits = turn_bits[i]
        flipped = ((bits & 1) ^ flipped) & (bits >> 1)
        turn_bits[i] = flipped
    for i in range(begin, size + 1):
        flips[i] = -1.0 if turn_bits[i] else 1.0
        taus[i] = det_basis * raw_tau[i] * flips[i]
    for i in range(begin, size + 1):
        k = first - 1 + i
        later = k > 0  # not the start
        t_drive = tangent[g_drive, i]
        singular = (sigma[E - 1, i] < min_ratio * sigma[0, i]) | (abs(t_drive) < min_drive)
        turned = later & ((flips[i] * t_drive) * h <= 0.0)
        crossed = later & (taus[i] * taus[i - 1] < 0.0)
        code = NEAR_SINGULAR if singular | turned else (SIGN_CHANGE if crossed else CLEAN)
        code = LIMIT if code == CLEAN and outside[i] > 0.0 else code
        near = later & (k < steps) & (wrapped[i] < near_start)
        status[i] = NEAR_START if code == CLEAN and near else code
    return flipped


@kernel(inline="always")
def scan_points(status, measures, out_s, span, far, hmax, ended):
    """``(stop, code, far)``: the block's first point that ends the path (``size + 1`` and ``ended`` if none) and
    why, point by point in the march's order, running the arclength's sum into ``out_s`` and the largest distance
    from the start ``far`` (carried from block to block). ``span = (first, begin, size, steps)``.

    The marked points one by one, the runs of clean points between them in loops. A point near the start
    (:data:`NEAR_START`) closes the path once ``far`` exceeds ``4 hmax`` (the march's test: its row is stored, but
    the path ends before it)."""
    _align, dist, wrapped, _outside = measures
    first, begin, size, steps = span
    stop, code = size + 1, ended
    arc = out_s[first - 1]  # the arclength so far, carried in a register (0 at the start)
    i = begin
    while i <= size:
        j = i
        while j <= size and status[j] == CLEAN:
            j += 1
        for p in range(i, j):  # a running sum, in the march's order
            arc = arc + dist[p] if first - 1 + p > 0 else 0.0
            out_s[first - 1 + p] = arc
        # The march's closed-path test keeps the largest distance from the start, and only compares it with
        # 4 hmax: once above, it stays above (unless a NaN comes, which the march's select keeps too).
        odd = 0
        if far > 4.0 * hmax:
            for p in range(i, j):
                odd += 0 if wrapped[p] == wrapped[p] else 1
        if odd > 0 or not far > 4.0 * hmax:
            for p in range(i, j):
                d = wrapped[p] if 0 < first - 1 + p < steps else 0.0
                far = far if far >= d else d
        if j > size:
            break
        if status[j] != NEAR_START:
            stop, code = j, status[j]
            break
        # Near the start: the march's closed-path test (the target's step ends the march before it).
        k = first - 1 + j
        arc = arc + dist[j]
        out_s[k] = arc
        d = wrapped[j]
        far = far if far >= d else d
        if far > 4.0 * hmax:
            stop, code = j, CLOSED  # row k is stored, but the path ends before it
            break
        i = j + 1
    return stop, code, far


@kernel(inline="always")
def store_rows(block, offsets, outs, first, begin, end, loose):
    """The block's rows ``begin .. end - 1`` into the outputs at rows ``first - 1 + i``: ``block = (q, sigma, res,
    taus)``, ``outs = (out_angles, out_sigma, out_res, out_tau, out_s)`` (the arclength is written by the scan),
    each joint's value ``q + offsets`` (what the trace reports); returns whether each of these rows passes the
    full-rank test of :func:`~linkwork.kinematics.kernels.every_row_full_rank` with ``loose``.

    Row by row (each output row's entries side by side in memory; the block's arrays, read along their columns,
    stay in the first-level cache), on slices of the block and of the outputs that start at 0; for the usual
    sizes (one loop of four joints, two of seven) with the sizes as literal constants, so that the loops over a
    row unroll. (Column by column, one output column at a time, costs three times as much.)"""
    n, E = block[0].shape[0], block[1].shape[0]
    if n == 4 and E == 3:
        return store_sized(block, offsets, outs, first, begin, end, loose, 4, 3)
    if n == 7 and E == 6:
        return store_sized(block, offsets, outs, first, begin, end, loose, 7, 6)
    return store_sized(block, offsets, outs, first, begin, end, loose, n, E)


@kernel(inline="always")
def store_sized(block, offsets, outs, first, begin, end, loose, n, E):
    """:func:`store_rows` with ``n`` joints and ``E`` singular values (literal constants where it is called)."""
    q, sigma, res, taus = block
    out_angles, out_sigma, out_res, out_tau, _out_s = outs
    lo, hi = first - 1 + begin, first - 1 + end
    angles, values = out_angles[lo:hi], out_sigma[lo:hi]
    q_rows, sigma_rows = q[:, begin:end], sigma[:, begin:end]
    for i in range(end - begin):
        for j in range(n):
            angles[i, j] = q_rows[j, i] + offsets[j]
        for e in range(E):
            values[i, e] = sigma_rows[e, i]
    out_res[lo:hi] = res[begin:end]
    out_tau[lo:hi] = taus[begin:end]
    # every_row_full_rank's test on these rows, the same comparisons (vectorised: no early exit)
    failing = False
    for i in range(end - begin):
        top = sigma_rows[0, i]
        low = top
        odd = False
        for e in range(1, E):
            x = sigma_rows[e, i]
            odd |= x != x
            low = x if x < low else low
        failing |= not ((not odd) & (top > 0.0) & (low / top > loose))
    return not failing


@kernel(inline="always", error_model="numpy")
def path_measures(q, groups, tangent, t0, bounds, measures):
    """At every point ``k`` of a path of joint values ``q (n, K)`` with unit tangents ``tangent (m, K)``:
    ``measures = (align, dist, wrapped, outside)`` (written): ``align[k]`` the tangent's inner product with the one
    before (``t0`` at ``k = 0``; orientations aside), ``dist[k]`` the step's length from ``k - 1`` (0 at ``k =
    0``), ``wrapped[k]`` the distance from the start with periodic unknowns wrapped onto ``[-pi, pi)``,
    ``outside[k]`` how many unknowns are outside ``bounds = (lo, hi, periodic)``.

    The inner products and step lengths point by point, the sums over the unknowns in registers (for the usual
    sizes, four and seven unknowns, with the sizes as literal constants: the sums unroll and the loop over the
    points vectorises); the distances from the start and the bounds one unknown at a time (vectorised)."""
    n, m = q.shape[0], tangent.shape[0]
    if n == 4 and m == 4:
        measures_sized(q, groups, tangent, t0, bounds, measures, 4, 4)
    elif n == 7 and m == 7:
        measures_sized(q, groups, tangent, t0, bounds, measures, 7, 7)
    else:
        measures_sized(q, groups, tangent, t0, bounds, measures, n, m)


@kernel(inline="always")
def measures_sized(q, groups, tangent, t0, bounds, measures, n, m):
    """:func:`path_measures` with ``n`` joints and ``m`` unknowns (literal constants where it is called); every
    sum in the order of the unknowns from 0.0, as one sum into zeroed arrays gives it."""
    lo, hi, periodic = bounds
    align, dist, wrapped, outside = measures
    K = tangent.shape[1]
    acc = 0.0
    for a in range(m):
        acc += tangent[a, 0] * t0[a]
    align[0] = acc
    for k in range(1, K):
        acc = 0.0
        for a in range(m):
            acc += tangent[a, k] * tangent[a, k - 1]
        align[k] = acc
    dist[0] = 0.0
    for k in range(1, K):
        acc = 0.0
        for j in range(n):
            du = q[j, k] - q[j, k - 1]
            acc += du * du
        dist[k] = np.sqrt(acc)
    wrapped[:] = 0.0
    outside[:] = 0.0
    for j in range(n):
        g = groups[j]
        qj = q[j]
        low, high, turn = lo[g], hi[g], TWO_PI if periodic[g] else 0.0
        for k in range(K):
            x = qj[k]
            outside[k] += 1.0 if (x < low) | (x > high) else 0.0
            x -= turn * np.floor(
                (x + np.pi) * (1.0 / TWO_PI)
            )  # periodic: onto [-pi, pi) (geometry.angles.wrap)
            wrapped[k] += x * x
    for k in range(K):
        wrapped[k] = np.sqrt(wrapped[k])
