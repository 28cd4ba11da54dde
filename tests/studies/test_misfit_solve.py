"""The misfit kernel's Gauss-Newton reaches the least closure residual: against scipy's least-squares solver on the
numpy closure of :mod:`linkwork.kinematics.closure`, point by point along the hexagon's path."""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

import linkwork as lw
from linkwork.kinematics.closure import closure_residual
from linkwork.linkages.hedgepeth_rods import deployed_angles
from linkwork.studies.imperfections import ImperfectionModel, hinge_errors, perturbed_twists, sample_seeds
from linkwork.studies.misfit import misfit_batch
from linkwork.studies.robustness import MAX_ITER, prepare


def test_misfit_is_the_least_residual_in_the_normal_plane() -> None:
    mech = lw.load("hedgepeth-rods", n=6)
    path = lw.trace(mech, until=("A", deployed_angles(6)[0]), steps=59)
    setup = prepare(mech, path, ImperfectionModel(1e-3, np.radians(0.05)), seed=4)
    errors = hinge_errors(sample_seeds(4, 0, 2), setup.mech, setup.model, setup.lines)
    twists = perturbed_twists(errors, setup.lines)
    path_args, loops, weights = setup.kernel_args()
    u_path, normal, _ = path_args  # one loop: its weight is 1
    misfit = misfit_batch(twists, path_args, loops, weights, MAX_ITER)
    for s in range(len(twists)):
        imperfect = lw.Mechanism.single_loop("imperfect", mech.joint_names, twists[s])
        for k in (1, 2, 3, 30, 59):

            def weighted(y: np.ndarray, k: int = k, m: lw.Mechanism = imperfect) -> np.ndarray:
                return weights[k] @ closure_residual(m, u_path[k] + normal[k] @ y)

            best = least_squares(
                weighted, np.zeros(normal.shape[2]), method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15
            )
            reference = float(np.linalg.norm(best.fun))
            # Never below the least residual (to rounding), and within 1e-6 of it: the solve stops once a further
            # Gauss-Newton step is predicted to lower |r|^2 by less than 1e-8 of it (seen: up to 2.4e-7 above).
            assert reference * (1.0 - 1e-9) - 1e-15 <= misfit[s, k] <= reference * (1.0 + 1e-6) + 1e-15


def _hat(a: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def test_one_loops_gradient_is_that_of_the_log_derivative() -> None:
    """``J^T rg`` (``rg`` from ``_log_gradient``, one vector a loop) equals ``(M J)^T r`` with ``M = T (I - ad_X /
    2) T^-1``, ``X = T^-1 r``, each matrix written out here (``ad_X = [[w^, 0], [v^, w^]]``), for random weights,
    residuals and columns, spatial (six rows) and planar (rows 2, 3, 4)."""
    from linkwork.studies.misfit import _log_gradient

    rng = np.random.default_rng(7)
    for rows in (np.arange(6), np.array([2, 3, 4])):
        for _ in range(20):
            length = float(rng.uniform(0.1, 10.0))
            T = np.eye(6)
            T[:3, :3] *= length
            T[3:, :3] = (
                rng.normal(size=(3, 3)) if len(rows) == 6 else _hat(np.array([*rng.normal(size=2), 0.0]))
            )
            full_r = np.zeros(6)
            full_r[rows] = rng.normal(size=len(rows)) * 1e-2
            X = np.linalg.solve(T, full_r)
            ad = np.zeros((6, 6))
            ad[:3, :3] = ad[3:, 3:] = _hat(X[:3])
            ad[3:, :3] = _hat(X[3:])
            M = T @ (np.eye(6) - ad / 2.0) @ np.linalg.inv(T)
            J = np.zeros((6, 5))
            J[rows] = rng.normal(size=(len(rows), 5))
            want = (M @ J).T @ full_r
            rg = np.empty(len(rows))
            _log_gradient.py_func(full_r[rows].copy(), T, rows, np.empty((3, 6)), rg)
            assert np.allclose(J[rows].T @ rg, want, rtol=1e-13, atol=1e-15)
