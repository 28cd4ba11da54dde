"""Branch-free sine, cosine and two-argument arctangent that LLVM vectorises, for loops over many points.

numba calls the C library's ``sin``, ``cos`` and ``atan2`` one value at a time (10-20 ns each), and a loop that
calls them is not vectorised. These are the same algorithms written with selects instead of branches, so that a
loop over points compiles to packed (AVX) instructions: fdlibm's minimax polynomials (as in musl's ``__sin``,
``__cos`` and ``atan``), after a Cody-Waite reduction by ``pi/2`` (three parts of ``pi/2``, fdlibm's
``__ieee754_rem_pio2`` for medium arguments) for the sine and cosine, and after fdlibm's reduction of ``|y/x|``
to three intervals for the arctangent. Each is within about one unit in the last place of the correctly
rounded value (tested against numpy over many arguments).

:func:`sincos` holds for ``|x| <= SINCOS_LIMIT`` (beyond it the reduction loses bits); the array forms
:func:`sincos_into` and :func:`atan2_into` fall back to the C library for arguments outside the fast path's range
(large or not finite), so they are right for every argument.

References
----------
W. J. Cody, W. Waite, *Software Manual for the Elementary Functions* (1980), Ch. 8 (the reduction).
Sun Microsystems' fdlibm 5.3, ``k_sin.c``, ``k_cos.c``, ``s_atan.c``, ``e_rem_pio2.c`` (the polynomials and the
parts of ``pi/2``), as kept in musl libc.
"""

from __future__ import annotations

import math

import numpy as np

from linkwork.kernel_cache import kernel

SINCOS_LIMIT = 1.0e6
"""Largest ``|x|`` that :func:`sincos` reduces exactly (``x 2/pi`` below ``2^20``, fdlibm's medium range)."""

_INV_PIO2 = 6.36619772367581382433e-01
_ROUNDER = 6755399441055744.0  # 1.5 * 2^52: adding and subtracting it rounds to the nearest integer
# pi/2 in parts of 33 bits (each product with a quadrant number below 2^20 is exact) and the tails.
_PIO2_1 = 1.57079632673412561417e00
_PIO2_1T = 6.07710050650619224932e-11
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_2T = 2.02226624879595063154e-21
_PIO2_3 = 2.02226624871116645580e-21
_PIO2_3T = 8.47842766036889956997e-32
_S1 = -1.66666666666666324348e-01
_S2 = 8.33333333332248946124e-03
_S3 = -1.98412698298579493134e-04
_S4 = 2.75573137070700676789e-06
_S5 = -2.50507602534068634195e-08
_S6 = 1.58969099521155010221e-10
_C1 = 4.16666666666666019037e-02
_C2 = -1.38888888888741095749e-03
_C3 = 2.48015872894767294178e-05
_C4 = -2.75573143513906633035e-07
_C5 = 2.08757232129817482790e-09
_C6 = -1.13596475577881948265e-11
_AT0 = 3.33333333333329318027e-01
_AT1 = -1.99999999998764832476e-01
_AT2 = 1.42857142725034663711e-01
_AT3 = -1.11111104054623557880e-01
_AT4 = 9.09088713343650656196e-02
_AT5 = -7.69187620504482999495e-02
_AT6 = 6.66107313738753120669e-02
_AT7 = -5.83357013379057348645e-02
_AT8 = 4.97687799461593236017e-02
_AT9 = -3.65315727442169155270e-02
_AT10 = 1.62858201153657823623e-02
_ATAN_HALF_HI = 4.63647609000806093515e-01
_ATAN_HALF_LO = 2.26987774529616870924e-17
_ATAN_ONE_HI = 7.85398163397448278999e-01
_ATAN_ONE_LO = 3.06161699786838301793e-17
_PIO2_HI = 1.57079632679489655800e00
_PIO2_LO = 6.12323399573676603587e-17
_PI_HI = 3.14159265358979311600e00
_PI_LO = 1.22464679914735317720e-16


@kernel(inline="always")
def sincos(x: float) -> tuple[float, float]:
    """``(cos x, sin x)`` for ``|x| <= SINCOS_LIMIT``, without branches.

    ``x = n pi/2 + y`` with ``y = y0 + y1`` (head and tail, ``|y| <= pi/4``) by fdlibm's three-step Cody-Waite
    reduction (every step taken: the extra steps only add bits); then the kernels ``__sin(y0, y1)`` and
    ``__cos(y0, y1)`` and the quadrant ``n mod 4`` picks which is which and their signs.
    """
    fn = (x * _INV_PIO2 + _ROUNDER) - _ROUNDER
    # fdlibm's medium-range reduction, all three steps.
    r = x - fn * _PIO2_1
    w = fn * _PIO2_1T
    t = r
    w = fn * _PIO2_2
    r = t - w
    w = fn * _PIO2_2T - ((t - r) - w)
    t = r
    w = fn * _PIO2_3
    r = t - w
    w = fn * _PIO2_3T - ((t - r) - w)
    y0 = r - w
    y1 = (r - y0) - w
    # __sin(y0, y1, 1) and __cos(y0, y1) (musl)
    z = y0 * y0
    zz = z * z
    rs = _S2 + z * (_S3 + z * _S4) + z * zz * (_S5 + z * _S6)
    v = z * y0
    sin_y = y0 - ((z * (0.5 * y1 - v * rs) - y1) - v * _S1)
    rc = z * (_C1 + z * (_C2 + z * _C3)) + zz * zz * (_C4 + z * (_C5 + z * _C6))
    hz = 0.5 * z
    one_hz = 1.0 - hz
    cos_y = one_hz + (((1.0 - one_hz) - hz) + (z * rc - y0 * y1))
    quadrant = fn - 4.0 * np.floor(0.25 * fn)  # n mod 4, as 0.0 .. 3.0
    odd = quadrant == 1.0 or quadrant == 3.0
    c = sin_y if odd else cos_y
    s = cos_y if odd else sin_y
    c = -c if quadrant == 1.0 or quadrant == 2.0 else c
    s = -s if quadrant >= 2.0 else s
    return c, s


@kernel(inline="always")
def atan2(y: float, x: float) -> float:
    """The angle of ``(x, y)`` in ``[-pi, pi]`` (as the C library's ``atan2`` for finite arguments, signed zeros
    included), without branches.

    ``a = min(|x|, |y|) / max(|x|, |y|)`` in ``[0, 1]``; ``atan(a)`` by fdlibm's reduction (``a`` below 7/16 as it
    is, below 11/16 about 1/2, else about 1) and its odd polynomial; then ``pi/2 - .`` where ``|y| > |x|``,
    ``pi - .`` where ``x`` is negative (its sign bit set) and the sign of ``y``. The constants ``pi/2`` and ``pi``
    are used in two parts, so the result stays within about one ulp.
    """
    ax, ay = abs(x), abs(y)
    big = max(ax, ay)
    small = min(ax, ay)
    a = small / big if big > 0.0 else 0.0
    low = a < 0.4375
    mid = a < 0.6875
    num = a if low else (2.0 * a - 1.0 if mid else a - 1.0)
    den = 1.0 if low else (2.0 + a if mid else a + 1.0)
    hi = 0.0 if low else (_ATAN_HALF_HI if mid else _ATAN_ONE_HI)
    lo = 0.0 if low else (_ATAN_HALF_LO if mid else _ATAN_ONE_LO)
    z = num / den
    z2 = z * z
    w = z2 * z2
    s1 = z2 * (_AT0 + w * (_AT2 + w * (_AT4 + w * (_AT6 + w * (_AT8 + w * _AT10)))))
    s2 = w * (_AT1 + w * (_AT3 + w * (_AT5 + w * (_AT7 + w * _AT9))))
    r = hi - ((z * (s1 + s2) - lo) - z)
    r = _PIO2_HI - (r - _PIO2_LO) if ay > ax else r
    r = _PI_HI - (r - _PI_LO) if math.copysign(1.0, x) < 0.0 else r
    return math.copysign(r, y)


@kernel(error_model="numpy")
def sincos_into(x: np.ndarray, c: np.ndarray, s: np.ndarray) -> None:
    """``c[k], s[k] = cos x[k], sin x[k]`` for every ``k`` (1-d arrays of one length): :func:`sincos` in a
    vectorised loop, the C library where ``|x| > SINCOS_LIMIT`` or ``x`` is not finite."""
    far = 0
    for k in range(x.shape[0]):
        xk = x[k]
        c[k], s[k] = sincos(xk)
        far += 0 if abs(xk) <= SINCOS_LIMIT else 1
    if far:
        for k in range(x.shape[0]):
            if not abs(x[k]) <= SINCOS_LIMIT:
                c[k], s[k] = np.cos(x[k]), np.sin(x[k])


@kernel(error_model="numpy")
def atan2_into(y: np.ndarray, x: np.ndarray, out: np.ndarray) -> None:
    """``out[k] = atan2(y[k], x[k])`` for every ``k`` (1-d arrays of one length): :func:`atan2` in a vectorised
    loop, the C library where an argument is not finite."""
    odd = 0
    for k in range(y.shape[0]):
        yk, xk = y[k], x[k]
        out[k] = atan2(yk, xk)
        odd += 0 if (abs(yk) < np.inf) & (abs(xk) < np.inf) else 1
    if odd:
        for k in range(y.shape[0]):
            if not (abs(y[k]) < np.inf and abs(x[k]) < np.inf):
                out[k] = np.arctan2(y[k], x[k])
