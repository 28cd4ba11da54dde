"""Batched rows of one-loop planar Jacobians: nanoseconds a point of ``planar_rows.one_loop_rows``.

The four-bar and slider-crank built-ins are traced through one turn of the crank in ``--points`` equal steps; their
closure Jacobians (``closure.jacobian``, outside the timing) are handed to
:func:`linkwork.kinematics.planar_rows.one_loop_rows` in one call, best of ``--repeats`` calls in-process (goal:
at most 10 ns a point). Gaussian random Jacobians are timed too (about a third of them fall back to the exact
second pass: an upper bound of the cost). Printed per set: ns a point, the points the first pass could not certify
(second pass: the 2x2 compression or the Jacobi SVD), and the largest error of the singular values against numpy's
SVD relative to sigma_1. Timings on a loaded machine are only indicative (the load average is printed): run it on
a quiet one. The Watt II six-bar (``examples/specs/watt-six-bar.toml``, two loops: ``6 x 7`` Jacobians) is timed
with :func:`linkwork.kinematics.planar_rows.multi_loop_rows` (the certified bidiagonal route, goal: at most 100 ns a
point), in the same process beside the Jacobi lanes it replaced (``planar_rows.jacobi_loop_rows``) and the
point-by-point routine before them (``dyad_solver.rows_at_points``), printed with its fall-backs (points the
certification sent to the exact Jacobi SVD) and the largest error of its singular values against numpy's SVD.
Writes ``benchmarks/results/planar_rows.json``.

Run: ``python benchmarks/bench_planar_rows.py`` (``--points``, ``--repeats``, ``--out``).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from threads import single_threaded

import linkwork as lw
from linkwork.kinematics.closure import jacobian
from linkwork.kinematics.dyad_solver import rows_at_points
from linkwork.kinematics.planar_rows import (
    jacobi_loop_rows,
    jacobi_loop_state,
    multi_loop_rows,
    multi_loop_state,
    one_loop_rows,
)

ROOT = Path(__file__).resolve().parent
RESULTS = ROOT / "results" / "planar_rows.json"
WATT = ROOT.parent / "examples" / "specs" / "watt-six-bar.toml"


def turn_jacobians(name: str, points: int) -> np.ndarray:
    """``(points, E, m)`` closure Jacobians of built-in (or spec file) ``name`` along one turn of its crank."""
    mech = lw.load(name)
    a = mech.index("A")
    trace = lw.trace(mech, until=("A", float(mech.offsets[a] + 2.0 * np.pi)), steps=points)
    return np.array([jacobian(mech, q) for q in (trace.angles - mech.offsets)[:points]])


def measure(J: np.ndarray, repeats: int) -> dict[str, float]:
    """Best time of ``repeats`` calls on ``J (K, 3, 4)``, the second-pass points and the largest error."""
    K = J.shape[0]
    jac = np.ascontiguousarray(J.transpose(1, 2, 0))
    sigma, tangent, raw_tau = np.empty((3, K)), np.empty((4, K)), np.empty(K)
    second = one_loop_rows(jac, sigma, tangent, raw_tau)  # compile or load, and the results
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        one_loop_rows(jac, sigma, tangent, raw_tau)
        best = min(best, time.perf_counter() - t0)
    s = np.linalg.svd(J, compute_uv=False)
    error = float(np.max(np.abs(sigma.T - s) / s[:, :1]))
    return {"points": K, "ns_per_point": best / K * 1e9, "second_pass": int(second), "sigma_error": error}


def measure_multi(J: np.ndarray, repeats: int) -> dict[str, float]:
    """Best time of ``repeats`` calls of ``multi_loop_rows`` on ``J (K, E, m)`` (each from a fresh warm start,
    as a path's first block), the fall-backs, the largest error, and the Jacobi lanes' and the point-by-point
    routine's times (the Jacobi lanes' calls alternating with the new route's)."""
    K, E, m = J.shape
    jac = np.ascontiguousarray(J.transpose(1, 2, 0))
    sigma, tangent, raw_tau = np.empty((E, K)), np.empty((m, K)), np.empty(K)
    fallbacks = multi_loop_rows(jac, sigma, tangent, raw_tau, 0, multi_loop_state(E))
    s = np.linalg.svd(J, compute_uv=False)
    error = float(np.max(np.abs(sigma.T - s) / s[:, :1]))
    jacobi_loop_rows(jac, sigma, tangent, raw_tau, 0, jacobi_loop_state(E))  # compile or load
    best, jacobi, before = np.inf, np.inf, np.inf
    for _ in range(repeats):
        state = multi_loop_state(E)
        t0 = time.perf_counter()
        multi_loop_rows(jac, sigma, tangent, raw_tau, 0, state)
        best = min(best, time.perf_counter() - t0)
        state = jacobi_loop_state(E)
        t0 = time.perf_counter()
        jacobi_loop_rows(jac, sigma, tangent, raw_tau, 0, state)
        jacobi = min(jacobi, time.perf_counter() - t0)
    rows_at_points(jac, sigma, tangent, raw_tau, 0, (np.eye(E), np.eye(E), np.eye(E)))  # compile or load
    for _ in range(max(1, repeats // 10)):
        state3 = (np.eye(E), np.eye(E), np.eye(E))
        t0 = time.perf_counter()
        rows_at_points(jac, sigma, tangent, raw_tau, 0, state3)
        before = min(before, time.perf_counter() - t0)
    return {
        "points": K,
        "ns_per_point": best / K * 1e9,
        "jacobi_lanes_ns_per_point": jacobi / K * 1e9,
        "point_by_point_ns_per_point": before / K * 1e9,
        "fall_backs": int(fallbacks),
        "sigma_error": error,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=3600)
    parser.add_argument("--repeats", type=int, default=2000)
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args()
    single_threaded()
    sets = {
        "four-bar": turn_jacobians("four-bar", args.points),
        "slider-crank": turn_jacobians("slider-crank", args.points),
        "random": np.random.default_rng(1).normal(size=(args.points, 3, 4)),
    }
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"one_loop_rows, best of {args.repeats} calls (load average {load:.2f}; goal <= 10 ns a point)")
    results = {}
    for name, J in sets.items():
        r = measure(J, args.repeats)
        results[name] = r
        print(
            f"  {name:13s} {r['ns_per_point']:6.2f} ns a point   second pass {r['second_pass']:5d} of "
            f"{r['points']} ({r['second_pass'] / r['points']:.1%})   sigma error {r['sigma_error']:.1e} sigma_1"
        )
    repeats = max(1, args.repeats // 20)
    print(f"multi_loop_rows, best of {repeats} calls (goal <= 100 ns a point)")
    r = measure_multi(turn_jacobians(str(WATT), args.points), repeats)
    results["watt-six-bar"] = r
    print(
        f"  {'watt-six-bar':13s} {r['ns_per_point']:6.1f} ns a point (Jacobi lanes "
        f"{r['jacobi_lanes_ns_per_point']:.1f}, point by point {r['point_by_point_ns_per_point']:.1f})   "
        f"fall-backs {r['fall_backs']} of {r['points']}   "
        f"sigma error {r['sigma_error']:.1e} sigma_1"
    )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(
        json.dumps({"load_average": load, "repeats": args.repeats, "sets": results}, indent=2)
    )


if __name__ == "__main__":
    main()
