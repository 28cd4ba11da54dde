"""The misfit and its first-order prediction against outside facts.

* A planar four-bar with in-plane hinge errors is still a four-bar: it keeps mobility 1 (misfit at rounding).
* Bennett's linkage is over-constrained: generic errors make it bind, linearly in the tolerance for small ones, and
  the first-order prediction from the nominal Jacobian's left null space matches the Monte Carlo.
* Moving every hinge line by the same rigid motion gives the same linkage moved: no misfit.
* Moving, turning or scaling the whole linkage changes nothing but the length unit.
* The compiled weighted closure agrees with the numpy reference of :mod:`linkwork.kinematics.closure`.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from linkwork.geometry import adjoint, exp_se3
from linkwork.kinematics.closure import closure_residual, jacobian
from linkwork.kinematics.mechanism import Mechanism
from linkwork.studies.imperfections import ImperfectionModel
from linkwork.studies.misfit import misfit_batch, weighted_closure
from linkwork.studies.robustness import prepare, robustness, run_chunk


def test_four_bar_with_in_plane_errors_keeps_mobility(four_bar):
    mech, path = four_bar
    model = ImperfectionModel(1e-2, np.radians(0.5), spatial=False)
    res = robustness(mech, path, model, 200, seed=4, workers=0)
    assert res.misfit_max.max() < 1e-10  # tolerance: the contract's 1e-10, the solve reaches rounding
    assert res.mobility_kept.all()


def test_four_bar_with_spatial_errors_binds(four_bar):
    mech, path = four_bar
    model = ImperfectionModel(1e-3, np.radians(0.05), spatial=True)
    res = robustness(mech, path, model, 100, seed=4, workers=0)
    assert (res.misfit_max > 1e-6).all()  # the errors are 1e-3: the misfit is of that order, not rounding
    assert not res.mobility_kept.any()


def test_bennett_binds_linearly_and_first_order_matches(bennett):
    mech, path = bennett
    medians, predicted = [], []
    for factor in (1.0, 2.0):
        model = ImperfectionModel(1e-5 * factor, np.radians(5e-4) * factor)
        res = robustness(mech, path, model, 400, seed=11, workers=0)
        assert (res.misfit_max > 0).all() and not res.mobility_kept.any()
        medians.append(np.median(res.misfit_max))
        predicted.append(np.median(res.first_order_max))
    assert (
        abs(medians[1] / medians[0] - 2.0) < 0.2
    )  # doubling both tolerances doubles the median, within 10 %
    for mc, fo in zip(medians, predicted, strict=True):
        assert abs(fo / mc - 1.0) < 0.1  # first order within 10 % of the Monte Carlo median


def test_first_order_matches_every_drive_value(bennett):
    """Per sample and per drive value, not just the medians: agreement to O(tolerance) relative."""
    mech, path = bennett
    setup = prepare(mech, path, ImperfectionModel(1e-6, np.radians(5e-5)), seed=2)
    chunk = run_chunk(setup, 0, 20)
    rel = np.abs(chunk.first_order_max / chunk.misfit_max - 1.0)
    assert rel.max() < 1e-3  # second-order terms are ~1e-6 relative; 1e-3 leaves room for conditioning


def _moved(mech: Mechanism, D: np.ndarray, scale: float = 1.0) -> Mechanism:
    tw = mech.twists.copy()
    tw[:, 3:] *= scale
    return replace(mech, twists=(adjoint(D) @ tw.T).T)


def test_same_rigid_motion_of_every_hinge_gives_no_misfit(bennett):
    mech, path = bennett
    setup = prepare(mech, path, ImperfectionModel(1e-3, np.radians(0.1)), seed=0)
    D = exp_se3(np.array([0.01, -0.02, 0.015, 0.03, 0.01, -0.02]))
    twists = (adjoint(D) @ setup.mech.twists.T).T[None, :, :].copy()
    misfit = misfit_batch(twists, *setup.kernel_args(), 30)
    assert misfit.max() < 1e-12  # tolerance: rounding of 4 joints x 6 rows


def test_misfit_is_frame_invariant_and_scales_with_the_linkage(bennett):
    mech, path = bennett
    model = ImperfectionModel(1e-4, np.radians(0.01))
    base = robustness(mech, path, model, 30, seed=5, workers=0)
    D = exp_se3(np.array([0.3, -1.1, 0.7, 2.0, -3.0, 0.5]))
    moved = robustness(_moved(mech, D), path, model, 30, seed=5, workers=0)
    np.testing.assert_allclose(moved.misfit_max, base.misfit_max, rtol=1e-7)
    big = robustness(
        _moved(mech, np.eye(4), 2.0), path, replace(model, position_tol=2e-4), 30, seed=5, workers=0
    )
    np.testing.assert_allclose(big.misfit_max, 2.0 * base.misfit_max, rtol=1e-7)
    assert abs(big.setup.scale.length / base.setup.scale.length - 2.0) < 1e-12


def test_weighted_closure_matches_the_numpy_reference(bennett):
    mech, _ = bennett
    rng = np.random.default_rng(0)
    q = rng.normal(size=mech.n_joints) * 0.3
    T = np.eye(6)
    T[:3, :3] *= 1.7
    T[3:, :3] = np.array([[0, -0.2, 0.4], [0.2, 0, -0.1], [-0.4, 0.1, 0]])
    joint, sign, ptr = mech.loop_arrays()
    rows = np.array(mech.rows, dtype=np.int64)
    r = np.empty(mech.n_equations)
    J = np.empty((mech.n_equations, mech.n_unknowns))
    weighted_closure((mech.twists, joint, sign, ptr, rows, mech.groups), q, T, r, J)
    np.testing.assert_allclose(r, T @ closure_residual(mech, q), atol=1e-13)
    np.testing.assert_allclose(J, T @ jacobian(mech, q) @ mech.coupling_matrix(), atol=1e-13)
