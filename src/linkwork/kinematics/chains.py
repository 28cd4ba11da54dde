"""Serial descriptions of a single loop (Denavit-Hartenberg, the paper's rods) turned into a :class:`Mechanism`.

A loop written as a product of constant transforms and joint rotations about local z,
``C_0 Rz(theta_1 + q_1) C_1 Rz(theta_2 + q_2) ... = I``, is the product of exponentials
``exp(xi_1 q_1) ... exp(xi_n q_n) G = I`` with ``xi_k`` the z-axis of the frame reached just before joint ``k``'s
rotation and ``G`` the whole product at the start values. A start given with rounded angles leaves ``G`` close to,
but not equal to, the identity: :func:`assemble_chain` corrects it onto the loop and reports the correction.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from linkwork.errors import AssemblyError
from linkwork.geometry import exp_se3, log_se3, rot_x, rot_z, translation
from linkwork.geometry.names import default_joint_names
from linkwork.kinematics.mechanism import Array, Mechanism


@dataclass(frozen=True)
class Assembly:
    """How a start configuration was closed: the residual before and after, and the correction per joint."""

    residual_before: float
    residual_after: float
    correction: Array  # (n,) radians


def dh_transform(theta: float, d: float, a: float, alpha: float) -> Array:
    """Denavit-Hartenberg link transform ``Rz(theta) Tz(d) Tx(a) Rx(alpha)`` (the spec file convention, docs/spec-format.md)."""
    return rot_z(theta) @ translation([0.0, 0.0, d]) @ translation([a, 0.0, 0.0]) @ rot_x(alpha)


def rod_transform(phi: float, omega: float, psi: float, v: Sequence[float]) -> Array:
    """The paper's rod transform ``[Rz(phi) Rx(omega) Rz(psi), v]`` (Eqs. (1)-(2), x-convention)."""
    T = rot_z(phi) @ rot_x(omega) @ rot_z(psi)
    T[:3, 3] = np.asarray(v, dtype=float)
    return T


def _chain_twists(constants: Sequence[Array], thetas: Array, rotation_first: bool) -> tuple[Array, Array]:
    """Joint twists at the start and the loop product ``G`` there.

    ``rotation_first``: factors are ``Rz(theta_k) C_k`` (DH) instead of ``C_k Rz(theta_k)`` (rods).
    """
    n = len(constants)
    g = np.eye(4)
    twists = np.zeros((n, 6))
    for k in range(n):
        if not rotation_first:
            g = g @ constants[k]
        z, p = g[:3, 2], g[:3, 3]
        twists[k] = np.concatenate([z, np.cross(p, z)])
        g = g @ rot_z(thetas[k])
        if rotation_first:
            g = g @ constants[k]
    return twists, g


def assemble_chain(
    name: str,
    joint_names: Sequence[str],
    constants: Sequence[Array],
    thetas: Sequence[float],
    *,
    rotation_first: bool,
    tolerance: float = 1e-12,
    max_correction: float = 0.2,
    meta: Mapping[str, Any] | None = None,
) -> tuple[Mechanism, Assembly]:
    """Build and close a single-loop :class:`Mechanism` from its serial description.

    The start angles are corrected onto the loop with the truncated-SVD Gauss-Newton iteration of Eq. (28)
    (minimum-norm correction). Raises :class:`AssemblyError` when the loop cannot be closed, or only by moving
    some joint by more than ``max_correction`` radians (then the start was not a rounded configuration of
    this loop but something else).
    """
    thetas_arr = np.asarray(thetas, dtype=float)
    twists, G = _chain_twists(constants, thetas_arr, rotation_first)
    mech = Mechanism.single_loop(name, joint_names, twists, offsets=thetas_arr, meta=meta)
    before = float(np.linalg.norm(log_se3(G)))
    q = np.zeros(len(joint_names))
    residual = before
    for _ in range(50):
        P = np.eye(4)
        cols = []
        for k in range(len(q)):
            cols.append(_adjoint_apply(P, twists[k]))
            P = P @ exp_se3(twists[k] * q[k])
        err = log_se3(P @ G)
        residual = float(np.linalg.norm(err))
        if residual < tolerance:
            break
        J = np.array(cols).T
        U, s, Vt = np.linalg.svd(J, full_matrices=False)
        keep = s > 1e-10 * s[0]
        q = q - Vt[keep].T @ ((U[:, keep].T @ err) / s[keep])  # Eq. (28)
    if residual > max(1e3 * tolerance, 1e-9):
        raise AssemblyError(
            f"{name}: the start configuration cannot be closed onto the loop "
            f"(closure residual {before:.3g} at the start, {residual:.3g} after correction)",
            residual=before,
        )
    if np.max(np.abs(q)) > max_correction:
        worst = int(np.argmax(np.abs(q)))
        raise AssemblyError(
            f"{name}: the start configuration is far from the loop (closure residual {before:.3g}); closing "
            f"it would move joint {joint_names[worst]} by {np.degrees(q[worst]):.3g} deg",
            residual=before,
        )
    assembled = mech.with_reference(q) if np.any(q) else mech
    return assembled, Assembly(before, residual, q)


def _adjoint_apply(T: Array, xi: Array) -> Array:
    """``Ad(T) xi`` for one transform and one twist."""
    R, p = T[:3, :3], T[:3, 3]
    w = R @ xi[:3]
    return np.concatenate([w, R @ xi[3:] + np.cross(p, w)])


def from_dh(
    name: str,
    params: Sequence[Mapping[str, float]],
    *,
    joint_names: Sequence[str] | None = None,
    meta: Mapping[str, Any] | None = None,
) -> tuple[Mechanism, Assembly]:
    """A loop in the DH convention ``T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``, closing when ``prod T_i = I``.

    ``params``: one mapping per joint with ``theta`` (start value), ``d``, ``a``, ``alpha`` (radians; missing = 0).
    """
    names = list(joint_names or default_joint_names(len(params)))
    constants = [
        translation([0.0, 0.0, p.get("d", 0.0)])
        @ translation([p.get("a", 0.0), 0.0, 0.0])
        @ rot_x(p.get("alpha", 0.0))
        for p in params
    ]
    thetas = [p.get("theta", 0.0) for p in params]
    info = {"convention": "dh", "params": [dict(p) for p in params], **dict(meta or {})}
    return assemble_chain(name, names, constants, thetas, rotation_first=True, meta=info)


def from_rods(
    name: str,
    rods: Sequence[Mapping[str, Any]],
    thetas: Sequence[float],
    *,
    joint_names: Sequence[str] | None = None,
    meta: Mapping[str, Any] | None = None,
) -> tuple[Mechanism, Assembly]:
    """A loop of the paper's rods: ``T_i = [Rz(phi) Rx(omega) Rz(psi), v] Rz(theta_i)`` and ``prod T_i = I`` (Eq. (12)).

    ``rods``: one mapping per joint with ``phi``, ``omega``, ``psi`` (radians) and ``v`` (3-vector).
    """
    names = list(joint_names or default_joint_names(len(rods)))
    constants = [rod_transform(r["phi"], r["omega"], r["psi"], r["v"]) for r in rods]
    info = {"convention": "rods", "rods": [dict(r) for r in rods], **dict(meta or {})}
    return assemble_chain(name, names, constants, thetas, rotation_first=False, meta=info)
