"""The Householder bidiagonalisation of ``7 x 6`` matrices (``J^T`` of two-loop planar Jacobians) and the tangent
``t = U e_7``, :data:`CHUNK` points at a time, unrolled: **generated** by ``tools/generate_bidiagonal_7x6.py`` (do
not edit by hand; a test checks that this file is its output).

:func:`reduce_points` is one loop over the points whose body is the whole reduction written out, each point's 42
entries in local variables: LLVM keeps them in registers (or the stack, never a streamed array) and vectorises the
loop across points (the rows of ``B`` are :data:`CHUNK` apart, a constant, so that the stores provably do not meet
the loads of later points). The arithmetic is that of Golub & Van Loan Alg. 5.4.2 as
:mod:`linkwork.kinematics.bidiagonal_rows` explains it: for each column ``k`` a reflection from the left zeroes
``M[k+1:, k]`` (``alpha = -sign(x) |v|``, ``v = x - alpha e_1``, ``beta = 1 / (|x| (|x| + |x_1|))``, the identity
for a zero vector), applied to the columns right of ``k`` as ``y -= beta (v . y) v``; then one from the right
zeroes ``M[k, k+2:]``, applied to the rows below ``k``; the tangent is ``e_7`` with the left reflections applied
last to first, normalised. Every inner product is summed in the same order as in the lane loops it replaces
(pivot first, then down the column or along the row), each product rounded at most once (a fused multiply-add
where LLVM contracts one, which only removes a rounding): the constants of Higham's Lemma 19.2, and so
:func:`linkwork.kinematics.bidiagonal_rows.reduction_bound`, hold unchanged.

References
----------
G. H. Golub, C. F. Van Loan, *Matrix Computations*, 4th ed., Johns Hopkins (2013), Alg. 5.4.2.
N. J. Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., SIAM (2002), Lemma 19.2.
"""

from __future__ import annotations

import math

from linkwork.kernel_cache import kernel

CHUNK = 256
"""Points reduced together, the length of each row of ``B`` (a multiple of the lanes of the roots, 16; about
60 kB of rows for ``7 x 6``)."""
FLOOR = 1e-300
"""A reflection whose ``|v|^2 / 2`` is below this is the identity (its factor is 0)."""
D = 42
"""``B``'s rows from here: the diagonal ``d`` of ``B`` (6 rows), then the superdiagonal ``e`` (5), ``det(U)
det(V)`` (1) and the unit tangent (7); rows ``0 .. 41`` are ``J^T`` (row ``a * 6 + e`` is ``J[e, a]``)."""
F = D + 6
"""The superdiagonal's first row."""
DET = F + 5
"""The row of ``det(U) det(V)``."""
T = DET + 1
"""The tangent's first row."""
ROWS = T + 7
"""``B``'s rows."""


@kernel(error_model="numpy", fastmath={"contract"})
def reduce_points(B, n):
    """Reduces the ``n`` (``<= CHUNK``) matrices ``J^T`` (``7 x 6``) of ``B`` (flat, ``ROWS x CHUNK``: row ``r``
    of point ``p`` at ``B[r * CHUNK + p]``) to upper bidiagonal form by Householder reflections from the left and
    the right (Golub & Van Loan Alg. 5.4.2), writing the diagonal, the superdiagonal, ``det(U) det(V)`` (``-1``
    for each reflection made) and the unit tangent ``U e_7`` into rows ``D ..``; rows ``0 .. 41`` are read only."""
    for p in range(n):
        m00 = B[0 * CHUNK + p]
        m01 = B[1 * CHUNK + p]
        m02 = B[2 * CHUNK + p]
        m03 = B[3 * CHUNK + p]
        m04 = B[4 * CHUNK + p]
        m05 = B[5 * CHUNK + p]
        m10 = B[6 * CHUNK + p]
        m11 = B[7 * CHUNK + p]
        m12 = B[8 * CHUNK + p]
        m13 = B[9 * CHUNK + p]
        m14 = B[10 * CHUNK + p]
        m15 = B[11 * CHUNK + p]
        m20 = B[12 * CHUNK + p]
        m21 = B[13 * CHUNK + p]
        m22 = B[14 * CHUNK + p]
        m23 = B[15 * CHUNK + p]
        m24 = B[16 * CHUNK + p]
        m25 = B[17 * CHUNK + p]
        m30 = B[18 * CHUNK + p]
        m31 = B[19 * CHUNK + p]
        m32 = B[20 * CHUNK + p]
        m33 = B[21 * CHUNK + p]
        m34 = B[22 * CHUNK + p]
        m35 = B[23 * CHUNK + p]
        m40 = B[24 * CHUNK + p]
        m41 = B[25 * CHUNK + p]
        m42 = B[26 * CHUNK + p]
        m43 = B[27 * CHUNK + p]
        m44 = B[28 * CHUNK + p]
        m45 = B[29 * CHUNK + p]
        m50 = B[30 * CHUNK + p]
        m51 = B[31 * CHUNK + p]
        m52 = B[32 * CHUNK + p]
        m53 = B[33 * CHUNK + p]
        m54 = B[34 * CHUNK + p]
        m55 = B[35 * CHUNK + p]
        m60 = B[36 * CHUNK + p]
        m61 = B[37 * CHUNK + p]
        m62 = B[38 * CHUNK + p]
        m63 = B[39 * CHUNK + p]
        m64 = B[40 * CHUNK + p]
        m65 = B[41 * CHUNK + p]
        sign = 1.0
        # From the left: column 0, rows 0 .. 6.
        acc = m00 * m00
        acc += m10 * m10
        acc += m20 * m20
        acc += m30 * m30
        acc += m40 * m40
        acc += m50 * m50
        acc += m60 * m60
        norm = math.sqrt(acc)
        alpha = -norm if m00 >= 0.0 else norm
        vv = norm * (norm + abs(m00))  # |x - alpha e_1|^2 / 2
        bl0 = 1.0 / vv if vv > FLOOR else 0.0
        hl0 = m00 - alpha
        m00 = alpha
        sign = -sign if bl0 > 0.0 else sign
        dot = hl0 * m01
        dot += m10 * m11
        dot += m20 * m21
        dot += m30 * m31
        dot += m40 * m41
        dot += m50 * m51
        dot += m60 * m61
        dot *= bl0
        m01 -= dot * hl0
        m11 -= dot * m10
        m21 -= dot * m20
        m31 -= dot * m30
        m41 -= dot * m40
        m51 -= dot * m50
        m61 -= dot * m60
        dot = hl0 * m02
        dot += m10 * m12
        dot += m20 * m22
        dot += m30 * m32
        dot += m40 * m42
        dot += m50 * m52
        dot += m60 * m62
        dot *= bl0
        m02 -= dot * hl0
        m12 -= dot * m10
        m22 -= dot * m20
        m32 -= dot * m30
        m42 -= dot * m40
        m52 -= dot * m50
        m62 -= dot * m60
        dot = hl0 * m03
        dot += m10 * m13
        dot += m20 * m23
        dot += m30 * m33
        dot += m40 * m43
        dot += m50 * m53
        dot += m60 * m63
        dot *= bl0
        m03 -= dot * hl0
        m13 -= dot * m10
        m23 -= dot * m20
        m33 -= dot * m30
        m43 -= dot * m40
        m53 -= dot * m50
        m63 -= dot * m60
        dot = hl0 * m04
        dot += m10 * m14
        dot += m20 * m24
        dot += m30 * m34
        dot += m40 * m44
        dot += m50 * m54
        dot += m60 * m64
        dot *= bl0
        m04 -= dot * hl0
        m14 -= dot * m10
        m24 -= dot * m20
        m34 -= dot * m30
        m44 -= dot * m40
        m54 -= dot * m50
        m64 -= dot * m60
        dot = hl0 * m05
        dot += m10 * m15
        dot += m20 * m25
        dot += m30 * m35
        dot += m40 * m45
        dot += m50 * m55
        dot += m60 * m65
        dot *= bl0
        m05 -= dot * hl0
        m15 -= dot * m10
        m25 -= dot * m20
        m35 -= dot * m30
        m45 -= dot * m40
        m55 -= dot * m50
        m65 -= dot * m60
        # From the right: row 0, columns 1 .. 5.
        acc = m01 * m01
        acc += m02 * m02
        acc += m03 * m03
        acc += m04 * m04
        acc += m05 * m05
        norm = math.sqrt(acc)
        alpha = -norm if m01 >= 0.0 else norm
        vv = norm * (norm + abs(m01))  # |x - alpha e_1|^2 / 2
        br0 = 1.0 / vv if vv > FLOOR else 0.0
        hr0 = m01 - alpha
        m01 = alpha
        sign = -sign if br0 > 0.0 else sign
        dot = hr0 * m11
        dot += m02 * m12
        dot += m03 * m13
        dot += m04 * m14
        dot += m05 * m15
        dot *= br0
        m11 -= dot * hr0
        m12 -= dot * m02
        m13 -= dot * m03
        m14 -= dot * m04
        m15 -= dot * m05
        dot = hr0 * m21
        dot += m02 * m22
        dot += m03 * m23
        dot += m04 * m24
        dot += m05 * m25
        dot *= br0
        m21 -= dot * hr0
        m22 -= dot * m02
        m23 -= dot * m03
        m24 -= dot * m04
        m25 -= dot * m05
        dot = hr0 * m31
        dot += m02 * m32
        dot += m03 * m33
        dot += m04 * m34
        dot += m05 * m35
        dot *= br0
        m31 -= dot * hr0
        m32 -= dot * m02
        m33 -= dot * m03
        m34 -= dot * m04
        m35 -= dot * m05
        dot = hr0 * m41
        dot += m02 * m42
        dot += m03 * m43
        dot += m04 * m44
        dot += m05 * m45
        dot *= br0
        m41 -= dot * hr0
        m42 -= dot * m02
        m43 -= dot * m03
        m44 -= dot * m04
        m45 -= dot * m05
        dot = hr0 * m51
        dot += m02 * m52
        dot += m03 * m53
        dot += m04 * m54
        dot += m05 * m55
        dot *= br0
        m51 -= dot * hr0
        m52 -= dot * m02
        m53 -= dot * m03
        m54 -= dot * m04
        m55 -= dot * m05
        dot = hr0 * m61
        dot += m02 * m62
        dot += m03 * m63
        dot += m04 * m64
        dot += m05 * m65
        dot *= br0
        m61 -= dot * hr0
        m62 -= dot * m02
        m63 -= dot * m03
        m64 -= dot * m04
        m65 -= dot * m05
        # From the left: column 1, rows 1 .. 6.
        acc = m11 * m11
        acc += m21 * m21
        acc += m31 * m31
        acc += m41 * m41
        acc += m51 * m51
        acc += m61 * m61
        norm = math.sqrt(acc)
        alpha = -norm if m11 >= 0.0 else norm
        vv = norm * (norm + abs(m11))  # |x - alpha e_1|^2 / 2
        bl1 = 1.0 / vv if vv > FLOOR else 0.0
        hl1 = m11 - alpha
        m11 = alpha
        sign = -sign if bl1 > 0.0 else sign
        dot = hl1 * m12
        dot += m21 * m22
        dot += m31 * m32
        dot += m41 * m42
        dot += m51 * m52
        dot += m61 * m62
        dot *= bl1
        m12 -= dot * hl1
        m22 -= dot * m21
        m32 -= dot * m31
        m42 -= dot * m41
        m52 -= dot * m51
        m62 -= dot * m61
        dot = hl1 * m13
        dot += m21 * m23
        dot += m31 * m33
        dot += m41 * m43
        dot += m51 * m53
        dot += m61 * m63
        dot *= bl1
        m13 -= dot * hl1
        m23 -= dot * m21
        m33 -= dot * m31
        m43 -= dot * m41
        m53 -= dot * m51
        m63 -= dot * m61
        dot = hl1 * m14
        dot += m21 * m24
        dot += m31 * m34
        dot += m41 * m44
        dot += m51 * m54
        dot += m61 * m64
        dot *= bl1
        m14 -= dot * hl1
        m24 -= dot * m21
        m34 -= dot * m31
        m44 -= dot * m41
        m54 -= dot * m51
        m64 -= dot * m61
        dot = hl1 * m15
        dot += m21 * m25
        dot += m31 * m35
        dot += m41 * m45
        dot += m51 * m55
        dot += m61 * m65
        dot *= bl1
        m15 -= dot * hl1
        m25 -= dot * m21
        m35 -= dot * m31
        m45 -= dot * m41
        m55 -= dot * m51
        m65 -= dot * m61
        # From the right: row 1, columns 2 .. 5.
        acc = m12 * m12
        acc += m13 * m13
        acc += m14 * m14
        acc += m15 * m15
        norm = math.sqrt(acc)
        alpha = -norm if m12 >= 0.0 else norm
        vv = norm * (norm + abs(m12))  # |x - alpha e_1|^2 / 2
        br1 = 1.0 / vv if vv > FLOOR else 0.0
        hr1 = m12 - alpha
        m12 = alpha
        sign = -sign if br1 > 0.0 else sign
        dot = hr1 * m22
        dot += m13 * m23
        dot += m14 * m24
        dot += m15 * m25
        dot *= br1
        m22 -= dot * hr1
        m23 -= dot * m13
        m24 -= dot * m14
        m25 -= dot * m15
        dot = hr1 * m32
        dot += m13 * m33
        dot += m14 * m34
        dot += m15 * m35
        dot *= br1
        m32 -= dot * hr1
        m33 -= dot * m13
        m34 -= dot * m14
        m35 -= dot * m15
        dot = hr1 * m42
        dot += m13 * m43
        dot += m14 * m44
        dot += m15 * m45
        dot *= br1
        m42 -= dot * hr1
        m43 -= dot * m13
        m44 -= dot * m14
        m45 -= dot * m15
        dot = hr1 * m52
        dot += m13 * m53
        dot += m14 * m54
        dot += m15 * m55
        dot *= br1
        m52 -= dot * hr1
        m53 -= dot * m13
        m54 -= dot * m14
        m55 -= dot * m15
        dot = hr1 * m62
        dot += m13 * m63
        dot += m14 * m64
        dot += m15 * m65
        dot *= br1
        m62 -= dot * hr1
        m63 -= dot * m13
        m64 -= dot * m14
        m65 -= dot * m15
        # From the left: column 2, rows 2 .. 6.
        acc = m22 * m22
        acc += m32 * m32
        acc += m42 * m42
        acc += m52 * m52
        acc += m62 * m62
        norm = math.sqrt(acc)
        alpha = -norm if m22 >= 0.0 else norm
        vv = norm * (norm + abs(m22))  # |x - alpha e_1|^2 / 2
        bl2 = 1.0 / vv if vv > FLOOR else 0.0
        hl2 = m22 - alpha
        m22 = alpha
        sign = -sign if bl2 > 0.0 else sign
        dot = hl2 * m23
        dot += m32 * m33
        dot += m42 * m43
        dot += m52 * m53
        dot += m62 * m63
        dot *= bl2
        m23 -= dot * hl2
        m33 -= dot * m32
        m43 -= dot * m42
        m53 -= dot * m52
        m63 -= dot * m62
        dot = hl2 * m24
        dot += m32 * m34
        dot += m42 * m44
        dot += m52 * m54
        dot += m62 * m64
        dot *= bl2
        m24 -= dot * hl2
        m34 -= dot * m32
        m44 -= dot * m42
        m54 -= dot * m52
        m64 -= dot * m62
        dot = hl2 * m25
        dot += m32 * m35
        dot += m42 * m45
        dot += m52 * m55
        dot += m62 * m65
        dot *= bl2
        m25 -= dot * hl2
        m35 -= dot * m32
        m45 -= dot * m42
        m55 -= dot * m52
        m65 -= dot * m62
        # From the right: row 2, columns 3 .. 5.
        acc = m23 * m23
        acc += m24 * m24
        acc += m25 * m25
        norm = math.sqrt(acc)
        alpha = -norm if m23 >= 0.0 else norm
        vv = norm * (norm + abs(m23))  # |x - alpha e_1|^2 / 2
        br2 = 1.0 / vv if vv > FLOOR else 0.0
        hr2 = m23 - alpha
        m23 = alpha
        sign = -sign if br2 > 0.0 else sign
        dot = hr2 * m33
        dot += m24 * m34
        dot += m25 * m35
        dot *= br2
        m33 -= dot * hr2
        m34 -= dot * m24
        m35 -= dot * m25
        dot = hr2 * m43
        dot += m24 * m44
        dot += m25 * m45
        dot *= br2
        m43 -= dot * hr2
        m44 -= dot * m24
        m45 -= dot * m25
        dot = hr2 * m53
        dot += m24 * m54
        dot += m25 * m55
        dot *= br2
        m53 -= dot * hr2
        m54 -= dot * m24
        m55 -= dot * m25
        dot = hr2 * m63
        dot += m24 * m64
        dot += m25 * m65
        dot *= br2
        m63 -= dot * hr2
        m64 -= dot * m24
        m65 -= dot * m25
        # From the left: column 3, rows 3 .. 6.
        acc = m33 * m33
        acc += m43 * m43
        acc += m53 * m53
        acc += m63 * m63
        norm = math.sqrt(acc)
        alpha = -norm if m33 >= 0.0 else norm
        vv = norm * (norm + abs(m33))  # |x - alpha e_1|^2 / 2
        bl3 = 1.0 / vv if vv > FLOOR else 0.0
        hl3 = m33 - alpha
        m33 = alpha
        sign = -sign if bl3 > 0.0 else sign
        dot = hl3 * m34
        dot += m43 * m44
        dot += m53 * m54
        dot += m63 * m64
        dot *= bl3
        m34 -= dot * hl3
        m44 -= dot * m43
        m54 -= dot * m53
        m64 -= dot * m63
        dot = hl3 * m35
        dot += m43 * m45
        dot += m53 * m55
        dot += m63 * m65
        dot *= bl3
        m35 -= dot * hl3
        m45 -= dot * m43
        m55 -= dot * m53
        m65 -= dot * m63
        # From the right: row 3, columns 4 .. 5.
        acc = m34 * m34
        acc += m35 * m35
        norm = math.sqrt(acc)
        alpha = -norm if m34 >= 0.0 else norm
        vv = norm * (norm + abs(m34))  # |x - alpha e_1|^2 / 2
        br3 = 1.0 / vv if vv > FLOOR else 0.0
        hr3 = m34 - alpha
        m34 = alpha
        sign = -sign if br3 > 0.0 else sign
        dot = hr3 * m44
        dot += m35 * m45
        dot *= br3
        m44 -= dot * hr3
        m45 -= dot * m35
        dot = hr3 * m54
        dot += m35 * m55
        dot *= br3
        m54 -= dot * hr3
        m55 -= dot * m35
        dot = hr3 * m64
        dot += m35 * m65
        dot *= br3
        m64 -= dot * hr3
        m65 -= dot * m35
        # From the left: column 4, rows 4 .. 6.
        acc = m44 * m44
        acc += m54 * m54
        acc += m64 * m64
        norm = math.sqrt(acc)
        alpha = -norm if m44 >= 0.0 else norm
        vv = norm * (norm + abs(m44))  # |x - alpha e_1|^2 / 2
        bl4 = 1.0 / vv if vv > FLOOR else 0.0
        hl4 = m44 - alpha
        m44 = alpha
        sign = -sign if bl4 > 0.0 else sign
        dot = hl4 * m45
        dot += m54 * m55
        dot += m64 * m65
        dot *= bl4
        m45 -= dot * hl4
        m55 -= dot * m54
        m65 -= dot * m64
        # From the left: column 5, rows 5 .. 6.
        acc = m55 * m55
        acc += m65 * m65
        norm = math.sqrt(acc)
        alpha = -norm if m55 >= 0.0 else norm
        vv = norm * (norm + abs(m55))  # |x - alpha e_1|^2 / 2
        bl5 = 1.0 / vv if vv > FLOOR else 0.0
        hl5 = m55 - alpha
        m55 = alpha
        sign = -sign if bl5 > 0.0 else sign
        # The tangent U e_7: the left reflections applied last to first.
        t0 = 0.0
        t1 = 0.0
        t2 = 0.0
        t3 = 0.0
        t4 = 0.0
        t5 = 0.0
        t6 = 1.0
        dot = hl5 * t5
        dot += m65 * t6
        dot *= bl5
        t5 -= dot * hl5
        t6 -= dot * m65
        dot = hl4 * t4
        dot += m54 * t5
        dot += m64 * t6
        dot *= bl4
        t4 -= dot * hl4
        t5 -= dot * m54
        t6 -= dot * m64
        dot = hl3 * t3
        dot += m43 * t4
        dot += m53 * t5
        dot += m63 * t6
        dot *= bl3
        t3 -= dot * hl3
        t4 -= dot * m43
        t5 -= dot * m53
        t6 -= dot * m63
        dot = hl2 * t2
        dot += m32 * t3
        dot += m42 * t4
        dot += m52 * t5
        dot += m62 * t6
        dot *= bl2
        t2 -= dot * hl2
        t3 -= dot * m32
        t4 -= dot * m42
        t5 -= dot * m52
        t6 -= dot * m62
        dot = hl1 * t1
        dot += m21 * t2
        dot += m31 * t3
        dot += m41 * t4
        dot += m51 * t5
        dot += m61 * t6
        dot *= bl1
        t1 -= dot * hl1
        t2 -= dot * m21
        t3 -= dot * m31
        t4 -= dot * m41
        t5 -= dot * m51
        t6 -= dot * m61
        dot = hl0 * t0
        dot += m10 * t1
        dot += m20 * t2
        dot += m30 * t3
        dot += m40 * t4
        dot += m50 * t5
        dot += m60 * t6
        dot *= bl0
        t0 -= dot * hl0
        t1 -= dot * m10
        t2 -= dot * m20
        t3 -= dot * m30
        t4 -= dot * m40
        t5 -= dot * m50
        t6 -= dot * m60
        acc = 0.0
        acc += t0 * t0
        acc += t1 * t1
        acc += t2 * t2
        acc += t3 * t3
        acc += t4 * t4
        acc += t5 * t5
        acc += t6 * t6
        acc = 1.0 / math.sqrt(acc)  # 1 to a few rounding errors
        B[(D + 0) * CHUNK + p] = m00
        B[(D + 1) * CHUNK + p] = m11
        B[(D + 2) * CHUNK + p] = m22
        B[(D + 3) * CHUNK + p] = m33
        B[(D + 4) * CHUNK + p] = m44
        B[(D + 5) * CHUNK + p] = m55
        B[(F + 0) * CHUNK + p] = m01
        B[(F + 1) * CHUNK + p] = m12
        B[(F + 2) * CHUNK + p] = m23
        B[(F + 3) * CHUNK + p] = m34
        B[(F + 4) * CHUNK + p] = m45
        B[DET * CHUNK + p] = sign
        B[(T + 0) * CHUNK + p] = t0 * acc
        B[(T + 1) * CHUNK + p] = t1 * acc
        B[(T + 2) * CHUNK + p] = t2 * acc
        B[(T + 3) * CHUNK + p] = t3 * acc
        B[(T + 4) * CHUNK + p] = t4 * acc
        B[(T + 5) * CHUNK + p] = t5 * acc
        B[(T + 6) * CHUNK + p] = t6 * acc
