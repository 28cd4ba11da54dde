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
