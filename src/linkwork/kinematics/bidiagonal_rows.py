"""Batched rows of multi-loop planar Jacobians, certified: the singular values of each ``E x m`` closure Jacobian
(``m = E + 1``) from its bidiagonal form, the tangent and the raw test function from the same reflections,
:data:`LANES` points side by side.

At each point ``J^T`` (``m x E``) is reduced to upper bidiagonal form by Householder reflections from the left and
the right, ``J^T = U [B; 0] V^T`` (Golub-Kahan; Golub & Van Loan Alg. 5.4.2), ``B`` with diagonal ``d`` and
superdiagonal ``e``. Then

* the tangent is ``t = U e_m`` (orthogonal to the range of ``J^T``: ``J t = 0``), and ``det([J; t^T]) = det(U)
  det(V) prod d_i`` (``[J; t^T] = diag(V, 1) diag(B^T, 1) U^T``; a reflection's determinant is ``-1``);
* the squared singular values are the eigenvalues of the tridiagonal ``T = B^T B / |B|_F^2`` (diagonal ``a_i = (d_i^2
  + e_(i-1)^2) / |B|_F^2``, off-diagonal ``d_i e_i / |B|_F^2``; scaled so that they lie in ``[0, 1]``). Its
  characteristic polynomial ``p`` and its first two derivatives come from the three-term recurrence of the leading
  minors (Golub & Van Loan Sec. 8.4.1), without division; the ``E - 1`` largest roots by Laguerre's method
  (cubically convergent, and for a polynomial with real roots convergent from any start to a root next to it:
  Stoer & Bulirsch Sec. 5.5, Wilkinson Sec. 7.48), started from the lane's previous point's (``state``); where a
  lane has none, or those steps do not certify it, from Samuelson's bound of the largest root, each next root from
  just below the one before with Maehly's implicit deflation ``p(x) / prod (x - x_j)`` (Stoer & Bulirsch Sec.
  5.5);
* the smallest singular value is ``sigma_E = |prod d_i| / (sigma_1 ... sigma_(E-1))`` (``|det B|`` is the product
  of ``B``'s singular values): accurate relative to itself however small, so a near rank drop is measured, not
  lost in the rounding of ``sigma_E^2``.

**Certification.** Every lane carries a first-order bound of its errors; a lane is certified when every singular
value is within :data:`SIGMA_TOL` times ``sigma_1`` of ``J``'s:

* the reduction's backward error: the computed ``B`` is that of ``J + dJ``, ``|dJ|_F <= c u |J|_F`` (``u`` the
  unit round-off; each reflection applied to a column or row of length ``k`` errs by at most ``(3 k + 10) u`` times
  its norm to first order, Higham Lemma 19.2 with its constants written out; ``c`` their sum over the reflections,
  :func:`reduction_bound`, 213 for ``6 x 7``), so each singular value of ``B`` is within ``c u |J|_F`` of ``J``'s
  (Weyl, Golub & Van Loan Cor. 8.6.2);
* each root ``x_i`` of ``p``: within ``(|p(x_i)| + mu) / |p'(x_i)|`` of an eigenvalue of the exact ``T`` of ``B``,
  ``mu`` the running error bound of the recurrence at ``x_i`` (Higham Sec. 3.1 and 5.1, with the rounding of ``T``'s
  entries from ``d`` and ``e`` as data errors), the residual ``|p|`` counting an unconverged iteration;
* the roots are distinct roots: their intervals ``x_i +- dx_i`` are disjoint and descending, the derived
  ``sigma_E`` is at most ``sigma_(E-1)`` (the product identity makes it the one root not found; below the others,
  it is the smallest), and the roots with ``sigma_E^2`` sum to ``trace(T)`` within their bounds;
* then ``|dsigma_i| <= dlambda_i / sigma_i`` (``lambda = sigma^2``: small ``sigma_i`` relative to ``sigma_1`` are
  where this fails, and those lanes fall back) and ``sigma_E``'s relative error is the sum of the others'.

A lane that is not certified by the warm steps is redone from the bounds (all lanes together, when any needs it);
one still not certified goes to the exact fall-back, a one-sided Jacobi SVD of ``J``
(:func:`linkwork.kinematics.small_svd.jacobi_svd`): accuracy never depends on the starting values. The tangent
and ``raw_tau`` are those of the reduction (Householder reflections are backward stable: ``|J t| <= c u |J|_F``,
``c`` as above, a few ``u sigma_1`` in practice).

The reduction and the tangent run :data:`CHUNK` points at a time (:func:`chunk_bidiagonal`), each loop over the
chunk's points innermost on separate rows of its array: long loops, which LLVM vectorises with a run-time check
that the rows do not overlap (the lanes' loops, 16 long at offsets known only at run time, stayed scalar). Each
point's arithmetic is the lane loops' before, in the same order (the results are bit for bit the same, so the
reduction's bound is unchanged). The roots then go :data:`LANES` points at a time; there every loop has the lane
innermost, or is the whole per-lane computation with no branches (conditional expressions only), so that LLVM
vectorises it across lanes; every kernel also runs as plain Python (the twins of
:mod:`linkwork.kinematics.jit`): divisors and square roots are guarded, so a degenerate lane gives a value that
fails its certification, never an exception or a warning.

References
----------
G. H. Golub, C. F. Van Loan, *Matrix Computations*, 4th ed., Johns Hopkins (2013): Alg. 5.4.2 (Householder
bidiagonalisation), Sec. 8.4.1 (the characteristic polynomial of a tridiagonal matrix), Cor. 8.6.2 (singular
values move by at most the norm of a perturbation).
N. J. Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., SIAM (2002): Sec. 3.1 and 5.1 (running
error bounds), Lemma 19.2 (applying a computed Householder reflection).
J. Stoer, R. Bulirsch, *Introduction to Numerical Analysis*, 3rd ed., Springer (2002), Sec. 5.5 (roots of
polynomials with real roots: Newton's and Laguerre's methods, Maehly's deflation).
J. H. Wilkinson, *The Algebraic Eigenvalue Problem*, Oxford (1965), Sec. 7.48 (Laguerre's method).
P. A. Samuelson, J. Am. Stat. Assoc. 63 (1968) 1522-1525 (the upper bound ``mean + sqrt(n - 1) std`` of the roots).
"""

from __future__ import annotations

import math

import numpy as np

from linkwork.kernel_cache import ROWS_OPTIONS, kernel
from linkwork.kinematics.small_svd import jacobi_svd

U = 2.0**-53
"""The unit round-off of float64."""
LANES = 16
"""Points whose roots are found side by side (each a lane of the packed operations)."""
CHUNK = 256
"""Points reduced together (:func:`chunk_bidiagonal`): a multiple of :data:`LANES`, long loops for the packed
operations, the chunk's array (about 150 kB for ``6 x 7``) in the L2 cache."""
SIGMA_TOL = 1e-13
"""A lane is certified when every singular value's error bound is below this times ``sigma_1``."""
WARM_EVALUATIONS = 3
"""Evaluations of the characteristic polynomial and its error bound at each root after :data:`BLIND_STEPS` (a
Laguerre step after each but the last, on the lanes not yet certified); the lanes stop together when every lane is
certified."""
BLIND_STEPS = 2
"""Laguerre steps from a warm start before the first evaluation of the bounds (without them: on the Watt six-bar's
turn in 3600 steps, lanes 16 points apart, two leave every root within a few rounding errors)."""
COLD_STEPS = 6
"""Laguerre steps for each root from the bounds (Maehly's deflation): enough for Gaussian Jacobians."""
BELOW = 1e-3
"""From the bounds, root ``i + 1``'s first iterate is root ``i`` times ``1 - BELOW`` (below it, off its pole)."""
FLOOR = 1e-300
"""Divisors are at least this (a degenerate lane gives finite nonsense, which fails its certification)."""


@kernel(inline="always")
def work_rows(m, E):
    """The rows of the work array (each ``LANES`` doubles, one a lane): ``M`` (``J^T``, ``m x E``, reduced in place:
    the left reflectors below the diagonal, the right ones right of the superdiagonal), the reflectors' first
    entries and factors (left and right, ``E`` each), ``det(U) det(V)``, the tangent (``m``), ``T``'s diagonal and
    squared off-diagonal (``E`` each), ``prod d_i``, ``|B|_F^2``, the roots, their bounds, their Laguerre steps,
    whether each is converged, the cold roots (``E`` each), the singular values (``E``), the certified flag, four temporaries, then the state:
    the previous roots (``E - 1``) and whether they are set. Returns their offsets and the total."""
    M = 0
    VH = M + m * E
    BETA = VH + E
    VR = BETA + E
    BR = VR + E
    DET = BR + E
    T = DET + 1
    A = T + m
    W = A + E
    PROD = W + E
    P1 = PROD + 1
    X = P1 + 1
    DX = X + E
    STEP = DX + E
    CONV = STEP + E
    XC = CONV + E
    SIG = XC + E
    OK = SIG + E
    TMP = OK + 1
    PREV = TMP + 4
    SET = PREV + E - 1
    return (
        M,
        VH,
        BETA,
        VR,
        BR,
        DET,
        T,
        A,
        W,
        PROD,
        P1,
        X,
        DX,
        STEP,
        CONV,
        XC,
        SIG,
        OK,
        TMP,
        PREV,
        SET,
        SET + 1,
    )


@kernel()
def bidiagonal_state(E):
    """The warm start carried along a path: each lane's roots at its last point (``E - 1`` rows of ``LANES``) and
    whether they are set (one row; fresh: not)."""
    return np.zeros(E * LANES)


@kernel(inline="always")
def reduction_bound(m, E):
    """``c`` of the reduction's backward error ``|dJ|_F <= c u |J|_F`` (first order): ``3 k + 10`` for each
    reflection of length ``k`` (left: ``m - j`` for ``j < E``; right: ``E - 1 - j`` for ``j < E - 2``)."""
    c = 0.0
    for j in range(E):
        c += 3.0 * (m - j) + 10.0
    for j in range(E - 2):
        c += 3.0 * (E - 1 - j) + 10.0
    return c


@kernel(inline="always")
def certifiable(m, E):
    """Whether the bidiagonal route can certify ``m x E`` (``J^T``) Jacobians: the reduction's share of the budget
    at its worst (``|J|_F = sqrt(E) sigma_1``), ``c u sqrt(E)``, is at most three quarters of :data:`SIGMA_TOL`,
    leaving the roots at least a quarter. True for two loops (``6 x 7``: ``c = 213``, 0.58) and fewer; false
    for three (``9 x 10``: ``c = 427``, 1.42, wider than the whole budget: every lane would fall back) and more."""
    return reduction_bound(m, E) * U * math.sqrt(E) <= 0.75 * SIGMA_TOL


@kernel(inline="always")
def chunk_rows(m, E):
    """The rows of the chunk's array (each :data:`CHUNK` doubles, one a point): ``M`` (``J^T``, ``m x E``,
    reduced in place as in :func:`work_rows`), the reflectors' first entries and factors (left and right, ``E``
    each), ``det(U) det(V)``, the tangent (``m``), two temporaries. Returns their offsets and the total."""
    M = 0
    VH = M + m * E
    BETA = VH + E
    VR = BETA + E
    BR = VR + E
    DET = BR + E
    T = DET + 1
    TMP = T + m
    return M, VH, BETA, VR, BR, DET, T, TMP, TMP + 2


@kernel(inline="always")
def chunk_reflect(B, n, pivot, head, factor, rows, start, stop, stride, det):
    """One Householder reflection at each of the ``n`` points of ``B``: its vector is row ``pivot`` and rows
    ``start, start + stride, ... < stop`` (zeroed below or right of the pivot); its first entry goes into row
    ``head``, its factor into row ``factor``, the pivot becomes ``alpha = -sign(x) |v|``, and ``det`` changes
    sign (a zero vector's reflection is the identity). ``rows`` the temporary."""
    acc = B[rows]
    x0 = B[pivot]
    for p in range(n):
        acc[p] = x0[p] * x0[p]
    for a in range(start, stop, stride):
        col = B[a]
        for p in range(n):
            x = col[p]
            acc[p] += x * x
    vh = B[head]
    beta = B[factor]
    sign = B[det]
    for p in range(n):
        norm = math.sqrt(acc[p])
        x = x0[p]
        alpha = -norm if x >= 0.0 else norm
        vv = norm * (norm + abs(x))  # |x - alpha e_k|^2 / 2
        b = 1.0 / vv if vv > FLOOR else 0.0
        vh[p] = x - alpha
        beta[p] = b
        x0[p] = alpha
        sign[p] = -sign[p] if b > 0.0 else sign[p]


@kernel(inline="always")
def chunk_apply(B, n, head, factor, vector, target, count, vstep, tstep, top, rows):
    """Applies a reflection (first entry row ``head``, factor row ``factor``, the rest rows ``vector + i vstep``,
    ``i = 0 .. count - 1``) to the vector whose first entry is row ``top`` and the rest rows ``target + i tstep``,
    at each of the ``n`` points: ``y -= beta (v . y) v``. ``rows`` the temporary (``beta (v . y)``)."""
    dot = B[rows]
    vh = B[head]
    y0 = B[top]
    for p in range(n):
        dot[p] = vh[p] * y0[p]
    for i in range(0, count - 1, 2):  # two terms a pass (half the loads and stores of ``dot``), in order
        u = B[vector + i * vstep]
        v = B[target + i * tstep]
        u2 = B[vector + (i + 1) * vstep]
        v2 = B[target + (i + 1) * tstep]
        for p in range(n):
            dot[p] = (dot[p] + u[p] * v[p]) + u2[p] * v2[p]
    if count % 2 == 1:
        u = B[vector + (count - 1) * vstep]
        v = B[target + (count - 1) * tstep]
        for p in range(n):
            dot[p] += u[p] * v[p]
    beta = B[factor]
    for p in range(n):
        d = dot[p] * beta[p]
        dot[p] = d
        y0[p] -= d * vh[p]
    for i in range(count):
        u = B[vector + i * vstep]
        v = B[target + i * tstep]
        for p in range(n):
            v[p] -= dot[p] * u[p]


@kernel(inline="always")
def chunk_bidiagonal(B, n, m, E):
    """Householder bidiagonalisation of the ``n`` matrices ``M`` (``m x E``) of ``B`` in place (Golub & Van Loan
    Alg. 5.4.2): for each column ``k`` a reflection from the left zeroes ``M[k+1:, k]``, then one from the right
    zeroes ``M[k, k+2:]``. ``DET`` collects ``-1`` for each reflection made. Every loop has the point innermost,
    over the chunk (separate rows, a long trip count: LLVM checks at run time that the rows do not overlap and
    runs the packed loop); each point's arithmetic is that of the lane loops before, in the same order."""
    M, VH, BETA, VR, BR, DET, _, TMP, _ = chunk_rows(m, E)
    sign = B[DET]
    for p in range(n):
        sign[p] = 1.0
    for k in range(E):
        # From the left: column k, rows k .. m - 1.
        chunk_reflect(B, n, M + k * E + k, VH + k, BETA + k, TMP, M + (k + 1) * E + k, M + m * E, E, DET)
        for c in range(k + 1, E):
            chunk_apply(
                B,
                n,
                VH + k,
                BETA + k,
                M + (k + 1) * E + k,
                M + (k + 1) * E + c,
                m - k - 1,
                E,
                E,
                M + k * E + c,
                TMP + 1,
            )
        if k >= E - 2:
            continue
        # From the right: row k, columns k + 1 .. E - 1 (its reflector in that row, right of k + 1).
        chunk_reflect(B, n, M + k * E + k + 1, VR + k, BR + k, TMP, M + k * E + k + 2, M + k * E + E, 1, DET)
        for a in range(k + 1, m):
            chunk_apply(
                B,
                n,
                VR + k,
                BR + k,
                M + k * E + k + 2,
                M + a * E + k + 2,
                E - k - 2,
                1,
                1,
                M + a * E + k + 1,
                TMP + 1,
            )


@kernel(inline="always")
def chunk_tangent(B, n, m, E):
    """``t = U e_m`` (normalised: a unit null vector of ``J`` where it has full row rank) from the left
    reflectors, applied last to first, at each of the ``n`` points."""
    M, VH, BETA, _, _, _, T, TMP, _ = chunk_rows(m, E)
    for a in range(m):
        row = B[T + a]
        for p in range(n):
            row[p] = 1.0 if a == m - 1 else 0.0
    for k in range(E - 1, -1, -1):
        chunk_apply(B, n, VH + k, BETA + k, M + (k + 1) * E + k, T + k + 1, m - k - 1, E, 1, T + k, TMP + 1)
    acc = B[TMP]
    for p in range(n):
        acc[p] = 0.0
    for a in range(m):
        row = B[T + a]
        for p in range(n):
            x = row[p]
            acc[p] += x * x
    for p in range(n):
        acc[p] = 1.0 / math.sqrt(acc[p])  # 1 to a few rounding errors
    for a in range(m):
        row = B[T + a]
        for p in range(n):
            row[p] *= acc[p]


@kernel(inline="always")
def lanes_tridiagonal(S, L, m, E):
    """``T = B^T B / |B|_F^2`` (diagonal into ``A``, squared off-diagonal into ``W``), ``|B|_F^2`` into ``P1`` and
    ``prod d_i`` into ``PROD``; ``DET`` becomes ``det(U) det(V) prod d_i``."""
    M, _, _, _, _, DET, _, A, W, PROD, P1, _, _, _, _, _, _, _, _, _, _, _ = work_rows(m, E)
    for l in range(L):
        total, prod = 0.0, 1.0
        for k in range(E):
            d = S[(M + k * E + k) * L + l]
            total += d * d
            prod *= d
        for k in range(E - 1):
            f = S[(M + k * E + k + 1) * L + l]
            total += f * f
        inv = 1.0 / total if total > FLOOR else 0.0
        before = 0.0
        for k in range(E):
            d = S[(M + k * E + k) * L + l]
            S[(A + k) * L + l] = (d * d + before) * inv
            if k < E - 1:
                f = S[(M + k * E + k + 1) * L + l]
                b = d * f * inv
                S[(W + k) * L + l] = b * b
                before = f * f
        S[P1 * L + l] = total
        S[PROD * L + l] = prod
        S[DET * L + l] *= prod


@kernel(inline="always")
def characteristic(S, L, E, l, x):
    """``p(x) = det(T - x I)``, ``p'(x)``, ``p''(x)`` at lane ``l`` by the three-term recurrence of the leading
    minors, and ``mu``, a first-order bound of ``|fl(p) - p|`` for the exact ``T`` of ``B`` (running error
    analysis: ``a_i`` errs by ``4 u a_i``, ``w_i`` by ``5 u w_i``, each product and difference by ``u``)."""
    _, _, _, _, _, _, _, A, W, _, _, _, _, _, _, _, _, _, _, _, _, _ = work_rows(E + 1, E)
    a = S[A * L + l]
    c = a - x
    pm, p = 1.0, c
    dm, dp = 0.0, -1.0
    hm, hp = 0.0, 0.0
    mm, mu = 0.0, U * (4.0 * a + abs(c))
    for k in range(1, E):
        a = S[(A + k) * L + l]
        w = S[(W + k - 1) * L + l]
        c = a - x
        pn = c * p - w * pm
        dn = c * dp - p - w * dm
        hn = c * hp - 2.0 * dp - w * hm
        mn = abs(c) * mu + w * mm + U * ((4.0 * a + 2.0 * abs(c)) * abs(p) + 6.0 * w * abs(pm) + abs(pn))
        pm, p, dm, dp, hm, hp, mm, mu = p, pn, dp, dn, hp, hn, mu, mn
    return p, dp, hp, mu


@kernel(inline="always")
def lanes_bounds(S, L, E):
    """At each lane's roots ``X``: their error bounds ``(|p| + mu) / |p'|`` into ``DX`` and Laguerre's steps
    ``n p / (p' +- sqrt((n - 1)^2 p'^2 - n (n - 1) p p''))`` (``n = E``, the sign of ``p'``) into ``STEP``, and
    into ``CONV`` whether the root is converged to round-off (``|p| <= mu``: the residual is within the
    evaluation's own error bound)."""
    _, _, _, _, _, _, _, _, _, _, _, X, DX, STEP, CONV, _, _, _, _, _, _, _ = work_rows(E + 1, E)
    n = float(E)
    for r in range(E - 1):
        for l in range(L):
            x = S[(X + r) * L + l]
            p, dp, hp, mu = characteristic(S, L, E, l, x)
            slope = abs(dp)
            S[(DX + r) * L + l] = (abs(p) + mu) / (slope if slope > FLOOR else FLOOR)
            disc = (n - 1.0) * ((n - 1.0) * dp * dp - n * p * hp)
            root = math.sqrt(disc if disc > 0.0 else 0.0)
            den = dp + root if dp >= 0.0 else dp - root
            S[(STEP + r) * L + l] = n * p / (den if abs(den) > FLOOR else FLOOR)
            S[(CONV + r) * L + l] = 1.0 if abs(p) <= mu else 0.0


@kernel(inline="always")
def lanes_step(S, L, E):
    """One Laguerre step (see :func:`lanes_bounds`) at every lane's roots ``X``, without their bounds (from a warm
    start, a lane's last point ``LANES`` points back, the first evaluations would not certify)."""
    _, _, _, _, _, _, _, _, _, _, _, X, _, _, _, _, _, _, _, _, _, _ = work_rows(E + 1, E)
    n = float(E)
    for r in range(E - 1):
        for l in range(L):
            x = S[(X + r) * L + l]
            p, dp, hp, _ = characteristic(S, L, E, l, x)
            disc = (n - 1.0) * ((n - 1.0) * dp * dp - n * p * hp)
            root = math.sqrt(disc if disc > 0.0 else 0.0)
            den = dp + root if dp >= 0.0 else dp - root
            S[(X + r) * L + l] = x - n * p / (den if abs(den) > FLOOR else FLOOR)


@kernel(inline="always")
def lanes_check(S, L, m, E, strict):
    """The singular values of every lane from its roots ``X`` and bounds ``DX`` into ``SIG`` (``sigma_E = |prod
    d_i| / prod sigma_i``), and whether they are certified into ``OK`` (see the module's docstring: every root
    within ``dx_i`` of an eigenvalue of ``T``, the intervals disjoint and descending, ``sigma_E <= sigma_(E-1)``,
    the trace, and every singular value within ``SIGMA_TOL sigma_1`` of ``J``'s). Returns the lanes not
    certified (with ``strict``, also not converged to round-off: stopping there makes the values independent of
    the starts, to round-off). The budget ``beta`` (``SIGMA_TOL sigma_1`` less the reduction's and the roundings' share): each
    ``sigma_i`` (``i < E``) errs by at most ``dsigma_i = dlambda_i / sigma_i <= beta sigma_i / ((E - 1) sigma_E +
    sigma_i)``, so that ``dsigma_i <= beta`` and ``sigma_E``'s error, ``sigma_E sum_i dsigma_i / sigma_i`` (its
    relative error is the sum of theirs), is at most ``beta`` too; no division."""
    _, _, _, _, _, _, _, A, _, PROD, P1, X, DX, _, CONV, _, SIG, OK, _, _, _, _ = work_rows(m, E)
    c = reduction_bound(m, E)
    bad = 0
    for l in range(L):
        p1 = S[P1 * L + l]
        trace, found, width = 0.0, 0.0, 0.0
        ok = True
        product = 1.0
        last = 2.0
        for r in range(E - 1):
            x = S[(X + r) * L + l]
            dx = S[(DX + r) * L + l]
            s = math.sqrt(x * p1 if x > 0.0 else 0.0)
            S[(SIG + r) * L + l] = s
            product *= s
            ok = ok & (x > 0.0) & (x + dx < last) & ((S[(CONV + r) * L + l] > 0.0) | (not strict))
            last = x - dx
            found += x
            width += dx
            trace += S[(A + r) * L + l]
        trace += S[(A + E - 1) * L + l]
        low = abs(S[PROD * L + l]) / (product if product > FLOOR else FLOOR)
        S[(SIG + E - 1) * L + l] = low
        s1 = S[SIG * L + l]
        beta = SIGMA_TOL * s1 - c * U * math.sqrt(p1) - 8.0 * E * U * s1
        spread = (E - 1.0) * low
        for r in range(E - 1):
            s = S[(SIG + r) * L + l]
            ok = ok & (S[(DX + r) * L + l] * p1 * (spread + s) <= beta * s * s)
        x_low = low * low / (p1 if p1 > FLOOR else FLOOR)
        ok = ok & (low <= S[(SIG + E - 2) * L + l])
        ok = ok & (abs(found + x_low - trace) <= 2.0 * width + 4.0 * E * U + 2.0 * x_low * SIGMA_TOL)
        S[OK * L + l] = 1.0 if ok else 0.0
        bad += 0 if ok else 1
    return bad


@kernel(**ROWS_OPTIONS)
def lanes_cold(S, L, m, E):
    """Roots into ``XC`` from the bounds: the largest from Samuelson's bound of ``T``'s eigenvalues (``1/E + sqrt(E
    - 1) std``, ``std`` from ``trace(T) = 1`` and ``|T|_F^2``), each next from just below the one before
    (:data:`BELOW`), by :data:`COLD_STEPS` Laguerre steps on ``p(x) / Q(x)``, ``Q = prod (x - x_j)`` over the
    roots found (Maehly's deflation), in the homogeneous form ``f = p Q^2``, ``f' = (p' Q - p Q') Q``, ``f'' = p''
    Q^2 - 2 p' Q' Q - p Q'' Q + 2 p Q'^2`` (Laguerre's step is unchanged when ``f, f', f''`` are scaled
    together): no division but the step's."""
    _, _, _, _, _, _, _, A, W, _, _, _, _, _, _, XC, _, _, _, _, _, _ = work_rows(m, E)
    for l in range(L):
        sq = 0.0
        for k in range(E):
            a = S[(A + k) * L + l]
            sq += a * a
        for k in range(E - 1):
            sq += 2.0 * S[(W + k) * L + l]
        mean = 1.0 / E
        spread = sq / E - mean * mean
        top = mean + math.sqrt((E - 1.0) * (spread if spread > 0.0 else 0.0))
        S[XC * L + l] = (top if top < 1.0 else 1.0) * (1.0 + 8.0 * U)
    for r in range(E - 1):
        n = float(E - r)
        for l in range(L):
            x = S[XC * L + l] if r == 0 else S[(XC + r - 1) * L + l] * (1.0 - BELOW)
            for _ in range(COLD_STEPS):
                p, dp, hp, _ = characteristic(S, L, E, l, x)
                q, dq, hq = 1.0, 0.0, 0.0
                for j in range(r):
                    t = x - S[(XC + j) * L + l]
                    hq = t * hq + 2.0 * dq
                    dq = t * dq + q
                    q = t * q
                f = p * q * q
                f1 = (dp * q - p * dq) * q
                f2 = (hp * q - 2.0 * dp * dq - p * hq) * q + 2.0 * p * dq * dq
                disc = (n - 1.0) * ((n - 1.0) * f1 * f1 - n * f * f2)
                root = math.sqrt(disc if disc > 0.0 else 0.0)
                den = f1 + root if f1 >= 0.0 else f1 - root
                x -= n * f / (den if abs(den) > FLOOR else FLOOR)
            S[(XC + r) * L + l] = x


@kernel(**ROWS_OPTIONS)
def lanes_refine(S, L, m, E):
    """Laguerre's steps from the roots ``X``: :data:`BLIND_STEPS` on every lane (:func:`lanes_step`), then
    :data:`WARM_EVALUATIONS` evaluations with their bounds, a step after each but the last on the lanes not yet
    certified and converged, all lanes stopping together when every lane is; returns the lanes not certified
    (converged or not) at the end."""
    _, _, _, _, _, _, _, _, _, _, _, X, _, STEP, _, _, _, OK, _, _, _, _ = work_rows(m, E)
    bad = L
    for _ in range(BLIND_STEPS):
        lanes_step(S, L, E)
    for it in range(WARM_EVALUATIONS):
        lanes_bounds(S, L, E)
        bad = lanes_check(S, L, m, E, True)
        if bad == 0:
            break
        if it == WARM_EVALUATIONS - 1:
            bad = lanes_check(S, L, m, E, False)  # certified, if not to round-off
            break
        for r in range(E - 1):
            for l in range(L):
                x = S[(X + r) * L + l]
                S[(X + r) * L + l] = x if S[OK * L + l] > 0.0 else x - S[(STEP + r) * L + l]
    return bad


@kernel(**ROWS_OPTIONS)
def lanes_roots(S, L, m, E):
    """The roots of every lane, certified where possible (``OK``): refined from the state's previous roots; if any
    lane is fresh or not certified, the roots from the bounds for those lanes, refined again."""
    _, _, _, _, _, _, _, _, _, _, _, X, _, _, _, XC, _, OK, _, PREV, SET, _ = work_rows(m, E)
    fresh = 0
    for l in range(L):
        fresh += 1 if S[SET * L + l] == 0.0 else 0
    bad = L
    if fresh < L:
        for r in range(E - 1):
            for l in range(L):
                S[(X + r) * L + l] = S[(PREV + r) * L + l]
        bad = lanes_refine(S, L, m, E)
    else:
        for l in range(L):
            S[OK * L + l] = 0.0
    if bad > 0:
        lanes_cold(S, L, m, E)
        for r in range(E - 1):
            for l in range(L):
                x = S[(X + r) * L + l]
                S[(X + r) * L + l] = x if S[OK * L + l] > 0.0 else S[(XC + r) * L + l]
        bad = lanes_refine(S, L, m, E)
    return bad


@kernel(**ROWS_OPTIONS)
def lanes_at(jac, sigma, raw_tau, points, S, B, base, fallback, m, E):
    """The singular values and the raw test function at the ``LANES`` points ``points`` of ``jac (E, m, K)``, side
    by side, from their reduction (columns ``base .. base + LANES - 1`` of the chunk's array ``B``); returns how
    many lanes fell back to the exact routine. ``m, E``: the sizes (literal at a call site, so that the loops over
    them unroll and the lanes' loops vectorise)."""
    M, _, _, _, _, DET, _, _, _, _, P1, _, _, _, _, _, SIG, OK, _, PREV, SET, _ = work_rows(m, E)
    DET_B = chunk_rows(m, E)[5]
    L = LANES  # a constant: LLVM proves the rows' ranges disjoint and vectorises without run-time checks
    for k in range(E):
        for l in range(L):
            S[(M + k * E + k) * L + l] = B[M + k * E + k, base + l]
        if k < E - 1:
            for l in range(L):
                S[(M + k * E + k + 1) * L + l] = B[M + k * E + k + 1, base + l]
    for l in range(L):
        S[DET * L + l] = B[DET_B, base + l]
    lanes_tridiagonal(S, L, m, E)
    bad = lanes_roots(S, L, m, E)
    count = 0
    for l in range(L):
        k = points[l]
        raw_tau[k] = S[DET * L + l]
        if bad > 0 and S[OK * L + l] == 0.0:  # not certified: the exact routine, cold
            A, Vx, Wx, norms, order = fallback
            for e in range(E):
                for c in range(m):
                    A[e, c] = jac[e, c, k]
            for a in range(m):
                for c in range(m):
                    Vx[a, c] = 1.0 if a == c else 0.0
            jacobi_svd(A, Vx, Wx, norms, order)
            for e in range(E):
                S[(SIG + e) * L + l] = norms[e]
            count += 1 if l == 0 or k != points[l - 1] else 0  # a repeated point (before ``begin``) once
        for e in range(E):
            sigma[e, k] = S[(SIG + e) * L + l]
    for r in range(E - 1):
        for l in range(L):
            s = S[(SIG + r) * L + l]
            p1 = S[P1 * L + l]
            S[(PREV + r) * L + l] = s * s / p1 if p1 > FLOOR else 0.0
    for l in range(L):
        S[SET * L + l] = 1.0 if S[P1 * L + l] > FLOOR else 0.0
    return count


@kernel(**ROWS_OPTIONS)
def lanes_pass(jac, sigma, tangent, raw_tau, begin, state, m, E):
    """:func:`bidiagonal_rows` with the sizes ``m, E`` given (literal at a call site): :data:`CHUNK` points at a
    time reduced together (:func:`chunk_bidiagonal`, :func:`chunk_tangent`), then their roots :data:`LANES` at a
    time (:func:`lanes_at`)."""
    K = jac.shape[2]
    _, _, _, _, _, _, _, _, _, _, _, _, _, _, _, _, _, _, _, PREV, _, total = work_rows(m, E)
    M, _, _, _, _, _, T, _, rows = chunk_rows(m, E)
    L = LANES
    S = np.zeros(total * L)
    for i in range(state.shape[0]):
        S[PREV * L + i] = state[i]
    B = np.empty((rows, CHUNK))
    fallback = (
        np.empty((E, m)),
        np.empty((m, m)),
        np.empty((E, m)),
        np.empty(m),
        np.empty(m, dtype=np.int64),
    )
    points = np.empty(CHUNK, dtype=np.int64)
    groups = (K - begin + L - 1) // L
    first = K - groups * L
    count = 0
    for g0 in range(0, groups, CHUNK // L):
        n = min(CHUNK, (groups - g0) * L)
        for p in range(n):
            k = first + g0 * L + p
            points[p] = k if k >= begin else begin
        for a in range(m):
            for e in range(E):
                row = B[M + a * E + e]
                for p in range(n):
                    row[p] = jac[e, a, points[p]]
        chunk_bidiagonal(B, n, m, E)
        chunk_tangent(B, n, m, E)
        for a in range(m):
            row = B[T + a]
            for p in range(n):
                tangent[a, points[p]] = row[p]
        for g in range(n // L):
            count += lanes_at(jac, sigma, raw_tau, points[g * L : (g + 1) * L], S, B, g * L, fallback, m, E)
    for i in range(state.shape[0]):
        state[i] = S[PREV * L + i]
    return count


@kernel(inline="always")
def takes_bidiagonal(m, E):
    """Whether :func:`bidiagonal_rows` serves ``m x E`` (``J^T``) Jacobians: two loops (``7 x 6``), the one
    multi-loop size that is :func:`certifiable` (one loop, ``4 x 3``, is
    :func:`linkwork.kinematics.planar_rows.one_loop_rows`' job; three loops and more are not certifiable). One
    size only, compiled with its sizes literal: a second, generic copy of these lanes doubled their compile."""
    return m == 7 and E == 6


@kernel(**ROWS_OPTIONS)
def bidiagonal_rows(jac, sigma, tangent, raw_tau, begin, state):
    """Singular values, unit tangent and raw test function of the two-loop planar Jacobians ``jac (6, 7, K)`` at
    points ``begin .. K - 1``, :data:`LANES` points side by side, certified (see the module's docstring); returns
    the number of points recomputed by the exact fall-back. ``state`` (:func:`bidiagonal_state`) is each lane's
    warm start, carried from call to call along a path: lane ``l`` takes points ``k0 + l``, aligned on the last
    point, so that from one call to the next every lane continues its own stretch. Other sizes
    (:func:`takes_bidiagonal`) raise ``ValueError``."""
    if not takes_bidiagonal(jac.shape[1], jac.shape[0]):
        raise ValueError("bidiagonal_rows takes two-loop (6 x 7) Jacobians only")
    return lanes_pass(jac, sigma, tangent, raw_tau, begin, state, 7, 6)
