"""Serial descriptions of a single loop (Denavit-Hartenberg, the paper's rods) turned into a :class:`Mechanism`.

A loop written as a product of constant transforms and joint rotations about local z,
``C_0 Rz(theta_1 + q_1) C_1 Rz(theta_2 + q_2) ... = I``, is the product of exponentials
``exp(xi_1 q_1) ... exp(xi_n q_n) G = I`` with ``xi_k`` the z-axis of the frame reached just before joint ``k``'s
rotation and ``G`` the whole product at the start values. A start given with rounded angles leaves ``G`` close to,
but not equal to, the identity: :func:`assemble_chain` corrects the angles onto the loop of the link parameters
as written (Gauss-Newton on the serial product itself), recomputes the twists there, and reports the correction.
Link parameters that close no loop (an over-constrained loop typed with rounded lengths) leave a least-squares
closure misfit: accepted up to ``closure_tol`` (play in the hinges), an :class:`AssemblyError` above it.

References
----------
W. W. Gan, S. Pellegrino, Proc. IMechE Part C 220 (2006), Eqs. (1)-(2), (12), (28).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from linkwork.errors import AssemblyError
from linkwork.geometry import bracket, log_se3, rot_x, rot_z, translation
from linkwork.geometry.names import default_joint_names
from linkwork.kinematics.mechanism import Array, Mechanism


@dataclass(frozen=True)
class Assembly:
    """How a start configuration was closed onto the loop of the written link parameters.

    Attributes
    ----------
    residual_before
        Closure residual (2-norm of ``log G``) at the start angles as written.
    residual_after
        The least-squares closure misfit left after the correction: round-off (~1e-16) for link parameters that
        close a loop; the play in the hinges that was accepted (at most ``closure_tol``) otherwise.
    correction
        ``(n,)`` radians added to the written start angles.
    closure_tol
        The largest misfit that was accepted.
    sigma
        Singular values of the loop's closure Jacobian at the corrected start (descending; at most 6).
    """

    residual_before: float
    residual_after: float
    correction: Array  # (n,) radians
    closure_tol: float = 1e-12
    sigma: Array = field(default_factory=lambda: np.zeros(0))

    @property
    def misfit(self) -> float:
        """The least-squares closure misfit of the assembled start (``residual_after``)."""
        return self.residual_after


def dh_transform(theta: float, d: float, a: float, alpha: float) -> Array:
    """Denavit-Hartenberg link transform ``Rz(theta) Tz(d) Tx(a) Rx(alpha)`` (the spec file convention, docs/spec-format.md)."""
    return rot_z(theta) @ translation([0.0, 0.0, d]) @ translation([a, 0.0, 0.0]) @ rot_x(alpha)


def rod_transform(phi: float, omega: float, psi: float, v: Sequence[float]) -> Array:
    """The paper's rod transform ``[Rz(phi) Rx(omega) Rz(psi), v]`` (Eqs. (1)-(2), x-convention)."""
    T = rot_z(phi) @ rot_x(omega) @ rot_z(psi)
    T[:3, 3] = np.asarray(v, dtype=float)
    return T


ROUNDOFF_PER_LENGTH = 64 * float(np.finfo(float).eps)
"""The misfit a loop closes to in floating point, per unit of its links' total length (a few ulps for each of a
few dozen products): the floor of the misfit accepted as closed, whatever ``closure_tol`` says."""


def _chain_twists(constants: Sequence[Array], thetas: Array, rotation_first: bool) -> tuple[Array, Array]:
    """Joint twists at ``thetas`` and the loop product ``G`` there.

    ``rotation_first``: factors are ``Rz(theta_k) C_k`` (DH) instead of ``C_k Rz(theta_k)`` (rods). Twist ``k``
    is the z-axis of the frame reached just before joint ``k``'s rotation, which is also the right-trivialised
    derivative ``dG/dtheta_k G^-1``: the columns of the closure Jacobian at ``thetas``.
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


def close_serial_loop(
    constants: Sequence[Array],
    thetas: ArrayLike,
    *,
    rotation_first: bool,
    keep: float = 1e-5,
    max_iterations: int = 80,
) -> tuple[Array, float]:
    """Start angles moved onto the loop of the written constant transforms, and the closure misfit left.

    Gauss-Newton on the exact serial product ``G(theta)`` (never on a model linearised at the rounded start):
    ``theta <- theta - J^+ log G`` with ``J`` the derivative of ``log G`` (the twists at the current angles
    through :func:`_dlog`) and the truncated-SVD pseudo-inverse of Eq. (28) keeping the singular values above
    ``keep * sigma_1``, so that the correction has minimum norm and does not slide along a (near-)motion. A step
    that does not lower the residual is halved; the iteration ends when the residual stops decreasing. A loop
    the parameters close ends at round-off; an over-constrained loop whose parameters close no loop ends where
    the residual is orthogonal to the directions kept: its least-squares misfit at the start, since along the
    near-motion (the dropped direction) the misfit changes only slowly.
    """
    theta = np.asarray(thetas, dtype=float).copy()
    _, G = _chain_twists(constants, theta, rotation_first)
    err = log_se3(G)
    residual = float(np.linalg.norm(err))
    for _ in range(max_iterations):
        if residual == 0.0:
            break
        twists, _ = _chain_twists(constants, theta, rotation_first)
        U, s, Vt = np.linalg.svd(_dlog(err) @ twists.T, full_matrices=False)
        r = int(np.sum(s > keep * s[0]))
        step = -Vt[:r].T @ ((U[:, :r].T @ err) / s[:r])  # Eq. (28)
        for _halving in range(30):
            _, G = _chain_twists(constants, theta + step, rotation_first)
            trial_err = log_se3(G)
            trial_residual = float(np.linalg.norm(trial_err))
            if trial_residual < residual:
                break
            step = 0.5 * step
        else:
            break
        progress = residual - trial_residual
        theta, err, residual = theta + step, trial_err, trial_residual
        if progress < 1e-6 * residual:
            break
    return theta, residual


def _dlog(y: Array) -> Array:
    """``(6, 6)`` derivative of ``log(exp(x) exp(y))`` in ``x`` at 0: ``I - ad_y / 2 + ad_y^2 / 12 - ad_y^4 / 720``.

    The Bernoulli series of ``z / (e^z - 1)`` (Baker-Campbell-Hausdorff); ``ad_y x = [y, x]``. Near a closed loop
    ``y`` is small and the series is exact to round-off; it matters where a misfit is left, since the
    least-squares stationary point of ``|log G|`` is defined by this derivative, not by the bare twists.
    """
    ad = np.array([bracket(y, e) for e in np.eye(6)]).T
    ad2 = ad @ ad
    return np.eye(6) - ad / 2.0 + ad2 / 12.0 - ad2 @ ad2 / 720.0


def assemble_chain(
    name: str,
    joint_names: Sequence[str],
    constants: Sequence[Array],
    thetas: Sequence[float],
    *,
    rotation_first: bool,
    closure_tol: float = 1e-12,
    max_correction: float = 0.2,
    meta: Mapping[str, Any] | None = None,
) -> tuple[Mechanism, Assembly]:
    """Build and close a single-loop :class:`Mechanism` from its serial description.

    The start angles are corrected onto the loop of the link parameters as written (:func:`close_serial_loop`)
    and the joint twists are computed from the serial description at the corrected angles, so that the link
    geometry is exactly the written one. A least-squares closure misfit up to ``closure_tol`` is accepted (play
    in the hinges) and recorded in the :class:`Assembly`.

    Raises
    ------
    AssemblyError
        One line: the link parameters do not close the loop (misfit above ``closure_tol``: the misfit, the
        smallest singular value and the joints are named), or closing the start would move some joint by more
        than ``max_correction`` radians (then the start was not a rounded configuration of this loop).
    """
    written = np.asarray(thetas, dtype=float)
    _, G0 = _chain_twists(constants, written, rotation_first)
    before = float(np.linalg.norm(log_se3(G0)))
    # The misfit accepted: closure_tol, or the round-off of closing a loop of this size if that is larger (a
    # Bennett linkage written 1e5 times larger closes only to 2.2e-11: its product of lengths of 1e5 rounds so).
    size = float(sum(np.linalg.norm(np.asarray(c)[:3, 3]) for c in constants))
    closure_tol = max(closure_tol, ROUNDOFF_PER_LENGTH * size)
    # Well-determined directions first (no slide along a near-motion), then every direction above round-off
    # (a loop at a near-singular start); the second pass is kept only when it closes the loop.
    closed, misfit = close_serial_loop(constants, written, rotation_first=rotation_first)
    if not misfit <= closure_tol:
        again, left = close_serial_loop(constants, closed, rotation_first=rotation_first, keep=1e-10)
        if left <= closure_tol:
            closed, misfit = again, left
    q = closed - written
    twists, _ = _chain_twists(constants, closed, rotation_first)
    sigma: Array = np.linalg.svd(twists.T, compute_uv=False).astype(float)
    if np.max(np.abs(q), initial=0.0) > max_correction:
        worst = int(np.argmax(np.abs(q)))
        raise AssemblyError(
            f"{name}: the start configuration is far from the loop (closure residual {before:.3g}); closing "
            f"it would move joint {joint_names[worst]} by {np.degrees(q[worst]):.3g} deg",
            residual=before,
        )
    if not misfit <= closure_tol:
        raise AssemblyError(
            _misfit_message(name, joint_names, misfit, closure_tol, before, sigma), residual=before
        )
    mech = Mechanism.single_loop(name, joint_names, twists, offsets=closed, meta=meta)
    return mech, Assembly(before, misfit, q, closure_tol, sigma)


def _misfit_message(
    name: str, joint_names: Sequence[str], misfit: float, closure_tol: float, before: float, sigma: Array
) -> str:
    """The one line saying that the link parameters do not close the loop, with the numbers."""
    loop = "-".join(joint_names)
    return (
        f"{name}: the link parameters do not close the loop {loop}: least-squares closure misfit {misfit:.3g} "
        f"> closure tolerance {closure_tol:.3g} (residual {before:.3g} at the start as written; smallest "
        f"singular value of the closure Jacobian {sigma[-1]:.3g}, largest {sigma[0]:.3g}); an over-constrained "
        "loop typed with rounded lengths or twists? Give them to full precision, or accept the misfit as play "
        "in the hinges with a closure tolerance above it (closure_tol / --closure-tol)"
    )


def from_dh(
    name: str,
    params: Sequence[Mapping[str, float]],
    *,
    joint_names: Sequence[str] | None = None,
    meta: Mapping[str, Any] | None = None,
    closure_tol: float = 1e-12,
) -> tuple[Mechanism, Assembly]:
    """A loop in the DH convention ``T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``, closing when ``prod T_i = I``.

    ``params``: one mapping per joint with ``theta`` (start value), ``d``, ``a``, ``alpha`` (radians; missing = 0).
    ``closure_tol``: the largest least-squares closure misfit accepted (see :func:`assemble_chain`).
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
    return assemble_chain(
        name, names, constants, thetas, rotation_first=True, closure_tol=closure_tol, meta=info
    )


def from_rods(
    name: str,
    rods: Sequence[Mapping[str, Any]],
    thetas: Sequence[float],
    *,
    joint_names: Sequence[str] | None = None,
    meta: Mapping[str, Any] | None = None,
    closure_tol: float = 1e-12,
) -> tuple[Mechanism, Assembly]:
    """A loop of the paper's rods: ``T_i = [Rz(phi) Rx(omega) Rz(psi), v] Rz(theta_i)`` and ``prod T_i = I`` (Eq. (12)).

    ``rods``: one mapping per joint with ``phi``, ``omega``, ``psi`` (radians) and ``v`` (3-vector).
    ``closure_tol``: the largest least-squares closure misfit accepted (see :func:`assemble_chain`).
    """
    names = list(joint_names or default_joint_names(len(rods)))
    constants = [rod_transform(r["phi"], r["omega"], r["psi"], r["v"]) for r in rods]
    info = {"convention": "rods", "rods": [dict(r) for r in rods], **dict(meta or {})}
    return assemble_chain(
        name, names, constants, thetas, rotation_first=False, closure_tol=closure_tol, meta=info
    )
