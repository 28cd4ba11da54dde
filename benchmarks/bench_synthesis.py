"""Benchmark of shape-change synthesis on a seat-like problem (three profiles of ~125-150 pieces, 5 segments).

Times the full search over every 5-segment design vector with joining (paper and refined searches), and the
segment-matrix search of one design vector with the engine's fits (numba + cache) against the plain-Python,
uncached baseline. Prints a table and writes ``benchmarks/results/bench_synthesis.json``.

Run: ``python benchmarks/bench_synthesis.py``
"""

from __future__ import annotations

import json
import platform
import time
from pathlib import Path

import numpy as np

from linkwork.synthesis import Problem, synthesize
from linkwork.synthesis.segment_fit import SegmentFitter
from linkwork.synthesis.segment_matrix import initial_segment_matrices, search_segment_matrix
from linkwork.synthesis.targets import target_profiles


def seat_profile(pan: float, back: float, lumbar: float, tilt_deg: float, n: int = 400) -> np.ndarray:
    """A seat pan from the knee to the hip, then a backrest with a lumbar bulge (synthetic, seat-like)."""
    t = np.linspace(0.0, 1.0, n)
    seat = np.column_stack([pan * (1.0 - t), 0.4 * np.sin(np.pi * t) + 0.3 * t])
    u = np.linspace(0.0, 1.0, n)[1:]
    ang = np.radians(90.0 + tilt_deg)
    d = np.array([np.cos(ang), np.sin(ang)])
    normal = np.array([-d[1], d[0]])
    rest = seat[-1] + np.outer(u * back, d) + np.outer(lumbar * np.sin(np.pi * u) ** 2 * (1.0 - u), normal)
    return np.vstack([seat, rest])


def seat_problem() -> Problem:
    """Arc lengths about 43, 51, 53 (the paper's seat: 44.42, 51.98, 54.39) with s_d = 0.35."""
    profiles = (
        seat_profile(19.0, 24.0, 2.0, 10.0),
        seat_profile(22.0, 28.5, 2.5, 14.0),
        seat_profile(23.0, 29.5, 3.0, 18.0),
    )
    return Problem(
        profiles=profiles,
        piece_length=0.35,
        min_pieces=5,
        segments=5,
        starts=5,
        merge_below=np.radians(5.0),
        names=("small", "average", "large"),
    )


def time_search(problem: Problem, design: str, *, cached: bool, vectorised: bool) -> tuple[float, float]:
    """Seconds and best E_max of one design vector's segment-matrix search with the given fitter."""
    targets = target_profiles(problem)
    pieces = [t.pieces for t in targets]
    fitter = SegmentFitter(targets, cached=cached, vectorised=vectorised)
    starts = initial_segment_matrices(
        design, pieces, problem.min_pieces, problem.starts, np.random.default_rng(0)
    )
    t0 = time.perf_counter()
    out = search_segment_matrix(
        design, starts, lambda sm: fitter.error_matrix(design, sm), problem.min_pieces
    )
    return time.perf_counter() - t0, float(out.error_matrix.max())


def main() -> None:
    problem = seat_problem()
    synthesize(problem)  # warm-up: load the compiled kernels from numba's cache (or compile them once)
    rows = []
    for search in ("paper", "refined"):
        t0 = time.perf_counter()
        result = synthesize(problem, search=search)  # type: ignore[arg-type]
        seconds = time.perf_counter() - t0
        rows.append(
            {
                "case": f"all 31 design vectors, joined ({search})",
                "seconds": seconds,
                "design": result.design,
                "e_max": result.e_max,
                "joined_e_max": result.joined_e_max,
                "pieces": [t.pieces for t in result.targets],
            }
        )
    design = rows[0]["design"]
    fast, fast_e = time_search(problem, str(design), cached=True, vectorised=True)
    slow, slow_e = time_search(problem, str(design), cached=False, vectorised=False)
    assert abs(fast_e - slow_e) < 1e-12, "engine and baseline disagree"
    rows.append({"case": f"search {design}: engine (numba + cache)", "seconds": fast, "e_max": fast_e})
    rows.append({"case": f"search {design}: plain Python, no cache", "seconds": slow, "e_max": slow_e})
    print(f"{'case':48s} {'seconds':>9s} {'E_max':>9s} {'joined':>9s}")
    for row in rows:
        joined = row.get("joined_e_max")
        print(
            f"{row['case']:48s} {row['seconds']:9.3f} {row['e_max']:9.4f} "
            f"{'' if joined is None else format(joined, '9.4f')}"
        )
    print(f"speed-up over the baseline: {slow / fast:.1f}x")
    out = Path(__file__).parent / "results" / "bench_synthesis.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    report = {
        "machine": {
            "python": platform.python_version(),
            "processor": platform.processor(),
            "system": platform.system(),
        },
        "rows": rows,
        "speedup_over_baseline": slow / fast,
    }
    out.write_text(json.dumps(report, indent=2) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
