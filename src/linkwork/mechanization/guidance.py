"""Rigid-body guidance: where to put an RR dyad so that a body passes through given positions.

A body's positions are ``(p, 3)`` poses ``(x, y, angle)`` of its frame; a point ``m`` of the body (in its frame)
is at ``W_j(m) = R(angle_j) m + (x_j, y_j)`` in position ``j``. An RR dyad (a binary link with a fixed pivot
``c``, the *centre point*, and a moving pivot ``m``, the *circle point*) guides the body when every ``W_j(m)``
lies on the circle about ``c``:

* 3 positions: any circle point; its centre point is the centre of the circle through its three positions.
* 4 positions: the circle points lie on a cubic, the circle-point curve, their centres on the centre-point curve.
* 5 positions: at most four circle points (Burmester points), where two such cubics meet.
* more positions: least-squares circles, with a structural error (the spread of the length the link would
  need across the positions).

Equal distances ``|W_j - c| = |W_1 - c|`` are linear in ``c``: ``2 (W_j - W_1) . c = |W_j|^2 - |W_1|^2``
(McCarthy, *Geometric Design of Linkages*, ch. 4-5); the ``|m|^2`` terms cancel, so each row is linear in ``m``
too, and the compatibility determinants are cubics in ``m``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray

from linkwork.errors import LinkworkError

Array = NDArray[np.float64]


def positions(poses: ArrayLike, point: ArrayLike) -> Array:
    """``(p, 2)`` positions ``W_j(m)`` of the body point ``m`` (body frame) in each pose ``(p, 3)``."""
    g = np.asarray(poses, dtype=float)
    m = np.asarray(point, dtype=float)
    c, s = np.cos(g[:, 2]), np.sin(g[:, 2])
    return np.column_stack([c * m[0] - s * m[1] + g[:, 0], s * m[0] + c * m[1] + g[:, 1]])


def inverse_poses(poses: ArrayLike) -> Array:
    """Poses of the fixed frame seen from the moving body (kinematic inversion), ``(p, 3)``."""
    g = np.asarray(poses, dtype=float)
    c, s = np.cos(g[:, 2]), np.sin(g[:, 2])
    x = -(c * g[:, 0] + s * g[:, 1])
    y = -(-s * g[:, 0] + c * g[:, 1])
    return np.column_stack([x, y, -g[:, 2]])


def circle_through(points: ArrayLike) -> tuple[Array, float]:
    """Centre ``(2,)`` and radius of the circle through three points ``(3, 2)``.

    Raises
    ------
    LinkworkError
        When the points are collinear (or two coincide): no finite circle passes through them.
    """
    z = np.asarray(points, dtype=float)
    if z.shape != (3, 2):
        raise ValueError(f"Expected points of shape (3, 2), got {z.shape}")
    a = 2.0 * (z[1:] - z[0])
    b = np.sum(z[1:] ** 2, axis=1) - np.sum(z[0] ** 2)
    scale = float(np.max(np.abs(z - z[0]))) or 1.0
    det = a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0]
    if abs(det) <= 1e-13 * scale * scale:
        raise LinkworkError(
            "the three positions are collinear (or two coincide): no circle passes through them"
        )
    centre = np.linalg.solve(a, b)
    return centre, float(np.linalg.norm(z[0] - centre))


def _rows(poses: Array, m: Array) -> tuple[Array, Array]:
    """Linear equations ``A c = b`` of equal distances from ``c`` to every position of ``m`` (``(p-1, 2)``)."""
    w = positions(poses, m)
    return 2.0 * (w[1:] - w[0]), np.sum(w[1:] ** 2, axis=1) - np.sum(w[0] ** 2)


@dataclass(frozen=True)
class Dyad:
    """A circle point on the moving body and its centre point, with how well the circle fits.

    Attributes
    ----------
    circle_point
        ``(2,)`` the moving pivot in the body frame.
    centre_point
        ``(2,)`` the fixed pivot.
    radius
        The link length ``|W_1 - c|`` (the dyad is exact in position 1).
    structural_error
        The spread of the length the link would need across the positions, ``max_j |W_j - c| - min_j |W_j -
        c|``: 0 (to rounding) for an exact dyad. A link of length ``radius`` misses the other positions by up to
        this much.
    """

    circle_point: Array
    centre_point: Array
    radius: float
    structural_error: float


def centre_point(poses: ArrayLike, circle_point: ArrayLike) -> Dyad:
    """The centre point of a circle point: exact for 3 positions, least squares beyond (Sec. 7).

    For ``p = 3`` the centre of the circle through the three positions; for ``p > 3`` the least-squares
    solution of the equal-distance equations, refined to minimise the geometric distances, with the link length
    fixed by position 1 and the structural error (the spread of the distances) reported.
    """
    g = np.asarray(poses, dtype=float)
    m = np.asarray(circle_point, dtype=float)
    w = positions(g, m)
    if len(g) < 3:
        raise ValueError(f"Expected at least 3 positions, got {len(g)}")
    if len(g) == 3:
        c, _ = circle_through(w)
    else:
        a, b = _rows(g, m)
        c = np.asarray(np.linalg.lstsq(a, b, rcond=None)[0], dtype=float)
        c = _refine_centre(w, c)
    radius = float(np.linalg.norm(w[0] - c))
    err = float(np.ptp(np.linalg.norm(w - c, axis=1)))
    return Dyad(m, c, radius, err)


def _refine_centre(w: Array, c: Array) -> Array:
    """Gauss-Newton on ``|w_j - c| - |w_1 - c|`` (the circle through position 1 that fits best)."""
    for _ in range(30):
        d = w - c
        r = np.linalg.norm(d, axis=1)
        if np.any(r == 0.0):
            break
        res = r[1:] - r[0]
        jac = -(d[1:] / r[1:, None]) + d[0] / r[0]
        step = np.linalg.lstsq(jac, -res, rcond=None)[0]
        c = c + step
        if np.max(np.abs(step)) <= 1e-15 * (1.0 + np.max(np.abs(c))):
            break
    return c


def fit_circle_point(poses: ArrayLike, circle_point: ArrayLike) -> Dyad:
    """Move a circle point to the nearest one whose positions fit a circle best (least squares, p > 5).

    Minimises ``sum_j (|W_j(m) - c| - |W_1(m) - c|)^2`` over ``m`` and ``c`` (Yao & Angeles style), starting at
    ``circle_point``; returns the fitted dyad and its structural error.
    """
    from scipy.optimize import least_squares

    g = np.asarray(poses, dtype=float)
    start = centre_point(g, circle_point)

    def residual(u: Array) -> Array:
        w = positions(g, u[:2])
        r = np.linalg.norm(w - u[2:], axis=1)
        return r[1:] - r[0]

    sol = least_squares(residual, np.concatenate([start.circle_point, start.centre_point]), method="lm")
    fitted = centre_point(g, sol.x[:2])
    return fitted if fitted.structural_error <= start.structural_error else start


# ------------------------------------------------------------------------------------------- 4 positions
def compatibility(poses: ArrayLike, point: ArrayLike, rows: tuple[int, int, int] = (1, 2, 3)) -> float:
    """The cubic ``det [2 (W_j - W_0), -(|W_j|^2 - |W_0|^2)]`` over three of the positions ``j`` (>= 1).

    Zero exactly when the positions ``0, rows...`` of ``point`` lie on one circle (or a line).
    """
    g = np.asarray(poses, dtype=float)
    a, b = _rows(g, np.asarray(point, dtype=float))
    idx = [r - 1 for r in rows]
    return float(np.linalg.det(np.column_stack([a[idx], -b[idx]])))


def circle_point_curve(
    poses: ArrayLike, *, rays: int = 180, origin: ArrayLike | None = None, reach: float | None = None
) -> tuple[Array, Array]:
    """Sample the circle-point and centre-point curves of four positions.

    Along each of ``rays`` lines through ``origin`` (default: the mean of the positions' origins) the
    compatibility cubic is a cubic in the line parameter; its real roots are circle points.

    Returns
    -------
    circle_points, centre_points
        ``(k, 2)`` each: circle points in the body frame and their centre points, roots farther than ``reach``
        (default 10 times the spread of the positions) from ``origin`` left out.
    """
    g = np.asarray(poses, dtype=float)
    if len(g) != 4:
        raise ValueError(f"Expected 4 positions, got {len(g)}")
    o = np.mean(inverse_poses(g)[:, :2], axis=0) if origin is None else np.asarray(origin, dtype=float)
    spread = float(np.ptp(g[:, :2], axis=0).max()) or 1.0
    reach = 10.0 * spread if reach is None else reach
    ts = np.array([-1.0, -1.0 / 3.0, 1.0 / 3.0, 1.0]) * spread
    circle, centre = [], []
    for phi in np.linspace(0.0, np.pi, rays, endpoint=False):
        u = np.array([np.cos(phi), np.sin(phi)])
        vals = [compatibility(g, o + t * u) for t in ts]
        coeffs = np.polyfit(ts / spread, vals, 3)
        if not np.any(coeffs):
            continue
        for root in np.roots(coeffs):
            if abs(root.imag) > 1e-9 * max(1.0, abs(root.real)):
                continue
            t = float(root.real) * spread
            if abs(t) > reach:
                continue
            m = o + t * u
            dyad = centre_point(g, m)
            if dyad.structural_error <= 1e-6 * spread and np.all(np.isfinite(dyad.centre_point)):
                circle.append(m)
                centre.append(dyad.centre_point)
    return np.reshape(circle, (-1, 2)), np.reshape(centre, (-1, 2))


# ------------------------------------------------------------------------------------------- 5 positions
_MONOMIALS = [(i, k) for i in range(4) for k in range(4 - i)]  # x^i y^k, i + k <= 3


def _cubic_coefficients(fun: object, origin: Array, scale: float) -> dict[tuple[int, int], float]:
    """Coefficients of the cubic ``fun(origin + scale (x, y))`` by least squares on a grid (exact to rounding)."""
    grid = np.linspace(-1.0, 1.0, 5)
    pts = np.array([(x, y) for x in grid for y in grid])
    basis = np.column_stack([pts[:, 0] ** i * pts[:, 1] ** k for i, k in _MONOMIALS])
    vals = np.array([fun(origin + scale * p) for p in pts])  # type: ignore[operator]
    coef = np.linalg.lstsq(basis, vals, rcond=None)[0]
    return dict(zip(_MONOMIALS, coef, strict=True))


def _in_x(coef: dict[tuple[int, int], float]) -> list[Array]:
    """``F_i(y)`` (numpy ``polyval`` order, highest first) with ``f = sum_i F_i(y) x^i``."""
    return [np.array([coef[(i, k)] for k in range(3 - i, -1, -1)]) for i in range(4)]


def _sylvester_pencil(f: list[Array], g: list[Array]) -> list[Array]:
    """``S_k`` with Sylvester matrix ``S(y) = sum_k y^k S_k`` (6 x 6) of two cubics in ``x``."""
    mats = [np.zeros((6, 6)) for _ in range(4)]
    for row_shift in range(3):
        for poly, offset in ((f, 0), (g, 3)):
            for i in range(4):  # coefficient of x^i sits in column (3 - i) + shift
                col = 3 - i + row_shift
                for k, value in enumerate(poly[i][::-1]):  # value multiplies y^k
                    mats[k][offset + row_shift, col] = value
    return mats


def _newton2(f: object, g: object, z: Array, scale: float) -> Array:
    """Newton's method on the pair of cubics ``f = g = 0`` with finite-difference Jacobians."""
    h = 1e-7 * scale
    for _ in range(50):
        r = np.array([f(z), g(z)])  # type: ignore[operator]
        jac = np.empty((2, 2))
        for k in range(2):
            e = np.zeros(2)
            e[k] = h
            jac[:, k] = (np.array([f(z + e), g(z + e)]) - np.array([f(z - e), g(z - e)])) / (2 * h)  # type: ignore[operator]
        try:
            step = np.linalg.solve(jac, -r)
        except np.linalg.LinAlgError:
            break
        z = z + step
        if np.max(np.abs(step)) <= 1e-14 * (scale + np.max(np.abs(z))):
            break
    return z


def _common_zeros(
    ca: dict[tuple[int, int], float], cb: dict[tuple[int, int], float], origin: Array, scale: float
) -> list[Array]:
    """Approximate real common zeros of two cubics (coefficients in the scaled coordinates about ``origin``): the
    hidden-variable resultant in ``y`` as a generalised eigenvalue problem, then the roots in ``x`` of the first
    cubic at each real eigenvalue."""
    mats = _sylvester_pencil(_in_x(ca), _in_x(cb))
    n = 6
    eye, zero = np.eye(n), np.zeros((n, n))
    big_a = np.block([[zero, eye, zero], [zero, zero, eye], [-mats[0], -mats[1], -mats[2]]])
    big_b = np.block([[eye, zero, zero], [zero, eye, zero], [zero, zero, mats[3]]])
    ys = scipy.linalg.eigvals(big_a, big_b)
    candidates: list[Array] = []
    fx = _in_x(ca)
    for y in ys:
        if not np.isfinite(y) or abs(y.imag) > 1e-5 * max(1.0, abs(y)):
            continue
        yr = float(y.real)
        if abs(yr) > 1e3:
            continue
        poly = np.array([np.polyval(fx[i], yr) for i in range(3, -1, -1)])
        roots = np.roots(poly) if np.any(poly) else np.array([])
        for x in roots:
            if abs(x.imag) > 1e-4 * max(1.0, abs(x)):
                continue
            candidates.append(origin + scale * np.array([float(x.real), yr]))
    return candidates


def burmester_points(poses: ArrayLike, *, tol: float = 1e-8) -> list[Dyad]:
    """The Burmester points of five positions: circle points whose five positions lie on one circle.

    The common real zeros of the compatibility cubics over positions (1, 2, 3, 4) and (1, 2, 3, 5), found by
    the hidden-variable resultant (the Sylvester matrix as a cubic matrix polynomial in ``y``, linearised to a
    generalised eigenvalue problem), polished by Newton's method. The poles of the positions, where the
    cubics meet without a circle, are left out. Returns 0, 2 or 4 dyads (each exact, structural error ~ 0).
    """
    g = np.asarray(poses, dtype=float)
    if len(g) != 5:
        raise ValueError(f"Expected 5 positions, got {len(g)}")
    origin = np.mean(inverse_poses(g)[:, :2], axis=0)
    scale = float(np.ptp(np.vstack([g[:, :2], inverse_poses(g)[:, :2]]), axis=0).max()) or 1.0

    def fa(m: Array) -> float:
        return compatibility(g, m, (1, 2, 3)) / scale**3

    def fb(m: Array) -> float:
        return compatibility(g, m, (1, 2, 4)) / scale**3

    ca = _cubic_coefficients(fa, origin, scale)
    cb = _cubic_coefficients(fb, origin, scale)
    found: list[Dyad] = []
    for z0 in _common_zeros(ca, cb, origin, scale):
        z = _newton2(
            lambda m: compatibility(g, m, (1, 2, 3)), lambda m: compatibility(g, m, (1, 2, 4)), z0, scale
        )
        if not np.all(np.isfinite(z)):
            continue
        w = positions(g, z)
        gaps = np.linalg.norm(w[:, None, :] - w[None, :, :], axis=2)[np.triu_indices(5, 1)]
        if gaps.min() <= 1e-6 * scale:  # a pole: two positions of the point coincide
            continue
        a, b = _rows(g, z)
        c = np.linalg.lstsq(a, b, rcond=None)[0]
        radius = float(np.linalg.norm(w[0] - c))
        err = float(np.ptp(np.linalg.norm(w - c, axis=1)))
        if err > tol * scale or radius > 1e6 * scale:
            continue
        if any(np.linalg.norm(d.circle_point - z) <= 1e-7 * scale for d in found):
            continue
        found.append(Dyad(np.asarray(z, dtype=float), np.asarray(c, dtype=float), radius, err))
    return found
