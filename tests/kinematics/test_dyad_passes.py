"""The closed form's passes over all points against computations outside them: the closure Jacobian and residual
(built from the poses' relative rotations) against :mod:`linkwork.kinematics.closure` at the reported joint
values (numpy's sine and cosine), the joint values against the poses, and the first failing point of a path (a
joint limit, a dyad without a solution) where an independent reading of the rows puts it."""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from closed_form_probe import kernel_rows

import linkwork as lw
from linkwork.kinematics import dyad_solver
from linkwork.kinematics.closure import closure_residual, jacobian
from linkwork.kinematics.mechanism import Mechanism

WATT = Path(__file__).resolve().parents[2] / "examples" / "specs" / "watt-six-bar.toml"


@pytest.fixture(autouse=True)
def compiled(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("LINKWORK_JIT", "compiled")


def kernel_call(
    mech: Mechanism, turn: float, steps: int, max_step: float | None = None
) -> tuple[tuple[Any, ...], tuple[Any, ...]]:
    """``(arguments, outputs)`` of the closed-form kernel on a paper-mode trace of ``turn`` radians of joint A
    (``max_step``: see ``closed_form_probe.kernel_rows``)."""
    return kernel_rows(mech, ("A", float(mech.offsets[mech.index("A")] + turn)), steps, max_step)


def passes(args: tuple[Any, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The positions and closure passes of the kernel on its own arguments: ``(poses, q, jac, res)``."""
    flat, plan, run = args
    joint_int, joint_geo, dyads, modes, head, _offsets = plan
    settings = run[0]
    steps = int(settings[dyad_solver.S_STEPS])
    K = steps + 1
    # the drive's values as the kernel steps them: a running sum, the target last
    drive_q = np.concatenate([[0.0], np.cumsum(np.full(steps - 1, settings[dyad_solver.S_STEP]))])
    drive_q = np.append(drive_q, settings[dyad_solver.S_TARGET])
    poses = np.zeros((head[2], 4, K))
    poses[:, 0] = 1.0
    status = np.zeros(K, dtype=np.int64)
    dyad_solver.place_driver(joint_int, joint_geo, head, drive_q, poses)
    dyad_solver.place_dyads(
        joint_int, joint_geo, dyads, modes, poses, settings[dyad_solver.S_MIN_MARGIN], status
    )
    assert not status.any()
    n, m, E = joint_int.shape[0], run[1].shape[0], 3 * (flat[3].shape[0] - 1)
    rel, q, jump = np.empty((n, 2, K)), np.empty((n, K)), np.zeros(K)
    carry = (np.zeros(n), np.zeros(n), np.zeros(K))  # the start: every joint at 0, no turns
    dyad_solver.joint_values(joint_int, joint_geo, poses, head[0], drive_q, rel, q, jump, carry)
    jac, res = np.empty((E, m, K)), np.empty(K)
    dyad_solver.planar_closure(flat, rel, q, jac, res, (np.empty((4, K)), np.empty(K), np.empty(K)))
    return poses, q, jac, res


CASES = {
    "four-bar": lambda: lw.load("four-bar"),
    "slider-crank": lambda: lw.load("slider-crank", offset=0.3),
    "watt": lambda: lw.load(str(WATT)),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_jacobian_and_residual_from_poses_equal_the_closure_at_the_reported_values(name: str) -> None:
    """The closure pass reads each revolute joint's cosine and sine from the bodies' poses, not from its value:
    its Jacobian equals :func:`~linkwork.kinematics.closure.jacobian` at the reported values (numpy's sin/cos)
    to 1e-13 of its size, and its residual norm that of :func:`~linkwork.kinematics.closure.closure_residual`
    to 1e-13 (both at round-off). Over 350 degrees of the crank (short of the closed path), in more points than
    two of the kernel's blocks: its rows equal these passes over the whole path exactly."""
    mech = CASES[name]()
    steps = 2 * dyad_solver.BLOCK + 7
    args, (count, status, out_angles, _sigma, out_res, *_rest) = kernel_call(mech, np.radians(350.0), steps)
    assert status == dyad_solver.CLEAN and count == steps + 1
    _poses, q, jac, res = passes(args)
    # the rows are these joint values, plus the reference offsets (numpy's sum)
    assert np.array_equal(q[:, :count].T + mech.offsets, out_angles[:count])
    assert np.array_equal(res, out_res)
    for k in range(0, count, 5):
        angles = q[:, k]
        reference = jacobian(mech, angles)
        assert np.max(np.abs(jac[:, :, k] - reference)) < 1e-13 * max(1.0, np.max(np.abs(reference))), k
        independent = float(np.linalg.norm(closure_residual(mech, angles)))
        assert independent < 1e-13 and abs(res[k] - independent) < 1e-13, k


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_full_rank_verdict_is_the_quick_rank_test_of_the_rows(name: str) -> None:
    """The kernel's last output (every row of full rank) is numpy's quick test :func:`all_full_rank` of its own
    singular values (every ratio above ``loose``, strictly): True with the default ``loose``, and either side of
    the path's smallest ratio, where it turns False at that ratio itself (the comparison is strict); the rows
    themselves do not depend on ``loose``."""
    from linkwork.kinematics.rank import Tolerances, all_full_rank

    mech = CASES[name]()
    args, out = kernel_call(mech, np.radians(300.0), 300)
    assert out[1] == dyad_solver.CLEAN and bool(out[-1])
    sigma = out[3]
    smallest = float(np.min(sigma.min(axis=1) / sigma[:, 0]))
    flat, plan, (settings, *rest) = args
    for loose, expected in (
        (1e-5, True),
        (np.nextafter(smallest, 0.0), True),
        (smallest, False),
        (0.5, False),
    ):
        tol = Tolerances(floor=min(1e-10, loose), loose=loose)
        assert all_full_rank(sigma, tol) == expected, loose
        changed = settings.copy()
        changed[dyad_solver.S_LOOSE] = loose
        again = dyad_solver.closed_form_path(flat, plan, (changed, *rest))
        assert bool(again[-1]) == expected, loose
        assert again[:2] == out[:2]
        assert all(np.array_equal(a, b) for a, b in zip(again[2:-1], out[2:-1], strict=True))


def test_joint_values_match_the_poses_and_continue_through_turns() -> None:
    """Every revolute joint's value turns its before body's pose into its after body's (to 1e-14), and successive
    values differ by less than the wrapped step (no spurious 2 pi jumps) over 350 degrees of the crank, in which
    the crank-coupler angle crosses +-180 degrees."""
    mech = lw.load("four-bar")
    args, (count, status, *_rest) = kernel_call(mech, np.radians(350.0), 350)
    assert count == 351
    assert status == dyad_solver.CLEAN
    poses, q, _jac, _res = passes(args)
    joint_int, joint_geo = args[1][0], args[1][1]
    for j in range(joint_int.shape[0]):
        a, b = joint_int[j, 1], joint_int[j, 2]
        turn = joint_geo[j, 2] * q[j]
        c = np.cos(turn) * poses[a, 0] - np.sin(turn) * poses[a, 1]  # R_a Rz(omega q)
        s = np.sin(turn) * poses[a, 0] + np.cos(turn) * poses[a, 1]
        assert np.max(np.hypot(c - poses[b, 0], s - poses[b, 1])) < 1e-14
        assert np.max(np.abs(np.diff(q[j]))) < 0.1
    assert abs(q[0, -1] - np.radians(350.0)) < 1e-12
    assert np.ptp(q[mech.index("B")]) > np.pi  # the angle read in [-pi, pi] was continued across the cut


def test_a_joint_limit_ends_the_path_at_the_first_row_beyond_it() -> None:
    """With an upper limit on the rocker's joint D inside its range, the kernel stops with LIMIT at exactly the
    first row whose D exceeds it (read from the unlimited run's rows)."""
    mech = lw.load("four-bar")
    args, (count, status, angles, *_rest) = kernel_call(mech, np.radians(300.0), 300)
    assert status == dyad_solver.CLEAN
    d = mech.index("D")
    g = args[0][4][d]
    u = passes(args)[1][
        d
    ]  # the joint's displacements as the kernel computes them (its rows: offsets + these)
    assert np.array_equal(u + mech.offsets[d], angles[:count, d])
    limit = 0.5 * (u.max() + u.min())
    settings, t0, lo, hi, periodic = args[2]
    hi = hi.copy()
    hi[g] = limit
    out = dyad_solver.closed_form_path(args[0], args[1], (settings, t0, lo, hi, periodic))
    expected = int(np.argmax(u > limit))
    assert expected > 0
    assert out[:2] == (expected, dyad_solver.LIMIT)
    np.testing.assert_array_equal(out[2][:expected], angles[:expected])


def test_a_dyad_without_a_solution_ends_the_path_at_the_first_such_row() -> None:
    """A double rocker driven past its fold: the kernel stops at the first row where the coupler and rocker
    cannot reach (distance from B to D above their sum, computed here) or hands over just before, near the fold
    (within its margin)."""
    mech = lw.load("four-bar", ground=2.0, crank=1.8, coupler=1.0, rocker=1.7, theta=np.radians(60.0))
    args, (count, status, *_rest) = kernel_call(mech, np.radians(150.0), 150)
    assert status in (dyad_solver.NO_SOLUTION, dyad_solver.NEAR_SINGULAR)
    settings = args[2][0]
    crank_angle = np.radians(60.0) + np.arange(151) * settings[dyad_solver.S_STEP]
    b = 1.8 * np.stack([np.cos(crank_angle), np.sin(crank_angle)], axis=1)
    reach = np.linalg.norm(b - np.array([2.0, 0.0]), axis=1)
    first = int(np.argmax(reach > 1.0 + 1.7))
    assert first > 0 and count <= first
    if status == dyad_solver.NO_SOLUTION:
        assert count == first


def test_a_path_back_at_its_start_ends_closed_where_the_march_would_see_it() -> None:
    """Two turns of a four-bar's crank in 1-degree steps: the kernel stops with CLOSED at the first row (not the
    last) whose distance from the start (angles wrapped, numpy's reading here) is below 1.5 steps after the path
    went farther than 4 maximum steps; that row is stored, the ones before are the path."""
    mech = lw.load("four-bar")
    args, (count, status, angles, *_rest) = kernel_call(mech, np.radians(720.0), 720)
    assert status == dyad_solver.CLOSED
    settings, periodic = args[2][0], args[2][4]
    h, hmax = settings[dyad_solver.S_STEP], settings[dyad_solver.S_HMAX]
    q = passes(args)[1][:, : count + 1]  # the kernel's displacements (its rows: offsets + these)
    assert np.array_equal(q.T + mech.offsets, angles[: count + 1])
    rows = mech.u_from_q(q.T)
    rows[:, periodic] = (rows[:, periodic] + np.pi) % (2.0 * np.pi) - np.pi
    distance = np.linalg.norm(rows, axis=1)
    far = np.maximum.accumulate(distance)
    closed = [k for k in range(1, count + 1) if far[k] > 4.0 * hmax and distance[k] < 1.5 * abs(h)]
    assert closed and closed[0] == count
    assert 350 < count <= 360  # about one turn


def test_a_drive_step_over_a_quarter_turn_ends_the_path_at_once() -> None:
    """Three steps for a full turn (120 degrees each, with max_step 120 degrees: the kernel is given the three
    steps): the march reads a jump of more than 90 degrees at the first step, so the kernel returns row 0 only,
    with JUMP (the tracer then decides)."""
    mech = lw.load("four-bar")
    args, (count, status, *_rest) = kernel_call(mech, np.radians(360.0), 3, max_step=np.radians(120.0))
    assert (count, status) == (1, dyad_solver.JUMP)
    assert abs(args[2][0][dyad_solver.S_STEP]) > 0.5 * np.pi


def slotted_lever() -> Mechanism:
    """A crank and slotted lever: crank A, a block pinned to it at B sliding in a slot of the lever (P, its line
    through the lever's pivot D at 10 degrees off the line D-B, so B is off it), the lever pivoted on the ground at D:
    an RPR dyad on the crank."""
    b = np.array([np.cos(np.radians(60.0)), np.sin(np.radians(60.0))])
    d = np.array([0.2, -2.0])
    toward = (b - d) / np.linalg.norm(b - d)
    turn = np.radians(10.0)
    slot = (
        np.cos(turn) * toward[0] - np.sin(turn) * toward[1],
        np.sin(turn) * toward[0] + np.cos(turn) * toward[1],
    )
    z = (0.0, 0.0, 1.0)
    joints = [
        {"name": "A", "bodies": ("ground", "crank"), "point": (0.0, 0.0), "direction": z},
        {"name": "B", "bodies": ("crank", "block"), "point": b, "direction": z},
        {"name": "S", "type": "P", "bodies": ("block", "lever"), "point": d, "direction": (*slot, 0.0)},
        {"name": "D", "bodies": ("lever", "ground"), "point": d, "direction": z},
    ]
    return Mechanism.from_joints("slotted lever", joints, planar=True)


def cross_slides() -> Mechanism:
    """A PRP dyad on a crank: a block sliding along x on the ground, pinned at P to a second block that slides
    along a line fixed in the crank (through P, along y at the start)."""
    z = (0.0, 0.0, 1.0)
    p = (1.5, 0.8)
    joints = [
        {"name": "A", "bodies": ("ground", "crank"), "point": (0.0, 0.0), "direction": z},
        {"name": "G", "type": "P", "bodies": ("ground", "runner"), "point": p, "direction": (1.0, 0.0, 0.0)},
        {"name": "P", "bodies": ("runner", "follower"), "point": p, "direction": z},
        {"name": "F", "type": "P", "bodies": ("follower", "crank"), "point": p, "direction": (0.0, 1.0, 0.0)},
    ]
    return Mechanism.from_joints("cross slides", joints, planar=True)


@pytest.mark.parametrize(
    ("build", "kind", "turn", "steps"), [(slotted_lever, "RPR", 300.0, 300), (cross_slides, "PRP", 60.0, 120)]
)
def test_rpr_and_prp_dyads_equal_the_predictor_corrector(
    build: Any, kind: str, turn: float, steps: int
) -> None:
    """The two dyad kinds no built-in has: the closed form takes the path (each dyad one vectorised loop), its
    rows equal the predictor-corrector's (angles and slides to 1e-10, singular values to 1e-12 of the largest),
    and it closes to round-off."""
    from linkwork.kinematics import tracer
    from linkwork.kinematics.dyads import dyad_plan

    mech = build()
    plan = dyad_plan(mech, mech.index("A"))
    assert plan is not None and len(plan.dyads) == 1
    kinds = "".join("RP"[plan.joint_int[j, 0]] for j in plan.dyads[0][:3])
    assert kinds == kind
    until = ("A", float(np.radians(turn)))
    _args, (count, status, *_rest) = kernel_call(mech, np.radians(turn), steps)
    assert (count, status) == (steps + 1, dyad_solver.CLEAN)
    fast = lw.trace(mech, until=until, steps=steps)
    original = tracer.closed_form_rows
    try:
        tracer.closed_form_rows = lambda *args, **kwargs: None  # type: ignore[assignment]
        general = lw.trace(mech, until=until, steps=steps)
    finally:
        tracer.closed_form_rows = original
    assert fast.angles.shape == general.angles.shape
    assert np.max(np.abs(fast.angles - general.angles)) < 1e-10
    assert np.max(np.abs(fast.sigma - general.sigma)) < 1e-12 * float(np.max(general.sigma))
    assert np.all(fast.residual < 1e-13)


def test_a_drive_step_of_whole_turns_is_no_jump() -> None:
    """One step of two whole turns brings every body back where it was: the march reads the drive's step wrapped
    (0), so the kernel reaches the target (2 rows) with the crank's value 720 degrees and every other joint at 0
    (max_step 720 degrees: the kernel is given the one step)."""
    mech = lw.load("four-bar")
    _args, (count, status, angles, *_rest) = kernel_call(
        mech, np.radians(720.0), 1, max_step=np.radians(720.0)
    )
    assert (count, status) == (2, dyad_solver.CLEAN)
    q = angles[1] - mech.offsets
    a = mech.index("A")
    assert abs(q[a] - np.radians(720.0)) < 1e-12
    assert np.max(np.abs(np.delete(q, a))) < 1e-12


def block_inputs(args: tuple[Any, ...]) -> tuple[np.ndarray, np.ndarray]:
    """``(rel, q)`` of every point of the kernel's path (as :func:`passes` computes them)."""
    _flat, plan, run = args
    joint_int, joint_geo, dyads, modes, head, _offsets = plan
    settings = run[0]
    steps = int(settings[dyad_solver.S_STEPS])
    drive_q = np.append(np.arange(steps) * settings[dyad_solver.S_STEP], settings[dyad_solver.S_TARGET])
    K, n = steps + 1, joint_int.shape[0]
    poses = np.zeros((head[2], 4, K))
    poses[:, 0] = 1.0
    status = np.zeros(K, dtype=np.int64)
    dyad_solver.place_driver(joint_int, joint_geo, head, drive_q, poses)
    dyad_solver.place_dyads(
        joint_int, joint_geo, dyads, modes, poses, settings[dyad_solver.S_MIN_MARGIN], status
    )
    rel, q = np.empty((n, 2, K)), np.empty((n, K))
    carry = (np.zeros(n), np.zeros(n), np.zeros(K))
    dyad_solver.joint_values(joint_int, joint_geo, poses, head[0], drive_q, rel, q, np.zeros(K), carry)
    return rel, q


def random_four_bars(count: int, seed: int) -> list[Mechanism]:
    """Grashof crank-rockers of random proportions (the crank the shortest link, with a margin), open and
    crossed, at a random start angle."""
    from linkwork.linkages.four_bar import four_bar

    rng = np.random.default_rng(seed)
    out: list[Mechanism] = []
    while len(out) < count:
        crank, coupler, rocker, ground = 0.3 + rng.random(), *(1.5 + 2.0 * rng.random(3))
        if crank + max(coupler, rocker, ground) > sum(sorted((coupler, rocker, ground))[:2]) - 0.1:
            continue  # not Grashof with a margin
        theta = float(2.0 * np.pi * rng.random())
        out.append(four_bar(ground, crank, coupler, rocker, theta, bool(len(out) % 2)))
    return out


@pytest.mark.parametrize("jit", ["compiled", "python"])
def test_closure_columns_on_a_reused_jacobian_equal_the_full_closure(jit: str) -> None:
    """The kernel writes the Jacobian's constant entries (each loop's omega_z row, the structural zeros) once a
    path and only the loop columns' v rows at each block (``closure_constants``, ``closure_columns``): on every
    built-in planar linkage, the two dyad kinds no built-in has (prismatic columns) and random four-bars, blocks
    computed one after another in one array equal :func:`planar_closure` on each block alone, bit for bit, also
    when the block before held other points (nothing of one block leaks into the next); compiled and as the
    plain-Python twins."""
    from linkwork.kinematics.jit import python_twin

    kernels: Any = dyad_solver
    if jit == "python":
        kernels = python_twin(
            {
                name: getattr(dyad_solver, name)
                for name in ("planar_closure", "closure_constants", "closure_columns")
            }
        )
    mechanisms = [CASES[name]() for name in sorted(CASES)] + [slotted_lever(), cross_slides()]
    mechanisms += random_four_bars(4, seed=11)
    for mech in mechanisms:
        args, (count, status, *_rest) = kernel_call(mech, np.radians(60.0), 30)
        assert (count, status) == (31, dyad_solver.CLEAN), mech.name
        flat = args[0]
        rel, q = block_inputs(args)
        E, m, K = 3 * (flat[3].shape[0] - 1), args[2][1].shape[0], q.shape[1]
        scratch = (np.empty((4, K)), np.empty(K), np.empty(K))
        jac = np.full((E, m, K), np.nan)
        fresh = np.empty(flat[1].shape[0], dtype=np.bool_)
        kernels.closure_constants(flat, jac, fresh)
        res = np.empty(K)
        other = (rel[:, :, ::-1].copy(), q[:, ::-1].copy())  # the block before: other points
        kernels.closure_columns(flat, *other, jac, res, scratch, fresh)
        kernels.closure_columns(flat, rel, q, jac, res, scratch, fresh)
        full, full_res = np.full((E, m, K), np.nan), np.empty(K)
        kernels.planar_closure(flat, rel, q, full, full_res, scratch)
        assert np.array_equal(jac, full) and np.array_equal(res, full_res), mech.name
        assert np.array_equal(np.signbit(jac), np.signbit(full)), mech.name  # zeros' signs too


def test_block_width_shares_the_steps_evenly_in_whole_groups_of_lanes() -> None:
    """Every path of 1 to 5,000 steps is covered by the fewest blocks of at most ``BLOCK`` points, each a whole
    number of the rows' lanes (so that each lane continues its own points from block to block), and the columns
    past the last point number fewer than a group of lanes a block (a last block of a few points no longer costs a
    whole block)."""
    from linkwork.kinematics.bidiagonal_rows import LANES

    width = getattr(dyad_solver.block_width, "py_func", dyad_solver.block_width)
    for steps in range(1, 5001):
        w = width(steps)
        blocks = -(-steps // w)
        assert w % LANES == 0 and LANES <= w <= dyad_solver.BLOCK, steps
        assert blocks == -(-steps // dyad_solver.BLOCK), steps
        assert blocks * w - steps < LANES * blocks, steps


@pytest.mark.parametrize("steps", [3600, 2 * 256 + 3, 100])
def test_watt_rows_equal_numpy_whatever_the_blocks(steps: int) -> None:
    """The closed form's rows of the Watt six-bar over 350 degrees of the crank in ``steps`` steps (15 blocks of
    240 points, 3 of 176; 100 steps are solved in 200, longer than the longest step, one block of 208) are numpy's
    singular values of the closure Jacobian at each row's joint values, to 1e-13 of sigma_1."""
    mech = lw.load(str(WATT))
    _args, (count, status, angles, sigma, *_rest) = kernel_call(mech, np.radians(350.0), steps)
    assert status == dyad_solver.CLEAN and count in (steps + 1, 2 * steps + 1)
    J = np.stack([jacobian(mech, a - mech.offsets) for a in angles[:count]])
    reference = np.linalg.svd(J, compute_uv=False)
    assert np.max(np.abs(sigma[:count] - reference) / reference[:, :1]) < 1e-13


@pytest.mark.parametrize("C", [17, 113, 241, 257])
def test_block_arrays_are_disjoint_and_start_apart_within_a_page(C: int) -> None:
    """The block arrays carved from one buffer (``carve_buffer``, ``carve``) lie inside it, overlap nowhere, and
    start at distinct places within a 4 KiB page (22 places, ``STAGGER`` doubles apart), the first half a page
    from the rows' state, whatever the sizes: no two of them are a multiple of 4 KiB apart at their starts."""
    carve_buffer = getattr(dyad_solver.carve_buffer, "py_func", dyad_solver.carve_buffer)
    carve = getattr(dyad_solver.carve, "py_func", dyad_solver.carve)
    page = dyad_solver.PAGE
    state = np.empty(1000)
    sizes = getattr(dyad_solver.block_sizes, "py_func", dyad_solver.block_sizes)(C, 6, 7, 7, 6)
    assert len(sizes) == 22
    buffer, base = carve_buffer(sizes, state)
    origin = buffer.ctypes.data
    assert ((origin + 8 * base) - state.ctypes.data) % (8 * page) == 8 * (page // 2)
    at, spans, starts = base, [], set()
    for index, size in enumerate(sizes):
        part, at = carve(buffer, at, base, index, size)
        begin = (part.ctypes.data - origin) // 8
        assert part.shape == (size,) and np.shares_memory(part, buffer)
        spans.append((begin, begin + size))
        starts.add((begin - base) % page)
    assert len(starts) == len(sizes)
    spans.sort()
    assert all(a[1] <= b[0] for a, b in itertools.pairwise(spans)) and spans[-1][1] <= len(buffer)
