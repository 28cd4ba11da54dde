"""The closed-form dyad path of planar paper-mode traces: the same rows as the predictor-corrector, positions
against independent circle intersections, singular values against a fresh SVD, and the hand-over near singular
points."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from closed_form_probe import kernel_rows

import linkwork as lw
from linkwork.kinematics import tracer
from linkwork.kinematics.closure import jacobian
from linkwork.kinematics.dyads import dyad_plan
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.trace_result import Trace
from linkwork.linkages.four_bar import four_bar as builtin_four_bar

WATT = Path(__file__).resolve().parents[2] / "examples" / "specs" / "watt-six-bar.toml"
ANGLE_TOL = 1e-12  # radians (lengths for a slider): the predictor-corrector's own closure tolerance


@pytest.fixture(autouse=True)
def compiled(monkeypatch: pytest.MonkeyPatch) -> None:
    """The closed form runs with the compiled kernels (with the plain-Python ones the tracer is used as before)."""
    monkeypatch.setenv("LINKWORK_JIT", "compiled")


def traced_both_ways(mech: Mechanism, until: tuple[str, float], steps: int) -> tuple[Trace, Trace, bool]:
    """``(closed form, predictor-corrector, whether the closed form took the path)`` of one paper-mode trace."""
    original = tracer.closed_form_rows
    taken: list[bool] = []

    def watched(*args: Any, **kwargs: Any) -> Any:
        rows = original(*args, **kwargs)
        taken.append(rows is not None)
        return rows

    try:
        tracer.closed_form_rows = watched  # type: ignore[assignment]
        fast = lw.trace(mech, until=until, steps=steps)
        tracer.closed_form_rows = lambda *args, **kwargs: None  # type: ignore[assignment]
        general = lw.trace(mech, until=until, steps=steps)
    finally:
        tracer.closed_form_rows = original
    return fast, general, bool(taken and taken[-1])  # the last call: the first may be the kernels' warm-up


def assert_same_trace(fast: Trace, general: Trace) -> None:
    """Every reported row and event of two traces agree (angles to ``ANGLE_TOL``)."""
    assert fast.angles.shape == general.angles.shape
    # 1e-12, or the predictor-corrector's own error where its closure residual (below its tolerance 1e-12) over
    # the smallest singular value says it may be larger (a factor 10 for the drive-held Jacobian's conditioning):
    # the closed form closes to round-off, and is checked against independent positions elsewhere.
    allowed = np.maximum(ANGLE_TOL, 10.0 * general.residual / general.sigma[:, -1])
    assert np.all(np.max(np.abs(fast.angles - general.angles), axis=1) < allowed)
    scale = float(np.max(general.sigma))
    assert np.max(np.abs(fast.sigma - general.sigma)) < 1e-12 * scale
    assert np.all(np.sign(fast.test) == np.sign(general.test))
    assert np.max(np.abs(fast.test - general.test)) < 1e-9 * float(np.max(np.abs(general.test)))
    assert np.max(np.abs(fast.arclength - general.arclength)) < 1e-10
    assert np.array_equal(fast.step, general.step) and np.array_equal(fast.rank, general.rank)
    assert np.array_equal(fast.branch, general.branch)
    assert [b.end_reason for b in fast.branches] == [b.end_reason for b in general.branches]
    assert len(fast.bifurcations) == len(general.bifurcations) and len(fast.folds) == len(general.folds)


def four_bar(
    ground: float, crank: float, coupler: float, rocker: float, theta: float, crossed: bool
) -> Mechanism:
    """A four-bar built here (not by the registry): ground pivots A (0, 0) and D (ground, 0), joints at crank
    angle ``theta`` from an independent circle intersection, the joint bodies written in mixed order."""
    b = crank * np.array([np.cos(theta), np.sin(theta)])
    c = circle_intersection(b, coupler, np.array([ground, 0.0]), rocker, -1.0 if crossed else 1.0)
    z = (0.0, 0.0, 1.0)
    joints = [
        {"name": "A", "bodies": ("ground", "crank"), "point": (0.0, 0.0), "direction": z},
        {"name": "B", "bodies": ("coupler", "crank"), "point": b, "direction": z},
        {"name": "C", "bodies": ("coupler", "rocker"), "point": c, "direction": (0.0, 0.0, -1.0)},
        {"name": "D", "bodies": ("rocker", "ground"), "point": (ground, 0.0), "direction": z},
    ]
    return Mechanism.from_joints("four-bar", joints, planar=True)


def circle_intersection(p: np.ndarray, r: float, q: np.ndarray, s: float, side: float) -> np.ndarray:
    """The point at distance ``r`` from ``p`` and ``s`` from ``q`` on the ``side`` (+1 left) of ``p -> q``."""
    d = float(np.linalg.norm(q - p))
    a = (r * r - s * s + d * d) / (2.0 * d)
    h = np.sqrt(r * r - a * a)
    e = (q - p) / d
    return p + a * e + side * h * np.array([-e[1], e[0]])


def generated_four_bars(count: int, seed: int) -> Iterator[tuple[Mechanism, tuple[float, ...], float, bool]]:
    """Grashof crank-rockers (the crank the shortest link) of random proportions, open and crossed: the mechanism,
    its lengths ``(ground, crank, coupler, rocker)``, the start crank angle and the circuit."""
    rng = np.random.default_rng(seed)
    made = 0
    while made < count:
        crank, coupler, rocker, ground = 0.3 + rng.random(), *(1.5 + 2.0 * rng.random(3))
        if crank + max(coupler, rocker, ground) > sum(sorted((coupler, rocker, ground))[:2]) - 0.1:
            continue  # not Grashof with a margin
        crossed, theta = bool(made % 2), float(2.0 * np.pi * rng.random())
        yield (
            four_bar(ground, crank, coupler, rocker, theta, crossed),
            (ground, crank, coupler, rocker),
            theta,
            crossed,
        )
        made += 1


@pytest.mark.parametrize(
    ("name", "params", "drive", "turn_deg", "steps"),
    [
        ("four-bar", {}, "A", 360.0, 360),
        ("four-bar crossed", {"crossed": True, "theta": np.radians(200.0)}, "A", -270.0, 200),
        ("slider-crank", {"offset": 0.4}, "A", 360.0, 180),
        ("slider-crank", {"crank": 1.0, "rod": 3.0, "theta": np.radians(70.0)}, "D", -1.0, 50),
        ("watt", {}, "A", 360.0, 360),
        ("four-bar", {}, "B", 40.0, 80),  # driven between two moving links: the crank is held instead
        ("four-bar", {}, "C", -20.0, 40),
        ("slider-crank", {"offset": 0.3}, "B", 30.0, 60),
    ],
)
def test_planar_builtins_closed_form_equals_predictor_corrector(
    name: str, params: dict[str, Any], drive: str, turn_deg: float, steps: int
) -> None:
    if name == "four-bar crossed":
        mech = builtin_four_bar(**params)  # the registry does not offer the crossed circuit
    else:
        mech = lw.load(str(WATT)) if name == "watt" else lw.load(name, **params)
    j = mech.index(drive)
    turn = np.radians(turn_deg) if mech.joint_types[j] == "R" else turn_deg
    fast, general, taken = traced_both_ways(mech, (drive, float(mech.offsets[j] + turn)), steps)
    assert taken, "the closed form should trace this path"
    assert fast.branches[0].end_reason == "reached target"
    assert np.all(fast.residual < 1e-13)
    assert_same_trace(fast, general)


def test_generated_four_bars_against_circle_intersections_and_fresh_svds() -> None:
    for mech, (ground, crank, coupler, rocker), theta, crossed in generated_four_bars(12, seed=18):
        # Short of a full turn: the tracer ends a path that comes back to its start as closed, before a target.
        fast, general, taken = traced_both_ways(mech, ("A", np.radians(350.0)), 175)
        assert taken
        assert_same_trace(fast, general)
        pivot = np.array([ground, 0.0])
        c0 = np.cross(mech.twists[2, :3], mech.twists[2, 3:])[
            :2
        ]  # C at the start (the point of its hinge line)
        for k, row in enumerate(fast.angles):
            # The independent position of C at this crank angle, and where the rocker's turn puts C: joint D
            # leads from the rocker to the ground, so the rocker turns by -D about D's pivot.
            b = crank * np.array([np.cos(theta + row[0]), np.sin(theta + row[0])])
            c = circle_intersection(b, coupler, pivot, rocker, -1.0 if crossed else 1.0)
            turn = -row[3]
            rotation = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
            assert np.linalg.norm(rotation @ (c0 - pivot) + pivot - c) < 1e-11
            sigma = np.linalg.svd(jacobian(mech, mech.q_from_angles(row)), compute_uv=False)
            assert np.max(np.abs(sigma - fast.sigma[k])) < 1e-12 * sigma[0]


def test_change_point_four_bar_hands_over_at_the_bifurcation() -> None:
    """A parallelogram's path through its crossing: the closed form gives up there and the tracer finds both
    bifurcations exactly as without it."""
    mech = lw.load("four-bar", ground=2.0, crank=1.0, coupler=2.0, rocker=1.0, theta=np.radians(60.0))
    fast, general, taken = traced_both_ways(mech, ("A", np.radians(419.5)), 358)
    assert not taken
    assert_same_trace(fast, general)
    assert len(fast.bifurcations) >= 1


def test_fold_of_a_double_rocker_hands_over() -> None:
    """A non-Grashof four-bar driven past its fold: the tracer reports the turning point as before."""
    mech = lw.load("four-bar", ground=2.0, crank=1.8, coupler=1.0, rocker=1.7, theta=np.radians(60.0))
    fast, general, taken = traced_both_ways(mech, ("A", float(mech.offsets[0] + np.radians(150.0))), 150)
    assert not taken
    assert_same_trace(fast, general)
    assert fast.branches[0].end_reason != "reached target"


def test_only_planar_driver_and_dyads_decompose() -> None:
    assert dyad_plan(lw.load("four-bar"), 0) is not None
    assert dyad_plan(lw.load("bennett"), 0) is None  # spatial
    assert dyad_plan(lw.load("four-bar").with_couplings([["A", "C"]]), 0) is None  # coupled joints
    assert dyad_plan(lw.load(str(WATT)), 0) is not None  # two dyads


def stephenson_six_bar() -> Mechanism:
    """A Stephenson six-bar built here: ternary ground (A, D, G) and ternary coupler (B, C, E), not joined."""
    P = {"A": (0.0, 0.0), "B": (0.8, 1.0), "C": (3.0, 2.2), "D": (3.6, 0.0), "E": (2.0, 3.0), "F": (4.2, 4.0),
         "G": (6.0, 0.5)}  # fmt: skip
    pairs = {"A": ("ground", "crank"), "B": ("crank", "coupler"), "C": ("coupler", "rocker"),
             "D": ("rocker", "ground"), "E": ("coupler", "link5"), "F": ("link5", "link6"), "G": ("link6", "ground")}  # fmt: skip
    joints = [{"name": n, "bodies": pairs[n], "point": P[n], "direction": (0.0, 0.0, 1.0)} for n in P]
    return Mechanism.from_joints("stephenson", joints, planar=True)


def test_stephenson_six_bar_driven_by_its_crank_or_through_a_triad() -> None:
    """Driven at A the rest is two dyads (closed form); driven at G it is a class-III group (no dyad to place
    first): the tracer as before. Both equal the predictor-corrector."""
    mech = stephenson_six_bar()
    assert dyad_plan(mech, mech.index("A")) is not None and dyad_plan(mech, mech.index("G")) is None
    for drive, turn, expect in (("A", 60.0, True), ("G", 10.0, False)):
        fast, general, taken = traced_both_ways(mech, (drive, np.radians(turn)), 60)
        assert taken == expect
        assert_same_trace(fast, general)


NEAR_SINGULAR = {
    # a parallelogram driven towards its change point at 180 deg (sigma_min -> 0 there)
    "change point": (
        dict(ground=2.0, crank=1.0, coupler=2.0, rocker=1.0, theta=np.radians(60.0)),
        179.9,
        1199,
    ),
    # a four-bar next to the change-point condition (ground + coupler = crank + rocker + 0.01)
    "near change point": (
        dict(ground=2.0, crank=1.0, coupler=2.01, rocker=1.0, theta=np.radians(60.0)),
        420.0,
        3600,
    ),
}


@pytest.mark.parametrize("case", sorted(NEAR_SINGULAR))
def test_singular_values_next_to_singular_points_equal_fresh_svds(case: str) -> None:
    """Every row the closed form computes on its way into a singular point of the Jacobian (until it hands over):
    the singular values equal a fresh SVD of the Jacobian at the row's joint values to 1e-12 of the largest, with
    the Jacobi sweeps stopped after a sweep with every cosine below 1e-8 and warm-started by extrapolation."""
    params, target, steps = NEAR_SINGULAR[case]
    mech = lw.load("four-bar", **params)
    _, (count, _status, angles, sigma, res, *_rest) = kernel_rows(mech, ("A", np.radians(target)), steps)
    assert count > 10
    ratios = []
    for k in range(count):
        fresh = np.linalg.svd(jacobian(mech, angles[k] - mech.offsets), compute_uv=False)
        assert np.max(np.abs(fresh - sigma[k])) < 1e-12 * fresh[0], (case, k)
        assert res[k] < 1e-13
        ratios.append(fresh[-1] / fresh[0])
    assert min(ratios) < 0.05  # the rows do come close to the singular point (the hand-over is at 1e-2)


def test_plain_python_twin_of_the_closed_form_gives_the_same_rows() -> None:
    """The kernel's plain-Python twin (numba's py_func, as LINKWORK_JIT=python would run it) and the compiled
    kernel: same status and rows, on a four-bar (one loop: the batched rows) and the Watt six-bar. Joint values,
    residuals and arclengths to 1e-13; singular values and test function to 2e-13 of their largest (the compiled
    one-loop rows contract products into fused multiply-adds, the twin rounds each: both within 1e-13 of the
    exact values, ``planar_rows.one_loop_rows``)."""
    from linkwork.kinematics import dyad_solver
    from linkwork.kinematics.jit import python_twin

    twin = python_twin({"closed_form_path": dyad_solver.closed_form_path}).closed_form_path
    for mech in (lw.load("four-bar"), lw.load(str(WATT))):
        args, out = kernel_rows(mech, ("A", float(mech.offsets[0] + np.radians(40.0))), 40)
        plain = twin(*args)
        assert plain[:2] == out[:2] == (41, 0)
        assert bool(plain[-1]) and bool(out[-1])  # every row of full rank (the kernel's verdict)
        for name, a, b in zip(("angles", "sigma", "res", "tau", "s"), plain[2:-1], out[2:-1], strict=True):
            scale = float(np.max(np.abs(b))) if name in ("sigma", "tau") else 0.5
            np.testing.assert_allclose(a, b, rtol=0.0, atol=2e-13 * scale, err_msg=name)


def test_shared_singular_values_kernel_against_numpy() -> None:
    """``dyad_solver.singular_values`` (the kernel another tracer may share: sizes read from its arguments, cold
    start from the identity) on triangles of 3 and 6 columns: generic, nearly singular (1e-9 of the largest) and
    with two equal values; to 1e-13 of the largest against numpy's SVD."""
    from linkwork.kinematics import dyad_solver

    rng = np.random.default_rng(7)
    for E in (3, 6):
        for kind in ("generic", "nearly singular", "equal pair"):
            U, _ = np.linalg.qr(rng.normal(size=(E, E)))
            Vt, _ = np.linalg.qr(rng.normal(size=(E, E)))
            s = np.sort(rng.uniform(0.5, 3.0, E))[::-1]
            if kind == "nearly singular":
                s[-1] = 1e-9 * s[0]
            elif kind == "equal pair":
                s[1] = s[0]
            R = np.linalg.qr(U @ np.diag(s) @ Vt, mode="r")
            M = np.vstack([R, np.zeros((1, E))])  # a QR's (m, E) array: R on and above the diagonal of M[:E]
            sigma = np.empty(E)
            dyad_solver.singular_values(M, np.empty((E, E)), np.eye(E), sigma)
            assert np.max(np.abs(sigma - np.linalg.svd(R, compute_uv=False))) < 1e-13 * s[0], (E, kind)
