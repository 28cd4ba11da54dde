"""SE(3) on plain numpy arrays: the exponential and logarithm, adjoints, Lie brackets and joint twists.

Conventions (used throughout linkwork):

* A transform ``T_A_B`` has shape ``(..., 4, 4)`` and maps coordinates in frame B into frame A, so
  ``T_A_C = T_A_B @ T_B_C``.
* A twist has shape ``(..., 6)`` and is laid out ``(omega, v)``: angular part first. Its matrix form is
  ``[[hat(omega), v], [0, 0]]``. A revolute joint about the line through ``p`` along unit ``u`` has twist
  ``(u, p x u)``; a prismatic joint along unit ``u`` has twist ``(0, u)``.
* The Lie bracket ``[a, b] = (wa x wb, wa x vb - wb x va)`` is the twist of ``hat(a) hat(b) - hat(b) hat(a)``.

Every function works over leading batch axes. These are the readable reference versions; the compiled kernels
in :mod:`linkwork.kinematics.kernels` do the same arithmetic one joint at a time.

References
----------
R. M. Murray, Z. Li, S. S. Sastry, *A Mathematical Introduction to Robotic Manipulation*, CRC Press, 1994, ch. 2.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]

#: Below this rotation angle the closed forms switch to their Taylor series.
SMALL_ANGLE = 1e-6


def hat3(w: ArrayLike) -> Array:
    """Skew matrix ``(..., 3, 3)`` of vectors ``(..., 3)``: ``hat3(w) @ x == cross(w, x)``."""
    w = np.asarray(w, dtype=float)
    if w.shape[-1:] != (3,):
        raise ValueError(f"Expected vectors of shape (..., 3), got {w.shape}")
    out = np.zeros((*w.shape[:-1], 3, 3))
    out[..., 0, 1], out[..., 0, 2] = -w[..., 2], w[..., 1]
    out[..., 1, 0], out[..., 1, 2] = w[..., 2], -w[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -w[..., 1], w[..., 0]
    return out


def twist_hat(xi: ArrayLike) -> Array:
    """4x4 matrix form ``(..., 4, 4)`` of twists ``(..., 6)`` laid out ``(omega, v)``."""
    xi = np.asarray(xi, dtype=float)
    if xi.shape[-1:] != (6,):
        raise ValueError(f"Expected twists of shape (..., 6), got {xi.shape}")
    out = np.zeros((*xi.shape[:-1], 4, 4))
    out[..., :3, :3] = hat3(xi[..., :3])
    out[..., :3, 3] = xi[..., 3:]
    return out


def rot_z(angle: ArrayLike) -> Array:
    """Homogeneous rotation about z by ``angle`` (radians), shape ``(..., 4, 4)``."""
    return _axis_rotation(angle, 2)


def rot_x(angle: ArrayLike) -> Array:
    """Homogeneous rotation about x by ``angle`` (radians), shape ``(..., 4, 4)``."""
    return _axis_rotation(angle, 0)


def _axis_rotation(angle: ArrayLike, axis: int) -> Array:
    """Homogeneous rotation about coordinate axis ``axis`` (0, 1, 2: x, y, z) by ``angle``, right-handed."""
    a = np.asarray(angle, dtype=float)
    out = np.zeros((*a.shape, 4, 4))
    c, s = np.cos(a), np.sin(a)
    i, k = ((1, 2), (2, 0), (0, 1))[axis]  # the plane turned, in the order that makes the rotation positive
    out[..., i, i], out[..., i, k], out[..., k, i], out[..., k, k] = c, -s, s, c
    out[..., axis, axis] = out[..., 3, 3] = 1.0
    return out


def translation(v: ArrayLike) -> Array:
    """Homogeneous translation by vectors ``(..., 3)``."""
    v = np.asarray(v, dtype=float)
    out = np.zeros((*v.shape[:-1], 4, 4))
    out[..., :3, 3] = v
    out[..., 0, 0] = out[..., 1, 1] = out[..., 2, 2] = out[..., 3, 3] = 1.0
    return out


def inverse(T: ArrayLike) -> Array:
    """Inverse of rigid transforms ``(..., 4, 4)`` using ``R^T``."""
    T = np.asarray(T, dtype=float)
    R, p = T[..., :3, :3], T[..., :3, 3]
    out = np.zeros_like(T)
    Rt = np.swapaxes(R, -1, -2)
    out[..., :3, :3] = Rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", Rt, p)
    out[..., 3, 3] = 1.0
    return out


def _so3_coefficients(theta: Array) -> tuple[Array, Array, Array]:
    """``A = sin t / t``, ``B = (1 - cos t) / t^2``, ``C = (t - sin t) / t^3``, free of cancellation.

    ``B`` is evaluated as ``2 sin^2(t/2) / t^2``; ``C`` by its Taylor series below 1e-2 (truncation < 1e-20).
    """
    small = theta < SMALL_ANGLE
    t = np.where(small, 1.0, theta)
    t2 = theta * theta
    A = np.where(small, 1.0 - t2 / 6.0, np.sin(t) / t)
    half = np.sin(0.5 * t) / t
    B = np.where(small, 0.5 - t2 / 24.0, 2.0 * half * half)
    series = theta < 1e-2
    tc = np.where(series, 1.0, theta)
    C = np.where(
        series,
        1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0 - t2 * t2 * t2 / 362880.0,
        (tc - np.sin(tc)) / (tc * tc * tc),
    )
    return A, B, C


def exp_so3(w: ArrayLike) -> Array:
    """Rotation matrices ``(..., 3, 3)`` of rotation vectors ``(..., 3)`` (Rodrigues' formula)."""
    w = np.asarray(w, dtype=float)
    theta = np.linalg.norm(w, axis=-1)
    A, B, _ = _so3_coefficients(theta)
    K = hat3(w)
    eye = np.broadcast_to(np.eye(3), K.shape)
    return eye + A[..., None, None] * K + B[..., None, None] * (K @ K)


def exp_se3(xi: ArrayLike) -> Array:
    """Rigid transforms ``(..., 4, 4)`` of twists ``(..., 6)``: the matrix exponential of ``twist_hat(xi)``."""
    xi = np.asarray(xi, dtype=float)
    w, v = xi[..., :3], xi[..., 3:]
    theta = np.linalg.norm(w, axis=-1)
    A, B, C = _so3_coefficients(theta)
    K = hat3(w)
    K2 = K @ K
    eye = np.broadcast_to(np.eye(3), K.shape)
    R = eye + A[..., None, None] * K + B[..., None, None] * K2
    V = eye + B[..., None, None] * K + C[..., None, None] * K2
    out = np.zeros((*xi.shape[:-1], 4, 4))
    out[..., :3, :3] = R
    out[..., :3, 3] = np.einsum("...ij,...j->...i", V, v)
    out[..., 3, 3] = 1.0
    return out


def log_so3(R: ArrayLike) -> Array:
    """Rotation vectors ``(..., 3)`` of rotation matrices ``(..., 3, 3)``, angle in ``[0, pi]``."""
    R = np.asarray(R, dtype=float)
    cos_t = np.clip((np.trace(R, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    skew = np.stack(
        [R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], axis=-1
    )
    sin_t = 0.5 * np.linalg.norm(skew, axis=-1)
    theta = np.arctan2(sin_t, cos_t)
    # Regular case: w = theta / (2 sin theta) * vee(R - R^T); series for theta -> 0.
    small = theta < SMALL_ANGLE
    safe_sin = np.where(small, 1.0, sin_t)
    factor = np.where(small, 0.5 + theta * theta / 12.0, theta / (2.0 * safe_sin))
    w = factor[..., None] * skew
    # Near pi, sin theta -> 0 and the skew part loses the axis: read it from the symmetric part instead.
    near_pi = theta > np.pi - 1e-4
    if np.any(near_pi):
        Rn = R[near_pi]
        th = theta[near_pi]
        B = (Rn + np.swapaxes(Rn, -1, -2)) / 2.0 - np.cos(th)[:, None, None] * np.eye(3)
        # B = (1 - cos t) u u^T: take the column of largest norm as the axis.
        idx = np.argmax(np.einsum("nii->ni", B), axis=-1)
        u = B[np.arange(len(idx)), :, idx]
        u /= np.linalg.norm(u, axis=-1, keepdims=True)
        # Fix the sign of the axis with the skew part (which is 2 sin t u).
        sgn = np.sign(np.einsum("ni,ni->n", u, skew[near_pi]))
        sgn[sgn == 0] = 1.0
        w[near_pi] = (sgn * th)[:, None] * u
    return w


def log_se3(T: ArrayLike) -> Array:
    """Twists ``(..., 6)`` of rigid transforms ``(..., 4, 4)``: inverse of :func:`exp_se3`."""
    T = np.asarray(T, dtype=float)
    w = log_so3(T[..., :3, :3])
    theta = np.linalg.norm(w, axis=-1)
    A, B, _ = _so3_coefficients(theta)
    # V^{-1} = I - K/2 + D K^2 with D = (1 - A / (2B)) / t^2, by its Taylor series below 1e-2 where the closed
    # form cancels (truncation < 1e-20).
    series = theta < 1e-2
    th2 = theta * theta
    t2 = np.where(series, 1.0, th2)
    D = np.where(
        series,
        1.0 / 12.0 + th2 / 720.0 + th2 * th2 / 30240.0 + th2 * th2 * th2 / 1209600.0,
        (1.0 - A / (2.0 * B)) / t2,
    )
    K = hat3(w)
    eye = np.broadcast_to(np.eye(3), K.shape)
    Vinv = eye - 0.5 * K + D[..., None, None] * (K @ K)
    v = np.einsum("...ij,...j->...i", Vinv, T[..., :3, 3])
    return np.concatenate([w, v], axis=-1)


def adjoint(T: ArrayLike) -> Array:
    """Adjoint matrices ``(..., 6, 6)`` of transforms: ``adjoint(T) @ xi`` is ``T hat(xi) T^-1`` as a twist."""
    T = np.asarray(T, dtype=float)
    R, p = T[..., :3, :3], T[..., :3, 3]
    out = np.zeros((*T.shape[:-2], 6, 6))
    out[..., :3, :3] = R
    out[..., 3:, 3:] = R
    out[..., 3:, :3] = hat3(p) @ R
    return out


def bracket(a: ArrayLike, b: ArrayLike) -> Array:
    """Lie bracket of twists ``(..., 6)``: ``[a, b] = (wa x wb, wa x vb - wb x va)``."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    wa, va, wb, vb = a[..., :3], a[..., 3:], b[..., :3], b[..., 3:]
    return np.concatenate([np.cross(wa, wb), np.cross(wa, vb) - np.cross(wb, va)], axis=-1)


def line_twist(point: ArrayLike, direction: ArrayLike, kind: str = "R") -> Array:
    """Unit twist ``(..., 6)`` of a revolute (``"R"``) about, or prismatic (``"P"``) along, a directed line."""
    p = np.asarray(point, dtype=float)
    u = np.asarray(direction, dtype=float)
    u = u / np.linalg.norm(u, axis=-1, keepdims=True)
    if kind == "R":
        return np.concatenate([u, np.cross(p, u)], axis=-1)
    if kind == "P":
        return np.concatenate([np.zeros_like(u), u], axis=-1)
    raise ValueError(f"Expected joint kind 'R' or 'P', got {kind!r}")
