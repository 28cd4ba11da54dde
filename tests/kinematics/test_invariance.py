"""A traced path belongs to the linkage, not to how it is written down; the derivatives are what they claim.

Invariances (docs/architecture.md): the same Bennett linkage (from DH parameters) and the same Hedgepeth hoop
(n = 6, the paper's Eqs. 7-12) traced after

* relabelling the loop's first joint (the loop product becomes a conjugate ``g^-1 P g``),
* moving the base frame (every twist carried by ``Ad(T)``: the product becomes ``T P T^-1``),
* reversing the loop (joints in reverse order, twists negated: the product becomes ``P^-1``)

gives the same angle of every named joint at the same drive values, and the same Jacobian rank. The compiled
kernel agrees with the numpy reference on random R/P mechanisms with several loops; the Jacobian matches
central finite differences of the right-trivialised loop product, and the Lie-bracket Hessian matches second
central differences of ``log P`` at a closed configuration (which needs exp and log free of small-angle
cancellation: checked last, against scipy's matrix exponential).

Reference values come from outside the code under test: Bennett's closed-form joint relation
``tan(t1/2) tan(t2/2) = sin((a2 + a1)/2) / sin((a2 - a1)/2)``, finite differences and ``scipy.linalg.expm``.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from linkwork.geometry import adjoint, exp_se3, inverse, log_se3
from linkwork.kinematics import closure, kernels
from linkwork.kinematics.chains import from_dh
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import numerical_rank
from linkwork.kinematics.trace_result import Trace
from linkwork.kinematics.tracer import trace
from linkwork.linkages import deployed_angle, hedgepeth

#: Seeded, no deadline (the first call may load numba's cache), few examples: the file runs in seconds.
PROPERTY = settings(deadline=None, max_examples=12, derandomize=True)

#: Paper mode (equal drive steps, the drive held by the corrector): every variant visits the same drive values
STEPS = 24

#: Same angle of every named joint (radians).
ANGLE_TOL = 1e-9


# ------------------------------------------------------------------------------------------------ linkages


def bennett(alpha1: float, alpha2: float, theta1: float) -> Mechanism:
    """Bennett's linkage from DH parameters (radians), closed exactly at ``theta1``.

    In the convention ``T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``: ``alpha3 = alpha1``,
    ``alpha4 = alpha2``, ``a_i = sin(alpha_i)``, ``theta3 = -theta1``, ``theta4 = -theta2``, and Bennett's
    relation gives ``theta2``.
    """
    k = np.sin((alpha2 + alpha1) / 2.0) / np.sin((alpha2 - alpha1) / 2.0)
    theta2 = 2.0 * np.arctan(k / np.tan(theta1 / 2.0))
    alphas = (alpha1, alpha2, alpha1, alpha2)
    thetas = (theta1, theta2, -theta1, -theta2)
    params = [{"theta": t, "a": float(np.sin(a)), "alpha": a} for t, a in zip(thetas, alphas, strict=True)]
    mech, assembly = from_dh("Bennett", params)
    assert assembly.residual_before < 1e-12, "Bennett's conditions close the loop exactly (residual < 1e-12)"
    return mech


def bennett_relation(alpha1: float, alpha2: float, angles: np.ndarray) -> np.ndarray:
    """Left minus right side of Bennett's relation for joints A and B at every row of ``angles``."""
    k = np.sin((alpha2 + alpha1) / 2.0) / np.sin((alpha2 - alpha1) / 2.0)
    return np.tan(angles[:, 0] / 2.0) * np.tan(angles[:, 1] / 2.0) - k


def relabelled(mech: Mechanism, shift: int) -> Mechanism:
    """The same loop started at joint ``shift``: twists, names and offsets rolled."""
    return Mechanism.single_loop(
        f"{mech.name} from {mech.joint_names[shift]}",
        np.roll(np.array(mech.joint_names), -shift).tolist(),
        np.roll(mech.twists, -shift, axis=0),
        np.roll(mech.offsets, -shift),
    )


def moved(mech: Mechanism, T: np.ndarray) -> Mechanism:
    """The same loop described in another base frame: every twist carried by ``Ad(T)``."""
    return Mechanism.single_loop(
        f"{mech.name} moved", mech.joint_names, mech.twists @ adjoint(T).T, mech.offsets
    )


def reversed_loop(mech: Mechanism) -> Mechanism:
    """The same loop walked backwards: ``exp(-xi_n q_n) ... exp(-xi_1 q_1) = I`` is the inverse product."""
    return Mechanism.single_loop(
        f"{mech.name} reversed", mech.joint_names[::-1], -mech.twists[::-1], mech.offsets[::-1]
    )


def paper_trace(mech: Mechanism, target: float) -> Trace:
    """``STEPS`` equal steps of joint A from its start to ``target`` (radians)."""
    path = trace(mech, drive="A", until=("A", target), steps=STEPS)
    assert path.branches[-1].end_reason == "reached target"
    return path


def by_name(path: Trace, names: tuple[str, ...]) -> np.ndarray:
    """The path's angles ``(N, n)`` with columns in the order of ``names``."""
    order = [path.mechanism.joint_names.index(name) for name in names]
    return path.angles[:, order]


def assert_same_path(variant: Trace, reference: Trace) -> None:
    """Same number of points, same angle of every named joint at each (1e-9 rad), same rank everywhere."""
    names = reference.mechanism.joint_names
    assert variant.angles.shape == reference.angles.shape
    np.testing.assert_allclose(by_name(variant, names), reference.angles, rtol=0.0, atol=ANGLE_TOL)
    np.testing.assert_array_equal(variant.rank, reference.rank)


def start_rank(mech: Mechanism, q: np.ndarray | None = None) -> int:
    """Numerical rank of the reference Jacobian (numpy) at ``q`` (default: the start)."""
    q = np.zeros(mech.n_joints) if q is None else q
    return numerical_rank(np.linalg.svd(closure.jacobian(mech, q), compute_uv=False))


def rigid_transform(seed: int) -> np.ndarray:
    """A random rigid transform: rotation by up to pi about a random axis, translation up to ~2."""
    rng = np.random.default_rng(seed)
    axis = rng.normal(size=3)
    w = axis / np.linalg.norm(axis) * rng.uniform(0.1, np.pi - 0.1)
    return exp_se3(np.concatenate([w, rng.uniform(-2.0, 2.0, size=3)]))


DEG = np.pi / 180.0
bennett_params = st.tuples(
    st.floats(15.0, 70.0),  # alpha1 (deg)
    st.floats(20.0, 80.0),  # alpha2 - alpha1 (deg), well away from the degenerate alpha1 = alpha2
    st.floats(40.0, 80.0),  # theta1 at the start (deg)
    st.floats(20.0, 60.0),  # how far A turns (deg), staying inside (0, 180) where the path is regular
)


# ----------------------------------------------------------------------------------------- the reference


@PROPERTY
@given(params=bennett_params)
def test_traced_bennett_path_satisfies_bennetts_relation(params: tuple[float, float, float, float]) -> None:
    a1, gap, t1, turn = params
    alpha1, alpha2 = a1 * DEG, (a1 + gap) * DEG
    mech = bennett(alpha1, alpha2, t1 * DEG)
    path = paper_trace(mech, (t1 + turn) * DEG)
    # Bennett's closed form, to 1e-9; and its symmetry theta3 = -theta1, theta4 = -theta2 to 1e-9 rad.
    np.testing.assert_allclose(bennett_relation(alpha1, alpha2, path.angles), 0.0, atol=1e-9)
    np.testing.assert_allclose(path.angles[:, 2], -path.angles[:, 0], atol=ANGLE_TOL)
    np.testing.assert_allclose(path.angles[:, 3], -path.angles[:, 1], atol=ANGLE_TOL)
    # Equal drive steps land exactly on the target (1e-12 rad) and the linkage keeps mobility 1.
    assert path.angles[-1, 0] == pytest.approx((t1 + turn) * DEG, abs=1e-12)
    assert set(path.mobility.tolist()) == {1}


# -------------------------------------------------------------------------------------------- invariances


@PROPERTY
@given(params=bennett_params, shift=st.integers(1, 3))
def test_relabelling_the_first_joint_of_bennett_keeps_its_path(
    params: tuple[float, float, float, float], shift: int
) -> None:
    a1, gap, t1, turn = params
    mech = bennett(a1 * DEG, (a1 + gap) * DEG, t1 * DEG)
    target = (t1 + turn) * DEG
    variant = relabelled(mech, shift)
    assert start_rank(variant) == start_rank(mech) == 3
    assert_same_path(paper_trace(variant, target), paper_trace(mech, target))


@PROPERTY
@given(params=bennett_params, seed=st.integers(0, 2**32 - 1))
def test_moving_the_base_frame_of_bennett_keeps_its_path(
    params: tuple[float, float, float, float], seed: int
) -> None:
    a1, gap, t1, turn = params
    mech = bennett(a1 * DEG, (a1 + gap) * DEG, t1 * DEG)
    target = (t1 + turn) * DEG
    variant = moved(mech, rigid_transform(seed))
    assert start_rank(variant) == start_rank(mech) == 3
    assert_same_path(paper_trace(variant, target), paper_trace(mech, target))


@PROPERTY
@given(params=bennett_params)
def test_reversing_the_loop_of_bennett_keeps_its_path(params: tuple[float, float, float, float]) -> None:
    a1, gap, t1, turn = params
    mech = bennett(a1 * DEG, (a1 + gap) * DEG, t1 * DEG)
    target = (t1 + turn) * DEG
    variant = reversed_loop(mech)
    assert start_rank(variant) == start_rank(mech) == 3
    assert_same_path(paper_trace(variant, target), paper_trace(mech, target))


HEDGEPETH_VARIANTS: dict[str, Callable[[Mechanism], Mechanism]] = {
    "relabel-B-first": lambda m: relabelled(m, 1),
    "relabel-D-first": lambda m: relabelled(m, 3),
    "relabel-F-first": lambda m: relabelled(m, 5),
    "move-base-frame": lambda m: moved(m, rigid_transform(2006)),
    "reverse-loop": reversed_loop,
    "reverse-and-move": lambda m: moved(reversed_loop(relabelled(m, 2)), rigid_transform(7)),
}


@pytest.mark.parametrize("variant", HEDGEPETH_VARIANTS)
def test_hedgepeth_hoop_path_to_deployment_is_invariant(variant: str) -> None:
    mech = hedgepeth(6)
    changed = HEDGEPETH_VARIANTS[variant](mech)
    target = deployed_angle(6)  # Eq. (10)
    reference = paper_trace(mech, target)
    other = paper_trace(changed, target)
    assert_same_path(other, reference)
    # Rank 5, mobility 1 at the folded bundle for both (exact integers).
    assert start_rank(changed) == start_rank(mech) == 5
    # ... and the rank of the numpy Jacobian at the deployed end is the same too.
    names = mech.joint_names
    q_end = changed.q_from_angles(other.angles[-1])
    assert start_rank(changed, q_end) == start_rank(mech, mech.q_from_angles(reference.angles[-1]))
    # The hoop stays symmetric along every variant's path: A = C = E and B = D = F (1e-9 rad).
    angles = by_name(other, names)
    np.testing.assert_allclose(angles[:, [2, 4]], angles[:, [0, 0]], atol=ANGLE_TOL)
    np.testing.assert_allclose(angles[:, [3, 5]], angles[:, [1, 1]], atol=ANGLE_TOL)


# -------------------------------------------------------------------------- kernels against the reference


def two_loop_mechanism(seed: int, types: tuple[str, ...], planar: bool = False) -> Mechanism:
    """A random mechanism of five joints between four bodies: two independent loops, R and P joints."""
    rng = np.random.default_rng(seed)
    bodies = [("ground", "b1"), ("b1", "b2"), ("b2", "ground"), ("b1", "b3"), ("b3", "b2")]
    joints = []
    for i, (pair, kind) in enumerate(zip(bodies, types, strict=True)):
        direction = rng.normal(size=3)
        point = rng.uniform(-1.0, 1.0, size=3)
        if planar:
            point[2] = 0.0
            direction = np.array([0.0, 0.0, 1.0]) if kind == "R" else np.append(direction[:2], 0.0)
        joints.append(
            {
                "name": f"J{i}",
                "type": kind,
                "bodies": pair,
                "point": point,
                "direction": direction,
                "value": rng.uniform(-1.0, 1.0),
            }
        )
    mech = Mechanism.from_joints("random two-loop", joints, planar=planar)
    assert len(mech.loops) == 2
    return mech


def kernel(mech: Mechanism, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Residual and reduced Jacobian from the compiled kernel."""
    joint, sign, ptr = mech.loop_arrays()
    residual = np.empty(mech.n_equations)
    jac = np.empty((mech.n_equations, mech.n_unknowns))
    arrays = (mech.twists, joint, sign, ptr, np.array(mech.rows, dtype=np.int64), mech.groups)
    kernels.closure_jacobian(arrays, np.ascontiguousarray(q, dtype=float), mech.n_unknowns, residual, jac)
    return residual, jac


joint_types = st.tuples(*[st.sampled_from("RP")] * 5)
seeds = st.integers(0, 2**32 - 1)


@PROPERTY
@given(seed=seeds, types=joint_types, planar=st.booleans())
def test_compiled_kernel_agrees_with_numpy_reference_on_random_mechanisms(
    seed: int, types: tuple[str, ...], planar: bool
) -> None:
    mech = two_loop_mechanism(seed, types, planar)
    # |q| <= 0.5 on five joints keeps every loop's rotation below pi, away from the log's branch cut.
    q = np.random.default_rng(seed + 1).uniform(-0.5, 0.5, size=mech.n_joints)
    residual, jac = kernel(mech, q)
    np.testing.assert_allclose(residual, closure.closure_residual(mech, q), rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(jac, closure.jacobian(mech, q), rtol=0.0, atol=1e-12)


@PROPERTY
@given(seed=seeds, types=joint_types)
def test_compiled_kernel_sums_coupled_columns_and_drops_fixed_joints(
    seed: int, types: tuple[str, ...]
) -> None:
    mech = two_loop_mechanism(seed, types)
    kinds = mech.joint_types
    pair = next(((i, j) for i in range(5) for j in range(i + 1, 5) if kinds[i] == kinds[j]), None)
    assert pair is not None  # five joints of two kinds: two share a kind
    fixed = next(j for j in range(5) if j not in pair)
    coupled = mech.with_couplings(
        [[mech.joint_names[pair[0]], mech.joint_names[pair[1]]]], [mech.joint_names[fixed]]
    )
    assert coupled.n_unknowns == 3
    u = np.random.default_rng(seed + 2).uniform(-0.4, 0.4, size=3)
    q = coupled.q_from_u(u)
    residual, jac = kernel(coupled, q)
    np.testing.assert_allclose(residual, closure.closure_residual(coupled, q), rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(
        jac, closure.reduce(coupled, closure.jacobian(coupled, q)), rtol=0.0, atol=1e-12
    )


# ----------------------------------------------------------------------------------- finite differences


def loop_logs(mech: Mechanism, q: np.ndarray, right: list[np.ndarray] | None = None) -> np.ndarray:
    """Stacked kept rows of ``log(P_k(q) R_k)`` over the loops (``R_k`` = identity by default)."""
    products = closure.loop_products(mech, q)
    right = right or [np.eye(4)] * len(products)
    rows = list(mech.rows)
    return np.concatenate([log_se3(P @ R)[rows] for P, R in zip(products, right, strict=True)])


@PROPERTY
@given(seed=seeds, types=joint_types)
def test_jacobian_columns_are_the_spatial_twists_of_finite_differences(
    seed: int, types: tuple[str, ...]
) -> None:
    mech = two_loop_mechanism(seed, types)
    q = np.random.default_rng(seed + 3).uniform(-0.5, 0.5, size=mech.n_joints)
    # Column i = log(P(q + eps e_i) P(q)^-1) / eps, centrally: error O(eps^2) ~ 1e-10, far below 1e-6.
    back = [inverse(P) for P in closure.loop_products(mech, q)]
    eps = 1e-5
    fd = np.empty((mech.n_equations, mech.n_joints))
    for i in range(mech.n_joints):
        e = np.zeros(mech.n_joints)
        e[i] = eps
        fd[:, i] = (loop_logs(mech, q + e, back) - loop_logs(mech, q - e, back)) / (2.0 * eps)
    np.testing.assert_allclose(closure.jacobian(mech, q), fd, rtol=0.0, atol=1e-6)


#: Step of the second differences: truncation ~ h^2 |f''''| / 12 ~ 1e-9 and round-off ~ eps / h^2 ~ 1e-8, both
#: well below the 1e-5 tolerance (this needs a log free of small-angle cancellation; see the tests at the end).
SECOND_DIFFERENCE_STEP = 1e-4


@cache
def closed_configurations() -> dict[str, tuple[Mechanism, np.ndarray]]:
    """Closed configurations (mechanism, q) away from the start: along Bennett's and the hoop's paths."""
    out: dict[str, tuple[Mechanism, np.ndarray]] = {}
    ben = bennett(45.0 * DEG, 75.0 * DEG, 90.0 * DEG)
    path = paper_trace(ben, 130.0 * DEG)
    out["bennett"] = (ben, ben.q_from_angles(path.angles[-1]))
    hoop = hedgepeth(6)
    path = paper_trace(hoop, 60.0 * DEG)
    out["hedgepeth"] = (hoop, hoop.q_from_angles(path.angles[-1]))
    return out


@pytest.mark.parametrize("name", ["bennett", "hedgepeth"])
@settings(deadline=None, max_examples=8, derandomize=True)
@given(seed=seeds)
def test_lie_bracket_hessian_matches_second_differences_of_log_closure(name: str, seed: int) -> None:
    mech, q = closed_configurations()[name]
    assert np.linalg.norm(closure.closure_residual(mech, q)) < 1e-11  # closed (1e-11)
    a = np.random.default_rng(seed).normal(size=mech.n_joints)
    a /= np.linalg.norm(a)
    H = closure.hessian(mech, q)
    # d2/ds2 log P(q + s a) at s = 0 by central differences: see SECOND_DIFFERENCE_STEP for the step.
    h = SECOND_DIFFERENCE_STEP
    second = (loop_logs(mech, q + h * a) - 2.0 * loop_logs(mech, q) + loop_logs(mech, q - h * a)) / h**2
    np.testing.assert_allclose(np.einsum("eij,i,j->e", H, a, a), second, rtol=0.0, atol=1e-5)


@PROPERTY
@given(seed=seeds, types=joint_types, direction=seeds)
def test_lie_bracket_hessian_matches_second_differences_on_random_mechanisms(
    seed: int, types: tuple[str, ...], direction: int
) -> None:
    mech = two_loop_mechanism(seed, types)
    q = np.zeros(mech.n_joints)  # the assembled reference: every loop closes exactly
    a = np.random.default_rng(direction).normal(size=mech.n_joints)
    a /= np.linalg.norm(a)
    h = SECOND_DIFFERENCE_STEP
    second = (loop_logs(mech, h * a) - 2.0 * loop_logs(mech, q) + loop_logs(mech, -h * a)) / h**2
    expected = np.einsum("eij,i,j->e", closure.hessian(mech, q), a, a)
    np.testing.assert_allclose(expected, second, rtol=0.0, atol=1e-5)


# ------------------------------------------------------ the exponential and logarithm the checks rely on


def expm_twist(xi: np.ndarray) -> np.ndarray:
    """An independent reference exponential: scipy's Pade matrix exponential of the 4x4 twist matrix."""
    from scipy.linalg import expm

    from linkwork.geometry import twist_hat

    return expm(twist_hat(xi))


def kernel_log(T: np.ndarray) -> np.ndarray:
    """The compiled logarithm of the kernels."""
    out = np.empty(6)
    kernels.log_rigid(np.ascontiguousarray(T[:3, :3]), np.ascontiguousarray(T[:3, 3]), out)
    return out


#: Rotation angles on both sides of the series thresholds of exp and log (1e-6 and 1e-2), where a closed form
#: such as (1 - cos t) / t^2 or (1 - A / (2B)) / t^2 would cancel catastrophically, and near pi.
ANGLES = [1e-9, 1e-7, 1.5e-6, 2e-6, 3e-6, 1e-4, 1e-3, 9.9e-3, 1.01e-2, 0.1, 0.3, 2.5, 3.1]


@pytest.mark.parametrize("angle", ANGLES)
def test_exp_se3_matches_the_matrix_exponential(angle: float) -> None:
    xi = np.array([angle, 0.0, 0.0, 0.0, 1.0, 0.0])
    np.testing.assert_allclose(exp_se3(xi), expm_twist(xi), rtol=0.0, atol=1e-12)


@pytest.mark.parametrize("angle", ANGLES)
def test_log_se3_and_the_compiled_log_invert_the_matrix_exponential(angle: float) -> None:
    xi = np.array([angle, 0.0, 0.0, 0.0, 1.0, 0.0])
    T = expm_twist(xi)
    np.testing.assert_allclose(log_se3(T), xi, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(kernel_log(T), xi, rtol=0.0, atol=1e-12)
