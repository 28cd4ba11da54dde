"""Tracing benchmark, paper mode: linkwork's compiled tracer against a plain numpy reading of the paper.

Two measurements, both in the paper's mode of Sec. 5 (200 equal steps of theta_A from the folded bundle to the
deployed angle of Eq. (10), closure tolerance 1e-12, corrector with the drive held):

(a) the Hedgepeth hexagon (n = 6, no couplings): :func:`linkwork.kinematics.tracer.trace` after one warm-up
    call (numba compilation or cache load, timed separately) against :mod:`baseline_paper` (Secs. 4.1-4.2 as
    printed), best and median of several repeats, their ratio (goal: >= 100x) and the largest joint-angle
    difference between the two paths (must be < 1e-8 rad at every step);
(b) time per step of coupled hoops (``A = C = ...``, ``B = D = ...``) for n = 6 ... 1000, with a least-squares
    line and log-log slopes of time per step against n (goal: linear, slope about 1 for large n), and the
    baseline for n up to 50, whose per-step cost grows as n^2 (each Jacobian column is a product of 2n
    matrices, Eq. (18)).

Prints a table and writes ``benchmarks/results/trace.json``.

Run: ``python benchmarks/bench_trace.py`` (``--repeats``, ``--quick`` for a short run).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from baseline_paper import trace_paper
from threads import single_threaded

from linkwork.kinematics.tracer import trace
from linkwork.linkages.hedgepeth import deployed_angle, hedgepeth

STEPS = 200  # Sec. 5: "moved along its kinematic path in 200 steps"
HEXAGON_GOAL = 100.0  # required speed-up of linkwork over the baseline on the hexagon
PATH_TOLERANCE = 1e-8  # radians: the two paths must agree this well at every step
SIZES = (6, 10, 20, 50, 100, 200, 500, 1000)
BASELINE_SIZES = (6, 10, 20, 50)
RESULTS = Path(__file__).resolve().parent / "results" / "trace.json"


def timed(run: Callable[[], Any], repeats: int) -> tuple[list[float], Any]:
    """Wall-clock seconds of ``repeats`` calls of ``run`` and the last call's result."""
    seconds = []
    out = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = run()
        seconds.append(time.perf_counter() - t0)
    return seconds, out


def linkwork_paper_mode(n: int, couple: bool) -> Callable[[], Any]:
    """A call tracing the n-rod hoop in paper mode (the mechanism is built once, outside the timing)."""
    mech = hedgepeth(n, couple=couple)
    until = ("A", deployed_angle(n))
    return lambda: trace(mech, until=until, steps=STEPS)


def machine_info() -> dict[str, Any]:
    """What the numbers were measured on."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            names = [line.split(":", 1)[1].strip() for line in f if line.startswith("model name")]
        cpu = names[0] if names else cpu
    except OSError:
        pass
    return {
        "cpu": cpu,
        "cpu_count": os.cpu_count(),
        "platform": platform.platform(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "numba": numba.__version__,
    }


def hexagon(repeats: int, lw_repeats: int) -> dict[str, Any]:
    """(a) The uncoupled hexagon: warm-up, linkwork and baseline timings, ratio and path difference."""
    run = linkwork_paper_mode(6, couple=False)
    t0 = time.perf_counter()
    run()  # numba compilation (first run ever) or cache load: timed separately, not part of the comparison
    warm_up = time.perf_counter() - t0
    lw_times, lw_path = timed(run, lw_repeats)
    base_times, base_path = timed(lambda: trace_paper(6, couple=False, steps=STEPS), repeats)
    diff = float(np.max(np.abs(lw_path.angles - base_path.angles)))
    return {
        "n": 6,
        "couple": False,
        "steps": STEPS,
        "warm_up_s": warm_up,
        "linkwork_best_s": min(lw_times),
        "linkwork_median_s": statistics.median(lw_times),
        "baseline_best_s": min(base_times),
        "baseline_median_s": statistics.median(base_times),
        "ratio_best": min(base_times) / min(lw_times),
        "ratio_median": statistics.median(base_times) / statistics.median(lw_times),
        "goal_ratio": HEXAGON_GOAL,
        "max_path_difference_rad": diff,
        "path_tolerance_rad": PATH_TOLERANCE,
        "baseline_corrector_iterations": base_path.iterations,
        "linkwork_max_residual": float(lw_path.residual.max()),
        "baseline_max_residual": float(base_path.residual.max()),
    }


def fit(ns: list[int], per_step: list[float]) -> dict[str, float]:
    """Least-squares line ``t = a + b n`` and log-log slopes of time per step against n (all n; n >= 100)."""
    x, y = np.asarray(ns, dtype=float), np.asarray(per_step)
    b, a = np.polyfit(x, y, 1)
    out = {
        "intercept_s": float(a),
        "slope_s_per_rod": float(b),
        "loglog_slope_all": float(np.polyfit(np.log(x), np.log(y), 1)[0]),
    }
    large = x >= 100
    if large.sum() >= 2:
        out["loglog_slope_n_ge_100"] = float(np.polyfit(np.log(x[large]), np.log(y[large]), 1)[0])
        # the per-step cost above the small-n floor (the line's intercept): the part that should grow as n
        above = y[large] - a
        if np.all(above > 0):
            out["loglog_slope_above_intercept"] = float(np.polyfit(np.log(x[large]), np.log(above), 1)[0])
    return out


def scaling(
    repeats: int, lw_repeats: int, sizes: tuple[int, ...], baseline_sizes: tuple[int, ...]
) -> dict[str, Any]:
    """(b) Time per step of coupled hoops, linkwork for every n and the baseline for small n."""
    rows = []
    for n in sizes:
        run = linkwork_paper_mode(n, couple=True)
        run()  # warm-up (the kernels are compiled per argument types, which do not change with n)
        lw_times, lw_path = timed(run, lw_repeats)
        row: dict[str, Any] = {
            "n": n,
            "linkwork_best_s": min(lw_times),
            "linkwork_per_step_s": min(lw_times) / STEPS,
            "linkwork_max_residual": float(lw_path.residual.max()),
        }
        if n in baseline_sizes:
            base_reps = repeats if n <= 20 else 1
            base_times, base_path = timed(partial(trace_paper, n, couple=True, steps=STEPS), base_reps)
            row["baseline_best_s"] = min(base_times)
            row["baseline_per_step_s"] = min(base_times) / STEPS
            row["ratio"] = min(base_times) / min(lw_times)
            row["max_path_difference_rad"] = float(np.max(np.abs(lw_path.angles - base_path.angles)))
        rows.append(row)
    lw_fit = fit([r["n"] for r in rows], [r["linkwork_per_step_s"] for r in rows])
    base_rows = [r for r in rows if "baseline_per_step_s" in r]
    base_fit = {}
    if len(base_rows) >= 2:
        x = np.log([r["n"] for r in base_rows])
        y = np.log([r["baseline_per_step_s"] for r in base_rows])
        base_fit["loglog_slope_all"] = float(np.polyfit(x, y, 1)[0])
        if len(base_rows) >= 3:
            base_fit["loglog_slope_last_two"] = float((y[-1] - y[-2]) / (x[-1] - x[-2]))
    return {"couple": True, "steps": STEPS, "rows": rows, "linkwork_fit": lw_fit, "baseline_fit": base_fit}


def profile_hexagon(calls: int = 20, loops: int = 20000) -> dict[str, float]:
    """Where the hexagon's trace spends its time: per-trace milliseconds and per-call microseconds.

    Splits ``trace`` with cProfile into the compiled ``march`` kernel, ``numerical_rank`` (called once per
    path point in Python) and the rest of the Python wrapper; then times, inside numba, one closure evaluation
    (``closure_jacobian``: residual and Jacobian, Eqs. (21), (23)) and one ``np.linalg.svd`` of the 6x6
    Jacobian (the predictor's null vector and each corrector iteration of Eq. (28)).
    """
    import cProfile
    import pstats

    from numba import njit

    from linkwork.kinematics.march import evaluate
    from linkwork.kinematics.workspace import Workspace

    run = linkwork_paper_mode(6, couple=False)
    run()
    total = min(timed(run, calls)[0])
    prof = cProfile.Profile()
    prof.enable()
    for _ in range(calls):
        run()
    prof.disable()
    stats = pstats.Stats(prof).stats  # type: ignore[attr-defined]
    by_name: dict[str, float] = {}
    for (_file, _line, name), (_cc, _nc, tottime, cumtime, _callers) in stats.items():
        key = {"march": "march", "numerical_rank": "numerical_rank", "trace": "trace"}.get(name)
        if key:
            by_name[key] = by_name.get(key, 0.0) + (tottime if key == "march" else cumtime)
    profiled = by_name.get("trace", float("nan"))

    @njit
    def evaluations(ws: Any, u: np.ndarray, count: int) -> float:  # pragma: no cover - compiled
        acc = 0.0
        for _ in range(count):
            acc += evaluate(ws[0], ws[1], ws[2], ws[3], ws[4], ws[5], u, ws[6], ws[7], ws[8])
        return acc

    @njit
    def svds(A: np.ndarray, count: int) -> float:  # pragma: no cover - compiled
        acc = 0.0
        for _ in range(count):
            acc += np.linalg.svd(A)[1][0]
        return acc

    w = Workspace.of(hedgepeth(6, couple=False))
    ws = (w.twists, w.loop_joint, w.loop_sign, w.loop_ptr, w.rows, w.groups, w.q, w.res, w.jac)
    u = np.full(6, 0.3)
    evaluations(ws, u, 10)
    jac = w.evaluate(u)[2]
    svds(jac, 10)
    eval_us = min(timed(lambda: evaluations(ws, u, loops), 3)[0]) / loops * 1e6
    svd_us = min(timed(lambda: svds(jac, loops), 3)[0]) / loops * 1e6

    # cProfile slows the Python parts: each part's share of the profiled time, applied to the real total.
    def ms(seconds: float) -> float:
        return seconds / profiled * total * 1e3

    march_s, rank_s = by_name.get("march", float("nan")), by_name.get("numerical_rank", float("nan"))
    return {
        "trace_ms": total * 1e3,
        "march_kernel_ms": ms(march_s),
        "numerical_rank_ms": ms(rank_s),
        "python_rest_ms": ms(profiled - march_s - rank_s),
        "closure_jacobian_us": eval_us,
        "svd_6x6_in_numba_us": svd_us,
    }


def report(hex_result: dict[str, Any], scale: dict[str, Any]) -> None:
    """Print both measurements as tables (rich when available)."""
    try:
        from rich.console import Console
        from rich.table import Table
    except ImportError:  # plain text
        Console = None  # type: ignore[assignment,misc]

    h = hex_result
    hex_lines = [
        ("warm-up (compile / cache load)", f"{h['warm_up_s'] * 1e3:.1f} ms"),
        (
            "linkwork best / median",
            f"{h['linkwork_best_s'] * 1e3:.2f} / {h['linkwork_median_s'] * 1e3:.2f} ms",
        ),
        (
            "baseline best / median",
            f"{h['baseline_best_s'] * 1e3:.1f} / {h['baseline_median_s'] * 1e3:.1f} ms",
        ),
        (
            "speed-up best / median",
            f"{h['ratio_best']:.1f}x / {h['ratio_median']:.1f}x (goal >= {HEXAGON_GOAL:.0f}x)",
        ),
        ("max |path difference|", f"{h['max_path_difference_rad']:.2e} rad (must be < {PATH_TOLERANCE:.0e})"),
    ]
    header = ("n", "linkwork us/step", "baseline us/step", "speed-up", "max |diff| rad")
    scale_lines = []
    for r in scale["rows"]:
        scale_lines.append(
            (
                str(r["n"]),
                f"{r['linkwork_per_step_s'] * 1e6:.1f}",
                f"{r['baseline_per_step_s'] * 1e6:.0f}" if "baseline_per_step_s" in r else "-",
                f"{r['ratio']:.0f}x" if "ratio" in r else "-",
                f"{r['max_path_difference_rad']:.1e}" if "max_path_difference_rad" in r else "-",
            )
        )
    f = scale["linkwork_fit"]
    nan = float("nan")
    fit_lines = [
        f"linkwork: t/step = {f['intercept_s'] * 1e6:.1f} us + {f['slope_s_per_rod'] * 1e9:.1f} ns * n",
        f"linkwork: log-log slope {f['loglog_slope_all']:.2f} (all n), "
        f"{f.get('loglog_slope_n_ge_100', nan):.2f} (n >= 100), "
        f"{f.get('loglog_slope_above_intercept', nan):.2f} (n >= 100, time above the intercept)",
    ]
    if scale["baseline_fit"]:
        b = scale["baseline_fit"]
        base_ns = [r["n"] for r in scale["rows"] if "baseline_per_step_s" in r]
        fit_lines.append(
            f"baseline: log-log slope {b['loglog_slope_all']:.2f} (n = {base_ns[0]}..{base_ns[-1]})"
            + (f", {b['loglog_slope_last_two']:.2f} (last two n)" if "loglog_slope_last_two" in b else "")
        )

    if Console is None:
        print(f"(a) Hedgepeth hexagon, n = 6, paper mode, {STEPS} steps")
        for k, v in hex_lines:
            print(f"  {k:34s} {v}")
        print(f"(b) coupled hoops, paper mode, {STEPS} steps")
        print("  " + " | ".join(header))
        for cells in scale_lines:
            print("  " + " | ".join(cells))
        for text in fit_lines:
            print("  " + text)
        return
    console = Console()
    t1 = Table(title=f"(a) Hedgepeth hexagon, n = 6, paper mode, {STEPS} steps")
    t1.add_column("measure")
    t1.add_column("value", justify="right")
    for k, v in hex_lines:
        t1.add_row(k, v)
    console.print(t1)
    t2 = Table(title=f"(b) coupled hoops (A = C = ..., B = D = ...), paper mode, {STEPS} steps")
    for name in header:
        t2.add_column(name, justify="right")
    for cells in scale_lines:
        t2.add_row(*cells)
    console.print(t2)
    for text in fit_lines:
        console.print(text)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--repeats", type=int, default=5, help="timed repeats per case (best and median reported)"
    )
    parser.add_argument(
        "--lw-repeats", type=int, default=20, help="timed repeats of linkwork's trace (cheap)"
    )
    parser.add_argument(
        "--profile", action="store_true", help="also time the pieces of linkwork's hexagon trace"
    )
    parser.add_argument("--quick", action="store_true", help="small sizes only (n <= 100, baseline n <= 20)")
    parser.add_argument("--out", type=Path, default=RESULTS, help="where to write the JSON results")
    args = parser.parse_args(argv)
    single_threaded()
    sizes = tuple(n for n in SIZES if n <= 100) if args.quick else SIZES
    baseline_sizes = tuple(n for n in BASELINE_SIZES if n <= 20) if args.quick else BASELINE_SIZES

    hex_result = hexagon(args.repeats, args.lw_repeats)
    scale = scaling(args.repeats, args.lw_repeats, sizes, baseline_sizes)
    report(hex_result, scale)
    pieces = profile_hexagon() if args.profile else None
    if pieces:
        print("hexagon trace, where the time goes: " + ", ".join(f"{k} {v:.2f}" for k, v in pieces.items()))

    args.out.parent.mkdir(parents=True, exist_ok=True)
    payload = {"machine": machine_info(), "hexagon": hex_result, "scaling": scale, "profile": pieces}
    args.out.write_text(json.dumps(payload, indent=2) + "\n", encoding="utf-8")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
