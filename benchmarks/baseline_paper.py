"""Timing baseline: a plain numpy reading of Gan & Pellegrino (2006), Secs. 4.1-4.2, for Hedgepeth's hoops.

Written as a reader of the paper would write it, with no attempt at speed: the loop is the product of 4x4
matrices ``T1 T_A T2 T_B ... = I`` (Eq. (12)) with the hinge matrix ``T_theta`` of Eq. (11); every Jacobian
column is the full product of the ``2n`` matrices with the derivative ``T'_theta`` (Eq. (16)) in place of one
hinge matrix (Eqs. (18)-(19)), whose skew part and translation give the column's six entries (Eqs. (20)-(21),
(27)). The predictor is the last right singular vector of that Jacobian (Sec. 4.1), oriented continuously and
scaled so that the drive joint A moves by an equal increment; the corrector (Sec. 4.2) forms the error matrix
``E`` (Eq. (23)), takes its skew part and translation as ``e`` and applies the truncated-SVD least-squares
correction of Eq. (28) with the drive joint held (its column dropped), until ``|e| < 1e-12``.

Each Jacobian costs ``n`` products of ``2n`` matrices, so a step costs O(n^2): the paper's method as printed.

Run ``python benchmarks/baseline_paper.py [n]`` to trace a hoop and compare with linkwork's paper mode.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from linkwork.linkages.hedgepeth import deployed_angle, rod_transforms

Array = NDArray[np.float64]

# Entries of a 4x4 matrix that make the six rows of Eqs. (21) and (27): a12, a13, a23, a14, a24, a34.
SIX_ROWS = ((0, 1), (0, 2), (1, 2), (0, 3), (1, 3), (2, 3))


@dataclass(frozen=True)
class PaperPath:
    """A path traced by :func:`trace_paper`.

    ``angles (steps + 1, n)`` in radians, ``residual (steps + 1,)`` the norm of ``e`` (Eq. (27)) at each
    point, ``iterations`` the corrector iterations in all.
    """

    angles: Array
    residual: Array
    iterations: int
    seconds: float


def hinge(theta: float) -> Array:
    """The hinge matrix ``T_theta``, a rotation by ``theta`` about the local z axis (Eq. (11))."""
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s, 0.0, 0.0], [s, c, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


def hinge_derivative(theta: float) -> Array:
    """``T'_theta = dT_theta / dtheta`` (Eq. (16))."""
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[-s, -c, 0.0, 0.0], [c, -s, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]])


def loop_factors(thetas: Array, T1: Array, T2: Array) -> list[Array]:
    """The ``2n`` factors of the loop product ``T1 T_A T2 T_B T1 T_C ...`` (Eq. (12))."""
    factors = []
    for k, theta in enumerate(thetas):
        factors.append(T1 if k % 2 == 0 else T2)
        factors.append(hinge(theta))
    return factors


def product(factors: list[Array]) -> Array:
    """The matrix product of the factors, left to right."""
    P = np.eye(4)
    for F in factors:
        P = P @ F
    return P


def six_entries(M: Array) -> Array:
    """Skew part of the top-left 3x3 block and translation of ``M``: the six rows of Eqs. (21) and (27)."""
    S = 0.5 * (M[:3, :3] - M[:3, :3].T)
    out = np.empty(6)
    for r, (i, k) in enumerate(SIX_ROWS):
        out[r] = S[i, k] if k < 3 else M[i, k]
    return out


def jacobian(thetas: Array, T1: Array, T2: Array, groups: NDArray[np.int64]) -> Array:
    """The ``6 x m`` Jacobian of Eqs. (18)-(21) (or the ``P, Q, R, S`` matrix of Eq. (27)).

    Column of hinge ``k``: the full loop product with ``T'_theta`` in place of that hinge's ``T_theta``
    (Eq. (18)).
    Hinges coupled into one unknown (``groups[k]``) add their columns.
    """
    m = int(groups.max()) + 1
    J = np.zeros((6, m))
    factors = loop_factors(thetas, T1, T2)
    for k, theta in enumerate(thetas):
        varied = list(factors)
        varied[2 * k + 1] = hinge_derivative(theta)
        J[:, groups[k]] += six_entries(product(varied))
    return J


def closure_error(thetas: Array, T1: Array, T2: Array) -> Array:
    """The error vector ``e`` of Eq. (27): skew part and translation of ``E = T1 T_A ... - I`` (Eq. (23))."""
    E = product(loop_factors(thetas, T1, T2)) - np.eye(4)
    return six_entries(E)


def truncated_solve(A: Array, e: Array, truncate: float = 1e-10) -> Array:
    """``-sum_i w_i u_i^T e / v_ii`` over the non-zero singular values (Eq. (28))."""
    U, v, Wt = np.linalg.svd(A)
    out = np.zeros(A.shape[1])
    for i in range(len(v)):
        if v[i] <= truncate * v[0]:
            break
        out -= Wt[i] * (U[:, i] @ e) / v[i]
    return out


def trace_paper(
    n: int,
    *,
    couple: bool = False,
    steps: int = 200,
    target: float | None = None,
    tol: float = 1e-12,
    max_iter: int = 25,
) -> PaperPath:
    """Trace Hedgepeth's n-rod hoop from the folded bundle (angles 0) in ``steps`` equal steps of ``theta_A``.

    ``target`` is the final ``theta_A`` (default: the deployed angle of Eq. (10)); ``couple`` imposes
    ``A = C = E = ...`` and ``B = D = F = ...`` (two unknowns). Raises ``RuntimeError`` when a corrector
    fails.
    """
    started = time.perf_counter()
    T1, T2 = rod_transforms(n)
    goal = deployed_angle(n) if target is None else target
    groups = np.array([k % 2 for k in range(n)] if couple else list(range(n)), dtype=np.int64)
    m = int(groups.max()) + 1
    drive = 0  # the unknown of hinge A
    free = [a for a in range(m) if a != drive]
    u = np.zeros(m)
    h = goal / steps
    tangent: Array | None = None
    angles = [u[groups].copy()]
    residuals = [float(np.linalg.norm(closure_error(u[groups], T1, T2)))]
    iterations = 0
    for step in range(1, steps + 1):
        # Predictor (Sec. 4.1): the zero-strain mechanism is the last right singular vector of Eq. (21).
        J = jacobian(u[groups], T1, T2, groups)
        t = np.linalg.svd(J)[2][-1]
        if tangent is None:
            t = t if t[drive] > 0 else -t  # first step: deploy, theta_A increasing
        elif t @ tangent < 0:
            t = -t  # keep the orientation continuous
        tangent = t
        u_new = u + (h / t[drive]) * t  # theta_A moves by exactly h
        u_new[drive] = step * h if step < steps else goal
        # Corrector (Sec. 4.2): Eqs. (23), (27) and (28) with theta_A held.
        for it in range(max_iter + 1):
            e = closure_error(u_new[groups], T1, T2)
            r = float(np.linalg.norm(e))
            if r < tol:
                break
            if it == max_iter:
                raise RuntimeError(f"corrector did not converge at step {step} (|e| = {r:.3g})")
            P = jacobian(u_new[groups], T1, T2, groups)
            u_new[free] += truncated_solve(P[:, free], e)
            iterations += 1
        u = u_new
        angles.append(u[groups].copy())
        residuals.append(r)
    return PaperPath(np.array(angles), np.array(residuals), iterations, time.perf_counter() - started)


def compare_with_linkwork(n: int, couple: bool = False, steps: int = 200) -> float:
    """Max |angle difference| (radians) between this baseline and linkwork's paper mode, over every step."""
    from linkwork.kinematics.tracer import trace
    from linkwork.linkages.hedgepeth import hedgepeth

    ours = trace_paper(n, couple=couple, steps=steps)
    theirs = trace(hedgepeth(n, couple=couple), until=("A", deployed_angle(n)), steps=steps)
    if theirs.angles.shape != ours.angles.shape:
        raise RuntimeError(
            f"path shapes differ: linkwork {theirs.angles.shape}, baseline {ours.angles.shape}"
        )
    return float(np.max(np.abs(theirs.angles - ours.angles)))


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 6
    path = trace_paper(n, couple=n >= 8)
    diff = compare_with_linkwork(n, couple=n >= 8)
    print(
        f"n = {n}: {len(path.angles) - 1} steps, {path.iterations} corrector iterations, "
        f"{path.seconds:.3f} s, max residual {path.residual.max():.2e}, "
        f"final theta = {np.degrees(path.angles[-1]).round(4)} deg"
    )
    print(
        f"max |angle difference| vs linkwork paper mode: {diff:.3e} rad ({'ok' if diff < 1e-8 else 'FAIL'})"
    )


if __name__ == "__main__":
    main()
