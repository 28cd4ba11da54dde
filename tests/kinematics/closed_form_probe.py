"""Test helpers for the planar closed form: the compiled kernel's own arguments and outputs on a trace, and the
accuracy contract of the batched rows kernels (``planar_rows``) checked against numpy's LAPACK."""

from __future__ import annotations

from typing import Any

import numpy as np

import linkwork as lw
from linkwork.kinematics.mechanism import Mechanism


def kernel_rows(
    mech: Mechanism, until: tuple[str, float], steps: int, max_step: float | None = None
) -> tuple[tuple[Any, ...], tuple[Any, ...]]:
    """``(arguments, outputs)`` of the compiled closed-form kernel on one paper-mode trace, whatever its status
    (rows ``0 .. count - 1`` are the closed form's, also where it then handed the path over). ``max_step``: the
    trace's (default its own); a drive step longer than it is solved at points no further apart
    (``dyads.closed_form_rows``), so the kernel sees ``steps`` steps only where each is at most ``max_step``."""
    from linkwork.kinematics import dyad_solver

    original = dyad_solver.closed_form_path
    seen: list[tuple[tuple[Any, ...], tuple[Any, ...]]] = []

    def watched(*args: Any) -> Any:
        out = original(*args)
        seen.append((args, out))
        return out

    try:
        dyad_solver.closed_form_path = watched  # type: ignore[assignment]
        lw.trace(mech, until=until, steps=steps, **({} if max_step is None else {"max_step": max_step}))
    finally:
        dyad_solver.closed_form_path = original
    assert seen, "the closed form was not tried"
    return seen[-1]


def assert_rows_contract(
    J: np.ndarray,
    rows: tuple[np.ndarray, np.ndarray, np.ndarray],
    tolerances: tuple[float, float, float, float],
    product_bound: bool = False,
) -> None:
    """Assert the rows kernels' contract on every point of ``J (K, E, E + 1)``: ``rows = (sigma (K, E), t (K, m),
    tau (K,))``; ``tolerances = (sigma, residual, unit, tau)``: every singular value within ``sigma * sigma_1`` of
    LAPACK's, descending; ``|J t| <= residual * sigma_1``; ``| |t| - 1 | <= unit``; ``tau`` within ``tau``
    relative of LAPACK's ``det([J; t^T])`` where J is well conditioned (``sigma_E > 1e-2 sigma_1``) and, with
    ``product_bound``, everywhere within ``tau * sigma_1^2 sigma_2`` of the signed product of LAPACK's singular
    values.

    LAPACK's determinant is taken on J scaled by a power of two near ``1 / sigma_1`` (exactly; unscaled, the
    bordered matrix's rows differ in scale by sigma_1 and LU loses that much); it is accurate to about
    ``eps sigma_1 / sigma_E`` relative, hence the relative comparison only where J is well conditioned, and the
    product of singular values (accurate to ``eps sigma_1^2 sigma_2``) elsewhere.
    """
    sigma, t, tau = rows
    sigma_tol, residual_tol, unit_tol, tau_tol = tolerances
    E = J.shape[1]
    s = np.linalg.svd(J, compute_uv=False)
    s1 = s[:, :1]
    assert np.all(np.abs(sigma - s) <= sigma_tol * s1), np.max(np.abs(sigma - s) / s1)
    assert np.all(sigma[:, :-1] >= sigma[:, 1:])
    residual = np.linalg.norm(np.einsum("kec,kc->ke", J, t), axis=1)
    assert np.all(residual <= residual_tol * s[:, 0]), np.max(residual / s[:, 0])
    assert np.all(np.abs(np.linalg.norm(t, axis=1) - 1.0) <= unit_tol)
    exponent = np.frexp(np.maximum(s[:, 0], 1e-300))[1]
    scaled = np.ldexp(J, -exponent[:, None, None])
    det = np.ldexp(np.linalg.det(np.concatenate([scaled, t[:, None, :]], axis=1)), E * exponent)
    conditioned = s[:, -1] > 1e-2 * s[:, 0]
    assert np.all(np.abs(tau - det)[conditioned] <= tau_tol * np.abs(det[conditioned]))
    if product_bound:
        product = np.sign(det) * np.prod(s, axis=1)
        assert np.all(np.abs(tau - product) <= tau_tol * s[:, 0] ** 2 * s[:, 1])
