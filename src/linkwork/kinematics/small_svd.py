"""Compiled singular value decomposition of the small matrices of tracing, without allocation: one-sided Jacobi
(Hestenes) rotations, warm-started from the previous point's right singular vectors.

Along a path the Jacobian changes little from one point to the next, so its right singular vectors ``V`` do too:
``W = A V`` with last point's ``V`` has nearly orthogonal columns, and a sweep or three of plane rotations (each
making one pair of columns of ``W`` orthogonal, the same rotation applied to ``V``) finish the decomposition
``A = W V^T``, ``W`` with orthogonal columns whose norms are the singular values. One-sided Jacobi computes every
singular value to a small multiple of ``eps * sigma_1`` (small ones often better), as LAPACK's ``gesdd`` does, and
needs no work space beyond ``W`` and ``V``: LAPACK's call from a kernel allocates its outputs and work arrays
each time, which on the 6x6 Jacobian of a six-hinge loop costs more than the arithmetic.

Used by the march's tangent and test function (:mod:`linkwork.kinematics.march`) and by the planar dyad solver
(:mod:`linkwork.kinematics.dyad_solver`, on the triangular factor of a QR).

References
----------
M. R. Hestenes, J. SIAM 6 (1958) 51-90 (one-sided Jacobi); J. Demmel, K. Veselic, SIAM J. Matrix Anal. Appl. 13
(1992) 1204-1245 (its accuracy).
"""

from __future__ import annotations

import numpy as np

from linkwork.kernel_cache import kernel

MAX_SWEEPS = 60
"""Sweeps before :func:`orthogonalize_columns` gives up (a cold 6x6 start needs about six, a warm one two to four)."""
ORTHOGONAL = 1e-15
"""A pair of columns is orthogonal when ``|w_p . w_r| <= ORTHOGONAL * |w_p| |w_r|``..."""
NEGLIGIBLE = 1e-30
"""... or when ``|w_p . w_r| <= NEGLIGIBLE |W|_F^2`` (about ``eps^2``): a column at the round-off level of the
matrix (a null direction) is then orthogonal to the others as far as its rounding lets it be, and rotating it
further would only shuffle noise (without this floor the sweeps need not stop)."""
TINY_ANGLE = 1e-17
"""A rotation by less than this (its tangent is about ``|w_p . w_r| / ||w_r|^2 - |w_p|^2|``) moves ``V``'s
columns by less than their rounding: not made."""


@kernel(inline="always")
def orthonormalize_columns(V: np.ndarray) -> None:
    """Gram-Schmidt on the columns of the square ``V``, in place (keeps its orientation): a warm start's rounding
    does not build up over a long path."""
    orthonormalise(V, V.shape[1])


@kernel(inline="always")
def orthonormalise(V: np.ndarray, E: int) -> None:
    """Modified Gram-Schmidt on the columns of ``V (E, E)`` in place; ``E`` given, so that a caller passing a
    literal size gets the loops unrolled (the planar dyad solver's 3x3)."""
    for c in range(E):
        for b in range(c):
            dot = 0.0
            for a in range(E):
                dot += V[a, b] * V[a, c]
            for a in range(E):
                V[a, c] -= dot * V[a, b]
        norm = 0.0
        for a in range(E):
            norm += V[a, c] * V[a, c]
        norm = 1.0 / np.sqrt(norm)
        for a in range(E):
            V[a, c] *= norm


@kernel(inline="always")
def orthogonalize_columns(W: np.ndarray, V: np.ndarray, sq: np.ndarray) -> int:
    """Cyclic one-sided Jacobi sweeps: rotate pairs of columns of ``W`` (and the same columns of ``V``) until no
    rotation is left to make (see below); returns the sweeps made. ``W = A V`` stays true for ``A`` the matrix
    decomposed, so at the end the columns of ``W`` are ``sigma_i u_i`` and those of ``V`` the ``v_i``.

    ``sq`` (``(k,)`` work space) holds the columns' squared norms, updated by each rotation (``|w_p|^2 - t g``,
    ``|w_r|^2 + t g``, with ``t`` the rotation's tangent and ``g = w_p . w_r``) and recomputed where the update
    cancels. A pair is left alone when it is orthogonal (:data:`ORTHOGONAL`, :data:`NEGLIGIBLE`) or when its
    rotation would turn ``V``'s columns by less than :data:`TINY_ANGLE` (a column at the round-off level of the
    matrix, a null direction, against a large one: turning it further only shuffles its noise).
    """
    k = W.shape[1]
    w_rows = W.shape[0]
    v_rows = V.shape[0]
    floor = 0.0
    for c in range(k):
        acc = 0.0
        for a in range(w_rows):
            acc += W[a, c] * W[a, c]
        sq[c] = acc
        floor += acc
    floor *= NEGLIGIBLE
    for sweep in range(MAX_SWEEPS):
        rotated = False
        for p in range(k - 1):
            for r in range(p + 1, k):
                gamma = 0.0
                for a in range(w_rows):
                    gamma += W[a, p] * W[a, r]
                alpha, beta = sq[p], sq[r]
                if abs(gamma) <= max(
                    ORTHOGONAL * np.sqrt(alpha * beta), floor, TINY_ANGLE * abs(beta - alpha)
                ):
                    continue
                rotated = True
                zeta = (beta - alpha) / (2.0 * gamma)
                tan = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + np.sqrt(1.0 + zeta * zeta))
                cos = 1.0 / np.sqrt(1.0 + tan * tan)
                sin = cos * tan
                for a in range(w_rows):
                    wp, wr = W[a, p], W[a, r]
                    W[a, p] = cos * wp - sin * wr
                    W[a, r] = sin * wp + cos * wr
                for a in range(v_rows):
                    vp, vr = V[a, p], V[a, r]
                    V[a, p] = cos * vp - sin * vr
                    V[a, r] = sin * vp + cos * vr
                sq[p] = alpha - tan * gamma
                sq[r] = beta + tan * gamma
                for c in (p, r):
                    if sq[c] < 0.25 * (alpha if c == p else beta):  # cancelled: recompute
                        acc = 0.0
                        for a in range(w_rows):
                            acc += W[a, c] * W[a, c]
                        sq[c] = acc
        if not rotated:
            return sweep + 1
    return MAX_SWEEPS


@kernel(inline="always")
def descending_norms(W: np.ndarray, norms: np.ndarray, order: np.ndarray) -> int:
    """``norms``: the column norms of ``W`` in descending order, ``order`` the columns they belong to; returns the
    sign of that permutation (+1 or -1)."""
    k = W.shape[1]
    for c in range(k):
        acc = 0.0
        for a in range(W.shape[0]):
            acc += W[a, c] * W[a, c]
        norms[c] = np.sqrt(acc)
        order[c] = c
    sign = 1
    for c in range(1, k):  # insertion sort (a handful of values), counting transpositions
        x = norms[c]
        i = order[c]
        a = c - 1
        while a >= 0 and norms[a] < x:
            norms[a + 1] = norms[a]
            order[a + 1] = order[a]
            sign = -sign
            a -= 1
        norms[a + 1] = x
        order[a + 1] = i
    return sign


@kernel(inline="always")
def jacobi_svd(A: np.ndarray, V: np.ndarray, W: np.ndarray, norms: np.ndarray, order: np.ndarray) -> int:
    """SVD of ``A (E, m)`` warm-started from the orthogonal ``V (m, m)`` (updated in place to ``A``'s right
    singular vectors, column ``order[i]`` for the ``i``-th largest value): ``W = A V`` (``(E, m)``, column ``c``
    is ``sigma u`` of ``V``'s column ``c``), ``norms`` the ``m`` column norms descending (the singular values,
    then ``m - E`` zeros when ``E < m``). Returns the sign of the permutation ``order``; ``det V`` is kept (+1
    from the identity)."""
    E, m = A.shape
    orthonormalize_columns(V)
    for e in range(E):
        for c in range(m):
            acc = 0.0
            for a in range(m):
                acc += A[e, a] * V[a, c]
            W[e, c] = acc
    orthogonalize_columns(W, V, norms)
    return descending_norms(W, norms, order)


@kernel(inline="always")
def det_sign_in_place(G: np.ndarray, n: int) -> float:
    """The sign of the determinant of ``G[:n, :n]`` (0.0 when singular), by Gaussian elimination with partial
    pivoting in place."""
    sign = 1.0
    for k in range(n):
        p = k
        big = abs(G[k, k])
        for i in range(k + 1, n):
            if abs(G[i, k]) > big:
                big, p = abs(G[i, k]), i
        if big == 0.0:
            return 0.0
        if p != k:
            sign = -sign
            for c in range(k, n):
                G[k, c], G[p, c] = G[p, c], G[k, c]
        if G[k, k] < 0.0:
            sign = -sign
        for i in range(k + 1, n):
            f = G[i, k] / G[k, k]
            for c in range(k + 1, n):
                G[i, c] -= f * G[k, c]
    return sign
