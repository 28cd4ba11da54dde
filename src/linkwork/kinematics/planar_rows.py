"""Batched rows of one-loop planar Jacobians: at every point of a path, the singular values, a unit tangent and the
raw test function of the ``3 x 4`` closure Jacobian, in closed form, vectorised across points.

The planar closed-form path (:func:`linkwork.kinematics.dyad_solver.closed_form_path`) evaluates, at each of its
``K`` points, the closure Jacobian ``J`` of a one-loop mechanism with one degree of freedom (a four-bar, a
slider-crank): ``E = 3`` rows ``(omega_z, v_x, v_y)`` (G&P Eq. (21)), ``m = 4`` columns. What a trace reports
from ``J`` (G&P Sec. 4 and 5: the zero-strain motion, the null vector of ``J``, and the singular values that
measure the distance to a bifurcation) has for a ``3 x 4`` matrix a closed form:

* The four signed ``3 x 3`` minors (cofactors) ``c_i = (-1)^(i+3) det(J without column i)`` span the null space:
  ``J c = 0`` (each row of ``J`` bordered below ``J`` gives a determinant with two equal rows). So ``t = c / |c|``
  is a unit tangent and ``det([J; t^T]) = c . t = |c|``: the raw test function.
* The characteristic polynomial of ``J J^T`` is ``lambda^3 - p1 lambda^2 + p2 lambda - p3`` with ``p1`` the sum
  of the squares of ``J``'s entries, ``p2`` the sum of the squares of its eighteen ``2 x 2`` minors and ``p3 =
  |c|^2`` (Cauchy-Binet), each a sum of squares computed from ``J`` itself (``J J^T`` is never formed). Its
  largest root ``lambda_1 = sigma_1^2`` is found by Newton's method from an upper bound (the iterates decrease
  monotonically to it: the polynomial is convex and increasing above ``p1 / 3``); then ``sigma_2^2 + sigma_3^2 =
  (p2 - p3 / lambda_1) / lambda_1`` and ``sigma_2^2 sigma_3^2 = p3 / lambda_1`` give ``sigma_2`` as the larger
  root of a quadratic, and ``sigma_3 = |c| / (sigma_1 sigma_2)`` (accurate relative to itself however small).

Each lane carries a first-order bound of its rounding errors (running error analysis of every sum, product and
Horner step, and the conditioning of each root: ``lambda_1`` through ``f'(lambda_1) = (lambda_1 - lambda_2)
(lambda_1 - lambda_3)``, ``lambda_2`` through the quadratic's discriminant ``(lambda_2 - lambda_3)^2``). Where the
bound exceeds :data:`SIGMA_TOL` (singular values, relative to ``sigma_1``) or :data:`TANGENT_TOL` (the cofactors,
relative to ``|c|``) -- near a double root, a near rank drop, or a Newton iteration not converged in
:data:`NEWTON_STEPS` -- the lane is recomputed by the exact fall-back, a one-sided Jacobi SVD of ``J``
(:func:`linkwork.kinematics.small_svd.jacobi_svd`), in a second pass.

The first pass is straight-line code over the points (a fixed number of Newton steps, conditional expressions, no
branches and no exceptions: ``error_model="numpy"``), which LLVM vectorises across points.

References
----------
W. W. Gan, S. Pellegrino, Proc. IMechE Part C 220 (2006), Eq. (21) and Sec. 4-5 (the Jacobian, its null vector
and singular values).
N. J. Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., SIAM (2002): Sec. 3.1 and 5.1 (running
error bounds of sums and of Horner's rule), Sec. 1.12 (the conditioning of a root).
J. Stoer, R. Bulirsch, *Introduction to Numerical Analysis*, 3rd ed., Springer (2002), Sec. 5.5 (Newton's method
on a polynomial with real roots from an upper bound of the largest root: monotone convergence).
P. A. Samuelson, J. Am. Stat. Assoc. 63 (1968) 1522-1525 (the upper bound ``mean + sqrt(n - 1) std`` of the roots).
"""

from __future__ import annotations

import math

import numpy as np

from linkwork.kernel_cache import kernel
from linkwork.kinematics.small_svd import jacobi_svd

U = 2.0**-53
"""The unit round-off of float64."""
NEWTON_STEPS = 4
"""Newton steps on the characteristic polynomial, the same in every lane (so that the loop vectorises)."""
SIGMA_TOL = 4e-14
"""A lane is certified when its error bounds on ``sigma_1`` and ``sigma_2`` are below this times ``sigma_1``
(``sigma_3``'s is below twice this)."""
TANGENT_TOL = 8e-15
"""... and its bound on the cofactors' error is below this times ``|c|`` (the tangent's residual ``|J t|`` is then
below this times ``sigma_1``, and the raw test function this relative)."""
FLOOR = 1e-300
"""Divisors are at least this (a degenerate lane then gives finite nonsense, flagged, not an exception)."""
FLAGGED = -1.0
"""The first pass's ``raw_tau`` of a lane it could not certify (a certified one is ``|c| > 0``)."""


@kernel(inline="always")
def fast_lane(jac, k, sigma, tangent, raw_tau):
    """The closed form at point ``k`` (see the module's docstring) into ``sigma[:, k]``, ``tangent[:, k]`` and
    ``raw_tau[k]``; ``raw_tau[k] = FLAGGED`` where its error bounds do not certify it."""
    a0, a1, a2, a3 = float(jac[0, 0, k]), float(jac[0, 1, k]), float(jac[0, 2, k]), float(jac[0, 3, k])
    b0, b1, b2, b3 = float(jac[1, 0, k]), float(jac[1, 1, k]), float(jac[1, 2, k]), float(jac[1, 3, k])
    c0, c1, c2, c3 = float(jac[2, 0, k]), float(jac[2, 1, k]), float(jac[2, 2, k]), float(jac[2, 3, k])
    # 2x2 minors of rows (1, 2), and the sums of the absolute values of their two products.
    m01, n01 = b0 * c1 - b1 * c0, abs(b0 * c1) + abs(b1 * c0)
    m02, n02 = b0 * c2 - b2 * c0, abs(b0 * c2) + abs(b2 * c0)
    m03, n03 = b0 * c3 - b3 * c0, abs(b0 * c3) + abs(b3 * c0)
    m12, n12 = b1 * c2 - b2 * c1, abs(b1 * c2) + abs(b2 * c1)
    m13, n13 = b1 * c3 - b3 * c1, abs(b1 * c3) + abs(b3 * c1)
    m23, n23 = b2 * c3 - b3 * c2, abs(b2 * c3) + abs(b3 * c2)
    # Cofactors c_i = (-1)^(i+3) det(J without column i), expanded along row 0, and their permanents of |J|
    # (each cofactor's rounding error is below 5 u times its permanent).
    C0 = a3 * m12 - a2 * m13 + a1 * m23
    C1 = a0 * m23 - a2 * m03 + a3 * m02
    C2 = a1 * m03 - a0 * m13 - a3 * m01
    C3 = a0 * m12 - a1 * m02 + a2 * m01
    C0 = -C0
    P0 = abs(a1) * n23 + abs(a2) * n13 + abs(a3) * n12
    P1 = abs(a0) * n23 + abs(a2) * n03 + abs(a3) * n02
    P2 = abs(a0) * n13 + abs(a1) * n03 + abs(a3) * n01
    P3 = abs(a0) * n12 + abs(a1) * n02 + abs(a2) * n01
    # The characteristic polynomial's coefficients (Cauchy-Binet): p1 = |J|_F^2, p2 = sum of the 2x2 minors'
    # squares, p3 = |c|^2.
    r0 = (a0 * a0 + a1 * a1) + (a2 * a2 + a3 * a3)
    r1 = (b0 * b0 + b1 * b1) + (b2 * b2 + b3 * b3)
    r2 = (c0 * c0 + c1 * c1) + (c2 * c2 + c3 * c3)
    p1 = r0 + r1 + r2
    e2 = r0 * r1 + r0 * r2 + r1 * r2  # bounds the sum of the squared |products| of the minors
    s12 = (m01 * m01 + m02 * m02) + (m03 * m03 + m12 * m12) + (m13 * m13 + m23 * m23)
    x01, x02, x03 = a0 * b1 - a1 * b0, a0 * b2 - a2 * b0, a0 * b3 - a3 * b0
    x12, x13, x23 = a1 * b2 - a2 * b1, a1 * b3 - a3 * b1, a2 * b3 - a3 * b2
    s01 = (x01 * x01 + x02 * x02) + (x03 * x03 + x12 * x12) + (x13 * x13 + x23 * x23)
    y01, y02, y03 = a0 * c1 - a1 * c0, a0 * c2 - a2 * c0, a0 * c3 - a3 * c0
    y12, y13, y23 = a1 * c2 - a2 * c1, a1 * c3 - a3 * c1, a2 * c3 - a3 * c2
    s02 = (y01 * y01 + y02 * y02) + (y03 * y03 + y12 * y12) + (y13 * y13 + y23 * y23)
    p2 = s01 + s02 + s12
    p3 = (C0 * C0 + C1 * C1) + (C2 * C2 + C3 * C3)
    q3 = (P0 * P0 + P1 * P1) + (P2 * P2 + P3 * P3)
    # lambda_1 by Newton from Samuelson's bound (mean + sqrt(2) std of the three roots), monotone from above.
    spread = p1 * p1 - 3.0 * p2
    lam = (p1 + 2.0 * math.sqrt(spread if spread > 0.0 else 0.0)) * (1.0 / 3.0) * (1.0 + 4.0 * U)
    for _ in range(NEWTON_STEPS):
        f = ((lam - p1) * lam + p2) * lam - p3
        fp = (3.0 * lam - 2.0 * p1) * lam + p2
        lam -= f / (fp if fp > FLOOR else FLOOR)
    # Running error bound of f(lam) by Horner's rule, with the coefficients' own errors.
    t1 = lam - p1
    t3 = t1 * lam + p2
    f = t3 * lam - p3
    fp = (3.0 * lam - 2.0 * p1) * lam + p2
    mod = math.sqrt(p3)  # |c|
    # |c| times the bound on the cofactors' error, 5 u |permanents| <= 2.5 u (q3 / |c| + |c|) (AM-GM).
    mod_dC = 2.5 * U * (q3 + p3)
    dp1 = 6.0 * U * p1
    dp2 = 11.0 * U * p2 + 4.0 * U * e2
    dp3 = 2.0 * mod_dC + 4.0 * U * p3
    df = abs(f) + 2.0 * U * lam * (abs(t3) + lam * abs(t1)) + U * abs(f) + (dp1 * lam + dp2) * lam + dp3
    den = lam * fp
    inv = 1.0 / (den if den > FLOOR else FLOOR)
    inv_lam = fp * inv
    dlam = df * lam * inv  # bound on |lam - lambda_1|
    rel_lam = dlam * inv_lam
    # lambda_2 and lambda_3: their sum S and product P, lambda_2 the larger root of x^2 - S x + P.
    P = p3 * inv_lam
    dP = dp3 * inv_lam + P * (rel_lam + 2.0 * U)
    S = (p2 - P) * inv_lam
    dS = (dp2 + dP) * inv_lam + abs(S) * (rel_lam + 3.0 * U)
    D = S * S - 4.0 * P
    dD = 2.0 * abs(S) * dS + 4.0 * dP + 3.0 * U * (S * S + 4.0 * P)
    root = math.sqrt(D if D > 0.0 else 0.0)
    lam2 = 0.5 * (S + root)
    s1 = math.sqrt(lam)
    s2 = math.sqrt(lam2 if lam2 > 0.0 else 0.0)
    s2 = s2 if s2 < s1 else s1
    den = s1 * s2 * mod
    w = 1.0 / (den if den > FLOOR else FLOOR)
    s3 = p3 * w  # |c| / (sigma_1 sigma_2)
    s3 = s3 if s3 < s2 else s2
    inv_mod = s1 * s2 * w
    # Certified: the cofactors (tangent, test function), lambda_1 (sigma_1), and lambda_2 (sigma_2) whose error
    # (dS + dD / root) / 2 must stay below 2 SIGMA_TOL sigma_1 sigma_2 (sigma_3 then follows).
    ok = (
        (mod_dC < TANGENT_TOL * p3)
        & (dlam <= 2.0 * SIGMA_TOL * lam)
        & (dS * root + dD <= 4.0 * SIGMA_TOL * s1 * s2 * root)
    )
    sigma[0, k] = s1
    sigma[1, k] = s2
    sigma[2, k] = s3
    tangent[0, k] = C0 * inv_mod
    tangent[1, k] = C1 * inv_mod
    tangent[2, k] = C2 * inv_mod
    tangent[3, k] = C3 * inv_mod
    raw_tau[k] = mod if ok else FLAGGED


@kernel(inline="always")
def exact_lane(jac, k, sigma, tangent, raw_tau, work):
    """The exact fall-back at point ``k``: a one-sided Jacobi SVD of ``J`` (``work = (A, V, W, norms, order)``,
    ``(3, 4)``, ``(4, 4)``, ``(3, 4)``, ``(4,)``, ``(4,)`` int). The tangent is the right singular vector of the
    column ``W`` left (numerically) zero, and ``det([J; t^T]) = det([W; e_i^T]) det V`` with ``det V = 1``: the
    cofactor of ``W`` (whose other columns are orthogonal, so that it is accurate relative to itself)."""
    A, V, W, norms, order = work
    for e in range(3):
        for c in range(4):
            A[e, c] = jac[e, c, k]
    for a in range(4):
        for c in range(4):
            V[a, c] = 1.0 if a == c else 0.0
    jacobi_svd(A, V, W, norms, order)
    null = order[3]
    for e in range(3):
        sigma[e, k] = norms[e]
    norm = 0.0
    for a in range(4):
        norm += V[a, null] * V[a, null]
    norm = 1.0 / math.sqrt(norm)  # V's columns are unit to a few rotations' rounding: to one rounding here
    for a in range(4):
        tangent[a, k] = V[a, null] * norm
    i, j, l = (1, 2, 3) if null == 0 else (0, 2, 3) if null == 1 else (0, 1, 3) if null == 2 else (0, 1, 2)
    det = (
        W[0, i] * (W[1, j] * W[2, l] - W[1, l] * W[2, j])
        - W[0, j] * (W[1, i] * W[2, l] - W[1, l] * W[2, i])
        + W[0, l] * (W[1, i] * W[2, j] - W[1, j] * W[2, i])
    )
    raw_tau[k] = det if null % 2 == 1 else -det


@kernel(error_model="numpy", fastmath={"contract"})
def one_loop_rows(jac, sigma, tangent, raw_tau):
    """Singular values, unit tangent and raw test function of ``K`` one-loop planar Jacobians.

    ``jac (3, 4, K)``: ``jac[e, c, k]`` row ``e``, column ``c`` of point ``k``'s Jacobian. Writes ``sigma (3, K)``
    (descending), ``tangent (4, K)`` (a unit null vector of each; either sign) and ``raw_tau (K,)`` (``det([J;
    t^T])`` for that ``t``). Returns the number of points recomputed by the exact fall-back.

    Every singular value is within ``1e-13 sigma_1`` of the exact one, ``|J t| <= 1e-14 sigma_1``, ``|t| = 1`` to
    ``1e-15``, and ``raw_tau`` within ``1e-13 sigma_1^2 sigma_2`` (relative ``1e-13`` unless ``J`` is nearly rank
    deficient): the closed form where its error bound certifies it, the Jacobi SVD elsewhere.
    """
    K = jac.shape[2]
    for k in range(K):
        fast_lane(jac, k, sigma, tangent, raw_tau)
    count = 0
    work = (np.empty((3, 4)), np.empty((4, 4)), np.empty((3, 4)), np.empty(4), np.empty(4, dtype=np.int64))
    for k in range(K):
        if raw_tau[k] < 0.0:
            exact_lane(jac, k, sigma, tangent, raw_tau, work)
            count += 1
    return count
