"""The normalised Jacobian's singular values (and so the robustness ratio) do not depend on how a linkage is drawn.

Invariances checked: rigid motion, uniform scaling (prismatic coordinates scale with the lengths), sliding a
hinge's written point along its line, relabelling the joints (a cyclic shift or reversal of a loop, which fixes
another body as the base; a reordering of a multi-loop mechanism's joints, which changes its cycle basis). The
hinge centre and length scale are checked against closed forms. The raw ratio is shown to change, so the tests
can fail.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import linkwork as lw
from linkwork.geometry import adjoint, line_twist
from linkwork.io.spec import load_spec
from linkwork.kinematics.closure import closure_residual, jacobian, reduce
from linkwork.kinematics.mechanism import Loop, Mechanism, cycle_basis
from linkwork.kinematics.normalization import (
    cycle_metric,
    hinge_centre,
    length_scale,
    normalized_jacobian,
    robustness_ratio,
)

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "examples" / "specs"


def slider_crank() -> Mechanism:
    """A planar slider-crank (crank 1, rod 3, offset 0.5): three revolute joints and one prismatic."""
    B = np.array([math.cos(0.7), math.sin(0.7)])
    C = np.array([B[0] + math.sqrt(9.0 - (B[1] - 0.5) ** 2), 0.5])
    joints = [
        {
            "name": "A",
            "type": "R",
            "bodies": ("ground", "crank"),
            "point": (0.0, 0.0),
            "direction": (0, 0, 1),
        },
        {"name": "B", "type": "R", "bodies": ("crank", "rod"), "point": tuple(B), "direction": (0, 0, 1)},
        {"name": "C", "type": "R", "bodies": ("rod", "slider"), "point": tuple(C), "direction": (0, 0, 1)},
        {
            "name": "S",
            "type": "P",
            "bodies": ("slider", "ground"),
            "point": (0, 0),
            "direction": (1, 0),
            "value": C[0],
        },
    ]
    return Mechanism.from_joints("slider-crank", joints, planar=True)


@pytest.fixture(scope="module")
def cases() -> dict[str, tuple[Mechanism, np.ndarray]]:
    """Mechanisms and a few configurations traced on them (away from the start)."""
    mechs = {
        "bennett": lw.load("bennett"),
        "hedgepeth-rods": lw.load("hedgepeth-rods", n=6),
        "sarrus": lw.load("sarrus"),
        "goldberg": lw.load("goldberg"),
        "watt": load_spec(SPECS / "watt-six-bar.toml").mechanism,
        "slider-crank": slider_crank(),
    }
    out = {}
    for name, mech in mechs.items():
        trace = lw.trace(mech, max_steps=12, max_step=math.radians(4.0))
        out[name] = (mech, trace.angles[:: max(1, len(trace.angles) // 4)])
    return out


def sigma(mech: Mechanism, angles: np.ndarray) -> np.ndarray:
    return np.linalg.svd(normalized_jacobian(mech, angles), compute_uv=False)


def raw_sigma(mech: Mechanism, angles: np.ndarray) -> np.ndarray:
    return np.linalg.svd(reduce(mech, jacobian(mech, mech.q_from_angles(angles))), compute_uv=False)


def moved(mech: Mechanism, R: np.ndarray, t: np.ndarray, s: float) -> Mechanism:
    """``mech`` scaled by ``s`` about the origin, then turned by ``R`` and moved by ``t``."""
    g = np.eye(4)
    g[:3, :3], g[:3, 3] = R, t
    twists = mech.twists.copy()
    prismatic = np.array([k == "P" for k in mech.joint_types])
    twists[~prismatic, 3:] *= s
    offsets = np.where(prismatic, s * mech.offsets, mech.offsets)
    return replace(mech, twists=(adjoint(g) @ twists.T).T, offsets=offsets)


def scaled_angles(mech: Mechanism, angles: np.ndarray, s: float) -> np.ndarray:
    return np.where([k == "P" for k in mech.joint_types], s * angles, angles)


motions = st.tuples(
    st.lists(st.floats(-math.pi, math.pi), min_size=3, max_size=3),
    st.lists(st.floats(-20.0, 20.0), min_size=3, max_size=3),
    st.floats(0.01, 100.0),
)


@settings(max_examples=20, deadline=None)
@given(motion=motions)
def test_rigid_motion_and_scaling_leave_the_singular_values(
    cases: dict[str, tuple[Mechanism, np.ndarray]], motion: tuple[list[float], list[float], float]
) -> None:
    euler, shift, s = motion
    for mech, configurations in cases.values():
        if mech.planar:  # a planar mechanism may only turn about z and move in its plane
            R, t = Rotation.from_euler("z", euler[0]).as_matrix(), np.array([shift[0], shift[1], 0.0])
        else:
            R, t = Rotation.from_euler("xyz", euler).as_matrix(), np.array(shift)
        other = moved(mech, R, t, s)
        for angles in configurations:
            np.testing.assert_allclose(
                sigma(other, scaled_angles(mech, angles, s)), sigma(mech, angles), rtol=1e-9, atol=1e-12
            )


def test_the_raw_ratio_depends_on_frame_and_unit_the_normalised_one_does_not() -> None:
    # The case: one Bennett linkage, then moved 10 units, turned and scaled by 10.
    mech = lw.load("bennett")
    other = moved(
        mech, Rotation.from_euler("xyz", [0.3, 1.0, -0.5]).as_matrix(), np.array([10.0, 0, 0]), 10.0
    )
    trace = lw.trace(mech, until=("A", math.radians(150.0)))
    moved_trace = replace(trace, mechanism=other)
    assert moved_trace.max_condition == pytest.approx(trace.max_condition, rel=1e-9)
    raw = [max(robustness_ratio(raw_sigma(m, a), 3) for a in trace.angles) for m in (mech, other)]
    assert raw[0] == pytest.approx(trace.max_condition_raw, rel=1e-9)
    assert raw[1] > 2.0 * raw[0]  # the raw criterion changes by a large factor
    assert trace.max_condition_raw == pytest.approx(np.nanmax(trace.condition_raw()), rel=1e-15)


def test_sliding_hinge_points_along_their_lines(cases: dict[str, tuple[Mechanism, np.ndarray]]) -> None:
    rng = np.random.default_rng(5)
    mech, configurations = cases["bennett"]
    lines = []
    for xi in mech.twists:
        w, v = xi[:3], xi[3:]
        lines.append((np.cross(w, v), w))
    slid = [line_twist(p + rng.uniform(-50, 50) * w, w) for p, w in lines]
    other = replace(mech, twists=np.array(slid))
    c0, L0 = hinge_centre(mech.twists, mech.joint_types)
    c1, L1 = hinge_centre(other.twists, other.joint_types)
    np.testing.assert_allclose(c1, c0, atol=1e-9)
    assert L1 == pytest.approx(L0, rel=1e-9)
    for angles in configurations:
        np.testing.assert_allclose(sigma(other, angles), sigma(mech, angles), rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize(("name", "shift"), [("hedgepeth-rods", 1), ("hedgepeth-rods", 2), ("goldberg", 3)])
def test_relabelling_a_loop_fixes_another_body_and_keeps_the_values(
    cases: dict[str, tuple[Mechanism, np.ndarray]], name: str, shift: int
) -> None:
    mech, configurations = cases[name]
    n = mech.n_joints
    order = np.roll(np.arange(n), -shift)
    for reverse in (False, True):
        idx = order[::-1] if reverse else order
        twists = -mech.twists[idx] if reverse else mech.twists[idx]
        groups = [[f"J{k}" for k in range(n) if idx[k] in members] for members in mech.group_members()]
        other = Mechanism.single_loop(
            "relabelled", [f"J{k}" for k in range(n)], twists, offsets=mech.offsets[idx]
        ).with_couplings([g for g in groups if len(g) > 1])
        for angles in configurations[1:]:
            np.testing.assert_allclose(sigma(other, angles[idx]), sigma(mech, angles), rtol=1e-9, atol=1e-12)
    # The raw values do change: the base body is another one away from the start (the symmetric hoop's
    # bodies are alike, the Goldberg loop's are not).
    assert name != "goldberg" or not np.allclose(
        raw_sigma(other, configurations[-1][idx]), raw_sigma(mech, configurations[-1])
    )


def test_another_cycle_basis_gives_the_same_values(cases: dict[str, tuple[Mechanism, np.ndarray]]) -> None:
    """Watt's chain with its loops A-B-C-D and D-E-F-G, or with A-B-C-D and the outer loop A-B-C-E-F-G."""
    mech, configurations = cases["watt"]
    d = mech.index("D")
    kept = [j for j in range(mech.n_joints) if j != d]
    [outer], _ = cycle_basis([mech.joint_bodies[j] for j in kept])
    outer_loop = Loop(tuple(kept[j] for j in outer.joints), outer.signs)
    first = next(lp for lp in mech.loops if {mech.joint_names[j] for j in lp.joints} == set("ABCD"))
    other = replace(mech, loops=(first, outer_loop))
    assert {frozenset(lp.joints) for lp in other.loops} != {frozenset(lp.joints) for lp in mech.loops}
    for angles in configurations:
        assert np.linalg.norm(closure_residual(other, other.q_from_angles(angles))) < 1e-9
        np.testing.assert_allclose(sigma(other, angles), sigma(mech, angles), rtol=1e-9, atol=1e-12)
    assert not np.allclose(raw_sigma(other, configurations[-1]), raw_sigma(mech, configurations[-1]))


# ------------------------------------------------------------------------------------------------------------
# closed forms
def test_hinge_centre_of_two_skew_lines_and_of_parallel_lines() -> None:
    # The x-axis and a y-direction line through (0, 0, 2): nearest point (0, 0, 1), one unit from each.
    skew = np.array([line_twist([0, 0, 0], [1, 0, 0]), line_twist([0, 0, 2], [0, 1, 0])])
    c, L = hinge_centre(skew, ["R", "R"])
    np.testing.assert_allclose(c, [0, 0, 1], atol=1e-12)
    assert L == pytest.approx(1.0, rel=1e-12)
    # Four z-parallel lines at the corners of a 2 x 4 rectangle centred at (3, 1): RMS distance sqrt(5).
    corners = [(2, -1, 7), (4, -1, 7), (4, 3, -2), (2, 3, 0)]
    parallel = np.array([line_twist(p, [0, 0, 1]) for p in corners])
    c, L = hinge_centre(parallel, ["R"] * 4)
    np.testing.assert_allclose(c[:2], [3, 1], atol=1e-12)
    assert L == pytest.approx(math.sqrt(5.0), rel=1e-12)
    # Concurrent lines (a spherical linkage): centre at the common point, scale 1 (every moment is zero).
    rng = np.random.default_rng(3)
    spherical = np.array([line_twist([1, 2, 3], rng.standard_normal(3)) for _ in range(4)])
    c, L = hinge_centre(spherical, ["R"] * 4)
    np.testing.assert_allclose(c, [1, 2, 3], atol=1e-9)
    assert L == 1.0


def test_length_scale_of_a_planar_four_bar_is_the_rms_pivot_distance() -> None:
    mech = load_spec(SPECS / "four-bar.toml").mechanism
    points = np.array([np.cross(xi[:3], xi[3:])[:2] for xi in mech.twists])
    expected = math.sqrt(np.mean(np.sum((points - points.mean(axis=0)) ** 2, axis=1)))
    assert length_scale(mech) == pytest.approx(expected, rel=1e-12)


def test_cycle_metric_of_a_single_loop_and_of_the_watt_chain() -> None:
    mech = lw.load("bennett")
    np.testing.assert_allclose(cycle_metric(mech), [[1 / math.sqrt(4)]], rtol=1e-12)
    watt = load_spec(SPECS / "watt-six-bar.toml").mechanism
    W = cycle_metric(watt)
    Z = np.zeros((2, 7))
    for k, loop in enumerate(watt.loops):
        Z[k, list(loop.joints)] = loop.signs
    np.testing.assert_allclose(W @ Z @ Z.T @ W.T, np.eye(2), atol=1e-12)
