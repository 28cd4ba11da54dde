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
* The characteristic polynomial ``f(lambda) = lambda^3 - p1 lambda^2 + p2 lambda - p3`` of ``J J^T`` has ``p1``
  the sum of the squares of ``J``'s entries, ``p2`` the sum of the squares of its eighteen ``2 x 2`` minors
  (Lagrange's identity gives them row pair by row pair, ``|J_i|^2 |J_j|^2 - (J_i . J_j)^2``) and ``p3 = |c|^2``
  (Cauchy-Binet). Its largest root ``lambda_1 = sigma_1^2`` is reached from Samuelson's upper bound of the roots
  by two steps of Householder's fourth-order method (the same count in every lane, a division each). Dividing ``f`` by ``lambda -
  lambda_1`` leaves ``x^2 - S x + P`` with ``S = p1 - lambda_1``, ``P = lambda_1 (lambda_1 - p1) + p2``; its
  larger root is ``lambda_2 = sigma_2^2``, and ``sigma_3 = |c| / (sigma_1 sigma_2)`` (accurate relative to itself
  however small).

Each lane carries a first-order bound of its rounding errors (running error analysis of every sum, product and
Horner step; a root's error is the bound of ``f`` there over ``|f'|``, with the residual ``|f|`` counted, so that
an unconverged iteration is caught too). The first pass certifies the cofactors to :data:`TANGENT_TOL` (relative
to ``|c|``), ``sigma_1`` to :data:`SIGMA_1_TOL` and ``sigma_2`` to :data:`SIGMA_2_TOL` (relative to ``sigma_1``).
A second pass recomputes the lanes it could not certify: where only ``sigma_2`` failed (``lambda_2`` nearly
double with ``lambda_3``: the coefficients' rounding moves such a root far), from the ``2 x 2`` compression of
``J J^T`` off its top eigenvector (:func:`gap_lane`, no cancellation); elsewhere (``sigma_1 = sigma_2``, a near
rank drop, a zero Jacobian) by the exact fall-back, a one-sided Jacobi SVD of ``J``
(:func:`linkwork.kinematics.small_svd.jacobi_svd`, warm-started from the previous fall-back point when it is the
point before).

The first pass is straight-line code over the points (a fixed number of iterations, conditional expressions, no
branches and no exceptions: ``error_model="numpy"``), which LLVM vectorises across points (packed ``vsqrtpd``,
``vdivpd``, ``vfmadd`` on ``ymm`` registers). Every kernel here also runs as plain Python (the twins of
:mod:`linkwork.kinematics.jit`): the scalars are Python floats and every divisor and square root is guarded, so a
degenerate lane gives a flagged value, never an exception or a warning.

References
----------
W. W. Gan, S. Pellegrino, Proc. IMechE Part C 220 (2006), Eq. (21) and Sec. 4-5 (the Jacobian, its null vector
and singular values).
N. J. Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., SIAM (2002): Sec. 3.1 and 5.1 (running
error bounds of sums and of Horner's rule), Sec. 1.12 (the conditioning of a root).
J. Stoer, R. Bulirsch, *Introduction to Numerical Analysis*, 3rd ed., Springer (2002), Sec. 5.5 (Newton's method
on a polynomial with real roots from an upper bound of the largest root); A. S. Householder, *The Numerical
Treatment of a Single Nonlinear Equation*, McGraw-Hill (1970), Sec. 4.4 (the methods of order ``d + 1``,
``x + d (1/f)^(d-1) / (1/f)^(d)``, here ``d = 3``).
E. Carlen, E. H. Lieb, M. Loss, Methods Appl. Anal. 13 (2006) 1-17 (``per(A) <= n! / n^(n/2) prod |a_i|``, which
bounds the cofactors' rounding errors).
G. H. Golub, C. F. Van Loan, *Matrix Computations*, 4th ed., Johns Hopkins (2013), Sec. 8.1.2 (Weyl: a symmetric
matrix's eigenvalues move by at most the norm of its perturbation), Sec. 8.6.3 (one-sided Jacobi).
P. A. Samuelson, J. Am. Stat. Assoc. 63 (1968) 1522-1525 (the upper bound ``mean + sqrt(n - 1) std`` of the roots).
"""

from __future__ import annotations

import math

import numpy as np

from linkwork.kernel_cache import ROWS_OPTIONS, kernel
from linkwork.kinematics.bidiagonal_rows import bidiagonal_rows, bidiagonal_state, takes_bidiagonal
from linkwork.kinematics.small_svd import jacobi_svd

U = 2.0**-53
"""The unit round-off of float64."""
ROOT_STEPS = 2
"""Steps of Householder's fourth-order method on the characteristic polynomial, the same in every lane (so that
the loop vectorises)."""
SIGMA_1_TOL = 2e-14
"""A lane is certified when its error bound on ``sigma_1`` is below this times ``sigma_1``, ..."""
SIGMA_2_TOL = 7e-14
"""... its bound on ``sigma_2`` below this times ``sigma_1`` (then ``sigma_3``'s is below ``SIGMA_1_TOL +
SIGMA_2_TOL + TANGENT_TOL < 1e-13`` times ``sigma_1``), ... The bound is mostly the measured residual of
``lambda_2``, so errors do reach it: a lower value sends more points to the 2x2 compression (accurate to about
1e-15, some 30 ns a point); 2e-14 gives 9e-15 on a four-bar's turn for about 1.3 ns a point more."""
TANGENT_TOL = 8e-15
"""... and its bound on the cofactors' error below this times ``|c|`` (the tangent's residual ``|J t|`` is then
below this times ``sigma_1``, and the raw test function this relative)."""
THIRD_UP = (1.0 + 4.0 * U) / 3.0
"""A third, rounded up (Samuelson's bound, times it, stays above the largest root)."""
FLOOR = 1e-300
"""Divisors are at least this (a degenerate lane then gives finite nonsense, flagged, not an exception)."""
FLAGGED = -np.inf
"""The first pass's ``raw_tau`` of a lane it could not certify (a certified one is ``|c| > 0``; one whose tangent,
raw test function and ``sigma_1`` it certified but not ``sigma_2`` is ``-|c|``)."""


@kernel(inline="always")
def fast_lane(jac, k, sigma, tangent, raw_tau):
    """The closed form at point ``k`` (see the module's docstring) into ``sigma[:, k]``, ``tangent[:, k]`` and
    ``raw_tau[k]``; ``raw_tau[k] = FLAGGED`` where its error bounds do not certify it.

    The bounds are first-order running error bounds (``u`` the unit round-off): a sum of ``n`` products errs by
    at most ``n u`` times the sum of their absolute values, bounded by Cauchy-Schwarz through the rows' squared
    norms ``r_e``; a cofactor by ``5 u`` times the permanent of ``|J|`` without its column, at most ``6 / 3^(3/2)``
    times the product of its rows' norms (Carlen, Lieb and Loss), so ``|dc|^2 <= 133 u^2 r0 r1 r2``; Horner's rule
    by ``3 u`` times its intermediate magnitudes, which at a root are at most ``p2``. A root's error is then the
    polynomial's error bound over ``|f'|`` there, plus the residual ``|f| / |f'|`` (first order).
    """
    a0, a1, a2, a3 = float(jac[0, 0, k]), float(jac[0, 1, k]), float(jac[0, 2, k]), float(jac[0, 3, k])
    b0, b1, b2, b3 = float(jac[1, 0, k]), float(jac[1, 1, k]), float(jac[1, 2, k]), float(jac[1, 3, k])
    c0, c1, c2, c3 = float(jac[2, 0, k]), float(jac[2, 1, k]), float(jac[2, 2, k]), float(jac[2, 3, k])
    # Cofactors c_i = (-1)^(i+3) det(J without column i), expanded along row 0 with the 2x2 minors of rows 1, 2.
    m01, m02, m03 = b0 * c1 - b1 * c0, b0 * c2 - b2 * c0, b0 * c3 - b3 * c0
    m12, m13, m23 = b1 * c2 - b2 * c1, b1 * c3 - b3 * c1, b2 * c3 - b3 * c2
    C0 = a2 * m13 - a1 * m23 - a3 * m12
    C1 = a0 * m23 - a2 * m03 + a3 * m02
    C2 = a1 * m03 - a0 * m13 - a3 * m01
    C3 = a0 * m12 - a1 * m02 + a2 * m01
    # The characteristic polynomial of J J^T (Cauchy-Binet): p1 = |J|_F^2, p2 = the sum of the squared 2x2
    # minors (Lagrange's identity, row pair by row pair: r_i r_j - (J_i . J_j)^2), p3 = |c|^2.
    r0 = (a0 * a0 + a1 * a1) + (a2 * a2 + a3 * a3)
    r1 = (b0 * b0 + b1 * b1) + (b2 * b2 + b3 * b3)
    r2 = (c0 * c0 + c1 * c1) + (c2 * c2 + c3 * c3)
    g01 = (a0 * b0 + a1 * b1) + (a2 * b2 + a3 * b3)
    g02 = (a0 * c0 + a1 * c1) + (a2 * c2 + a3 * c3)
    g12 = (b0 * c0 + b1 * c1) + (b2 * c2 + b3 * c3)
    q01, q02, q12 = r0 * r1, r0 * r2, r1 * r2
    p1 = r0 + r1 + r2
    p2 = (q01 - g01 * g01) + (q02 - g02 * g02) + (q12 - g12 * g12)
    p3 = (C0 * C0 + C1 * C1) + (C2 * C2 + C3 * C3)
    e2 = q01 + q02 + q12
    hadamard = q01 * r2  # r0 r1 r2 >= |c|^2
    # Error bounds of the coefficients, Horner's rule's own at a root of the cubic folded in (its intermediates
    # are then lambda_i (lambda_j + lambda_k) and lambda_j lambda_k, at most p2); |c| dc <= 5.8 u (r0 r1 r2 + p3).
    dp1 = 4.0 * U * p1
    dp2 = 14.0 * U * e2 + 7.0 * U * p2
    dp3 = 11.6 * U * (hadamard + p3) + 3.0 * U * p3
    # lambda_1 from Samuelson's bound (mean + sqrt(2) std of the three roots) by Householder's fourth-order steps
    # x - f (f'^2 - f f'' / 2) / (f'^3 - f f' f'' + f^2 f''' / 6), f''' = 6: its error ~1e-2 -> 1e-8 -> round-off.
    spread = p1 * p1 - 3.0 * p2
    lam = (p1 + 2.0 * math.sqrt(spread if spread > 0.0 else 0.0)) * THIRD_UP
    for _ in range(ROOT_STEPS):
        f = ((lam - p1) * lam + p2) * lam - p3
        fp = (3.0 * lam - 2.0 * p1) * lam + p2
        fpp = 6.0 * lam - 2.0 * p1
        den = (fp * fp - f * fpp) * fp + f * f
        lam -= f * (fp * fp - 0.5 * f * fpp) / (den if den > FLOOR else FLOOR)
    t1 = lam - p1
    t3 = t1 * lam + p2
    f1 = t3 * lam - p3
    fp1 = (3.0 * lam - 2.0 * p1) * lam + p2
    df1 = abs(f1) + (dp1 * lam + dp2) * lam + dp3
    # lambda_2 and lambda_3 are the roots of the deflated quadratic x^2 - S x + P (synthetic division of the
    # cubic by x - lambda_1: S = p1 - lambda_1, P = lambda_1 (lambda_1 - p1) + p2); lambda_2, the larger, is
    # certified by its own residual in the cubic, whatever the errors of lambda_1, S and P.
    S = -t1
    D = S * S - 4.0 * t3
    root = math.sqrt(D if D > 0.0 else 0.0)
    lam2 = 0.5 * (S + root)
    t1 = lam2 - p1
    f2 = ((t1 * lam2) + p2) * lam2 - p3
    fp2 = abs((3.0 * lam2 - 2.0 * p1) * lam2 + p2)
    df2 = abs(f2) + (dp1 * lam2 + dp2) * lam2 + dp3
    s1 = math.sqrt(lam)
    s2 = math.sqrt(lam2 if lam2 > 0.0 else 0.0)
    s2 = s2 if s2 < s1 else s1
    mod = math.sqrt(p3)  # |c|
    den = s1 * s2 * mod
    w = 1.0 / (den if den > FLOOR else FLOOR)
    s3 = p3 * w  # |c| / (sigma_1 sigma_2)
    s3 = s3 if s3 < s2 else s2
    inv_mod = s1 * s2 * w
    # Certified: the cofactors (|J t| and raw_tau; 133 u^2 r0 r1 r2 bounds |dc|^2), lambda_1 (sigma_1 =
    # sqrt(lambda_1)), lambda_2 (sigma_2, within a quarter of its gap to lambda_3); then sigma_3 = |c| /
    # (sigma_1 sigma_2) errs by at most sigma_3 (|dc| / |c| + dsigma_1 / sigma_1) + dsigma_2.
    first = (133.0 * U * U * hadamard < TANGENT_TOL * TANGENT_TOL * p3) & (
        df1 <= 2.0 * SIGMA_1_TOL * lam * fp1
    )
    second = (df2 <= 2.0 * SIGMA_2_TOL * s1 * s2 * fp2) & (4.0 * df2 <= root * fp2)
    sigma[0, k] = s1
    sigma[1, k] = s2
    sigma[2, k] = s3
    tangent[0, k] = C0 * inv_mod
    tangent[1, k] = C1 * inv_mod
    tangent[2, k] = C2 * inv_mod
    tangent[3, k] = C3 * inv_mod
    raw_tau[k] = (mod if second else -mod) if first else FLAGGED


@kernel(inline="always")
def gap_lane(jac, k, sigma, raw_tau):
    """``sigma_2`` and ``sigma_3`` at point ``k`` where the first pass certified ``sigma_1``, the tangent and
    ``raw_tau = -|c|`` but not ``sigma_2`` (``lambda_2`` close to ``lambda_3``: the cubic's coefficients' errors
    move a nearly double root far): from the ``2 x 2`` compression ``M`` of ``A = J J^T`` onto the complement of
    its top eigenvector ``u_1``, whose eigenvalues ``(a + d) / 2 +- sqrt(((a - d) / 2)^2 + b^2)`` lose nothing to
    cancellation. ``u_1`` is the largest cross product of two rows of ``A - lambda_1 I`` (rank two; ``lambda_1``
    is well separated, the first pass certified it), the complement spanned by a Householder reflection's columns.
    Each entry of ``M`` errs by at most ``20 u p1`` (Weyl: so do its eigenvalues). Returns whether that bound
    certifies ``sigma_2`` (then written, with ``sigma_3 = |c| / (sigma_1 sigma_2)`` and ``raw_tau = |c|``)."""
    a0, a1, a2, a3 = float(jac[0, 0, k]), float(jac[0, 1, k]), float(jac[0, 2, k]), float(jac[0, 3, k])
    b0, b1, b2, b3 = float(jac[1, 0, k]), float(jac[1, 1, k]), float(jac[1, 2, k]), float(jac[1, 3, k])
    c0, c1, c2, c3 = float(jac[2, 0, k]), float(jac[2, 1, k]), float(jac[2, 2, k]), float(jac[2, 3, k])
    r0 = (a0 * a0 + a1 * a1) + (a2 * a2 + a3 * a3)
    r1 = (b0 * b0 + b1 * b1) + (b2 * b2 + b3 * b3)
    r2 = (c0 * c0 + c1 * c1) + (c2 * c2 + c3 * c3)
    g01 = (a0 * b0 + a1 * b1) + (a2 * b2 + a3 * b3)
    g02 = (a0 * c0 + a1 * c1) + (a2 * c2 + a3 * c3)
    g12 = (b0 * c0 + b1 * c1) + (b2 * c2 + b3 * c3)
    s1 = float(sigma[0, k])
    mod = -float(raw_tau[k])
    lam = s1 * s1
    x0, x1, x2 = r0 - lam, g01, g02  # the rows of A - lambda_1 I
    y0, y1, y2 = g01, r1 - lam, g12
    z0, z1, z2 = g02, g12, r2 - lam
    u0, u1, u2 = x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0
    n = u0 * u0 + u1 * u1 + u2 * u2
    v0, v1, v2 = x1 * z2 - x2 * z1, x2 * z0 - x0 * z2, x0 * z1 - x1 * z0
    nv = v0 * v0 + v1 * v1 + v2 * v2
    if nv > n:
        u0, u1, u2, n = v0, v1, v2, nv
    v0, v1, v2 = y1 * z2 - y2 * z1, y2 * z0 - y0 * z2, y0 * z1 - y1 * z0
    nv = v0 * v0 + v1 * v1 + v2 * v2
    if nv > n:
        u0, u1, u2, n = v0, v1, v2, nv
    if not n > 0.0:
        return False
    scale = 1.0 / math.sqrt(n)
    u0, u1, u2 = u0 * scale, u1 * scale, u2 * scale
    # Householder reflection taking u_1 to -+e_0: its columns 1 and 2 span the complement.
    w0 = u0 + (1.0 if u0 >= 0.0 else -1.0)
    beta = 1.0 / (1.0 + abs(u0))
    q0, q1, q2 = -beta * w0 * u1, 1.0 - beta * u1 * u1, -beta * u2 * u1
    h0, h1, h2 = -beta * w0 * u2, -beta * u1 * u2, 1.0 - beta * u2 * u2
    Aq0, Aq1, Aq2 = (
        r0 * q0 + g01 * q1 + g02 * q2,
        g01 * q0 + r1 * q1 + g12 * q2,
        g02 * q0 + g12 * q1 + r2 * q2,
    )
    Ah0, Ah1, Ah2 = (
        r0 * h0 + g01 * h1 + g02 * h2,
        g01 * h0 + r1 * h1 + g12 * h2,
        g02 * h0 + g12 * h1 + r2 * h2,
    )
    m_a = q0 * Aq0 + q1 * Aq1 + q2 * Aq2
    m_b = q0 * Ah0 + q1 * Ah1 + q2 * Ah2
    m_d = h0 * Ah0 + h1 * Ah1 + h2 * Ah2
    half = 0.5 * (m_a - m_d)
    lam2 = 0.5 * (m_a + m_d) + math.sqrt(half * half + m_b * m_b)
    s2 = math.sqrt(lam2 if lam2 > 0.0 else 0.0)
    if not (10.0 * U * (r0 + r1 + r2) <= SIGMA_2_TOL * s1 * s2 and s2 <= s1):
        return False
    s3 = mod / (s1 * s2)
    sigma[1, k] = s2
    sigma[2, k] = s3 if s3 < s2 else s2
    raw_tau[k] = mod
    return True


@kernel(inline="always")
def exact_lane(jac, k, sigma, tangent, raw_tau, work, warm):
    """The exact fall-back at point ``k``: a one-sided Jacobi SVD of ``J`` (``work = (A, V, W, norms, order)``,
    ``(3, 4)``, ``(4, 4)``, ``(3, 4)``, ``(4,)``, ``(4,)`` int), started from ``V`` when ``warm`` (the previous
    point's right singular vectors: along a path they change little, and a sweep or two finish), else from the
    identity. The tangent is the right singular vector of the column of ``W`` left (numerically) zero, and
    ``det([J; t^T]) = det([W; e_i^T]) det V`` with ``det V = 1`` (rotations only): the cofactor of ``W`` (whose
    other columns are orthogonal, so that it is accurate relative to itself)."""
    A, V, W, norms, order = work
    for e in range(3):
        for c in range(4):
            A[e, c] = jac[e, c, k]
    if not warm:
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


@kernel(**ROWS_OPTIONS)
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
    last = -2
    for k in range(K):
        if raw_tau[k] < 0.0:
            count += 1
            if raw_tau[k] > FLAGGED and gap_lane(jac, k, sigma, raw_tau):
                continue
            exact_lane(jac, k, sigma, tangent, raw_tau, work, last == k - 1)
            last = k
    return count


LANES = 16
"""Points of a multi-loop Jacobian solved side by side by :func:`jacobi_loop_rows` (each a lane of its packed
operations: four ``ymm`` registers). Fewer lanes leave the loops' set-up and the rotations' latency exposed, more
warm-start each point from one further back (more sweeps): on the Watt six-bar's turn 4, 8, 16, 32, 64 lanes cost
about 1500, 900, 560, 590, 630 ns a point (loaded machine)."""
LOCKSTEP_SWEEPS = 12
"""Jacobi sweeps the lanes make together before a lane still not finished falls back to the exact routine."""
WIDE = 1e-16
"""A sweep in which some pair's squared cosine exceeds this did not finish (after one in which none did, the
columns are orthogonal to about ``1e-16``: Jacobi converges quadratically)."""
TINY = 1e-30
"""A pair whose squared cosine is below this is not rotated."""
SEPARATED = 1e-17
"""A sweep leaves a pair as it is in every lane when, in each, ``gamma^2 <= SEPARATED |alpha - beta| min(alpha,
beta)`` (``alpha, beta`` the columns' squared norms, ``gamma`` their dot product): the eigenvalues of the pair's
``2 x 2`` Gram matrix are then its diagonal moved by at most ``gamma^2 / |alpha - beta| <= SEPARATED min(alpha,
beta)`` (relative ``1e-17``), so the column norms are the singular values as accurately as after the rotation. Such
a pair's squared cosine is below ``WIDE`` (``|alpha - beta| min <= alpha beta``): it is a finished sweep's pair,
whose rotation (a few hundred flops) the check alone now replaces."""
EXTRAPOLATE = 0.1
"""A lane's warm start is extrapolated only where that moves no entry of its last ``V`` by more than this (then
the guess is well conditioned and one Gram-Schmidt pass makes it orthogonal to round-off); elsewhere (unrelated
points, a jump) it is its last ``V``, orthogonal already."""


@kernel(inline="always")
def lane_rows(m, E):
    """The rows of :func:`jacobi_loop_rows`'s work array (each row ``LANES`` doubles, one a lane): where ``M`` (``J^T``
    and its QR, ``m x E``), the reflectors' first entries and factors (``E`` each), ``det``, the tangent
    (``m``), ``W`` (``E x E``), the sweep's flags, three temporaries, then the warm start ``V``, ``V_1``, ``V_2``
    (``E x E`` each) and its depth begin, and the total. One array, indexed by constants once the sizes are
    literal, so that LLVM sees that the lanes' loops carry no dependence and vectorises them without checks."""
    M = 0
    VH = M + m * E
    BETA = VH + E
    DET = BETA + E
    T = DET + 1
    W = T + m
    WIDE_ROW = W + E * E
    TMP = WIDE_ROW + 1
    V = TMP + 3
    V1 = V + E * E
    V2 = V1 + E * E
    DEPTH = V2 + E * E
    return M, VH, BETA, DET, T, W, WIDE_ROW, TMP, V, V1, V2, DEPTH, DEPTH + 1


@kernel()
def jacobi_loop_state(E):
    """The warm start of :func:`jacobi_loop_rows`, carried from one call to the next along a path: each lane's
    right singular vectors at its last point and the two before (``3 x E x E`` rows of ``LANES``) and how many of
    them are set (one row; fresh: the identity, none)."""
    state = np.zeros((3 * E * E + 1) * LANES)
    for a in range(E):
        for l in range(LANES):
            state[(a * E + a) * LANES + l] = 1.0
    return state


@kernel(**ROWS_OPTIONS)
def lanes_qr(S, L, m, E):
    """Householder QR of the ``LANES`` matrices ``M`` (``J^T``, ``m x E``) of the work array ``S`` in place, side
    by side: ``R`` on and above the diagonal, the reflectors below it with their first entries in ``VH`` and
    their ``2 / |v|^2`` in ``BETA``; ``DET`` the ``det(Q)`` of each (``-1`` a reflection). A zero column is left
    as it is (its factor 0; ``R`` then has a zero on its diagonal). Every loop has the lane innermost."""
    M, VH, BETA, DET, _, _, _, TMP, _, _, _, _, _ = lane_rows(m, E)
    for l in range(L):
        S[DET * L + l] = 1.0
    for k in range(E):
        for l in range(L):
            S[TMP * L + l] = 0.0
        for a in range(k, m):
            for l in range(L):
                x = S[(M + a * E + k) * L + l]
                S[TMP * L + l] += x * x
        for l in range(L):
            norm = math.sqrt(S[TMP * L + l])
            x = S[(M + k * E + k) * L + l]
            alpha = -norm if x >= 0.0 else norm
            vv = norm * (norm + abs(x))  # |x - alpha e_k|^2 / 2
            b = 1.0 / vv if vv > FLOOR else 0.0
            S[(VH + k) * L + l] = x - alpha
            S[(BETA + k) * L + l] = b
            S[(M + k * E + k) * L + l] = alpha
            S[DET * L + l] = -S[DET * L + l] if b > 0.0 else S[DET * L + l]
        for c in range(k + 1, E):
            for l in range(L):
                S[(TMP + 1) * L + l] = S[(VH + k) * L + l] * S[(M + k * E + c) * L + l]
            for a in range(k + 1, m):
                for l in range(L):
                    S[(TMP + 1) * L + l] += S[(M + a * E + k) * L + l] * S[(M + a * E + c) * L + l]
            for l in range(L):
                d = S[(TMP + 1) * L + l] * S[(BETA + k) * L + l]
                S[(TMP + 1) * L + l] = d
                S[(M + k * E + c) * L + l] -= d * S[(VH + k) * L + l]
            for a in range(k + 1, m):
                for l in range(L):
                    S[(M + a * E + c) * L + l] -= S[(TMP + 1) * L + l] * S[(M + a * E + k) * L + l]


@kernel(inline="always")
def lanes_tangent(S, L, m, E):
    """``T = Q e_m`` (normalised: a unit null vector of ``J`` where it has full row rank) from
    :func:`lanes_qr`'s reflectors, applied last to first."""
    M, VH, BETA, _, T, _, _, TMP, _, _, _, _, _ = lane_rows(m, E)
    for a in range(m):
        for l in range(L):
            S[(T + a) * L + l] = 1.0 if a == m - 1 else 0.0
    for k in range(E - 1, -1, -1):
        for l in range(L):
            S[(TMP + 1) * L + l] = S[(VH + k) * L + l] * S[(T + k) * L + l]
        for a in range(k + 1, m):
            for l in range(L):
                S[(TMP + 1) * L + l] += S[(M + a * E + k) * L + l] * S[(T + a) * L + l]
        for l in range(L):
            d = S[(TMP + 1) * L + l] * S[(BETA + k) * L + l]
            S[(TMP + 1) * L + l] = d
            S[(T + k) * L + l] -= d * S[(VH + k) * L + l]
        for a in range(k + 1, m):
            for l in range(L):
                S[(T + a) * L + l] -= S[(TMP + 1) * L + l] * S[(M + a * E + k) * L + l]
    for l in range(L):
        S[TMP * L + l] = 0.0
    for a in range(m):
        for l in range(L):
            x = S[(T + a) * L + l]
            S[TMP * L + l] += x * x
    for l in range(L):
        S[TMP * L + l] = 1.0 / math.sqrt(S[TMP * L + l])  # 1 to a few rounding errors
    for a in range(m):
        for l in range(L):
            S[(T + a) * L + l] *= S[TMP * L + l]


@kernel(**ROWS_OPTIONS)
def lanes_warm_start(S, L, m, E):
    """Each lane's start ``V``: its right singular vectors extrapolated from its last three points (``3 V - 3
    V_1 + V_2``, off by their third difference) once it has three and the extrapolation moves no entry by more
    than :data:`EXTRAPOLATE`, else its last (the identity when fresh);
    orthonormalised (modified Gram-Schmidt); then ``W = R V``, ``R`` the upper triangle of ``M[:E]``. The
    history moves back one point."""
    M, _, _, _, _, W, _, TMP, V, V1, V2, DEPTH, _ = lane_rows(m, E)
    for l in range(L):
        S[TMP * L + l] = 0.0
    for i in range(E * E):
        for l in range(L):
            step = 2.0 * S[(V + i) * L + l] - 3.0 * S[(V1 + i) * L + l] + S[(V2 + i) * L + l]
            S[TMP * L + l] = max(S[TMP * L + l], abs(step))
    for l in range(
        L
    ):  # extrapolate where the correction is small (a smooth path), so V stays well conditioned
        S[TMP * L + l] = 1.0 if (S[DEPTH * L + l] >= 3.0) & (S[TMP * L + l] <= EXTRAPOLATE) else 0.0
    for i in range(E * E):
        for l in range(L):
            x, x1 = S[(V + i) * L + l], S[(V1 + i) * L + l]
            S[(V + i) * L + l] = 3.0 * (x - x1) + S[(V2 + i) * L + l] if S[TMP * L + l] > 0.0 else x
            S[(V2 + i) * L + l] = x1
            S[(V1 + i) * L + l] = x
    for l in range(L):
        depth = S[DEPTH * L + l]
        S[DEPTH * L + l] = depth + 1.0 if depth < 3.0 else 3.0
    for c in range(E):
        for b in range(c):
            for l in range(L):
                S[TMP * L + l] = 0.0
            for a in range(E):
                for l in range(L):
                    S[TMP * L + l] += S[(V + a * E + b) * L + l] * S[(V + a * E + c) * L + l]
            for a in range(E):
                for l in range(L):
                    S[(V + a * E + c) * L + l] -= S[TMP * L + l] * S[(V + a * E + b) * L + l]
        for l in range(L):
            S[TMP * L + l] = 0.0
        for a in range(E):
            for l in range(L):
                x = S[(V + a * E + c) * L + l]
                S[TMP * L + l] += x * x
        for l in range(L):
            S[TMP * L + l] = 1.0 / math.sqrt(S[TMP * L + l])
        for a in range(E):
            for l in range(L):
                S[(V + a * E + c) * L + l] *= S[TMP * L + l]
    for a in range(E):
        for c in range(E):
            for l in range(L):
                S[TMP * L + l] = 0.0
            for b in range(a, E):
                for l in range(L):
                    S[TMP * L + l] += S[(M + a * E + b) * L + l] * S[(V + b * E + c) * L + l]
            for l in range(L):
                S[(W + a * E + c) * L + l] = S[TMP * L + l]


@kernel(**ROWS_OPTIONS)
def lanes_sweep(S, L, m, E):
    """One cyclic sweep of one-sided Jacobi rotations (Hestenes) on the columns of every lane's ``W (E, E)``
    (and ``V``), side by side: the rotation of :func:`linkwork.kinematics.dyad_solver.jacobi_sweeps`, made as
    the identity where a pair's squared cosine is below :data:`TINY`; a lane's ``WIDE_ROW`` entry set to 1
    where some pair's squared cosine exceeded :data:`WIDE` (that lane's sweep did not finish). A pair that is
    :data:`SEPARATED` in every lane is left as it is, and ``V`` (only the next point's warm start) is not rotated
    where every lane's rotation is within ``1e-8`` of the identity: a finished sweep is then mostly a check."""
    _, _, _, _, _, W, WIDE_ROW, TMP, V, _, _, _, _ = lane_rows(m, E)
    for p in range(E - 1):
        for r in range(p + 1, E):
            for l in range(L):
                S[TMP * L + l] = 0.0
                S[(TMP + 1) * L + l] = 0.0
                S[(TMP + 2) * L + l] = 0.0
            for a in range(E):
                for l in range(L):
                    wp, wr = S[(W + a * E + p) * L + l], S[(W + a * E + r) * L + l]
                    S[TMP * L + l] += wp * wp
                    S[(TMP + 1) * L + l] += wr * wr
                    S[(TMP + 2) * L + l] += wp * wr
            wide, keep = 0, 0
            for l in range(L):
                alpha, beta, gamma = S[TMP * L + l], S[(TMP + 1) * L + l], S[(TMP + 2) * L + l]
                gg, ab = gamma * gamma, alpha * beta
                wide += 1 if gg > WIDE * ab else 0
                keep += 1 if gg > SEPARATED * abs(alpha - beta) * min(alpha, beta) else 0
                S[WIDE_ROW * L + l] = 1.0 if gg > WIDE * ab else S[WIDE_ROW * L + l]
            if keep == 0:
                continue  # in every lane, leaving the pair as it is moves its squared norms by < 1e-17 relative
            for l in range(L):
                alpha, beta, gamma = S[TMP * L + l], S[(TMP + 1) * L + l], S[(TMP + 2) * L + l]
                gg, ab = gamma * gamma, alpha * beta
                d = beta - alpha
                root = math.sqrt(d * d + 4.0 * gg)
                big = abs(d) + root
                den = 2.0 * root * big
                turn = (gg > TINY * ab) & (den > FLOOR)
                inv = 1.0 / math.sqrt(den) if turn else 0.0
                S[TMP * L + l] = big * inv if turn else 1.0
                S[(TMP + 1) * L + l] = (2.0 * gamma if d >= 0.0 else -2.0 * gamma) * inv
            for a in range(E):
                for l in range(L):
                    cos, sin = S[TMP * L + l], S[(TMP + 1) * L + l]
                    wp, wr = S[(W + a * E + p) * L + l], S[(W + a * E + r) * L + l]
                    S[(W + a * E + p) * L + l] = cos * wp - sin * wr
                    S[(W + a * E + r) * L + l] = sin * wp + cos * wr
            if wide == 0:
                continue  # every lane's rotation is within 1e-8 of the identity: V (a warm start) keeps it
            for a in range(E):
                for l in range(L):
                    cos, sin = S[TMP * L + l], S[(TMP + 1) * L + l]
                    vp, vr = S[(V + a * E + p) * L + l], S[(V + a * E + r) * L + l]
                    S[(V + a * E + p) * L + l] = cos * vp - sin * vr
                    S[(V + a * E + r) * L + l] = sin * vp + cos * vr


@kernel(**ROWS_OPTIONS)
def lanes_at(jac, sigma, tangent, raw_tau, points, S, fallback, m, E):
    """The rows at the ``LANES`` points ``points`` of ``jac (E, m, K)``, side by side (see
    :func:`jacobi_loop_rows`; ``S`` the work array, :func:`lane_rows`); returns how many lanes fell back to the
    exact routine. ``m, E``: the sizes (literal constants at a call site, so that the loops over them unroll and
    the lanes' loops vectorise)."""
    M, _, _, DET, T, W, WIDE_ROW, TMP, _, _, _, DEPTH, _ = lane_rows(m, E)
    L = points.shape[0]  # LANES at run time: a loop of a known count of eight LLVM unrolls, not vectorises
    for a in range(m):
        for e in range(E):
            for l in range(L):
                S[(M + a * E + e) * L + l] = jac[e, a, points[l]]
    lanes_qr(S, L, m, E)
    lanes_tangent(S, L, m, E)
    for k in range(E):
        for l in range(L):
            S[DET * L + l] *= S[(M + k * E + k) * L + l]
    lanes_warm_start(S, L, m, E)
    for _ in range(LOCKSTEP_SWEEPS):
        for l in range(L):
            S[WIDE_ROW * L + l] = 0.0
        lanes_sweep(S, L, m, E)
        left = 0.0
        for l in range(L):
            left += S[WIDE_ROW * L + l]
        if left == 0.0:
            break
    # The singular values: the columns' norms, into row 0 of W (free now), sorted descending (odd-even
    # transposition sort: E rounds of compare-exchanges, the same in every lane).
    for c in range(E):
        for l in range(L):
            S[TMP * L + l] = 0.0
        for a in range(E):
            for l in range(L):
                x = S[(W + a * E + c) * L + l]
                S[TMP * L + l] += x * x
        for l in range(L):
            S[(W + c) * L + l] = math.sqrt(S[TMP * L + l])
    for rnd in range(E):
        for c in range(rnd % 2, E - 1, 2):
            for l in range(L):
                x, y = S[(W + c) * L + l], S[(W + c + 1) * L + l]
                S[(W + c) * L + l] = x if x >= y else y
                S[(W + c + 1) * L + l] = y if x >= y else x
    count = 0
    for l in range(L):
        k = points[l]
        for e in range(E):
            sigma[e, k] = S[(W + e) * L + l]
        for a in range(m):
            tangent[a, k] = S[(T + a) * L + l]
        raw_tau[k] = S[DET * L + l]
        if S[WIDE_ROW * L + l] > 0.0:  # not finished in LOCKSTEP_SWEEPS: the exact routine, cold
            A, Vx, Wx, norms, order = fallback
            for e in range(E):
                for c in range(m):
                    A[e, c] = jac[e, c, k]
            for a in range(m):
                for c in range(m):
                    Vx[a, c] = 1.0 if a == c else 0.0
            jacobi_svd(A, Vx, Wx, norms, order)
            for e in range(E):
                sigma[e, k] = norms[e]
            S[DEPTH * L + l] = 0.0  # its warm start was no good: the next point starts from its last V alone
            count += 1
    return count


@kernel(**ROWS_OPTIONS)
def lanes_pass(jac, sigma, tangent, raw_tau, begin, state, m, E):
    """:func:`jacobi_loop_rows` with the sizes ``m, E`` given (literal at a call site)."""
    K = jac.shape[2]
    _, _, _, _, _, _, _, _, V, _, _, _, total = lane_rows(m, E)
    L = state.shape[0] // (3 * E * E + 1)  # LANES, but read at run time (see lanes_at)
    S = np.empty(total * L)
    for i in range(state.shape[0]):
        S[V * L + i] = state[i]
    fallback = (
        np.empty((E, m)),
        np.empty((m, m)),
        np.empty((E, m)),
        np.empty(m),
        np.empty(m, dtype=np.int64),
    )
    points = np.empty(L, dtype=np.int64)
    groups = (K - begin + L - 1) // L
    first = K - groups * L
    count = 0
    for g in range(groups):
        for l in range(L):
            k = first + g * L + l
            points[l] = k if k >= begin else begin
        count += lanes_at(jac, sigma, tangent, raw_tau, points, S, fallback, m, E)
    for i in range(state.shape[0]):
        state[i] = S[V * L + i]
    return count


@kernel(**ROWS_OPTIONS)
def jacobi_loop_rows(jac, sigma, tangent, raw_tau, begin, state):
    """The route :func:`multi_loop_rows` took before its certified bidiagonal one, and still takes for three loops
    and more (the benchmark's baseline for two, ``benchmarks/bench_planar_rows.py``; its singular values are not
    certified lane by lane, only their sweeps' convergence). Singular values, unit tangent and raw test function of the multi-loop planar Jacobians ``jac (E, m, K)``
    (``m = E + 1``, one degree of freedom) at points ``begin .. K - 1``, :data:`LANES` points side by side.

    Writes ``sigma (E, K)`` (descending), ``tangent (m, K)`` (a unit null vector; either sign) and ``raw_tau
    (K,)`` (``det([J; t^T])`` for that ``t``); returns the number of points whose singular values the lanes did
    not finish (recomputed by :func:`linkwork.kinematics.small_svd.jacobi_svd`, cold).

    At each point a Householder QR of ``J^T = Q R``: the tangent is ``Q e_m`` and ``det([J; t^T]) = det(Q)
    det(R)``; the singular values are ``R``'s, by one-sided Jacobi on ``W = R V``, ``V`` the right singular
    vectors extrapolated from the lane's last three points (``state``, :func:`jacobi_loop_state`, carried from
    call to call along a path). Lane ``l`` takes points ``k0 + l``: each lane's previous point is ``LANES``
    points back (the groups are aligned on the last point, so that from one call to the next every lane
    continues its own stretch). The sweeps go on, all lanes together, until none has a pair left wider than
    :data:`WIDE` (after one sweep from a warm start, mostly two); the lanes' rotations are independent, so they
    run as packed operations instead of waiting on each other. Every singular value is within ``1e-13
    sigma_1``, ``|J t| <= 1e-14 sigma_1`` (Householder QR is backward stable), ``|t| = 1`` to ``1e-15``.
    """
    E, m = jac.shape[0], jac.shape[1]
    # Sizes as data (no literal 6 x 7 copy: two loops take the bidiagonal route, and a second, unrolled copy of
    # these lanes took minutes of every cold compile).
    return lanes_pass(jac, sigma, tangent, raw_tau, begin, state, m, E)


@kernel()
def multi_loop_state(E):
    """The warm start of :func:`multi_loop_rows`, carried from one call to the next along a path
    (:func:`linkwork.kinematics.bidiagonal_rows.bidiagonal_state`: each lane's squared singular values at its last
    point) where that route is taken (:func:`linkwork.kinematics.bidiagonal_rows.takes_bidiagonal`: two
    loops), else :func:`jacobi_loop_state` (the Jacobi lanes' right singular vectors)."""
    if takes_bidiagonal(E + 1, E):
        return bidiagonal_state(E)
    return jacobi_loop_state(E)


@kernel(**ROWS_OPTIONS)
def multi_loop_rows(jac, sigma, tangent, raw_tau, begin, state):
    """Singular values, unit tangent and raw test function of the multi-loop planar Jacobians ``jac (E, m, K)``
    (``m = E + 1``, one degree of freedom) at points ``begin .. K - 1``.

    Writes ``sigma (E, K)`` (descending), ``tangent (m, K)`` (a unit null vector; either sign) and ``raw_tau
    (K,)`` (``det([J; t^T])`` for that ``t``); returns the number of points whose singular values the certified
    route could not certify (recomputed by :func:`linkwork.kinematics.small_svd.jacobi_svd`, cold). ``state``
    (:func:`multi_loop_state`) is carried from call to call along a path.

    Two loops (``6 x 7``, :mod:`linkwork.kinematics.bidiagonal_rows`): a Householder bidiagonalisation of ``J^T``, 16 points
    side by side, gives the tangent, ``det([J; t^T])`` and a bidiagonal ``B``; the squared singular values are the
    roots of ``B^T B``'s characteristic polynomial (Laguerre's method from the lane's previous point's, else from
    the bounds), the smallest ``|det B|`` over the others' product; every lane carries a first-order error bound
    and is certified to ``1e-13 sigma_1`` for every singular value, or falls back. ``|J t| <= 1e-14 sigma_1``
    (Householder reflections are backward stable), ``|t| = 1`` to ``1e-15``.

    Three loops and more (``9 x 10``, ...): the reduction's own error bound there is wider than the budget
    (:func:`linkwork.kinematics.bidiagonal_rows.certifiable`), so every lane would fall back; those sizes take the
    Jacobi lanes (:func:`jacobi_loop_rows`, its state from :func:`multi_loop_state`) instead.
    """
    E, m = jac.shape[0], jac.shape[1]
    if takes_bidiagonal(m, E):
        return bidiagonal_rows(jac, sigma, tangent, raw_tau, begin, state)
    return jacobi_loop_rows(jac, sigma, tangent, raw_tau, begin, state)
