"""Planar benchmark: linkwork's closed-form dyad path against pylinkage's compiled ``step_fast`` per crank position.

For each planar linkage (the four-bar and slider-crank built-ins, the Watt II six-bar of ``examples/specs``) one
full turn of the crank in ``--positions`` equal steps is computed three ways, single-threaded, after a warm-up:

- **linkwork** ``trace(mech, until=(crank, start + 360 deg), steps=N)``: the closed-form dyad solver
  (:mod:`linkwork.kinematics.dyads`), with the singular values, test function and residual at every position;
- **predictor-corrector** the same call with the closed form switched off (the general tracer: the plain
  baseline of this benchmark);
- **pylinkage** ``Linkage.step_fast(N)`` on the same linkage built from pylinkage's ``Crank`` / ``RRRDyad`` /
  ``RRPDyad`` (positions only, no Jacobian).

Printed per linkage: microseconds per crank position (best of ``--repeats``; linkwork and pylinkage timed in
alternation, round after round, in one process), of which linkwork's compiled kernel (the rest is the Python
around it: set-up and the Trace), the ratios linkwork / pylinkage (goal <= 1) and predictor-corrector / linkwork,
and the largest distance between the joint positions both programs computed (an outside check of the closed form).
Timings on a loaded machine are only indicative: run it on a quiet one. Writes ``benchmarks/results/planar.json``.

Run: ``python benchmarks/bench_planar.py`` (``--positions``, ``--repeats``, ``--out``); needs ``pip install
pylinkage`` (the ``bench`` extra).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from threads import single_threaded

import linkwork as lw
from linkwork.kinematics import dyad_solver, tracer
from linkwork.kinematics.closure import body_poses
from linkwork.kinematics.mechanism import Mechanism

ROOT = Path(__file__).resolve().parent
RESULTS = ROOT / "results" / "planar.json"
WATT = ROOT.parent / "examples" / "specs" / "watt-six-bar.toml"


def best_of(run: Callable[[], Any], repeats: int) -> tuple[float, Any]:
    """Best wall time of ``repeats`` calls and the last result."""
    best, out = np.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = run()
        best = min(best, time.perf_counter() - t0)
    return best, out


def joint_points(mech: Mechanism, angles: np.ndarray, joints: list[str]) -> np.ndarray:
    """``(K, len(joints), 2)`` positions of the named revolute joints along a trace (their pivot on the body
    after them, placed by the body poses)."""
    out = np.empty((len(angles), len(joints), 2))
    for k, row in enumerate(angles):
        poses = body_poses(mech, angles=row)
        for i, name in enumerate(joints):
            j = mech.index(name)
            w, v = mech.twists[j, :3], mech.twists[j, 3:]
            point = np.append(np.cross(w, v)[:2], 0.0)  # the hinge line's point nearest the origin
            after = mech.joint_bodies[j][1]
            out[k, i] = (poses[after] @ np.append(point, 1.0))[:2]
    return out


def pylinkage_model(name: str, mech: Mechanism, positions: int) -> tuple[Any, list[str]]:
    """The same linkage in pylinkage, its crank turning by one step per iteration, and the linkwork joints whose
    positions its outputs follow (in order)."""
    import pylinkage as pl

    def point(joint: str) -> np.ndarray:
        j = mech.index(joint)
        return np.cross(mech.twists[j, :3], mech.twists[j, 3:])[:2]

    step = 2.0 * np.pi / positions
    a = point("A")
    ground_a = pl.Ground(*a)
    b = point("B")
    crank = pl.Crank(
        ground_a, radius=float(np.hypot(*(b - a))), angular_velocity=step,
        initial_angle=float(np.arctan2(*(b - a)[::-1])),
    )  # fmt: skip
    if name == "slider-crank":
        c = point("C")
        guide_a, guide_b = pl.Ground(0.0, float(c[1])), pl.Ground(1.0, float(c[1]))
        slider = pl.RRPDyad(crank, guide_a, guide_b, distance=float(np.hypot(*(c - b))), x=c[0], y=c[1])
        return pl.Linkage([ground_a, guide_a, guide_b, crank, slider]), ["B", "C"]
    c, d = point("C"), point("D")
    ground_d = pl.Ground(*d)
    rocker = pl.RRRDyad(
        crank,
        ground_d,
        distance1=float(np.hypot(*(c - b))),
        distance2=float(np.hypot(*(c - d))),
        x=c[0],
        y=c[1],
    )
    if name == "four-bar":
        return pl.Linkage([ground_a, ground_d, crank, rocker]), ["B", "C"]
    e, f, g = point("E"), point("F"), point("G")
    # E is a point of the ternary rocker (C, D, E): a dyad on C and D with E's distances to them.
    e_pt = pl.RRRDyad(
        rocker,
        ground_d,
        distance1=float(np.hypot(*(e - c))),
        distance2=float(np.hypot(*(e - d))),
        x=e[0],
        y=e[1],
    )
    ground_g = pl.Ground(*g)
    f_pt = pl.RRRDyad(
        e_pt,
        ground_g,
        distance1=float(np.hypot(*(f - e))),
        distance2=float(np.hypot(*(f - g))),
        x=f[0],
        y=f[1],
    )
    return pl.Linkage([ground_a, ground_d, ground_g, crank, rocker, e_pt, f_pt]), ["B", "C", "E", "F"]


def bench_one(name: str, mech: Mechanism, positions: int, repeats: int) -> dict[str, Any]:
    """One linkage: linkwork closed form, the predictor-corrector, pylinkage; per-position costs and ratios.

    linkwork and pylinkage are timed in alternation, round after round in this process (best of ``repeats``
    each), so that a load that comes and goes on the machine hits both alike; the compiled kernel's own time
    inside linkwork's call is recorded too (the rest is the Python around it: set-up, the Trace)."""
    crank = mech.index("A")
    until = ("A", float(mech.offsets[crank] + 2.0 * np.pi))
    limit = 10 * positions

    def run() -> Any:
        return lw.trace(mech, until=until, steps=positions, max_steps=limit)

    run()  # compile or load the kernels
    closed_form = tracer.closed_form_rows
    kernel = dyad_solver.closed_form_path
    taken: list[bool] = []
    kernel_seconds: list[float] = []

    def watched(*args: Any, **kwargs: Any) -> Any:
        rows = closed_form(*args, **kwargs)
        taken.append(rows is not None)
        return rows

    def timed_kernel(*args: Any) -> Any:
        t0 = time.perf_counter()
        out = kernel(*args)
        kernel_seconds.append(time.perf_counter() - t0)
        return out

    try:
        tracer.closed_form_rows = lambda *args, **kwargs: None  # the general predictor-corrector
        run()
        t_pc, path_pc = best_of(run, max(1, repeats // 4))
        tracer.closed_form_rows = watched
        dyad_solver.closed_form_path = timed_kernel
        path = run()
        model: Any = None
        try:
            model, joints = pylinkage_model(name, mech, positions)
        except ImportError:
            pass
        t_lw = t_pl = np.inf
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if model is not None:
                model.step_fast(positions)  # compile
            for _ in range(repeats):  # alternate: the same load for both
                t0 = time.perf_counter()
                path = run()
                t_lw = min(t_lw, time.perf_counter() - t0)
                if model is not None:
                    t0 = time.perf_counter()
                    model.step_fast(positions)
                    t_pl = min(t_pl, time.perf_counter() - t0)
            if model is not None:  # the positions check on a fresh model's first turn (each call goes on from
                # where the last ended, and pylinkage's crank angle drifts by round-off from turn to turn)
                traj = pylinkage_model(name, mech, positions)[0].step_fast(positions)
    finally:
        tracer.closed_form_rows = closed_form
        dyad_solver.closed_form_path = kernel
    if not all(taken):
        print(f"  note: {name}: the closed form handed this path over to the predictor-corrector")
    row: dict[str, Any] = {
        "positions": positions,
        "linkwork_us_per_position": t_lw / positions * 1e6,
        "linkwork_kernel_us_per_position": min(kernel_seconds) / positions * 1e6,
        "predictor_corrector_us_per_position": t_pc / positions * 1e6,
        "predictor_corrector_over_linkwork": t_pc / t_lw,
        "max_difference_from_predictor_corrector_rad": float(np.max(np.abs(path.angles - path_pc.angles))),
    }
    if model is None:
        row["pylinkage"] = "not installed (pip install pylinkage, or the bench extra)"
        return row
    row["pylinkage_us_per_position"] = t_pl / positions * 1e6
    row["linkwork_over_pylinkage"] = t_lw / t_pl
    row["linkwork_kernel_over_pylinkage"] = min(kernel_seconds) / t_pl
    ours = joint_points(mech, path.angles[1:], joints)
    theirs = _pylinkage_joints(traj, model, joints)
    shift = _best_alignment(ours, theirs)
    row["max_position_difference_from_pylinkage"] = shift
    return row


def _pylinkage_joints(traj: np.ndarray, model: Any, joints: list[str]) -> np.ndarray:
    """pylinkage's trajectory of the moving joints (crank tip, then the dyads' points) in linkwork's order."""
    import pylinkage as pl

    moving = [i for i, c in enumerate(model.components) if not isinstance(c, pl.Ground)]
    return np.asarray(traj)[:, moving[: len(joints)], :]


def _best_alignment(ours: np.ndarray, theirs: np.ndarray) -> float:
    """Largest joint-position distance, pylinkage's iterations matched to linkwork's positions (pylinkage may
    record the state before or after each crank step)."""
    best = np.inf
    for lag in (-1, 0, 1):
        a = ours[max(0, lag) : len(ours) + min(0, lag)]
        b = theirs[max(0, -lag) : len(theirs) + min(0, -lag)]
        k = min(len(a), len(b))
        best = min(best, float(np.max(np.linalg.norm(a[:k] - b[:k], axis=-1))))
    return best


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--positions", type=int, default=3600, help="crank positions per turn")
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args(argv)
    single_threaded()
    cases = {
        "four-bar": lw.load("four-bar"),
        "slider-crank": lw.load("slider-crank"),
        "watt-six-bar": lw.load(str(WATT)),
    }
    report: dict[str, Any] = {"load_before": os.getloadavg(), "threads": "1 (NUMBA_NUM_THREADS, BLAS)"}
    for name, mech in cases.items():
        report[name] = bench_one(name, mech, args.positions, args.repeats)
    report["load_after"] = os.getloadavg()
    print(
        f"{'linkage':14s} {'linkwork':>10s} {'(kernel)':>10s} {'pylinkage':>10s} {'lw/pyl':>8s} {'pred-corr':>10s}"
        f" {'pc/lw':>7s}"
    )
    print(f"{'':14s} {'us/pos':>10s} {'us/pos':>10s} {'us/pos':>10s} {'(<=1)':>8s} {'us/pos':>10s} {'':>7s}")
    for name in cases:
        r = report[name]
        pyl = r.get("pylinkage_us_per_position", float("nan"))
        ratio = r.get("linkwork_over_pylinkage", float("nan"))
        print(
            f"{name:14s} {r['linkwork_us_per_position']:10.3f} {r['linkwork_kernel_us_per_position']:10.3f} "
            f"{pyl:10.3f} {ratio:8.2f} "
            f"{r['predictor_corrector_us_per_position']:10.3f} {r['predictor_corrector_over_linkwork']:7.1f}"
        )
        print(
            f"{'':14s} paths: closed form vs predictor-corrector {r['max_difference_from_predictor_corrector_rad']:.1e}"
            f" rad; joints vs pylinkage {r.get('max_position_difference_from_pylinkage', float('nan')):.1e}"
        )
    print(
        f"load average before {report['load_before']}, after {report['load_after']} (timings need a quiet machine)"
    )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
