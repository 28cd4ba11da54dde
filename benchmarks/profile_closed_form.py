"""Where the closed-form planar kernel's time goes, pass by pass, with the rows (``planar_rows``) set aside.

For a planar linkage (the Watt II six-bar of ``examples/specs`` by default; the four-bar and slider-crank
built-ins too) the arguments ``lw.trace`` passes to ``dyad_solver.closed_form_path`` for one full turn of the crank
in ``--positions`` equal steps are recorded, and:

- **whole path**: ``closed_form_path`` as it runs, and a copy of it whose rows pass replays rows computed
  beforehand (the same values, so the same checks pass and the path runs to its end): the copy's time is the
  kernel without the rows (plus the replay's copying, timed on its own and printed). With ``--against REV``, the
  same replayed copy of git revision ``REV``'s ``dyad_solver.py`` is timed in alternation with this tree's
  (an A/B of the non-rows kernel in one process), and both copies' rows are checked to be bit-identical.
- **per pass**: each pass of one block of :data:`~linkwork.kinematics.dyad_solver.BLOCK` points in the middle
  of the path, repeated over the same block data inside a compiled loop (no dispatch; ``error_model="numpy"``
  as in the kernel, into which the passes are inlined), in ns a point.

Best of ``--repeats`` rounds, all variants in alternation in each round; the load average is printed (timings on a
loaded machine are only indicative). Run ``linkwork compile`` first after editing a kernel.

Run: ``python benchmarks/profile_closed_form.py`` (``--linkage``, ``--positions``, ``--repeats``, ``--against``).
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import re
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from ab_closed_form import call_for, kernel_arguments, same_rows
from threads import single_threaded

from linkwork.kinematics import dyad_solver
from linkwork.kinematics.planar_rows import multi_loop_rows, multi_loop_state, one_loop_rows

ROOT = Path(__file__).resolve().parent.parent
SOURCE = "src/linkwork/kinematics/dyad_solver.py"
WATT = ROOT / "examples" / "specs" / "watt-six-bar.toml"
LINKAGES = {"watt-six-bar": str(WATT), "four-bar": "four-bar", "slider-crank": "slider-crank"}
ROWS_CALL = re.compile(r"(one_loop_rows|multi_loop_rows)\(\s*jac,\s*sigma,\s*tangent,\s*raw_tau[^)]*\)")
REPLAY = '''

@numba.njit(error_model="numpy")
def replay_rows(sigma, tangent, raw_tau, first):
    """The rows of the block starting at point ``first``, from the recorded ones (a copy, no computation)."""
    E, m = sigma.shape[0], tangent.shape[0]
    begin = 0 if first == 1 else 1
    K, shift = sigma.shape[1], first - 1
    for e in range(E):
        sigma[e, begin:] = REPLAY_SIGMA[e, shift + begin : shift + K]
    for a in range(m):
        tangent[a, begin:] = REPLAY_TANGENT[a, shift + begin : shift + K]
    raw_tau[begin:] = REPLAY_TAU[shift + begin : shift + K]
    return 0


@numba.njit(error_model="numpy")
def replay_all(sigma, tangent, raw_tau, points, block):
    """Every block's replay (the copying alone, as the path's blocks do it)."""
    for first in range(1, points, block):
        replay_rows(sigma, tangent, raw_tau, first)
'''


def replayed_copy(text: str, folder: Path, tag: str, rows: tuple[np.ndarray, ...]) -> ModuleType:
    """``dyad_solver``'s source ``text`` compiled with plain ``numba.njit``, its rows call replaced by a replay of
    ``rows = (sigma (E, P), tangent (m, P), raw_tau (P,))`` (read as compile-time constants)."""
    text = text.replace(
        "from linkwork.kernel_cache import kernel\n",
        "import numba\n\n\ndef kernel(**options):\n    return numba.njit(**options)\n\n",
    )
    text, count = ROWS_CALL.subn("replay_rows(sigma, tangent, raw_tau, first)", text)
    if count == 0:
        raise SystemExit("no rows call found to replay in dyad_solver.py")
    path = folder / f"dyad_solver_{tag}.py"
    path.write_text(text + REPLAY)
    spec = importlib.util.spec_from_file_location(f"dyad_solver_{tag}", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.REPLAY_SIGMA, module.REPLAY_TANGENT, module.REPLAY_TAU = rows
    return module


class Block:
    """The block arrays of ``closed_form_path`` (column 0 the point before, columns 1 .. BLOCK the block's
    points), filled block by block as the kernel fills them, with the rows of every point kept."""

    def __init__(self, call: tuple[Any, ...]) -> None:
        self.flat, self.plan, self.run = call
        joint_int, head = self.plan[0], self.plan[4]
        settings, t0 = self.run[0], self.run[1]
        n, m, E = joint_int.shape[0], t0.shape[0], 3 * (self.flat[3].shape[0] - 1)
        C = dyad_solver.BLOCK + 1
        self.n, self.m, self.E, self.C = n, m, E, C
        self.steps = int(settings[dyad_solver.S_STEPS])
        self.drive_q = np.zeros(C)
        self.poses = np.zeros((head[2], 4, C))
        self.poses[:, 0, :] = 1.0
        self.status = np.zeros(C, dtype=np.int64)
        self.rel, self.q, self.jump = np.empty((n, 2, C)), np.empty((n, C)), np.zeros(C)
        self.carry = (np.zeros(n), np.zeros(n), np.zeros(C))
        self.scratch = (np.empty((4, C)), np.empty(C), np.empty(C))
        self.jac, self.res = np.empty((E, m, C)), np.empty(C)
        self.sigma, self.tangent, self.raw_tau = np.empty((E, C)), np.empty((m, C)), np.empty(C)
        self.measures = tuple(np.zeros(C) for _ in range(4))
        self.svd_state = multi_loop_state(E)
        self.first = 1

    def positions(self, first: int) -> None:
        """The drive's values, the poses and the joints of the block from point ``first`` (the kernel's sums)."""
        settings = self.run[0]
        h, target = settings[dyad_solver.S_STEP], settings[dyad_solver.S_TARGET]
        value = self.drive_q[0]
        for i in range(1, self.C):
            value = target if first - 1 + i == self.steps else value + h
            self.drive_q[i] = value
        joint_int, joint_geo, dyads, modes, head = self.plan[:5]
        self.status[:] = 0
        self.jump[:] = 0.0
        dyad_solver.place_driver(joint_int, joint_geo, head, self.drive_q, self.poses)
        margin = settings[dyad_solver.S_MIN_MARGIN]
        dyad_solver.place_dyads(joint_int, joint_geo, dyads, modes, self.poses, margin, self.status)
        dyad_solver.joint_values(
            joint_int, joint_geo, self.poses, head[0], self.drive_q, self.rel, self.q, self.jump, self.carry
        )

    def rows(self, first: int) -> None:
        """The closure and the rows of the block (the rows of column 0 carried, as the kernel does)."""
        dyad_solver.planar_closure(self.flat, self.rel, self.q, self.jac, self.res, self.scratch)
        if self.E == 3 and self.m == 4:
            one_loop_rows(self.jac, self.sigma, self.tangent, self.raw_tau)
        else:
            multi_loop_rows(
                self.jac, self.sigma, self.tangent, self.raw_tau, 0 if first == 1 else 1, self.svd_state
            )
        bounds = (self.run[2], self.run[3], self.run[4])
        dyad_solver.path_measures(self.q, self.flat[4], self.tangent, self.run[1], bounds, self.measures)

    def next_block(self) -> None:
        """The block's last column becomes the next block's column 0."""
        B = dyad_solver.BLOCK
        self.poses[:, :, 0] = self.poses[:, :, B]
        self.drive_q[0] = self.drive_q[B]
        self.carry[0][:] = self.q[:, B]
        for x in (self.sigma, self.tangent):
            x[:, 0] = x[:, B]
        self.raw_tau[0] = self.raw_tau[B]


def recorded_rows(call: tuple[Any, ...]) -> tuple[tuple[np.ndarray, ...], Block, int]:
    """Every point's rows ``(sigma, tangent, raw_tau)`` along the path (as the kernel's blocks compute them), and
    the block state of the middle block (its first point)."""
    block = Block(call)
    B, P = dyad_solver.BLOCK, block.steps + dyad_solver.BLOCK + 1
    sigma, tangent, raw_tau = np.zeros((block.E, P)), np.zeros((block.m, P)), np.zeros(P)
    middle = 1 + B * max(0, (block.steps // B) // 2 - 1)
    saved: Block | None = None
    for first in range(1, block.steps + 1, B):
        if first == middle:
            saved = Block(call)
            saved.__dict__.update({k: _copied(v) for k, v in block.__dict__.items()})
        block.positions(first)
        block.rows(first)
        sigma[:, first - 1 : first + B] = block.sigma
        tangent[:, first - 1 : first + B] = block.tangent
        raw_tau[first - 1 : first + B] = block.raw_tau
        block.next_block()
    assert saved is not None
    saved.positions(middle)
    saved.rows(middle)
    saved.first = middle
    return (sigma, tangent, raw_tau), saved, middle


def _copied(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.copy()
    if isinstance(value, tuple) and all(isinstance(x, np.ndarray) for x in value):
        return tuple(x.copy() for x in value)
    return value


@numba.njit(error_model="numpy")
def _repeat_driver(R, joint_int, joint_geo, head, drive_q, poses):  # type: ignore[no-untyped-def]
    for _ in range(R):
        dyad_solver.place_driver(joint_int, joint_geo, head, drive_q, poses)


@numba.njit(error_model="numpy")
def _repeat_dyads(R, joint_int, joint_geo, dyads, modes, poses, margin, status):  # type: ignore[no-untyped-def]
    for _ in range(R):
        dyad_solver.place_dyads(joint_int, joint_geo, dyads, modes, poses, margin, status)


@numba.njit(error_model="numpy")
def _repeat_joints(R, joint_int, joint_geo, poses, drive, drive_q, rel, q, jump, carry):  # type: ignore[no-untyped-def]
    start = carry[0].copy()
    total = carry[1].copy()
    for _ in range(R):
        carry[0][:] = start
        carry[1][:] = total
        dyad_solver.joint_values(joint_int, joint_geo, poses, drive, drive_q, rel, q, jump, carry)


@numba.njit(error_model="numpy")
def _repeat_closure(R, flat, rel, q, jac, res, scratch):  # type: ignore[no-untyped-def]
    fresh = np.empty(flat[1].shape[0], dtype=np.bool_)
    dyad_solver.closure_constants(flat, jac, fresh)
    for _ in range(R):
        dyad_solver.closure_columns(flat, rel, q, jac, res, scratch, fresh)


@numba.njit(error_model="numpy")
def _repeat_measures(R, q, groups, tangent, t0, bounds, measures):  # type: ignore[no-untyped-def]
    for _ in range(R):
        dyad_solver.path_measures(q, groups, tangent, t0, bounds, measures)


@numba.njit(error_model="numpy")
def _repeat_drive_values(R, drive_q, first, steps, h, target):  # type: ignore[no-untyped-def]
    for _ in range(R):
        dyad_solver.drive_values(drive_q, first, steps, h, target)


@numba.njit(error_model="numpy")
def _repeat_first_failure(R, status, jump, size):  # type: ignore[no-untyped-def]
    for _ in range(R):
        status[:] = 0
        jump[:] = 0.0
        dyad_solver.first_failure(status, jump, size)


@numba.njit(error_model="numpy")
def _repeat_checks(R, rows, orient, status, span, g_drive, h, limits):  # type: ignore[no-untyped-def]
    for _ in range(R):
        dyad_solver.check_points(rows, orient, status, span, g_drive, h, limits, 0)


@numba.njit(error_model="numpy")
def _repeat_scan(R, status, measures, out_s, span, far, hmax):  # type: ignore[no-untyped-def]
    for _ in range(R):
        dyad_solver.scan_points(status, measures, out_s, span, far, hmax, 0)


@numba.njit(error_model="numpy")
def _repeat_store(R, block, offsets, outs, first, begin, end, loose):  # type: ignore[no-untyped-def]
    for _ in range(R):
        dyad_solver.store_rows(block, offsets, outs, first, begin, end, loose)


@numba.njit(error_model="numpy")
def _repeat_multi_rows(R, jac, sigma, tangent, raw_tau, state):  # type: ignore[no-untyped-def]
    for _ in range(R):
        multi_loop_rows(jac, sigma, tangent, raw_tau, 1, state)


@numba.njit(error_model="numpy")
def _repeat_one_rows(R, jac, sigma, tangent, raw_tau):  # type: ignore[no-untyped-def]
    for _ in range(R):
        one_loop_rows(jac, sigma, tangent, raw_tau)


def pass_timers(block: Block) -> dict[str, Callable[[int], None]]:
    """Each pass of the block, as ``run(R)``: the pass ``R`` times over the same block data."""
    b = block
    joint_int, joint_geo, dyads, modes, head, offsets = b.plan
    settings, t0, lo, hi, periodic = b.run
    margin = settings[dyad_solver.S_MIN_MARGIN]
    status = b.status.copy()
    timers: dict[str, Callable[[int], None]] = {
        "driver": lambda R: _repeat_driver(R, joint_int, joint_geo, head, b.drive_q.copy(), b.poses.copy()),
        "dyads": lambda R: _repeat_dyads(
            R, joint_int, joint_geo, dyads, modes, b.poses.copy(), margin, status
        ),
        "joint values": lambda R: _repeat_joints(
            R,
            joint_int,
            joint_geo,
            b.poses,
            head[0],
            b.drive_q,
            b.rel.copy(),
            b.q.copy(),
            b.jump.copy(),
            tuple(x.copy() for x in b.carry),
        ),
        "closure": lambda R: _repeat_closure(R, b.flat, b.rel, b.q, b.jac.copy(), b.res.copy(), b.scratch),
        "measures": lambda R: _repeat_measures(
            R, b.q, b.flat[4], b.tangent, t0, (lo, hi, periodic), tuple(np.zeros(b.C) for _ in range(4))
        ),
    }
    h, steps = settings[dyad_solver.S_STEP], b.steps
    first, B, C = b.first, dyad_solver.BLOCK, b.C
    span = (first, 1, B, steps)
    limits = (settings[dyad_solver.S_MIN_RATIO], settings[dyad_solver.S_MIN_DRIVE], 1.5 * abs(h), 1.0, 1.0)
    orient = (np.ones(C), b.raw_tau.copy(), np.zeros(C, dtype=np.int64))
    rows = (b.sigma, b.tangent, b.raw_tau, b.measures)
    checked = np.zeros(C, dtype=np.int64)
    dyad_solver.check_points(rows, orient, checked, span, b.flat[4][head[0]], h, limits, 0)
    outs = (np.empty((steps + 1, b.n)), np.empty((steps + 1, b.E)), *(np.empty(steps + 1) for _ in range(3)))
    timers["drive values"] = lambda R: _repeat_drive_values(
        R, b.drive_q.copy(), first, steps, h, settings[dyad_solver.S_TARGET]
    )
    timers["first failure"] = lambda R: _repeat_first_failure(R, status.copy(), b.jump.copy(), B)
    timers["checks"] = lambda R: _repeat_checks(
        R, rows, orient, np.zeros(C, dtype=np.int64), span, b.flat[4][head[0]], h, limits
    )
    timers["scan"] = lambda R: _repeat_scan(R, checked, b.measures, outs[4], span, 1e9, 1e-3)
    timers["store rows"] = lambda R: _repeat_store(
        R, (b.q, b.sigma, b.res, orient[1]), offsets, outs, first, 1, B + 1, settings[dyad_solver.S_LOOSE]
    )
    if b.E == 3 and b.m == 4:
        timers["(rows)"] = lambda R: _repeat_one_rows(
            R, b.jac, b.sigma.copy(), b.tangent.copy(), b.raw_tau.copy()
        )
    else:
        timers["(rows)"] = lambda R: _repeat_multi_rows(
            R, b.jac, b.sigma.copy(), b.tangent.copy(), b.raw_tau.copy(), b.svd_state.copy()
        )
    return timers


def source_at(rev: str) -> str:
    """``dyad_solver.py`` at git revision ``rev`` (``.``: this tree's file)."""
    if rev == ".":
        return (ROOT / SOURCE).read_text()
    return subprocess.run(
        ["git", "show", f"{rev}:{SOURCE}"], cwd=ROOT, check=True, capture_output=True, text=True
    ).stdout


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--linkage", choices=sorted(LINKAGES), default="watt-six-bar")
    parser.add_argument("--positions", type=int, default=3600)
    parser.add_argument("--repeats", type=int, default=30, help="rounds (best of)")
    parser.add_argument("--inner", type=int, default=400, help="block passes per timing (per-pass part)")
    parser.add_argument(
        "--against", default=None, help="also time this git revision's kernel (replayed rows)"
    )
    args = parser.parse_args(argv)
    single_threaded()
    call = kernel_arguments(LINKAGES[args.linkage], args.positions)
    rows, block, middle = recorded_rows(call)
    points = int(call[2][0][dyad_solver.S_STEPS]) + 1
    with tempfile.TemporaryDirectory() as folder:
        ours = replayed_copy(source_at("."), Path(folder), "ours", rows)
        variants: dict[str, Callable[[], Any]] = {
            "kernel (cached, with rows)": lambda: dyad_solver.closed_form_path(*call),
            "this tree, rows replayed": lambda: ours.closed_form_path(*call),
        }
        expected = dyad_solver.closed_form_path(*call)
        checks = {"this tree, rows replayed": same_rows(expected, ours.closed_form_path(*call), call)}
        if args.against:
            theirs = replayed_copy(source_at(args.against), Path(folder), "theirs", rows)
            their_call = call_for(theirs, call)
            variants[f"{args.against}, rows replayed"] = lambda: theirs.closed_form_path(*their_call)
            checks[f"{args.against}, rows replayed"] = same_rows(
                expected, theirs.closed_form_path(*their_call), call
            )
        sig, tan, tau = (x.copy() for x in (block.sigma, block.tangent, block.raw_tau))
        variants["(the replay's copying alone)"] = lambda: ours.replay_all(
            sig, tan, tau, points, dyad_solver.BLOCK
        )
        timers = pass_timers(block)
        for run in (*variants.values(), *(lambda t=t: t(1) for t in timers.values())):
            run()  # compile
        best = {name: np.inf for name in (*variants, *timers)}
        for _ in range(args.repeats):
            for name, run in variants.items():
                t0 = time.perf_counter()
                run()
                best[name] = min(best[name], time.perf_counter() - t0)
            for name, timer in timers.items():
                t0 = time.perf_counter()
                timer(args.inner)
                best[name] = min(best[name], (time.perf_counter() - t0) / args.inner)
    print(f"{args.linkage}: {points} points, blocks of {dyad_solver.BLOCK}; load average {os.getloadavg()}")
    print("whole path (ns a point):")
    for name in variants:
        same = "" if name not in checks else ("  rows bit-identical" if checks[name] else "  rows DIFFER")
        print(f"  {name:34s} {best[name] / points * 1e9:8.1f}{same}")
    print(f"per pass, block from point {middle} (ns a point):")
    total = 0.0
    for name in timers:
        value = best[name] / dyad_solver.BLOCK * 1e9
        total += 0.0 if name.startswith("(") else value
        print(f"  {name:34s} {value:8.1f}")
    print(f"  {'sum of the passes above':34s} {total:8.1f}")


if __name__ == "__main__":
    main()
