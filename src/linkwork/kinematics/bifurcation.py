"""Bifurcation points: locate a sign change of the test function, and find every branch tangent there.

At a located point the reduced Jacobian ``J`` has a null space ``N`` of dimension 2 (a simple bifurcation). A
branch tangent ``t = N a`` satisfies the quadratic branching equation ``l^T H(t, t) = 0`` for every left null vector
``l`` of ``J``, with ``H`` the exact Hessian from Lie brackets (Kumar & Pellegrino 2000). When those quadratic forms
vanish (degenerate) or the kernel is larger than two, the branches are found instead by intersecting the solution
set with a small sphere around the point.

References
----------
P. Kumar, S. Pellegrino, "Computation of kinematic paths and bifurcation points", Int. J. Solids Struct. 37
(2000) 7003-7027.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from linkwork.kinematics.closure import hessian, reduce
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import Tolerances, numerical_rank
from linkwork.kinematics.workspace import Workspace

Array = NDArray[np.float64]

__all__ = [
    "Workspace",
    "branch_tangents",
    "correct_on_plane",
    "hermite",
    "locate",
    "locate_minimum",
    "polish",
]


def _accept(tol: Tolerances) -> float:
    """Largest residual a stalled correction is accepted with (see :func:`linkwork.kinematics.march.correct`)."""
    return max(tol.closure, tol.roundoff * tol.exact)


def correct_on_plane(
    ws: Workspace, u_pred: Array, normal: Array, tol: Tolerances, max_iter: int = 30
) -> tuple[Array, float, bool]:
    """Correct ``u_pred`` onto the loop within the hyperplane through it orthogonal to ``normal`` (Eq. (28))."""
    m = u_pred.shape[0]
    n = normal / np.linalg.norm(normal)
    # Orthonormal basis V of the hyperplane's directions.
    Q, _ = np.linalg.qr(np.column_stack([n, np.eye(m)]))
    V = Q[:, 1:m]
    u = u_pred.copy()
    r = np.inf
    prev = np.inf
    for _ in range(max_iter):
        r, res, jac = ws.evaluate(u)
        if r < tol.exact or (r < _accept(tol) and r > 0.5 * prev):
            return u, r, True
        prev = r
        A = jac @ V
        U, s, Wt = np.linalg.svd(A, full_matrices=False)
        keep = s > tol.truncate * s[0]
        u = u - V @ (Wt[keep].T @ ((U[:, keep].T @ res) / s[keep]))
    return u, r, r < _accept(tol)


def hermite(x: float, lo: tuple[float, Array, Array], hi: tuple[float, Array, Array], axis: Array) -> Array:
    """The cubic Hermite curve through two path points with their tangents, at parameter ``x``.

    ``lo`` and ``hi`` are ``(h, u, t)``: the parameter ``h = axis . (u - u_ref)`` of each point, the point and
    its tangent; each tangent is scaled so that ``axis . (du/dh) = 1``.
    """
    (h0, u0, t0), (h1, u1, t1) = lo, hi
    d = h1 - h0
    s = (x - h0) / d
    m0, m1 = t0 / (axis @ t0), t1 / (axis @ t1)
    return (
        (2 * s**3 - 3 * s**2 + 1) * u0
        + (s**3 - 2 * s**2 + s) * d * m0
        + (-2 * s**3 + 3 * s**2) * u1
        + (s**3 - s**2) * d * m1
    )


def locate(
    ws: Workspace,
    u_a: Array,
    t_a: Array,
    basis_a: Array,
    u_b: Array,
    t_b: Array,
    r_path: int,
    tol: Tolerances,
    n_sigma: int,
    weight: Array,
) -> tuple[Array, float]:
    """Locate the zero of the test function between path points ``a`` and ``b`` (Illinois regula falsi).

    Points are parametrised by ``h = t_a . (u - u_a)``. Each trial point is predicted by the cubic Hermite
    interpolant between the two bracketing points (with their tangents) and corrected in the hyperplane of its
    ``h``: the prediction error, fourth order in the bracket, stays far below the distance to the other branch
    crossing there, so the trials stay on the branch being traced. A trial the corrector cannot close ends the
    search (the point and bracket so far are returned): it is not a point of the path, and taken as a bracket's
    end it sent the next prediction turns away (a parallelogram of size 1e-3 placed 1e3 from the origin, its
    file's coordinates holding its shape to 2e-10: a trial corrected onto the other branch 1e-3 rad from the
    crossing, whose tangent lies across the axis, made the next Hermite prediction 50 rad away, and the point
    reported was the other crossing, 45 turns off). ``weight`` is the step's metric (tangents are oriented in it,
    :func:`~linkwork.kinematics.march.tangent_and_test`). Returns the point and the bracket width.
    """

    def evaluate_at(u: Array) -> tuple[float, Array]:
        _, _, jac = ws.evaluate(u)
        t = np.empty_like(t_a)
        value = ws.kernels.tangent_and_test(
            jac, t_a.copy(), basis_a.copy(), r_path, t, np.empty(n_sigma), weight
        )
        return float(value), t

    f_lo, _ = evaluate_at(u_a)
    f_hi, t_b2 = evaluate_at(u_b)
    lo: tuple[float, Array, Array] = (0.0, u_a.copy(), t_a.copy())
    hi: tuple[float, Array, Array] = (float(t_a @ (u_b - u_a)), u_b.copy(), t_b2)
    side = 0
    best = u_b.copy()
    for _ in range(200):
        if abs(hi[0] - lo[0]) < tol.locate:
            break
        x = hi[0] - f_hi * (hi[0] - lo[0]) / (f_hi - f_lo) if f_hi != f_lo else 0.5 * (lo[0] + hi[0])
        if not (min(lo[0], hi[0]) < x < max(lo[0], hi[0])):
            x = 0.5 * (lo[0] + hi[0])
        u_x, _, ok = correct_on_plane(ws, hermite(x, lo, hi, t_a), t_a, tol)
        if not ok:
            break
        f_x, t_x = evaluate_at(u_x)
        best = u_x
        if f_x == 0.0:
            return u_x, 0.0
        if (f_x > 0) == (f_hi > 0):
            hi, f_hi = (x, u_x, t_x), f_x
            if side == 1:
                f_lo *= 0.5
            side = 1
        else:
            lo, f_lo = (x, u_x, t_x), f_x
            if side == -1:
                f_hi *= 0.5
            side = -1
    return best, abs(hi[0] - lo[0])


def branch_tangents(
    mech: Mechanism,
    ws: Workspace,
    u: Array,
    tol: Tolerances,
    radius: float = 1e-3,
    rank_hint: int | None = None,
) -> tuple[Array, str, int, Array]:
    """Every branch tangent (rows, unit, in the unknowns, one per line through the point) at a singular ``u``.

    ``rank_hint``: the rank a located sign change of the test function implies (one below the path's); it is
    taken when the singular value it makes zero is below ``tol.loose`` relative, since a point located on a
    branch through a singular point is only as close to it as the corrector's residual allows (quadratically).
    Returns ``(tangents, method, rank, sigma)`` with ``method`` "quadratic", "sphere" or "none".
    """
    _, _, jac = ws.evaluate(u)
    U, s, Vt = np.linalg.svd(jac)
    rank = numerical_rank(s, tol)
    if rank_hint is not None and rank_hint < rank and s[rank_hint] <= tol.loose * s[0]:
        rank = rank_hint
    m = jac.shape[1]
    N = Vt[rank:].T  # (m, d) null space
    d = N.shape[1]
    if d < 2:  # no rank drop: not a bifurcation point
        return np.zeros((0, m)), "none", rank, s
    L = U[:, rank:]  # left null space
    if d == 2 and L.shape[1] > 0:
        H = reduce(mech, hessian(mech, mech.q_from_u(u)))  # (E, m, m), exact (Lie brackets)
        forms = np.einsum("el,eab,ai,bj->lij", L, H, N, N)  # (c, 2, 2): l^T H(N a, N a)
        coeffs = np.stack([forms[:, 0, 0], 2.0 * forms[:, 0, 1], forms[:, 1, 1]], axis=1)
        scale = np.abs(H).max() if H.size else 1.0
        _, cs, cv = np.linalg.svd(coeffs)
        significant = cs > 1e-6 * max(scale, 1e-300)
        if np.any(significant):
            phis = _common_roots(cv[: int(significant.sum())], cs[: int(significant.sum())])
            if phis:
                tangents = np.array([N @ np.array([np.cos(p), np.sin(p)]) for p in phis])
                return tangents, "quadratic", rank, s
    return _sphere_tangents(ws, u, N, radius, tol), "sphere", rank, s


def _common_roots(forms: Array, weights: Array) -> list[float]:
    """Angles ``phi`` in ``[0, pi)`` where every form ``a c^2 + b c s + c s^2`` vanishes (least squares)."""
    if forms.shape[0] == 1:
        a, b, c = forms[0]
        roots = []
        if abs(c) < 1e-12 * max(abs(a), abs(b), 1e-300):
            roots.append(np.pi / 2)
            if abs(b) > 0:
                roots.append(float(np.arctan2(-a, b)))  # a + b tan = 0
        else:
            disc = b * b - 4 * a * c
            if disc < -1e-12 * (b * b + abs(4 * a * c)):
                return []
            disc = max(disc, 0.0)
            for sgn in (1.0, -1.0):
                roots.append(float(np.arctan((-b + sgn * np.sqrt(disc)) / (2 * c))))
        return sorted({round(r % np.pi, 12) for r in roots})
    grid = np.linspace(0.0, np.pi, 1441)
    c, s = np.cos(grid), np.sin(grid)
    vals = (weights[:, None] * (forms[:, 0:1] * c * c + forms[:, 1:2] * c * s + forms[:, 2:3] * s * s)) ** 2
    total = vals.sum(axis=0)
    out = []
    for i in range(1, len(grid) - 1):
        if total[i] <= total[i - 1] and total[i] <= total[i + 1] and total[i] < 1e-6 * total.max():
            out.append(float(grid[i]))
    return out


def _sphere_tangents(ws: Workspace, u: Array, N: Array, radius: float, tol: Tolerances) -> Array:
    """Directions of the solution curves leaving ``u``: the solution set met by a small sphere (fallback)."""
    d = N.shape[1]
    rng = np.random.default_rng(0)
    samples = rng.normal(size=(64 * d, d)) if d > 2 else None
    if samples is None:
        ang = np.linspace(0.0, 2 * np.pi, 72, endpoint=False)
        samples = np.column_stack([np.cos(ang), np.sin(ang)])
    samples /= np.linalg.norm(samples, axis=1, keepdims=True)
    found: list[Array] = []
    for a in samples:
        direction = N @ a
        v, _r, ok = correct_on_plane(ws, u + radius * direction, direction, tol)
        if not ok:
            continue
        t = (v - u) / np.linalg.norm(v - u)
        if all(abs(t @ f) < 0.999 for f in found):
            found.append(t)
    return np.array(found).reshape(len(found), N.shape[0])


def polish(
    ws: Workspace, u: Array, tangents: Array, tol: Tolerances, radius: float = 2e-3
) -> tuple[Array, float, float]:
    """Refine a located simple bifurcation point as the intersection of its two branches: ``(point, gap,
    accuracy)``.

    Closing a loop at a double point is only as accurate as the square root of the residual. Here each branch
    is sampled instead at four regular points (signed distances ``-2r, -r, r, 2r`` along its tangent, corrected
    in the hyperplanes there, where the corrector converges quadratically), a cubic is fitted through them, and
    the point nearest both cubics is taken (:func:`intersect_branches`). The cubics' own error, of order
    ``r^4``, is far larger than the distance between them (which is round-off), so the intersection is taken at
    ``r`` and at ``r / 2``: the second is returned, and its accuracy is the larger of the distance between the
    two results (an ``r^4`` error falls sixteenfold when ``r`` halves, so that distance bounds the second's) and
    the distance ``gap`` between its cubics, plus the bound on what its samples' round-off moves it. NaN gap and accuracy when the branches cannot be sampled.
    """
    coarse, gap, _ = intersect_branches(ws, u, tangents, tol, radius)
    if not np.isfinite(gap):
        return u, float("nan"), float("nan")
    fine, fine_gap, noise = intersect_branches(ws, u, tangents, tol, 0.5 * radius)
    if not np.isfinite(fine_gap):
        return u, float("nan"), float("nan")
    return fine, fine_gap, max(fine_gap, float(np.linalg.norm(fine - coarse))) + noise


def intersect_branches(
    ws: Workspace, u: Array, tangents: Array, tol: Tolerances, radius: float
) -> tuple[Array, float, float]:
    """The point nearest two cubics fitted to the two branches through ``u`` (each sampled at signed distances
    ``-2r, -r, r, 2r`` along its tangent, corrected in the hyperplanes there): ``(point, gap, noise)``, ``gap``
    the distance between the cubics there and ``noise`` a bound on how far the samples' own errors move it.

    The samples are corrected to round-off (until the residual stops falling), not only below ``tol.exact``: a
    residual ``e`` leaves a sample about ``e / sigma`` off its branch (:func:`_sample_error`), and a distance
    ``r`` from a simple bifurcation point the smallest singular value ``sigma`` is itself of order ``r`` (the
    parallelogram's crossing was 7.5e-11 rad off, stopping at 1e-12). A cubic through samples each off by at
    most ``delta`` is off by at most ``sum_k |l_k(x)| delta`` at ``x`` (``l_k`` its Lagrange basis), and two
    curves crossing at an angle ``theta`` that move by ``a`` and ``b`` move their crossing by at most
    ``(a + b) / sin(theta)``.
    """
    if tangents.shape[0] != 2:
        return u, float("nan"), float("nan")
    tol = replace(tol, exact=0.0)
    fits = []
    for t in tangents:
        t = t / np.linalg.norm(t)
        params, points, errors = [], [], []
        for k in (-2.0, -1.0, 1.0, 2.0):
            p, r, ok = correct_on_plane(ws, u + k * radius * t, t, tol)
            if not ok:
                return u, float("nan"), float("nan")
            params.append(t @ (p - u))
            points.append(p)
            errors.append(_sample_error(ws, p, t, r, tol))
        V = np.vander(np.array(params), 4)  # cubic through the four samples
        fits.append((np.linalg.solve(V, np.array(points)), np.linalg.inv(V), np.array(errors)))

    def curve(i: int, x: float) -> Array:
        return np.vander(np.array([x]), 4)[0] @ fits[i][0]

    def slope(i: int, x: float) -> Array:
        return np.array([3.0 * x * x, 2.0 * x, 1.0, 0.0]) @ fits[i][0]

    # Nearest points of the two curves: Gauss-Newton on (x1, x2).
    x = np.zeros(2)
    for _ in range(30):
        d = curve(0, x[0]) - curve(1, x[1])
        J = np.column_stack([slope(0, x[0]), -slope(1, x[1])])
        step = np.linalg.lstsq(J, -d, rcond=None)[0]
        x += step
        if np.linalg.norm(step) < 1e-15:
            break
    a, b = curve(0, x[0]), curve(1, x[1])
    moved = sum(float(np.abs(np.vander(np.array([x[i]]), 4)[0] @ fits[i][1]) @ fits[i][2]) for i in range(2))
    s0, s1 = slope(0, x[0]), slope(1, x[1])
    cos = float(s0 @ s1) / float(np.linalg.norm(s0) * np.linalg.norm(s1))
    sine = np.sqrt(max(1.0 - cos * cos, 0.0))
    noise = moved / sine if sine > 0.0 else float("inf")
    return 0.5 * (a + b), float(np.linalg.norm(a - b)), noise


def _sample_error(ws: Workspace, p: Array, t: Array, r: float, tol: Tolerances) -> float:
    """How far a point corrected in the hyperplane normal to ``t`` to residual ``r`` can be from where that
    hyperplane meets the path: ``r / sigma``, ``sigma`` the smallest singular value the corrector keeps of the
    Jacobian restricted to the hyperplane (the next Gauss-Newton step's bound)."""
    _, _, jac = ws.evaluate(p)
    n = t / np.linalg.norm(t)
    Q, _ = np.linalg.qr(np.column_stack([n, np.eye(len(p))]))
    s = np.linalg.svd(jac @ Q[:, 1:], compute_uv=False)
    kept = s[s > tol.truncate * s[0]]
    return float(r / kept[-1]) if len(kept) else float("inf")


def locate_minimum(
    ws: Workspace,
    u_a: Array,
    t_a: Array,
    u_b: Array,
    t_b: Array,
    r_path: int,
    tol: Tolerances,
) -> tuple[Array, float]:
    """Minimise the smallest non-zero singular value ratio ``sigma_r / sigma_1`` along the branch between
    points ``a`` and ``b`` (golden section in ``h = t_a . (u - u_a)``, points predicted by the cubic Hermite
    interpolant and corrected in their hyperplane; a trial the corrector cannot close is not a point of the path,
    and never the minimum). Catches rank drops where the test function keeps its sign. Returns the point and the
    ratio there."""
    h_b = float(t_a @ (u_b - u_a))

    def ratio(x: float) -> tuple[float, Array]:
        u, _, ok = correct_on_plane(ws, hermite(x, (0.0, u_a, t_a), (h_b, u_b, t_b), t_a), t_a, tol)
        if not ok:  # not a point of the path: never its minimum
            return np.inf, u
        _, _, jac = ws.evaluate(u)
        s = np.linalg.svd(jac, compute_uv=False)
        return float(s[r_path - 1] / s[0]), u

    golden = (np.sqrt(5.0) - 1.0) / 2.0
    lo, hi = 0.0, h_b
    x1, x2 = hi - golden * (hi - lo), lo + golden * (hi - lo)
    (f1, u1), (f2, u2) = ratio(x1), ratio(x2)
    for _ in range(80):
        if abs(hi - lo) < tol.locate:
            break
        if f1 < f2:
            hi, x2, f2, u2 = x2, x1, f1, u1
            x1 = hi - golden * (hi - lo)
            f1, u1 = ratio(x1)
        else:
            lo, x1, f1, u1 = x1, x2, f2, u2
            x2 = lo + golden * (hi - lo)
            f2, u2 = ratio(x2)
    return (u1, f1) if f1 < f2 else (u2, f2)


def refine_singular(
    ws: Workspace, u: Array, rank: int, tol: Tolerances, *, max_iter: int = 30, fd_step: float = 1e-6
) -> Array | None:
    """The singular point of rank ``rank`` next to ``u``, or None when there is none within reach.

    Near a node of the solution set a corrector lands on one of the curves, off the node by about the square root
    of its residual, so a located sign change can leave a point whose smallest singular value is small but not
    zero. Here Gauss-Newton solves the extended system of a singular point (Moore & Spence): the closure
    ``F(u) = 0``, a left null vector ``J(u)^T w = 0`` and ``|w| = 1``, with ``w`` started at the left singular
    vectors of ``J(u)`` beyond ``rank`` (central differences give the derivative of ``J^T w`` in ``u``). It is
    consistent at a singular point, where it converges quadratically; the result is accepted when the closure
    residual is within ``tol.closure`` and singular value ``rank`` is below ``tol.loose`` relative.
    """
    _, r, jac = ws.evaluate(u)
    U, s, _ = np.linalg.svd(jac)
    if rank >= len(s):
        return None
    w = U[:, rank].copy()
    x = u.copy()
    m = len(u)
    for _ in range(max_iter):
        _, r, jac = ws.evaluate(x)
        g = np.concatenate([r, jac.T @ w, [w @ w - 1.0]])
        if np.linalg.norm(g) < tol.closure:
            break
        dJw = np.empty((m, m))
        for k in range(m):
            e = np.zeros(m)
            e[k] = fd_step
            _, _, jp = ws.evaluate(x + e)
            _, _, jm = ws.evaluate(x - e)
            dJw[:, k] = (jp - jm).T @ w / (2.0 * fd_step)
        A = np.zeros((len(g), m + len(w)))
        A[: len(r), :m] = jac
        A[len(r) : len(r) + m, :m] = dJw
        A[len(r) : len(r) + m, m:] = jac.T
        A[-1, m:] = 2.0 * w
        delta = np.linalg.lstsq(A, -g, rcond=None)[0]
        x += delta[:m]
        w += delta[m:]
        if not np.all(np.isfinite(x)):
            return None
    res, _, jac = ws.evaluate(x)
    s = np.linalg.svd(jac, compute_uv=False)
    if res <= tol.closure and s[rank] <= tol.loose * s[0]:
        return x
    return None
