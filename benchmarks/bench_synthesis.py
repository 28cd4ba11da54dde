"""Benchmark of shape-change synthesis.

1. A seat-like problem (three profiles of ~125-150 pieces, 5 segments): the full search over every 5-segment
   design vector with joining (paper and refined searches), and the segment-matrix search of one design vector
   with the engine's fits (numba + cache) against the plain-Python, uncached baseline.
2. The design search on the bundled wing for ``q`` segments (``2^q - 1`` design vectors): the engine (compiled
   segment-matrix search, designs joined in the order of a lower bound on the joined ``E_max`` and pruned when
   the bound cannot beat the best) against the exhaustive search (every design joined) and against the plain
   baseline (the segment-matrix search in Python, every design joined, as linkwork did before). The pruned
   search must choose the same design as the exhaustive one; the script checks it.

Prints tables and writes ``benchmarks/results/bench_synthesis.json``. The machine's load is printed with the
timings (``/proc/loadavg``): timings on a loaded machine are longer in proportion.

Run: ``python benchmarks/bench_synthesis.py`` (wing: pruned for q = 10 and 12, exhaustive and baseline for
q = 10); ``--full`` also runs the exhaustive search and the baseline for q = 12 (several minutes).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import platform
import time
from pathlib import Path
from typing import Any

import numpy as np

from linkwork.data import example
from linkwork.io.problem import load_problem
from linkwork.synthesis import Problem, synthesize
from linkwork.synthesis.search import JoinedDesign, join_design, segment_design
from linkwork.synthesis.segment_fit import SegmentFitter
from linkwork.synthesis.segment_matrix import design_vectors, initial_segment_matrices, search_segment_matrix
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


def load() -> str:
    """The machine's load averages (1, 5, 15 minutes)."""
    return " ".join(f"{v:.2f}" for v in os.getloadavg())


def plain_baseline(problem: Problem) -> tuple[float, str, float]:
    """Seconds, design and joined E_max of the search as it was: Python segment-matrix search, all joined."""
    t0 = time.perf_counter()
    targets = target_profiles(problem)
    fitter = SegmentFitter(targets, compiled=False)
    assert problem.segments is not None
    best: JoinedDesign | None = None
    for design in design_vectors(problem.segments, [t.pieces for t in targets]):
        outcome = join_design(problem, segment_design(problem, design, targets, fitter), targets, fitter)
        if isinstance(outcome, JoinedDesign) and (best is None or outcome.rank_key < best.rank_key):
            best = outcome
    assert best is not None
    return time.perf_counter() - t0, best.design, best.joined_e_max


def wing_rows(pruned_q: list[int], exhaustive_q: list[int]) -> list[dict[str, Any]]:
    """Time the wing's design search: pruned, exhaustive and the plain baseline; check they agree."""
    base = load_problem(example("wing"))
    synthesize(dataclasses.replace(base, segments=3))  # load the compiled kernels
    rows: list[dict[str, Any]] = []
    for q in sorted(set(pruned_q) | set(exhaustive_q)):
        problem = dataclasses.replace(base, segments=q)
        t0, c0 = time.perf_counter(), time.process_time()
        pruned = synthesize(problem)
        seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
        joined = pruned.stats.designs_tried - pruned.stats.pruned - len(pruned.stats.skipped)
        row: dict[str, Any] = {
            "case": f"wing q={q}: {2**q - 1} designs, pruned ({joined} joined)",
            "seconds": seconds,
            "cpu_seconds": cpu,
            "design": pruned.design,
            "e_max": pruned.e_max,
            "joined_e_max": pruned.joined_e_max,
            "load": load(),
        }
        rows.append(row)
        if q not in exhaustive_q:
            continue
        t0, c0 = time.perf_counter(), time.process_time()
        full = synthesize(problem, prune=False)
        rows.append(
            {
                "case": f"wing q={q}: exhaustive (every design joined)",
                "seconds": time.perf_counter() - t0,
                "cpu_seconds": time.process_time() - c0,
                "design": full.design,
                "e_max": full.e_max,
                "joined_e_max": full.joined_e_max,
                "load": load(),
            }
        )
        assert full.design == pruned.design, f"q={q}: pruned chose {pruned.design}, exhaustive {full.design}"
        c0 = time.process_time()
        plain, design, e_max = plain_baseline(problem)
        rows.append(
            {
                "case": f"wing q={q}: plain baseline (Python search, all joined)",
                "seconds": plain,
                "cpu_seconds": time.process_time() - c0,
                "design": design,
                "e_max": None,
                "joined_e_max": e_max,
                "load": load(),
            }
        )
        assert design == pruned.design, f"q={q}: pruned chose {pruned.design}, the baseline {design}"
        row["speedup_over_baseline"] = plain / seconds
        row["cpu_speedup_over_baseline"] = rows[-1]["cpu_seconds"] / cpu
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--full", action="store_true", help="also the exhaustive search and baseline for q = 12"
    )
    args = parser.parse_args()
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
    rows += wing_rows([10, 12], [10, 12] if args.full else [10])
    print(f"load averages {load()} on {os.cpu_count()} cores")
    print(f"{'case':58s} {'seconds':>9s} {'CPU s':>9s} {'design':>13s} {'E_max':>9s} {'joined':>10s}")
    for row in rows:
        joined = row.get("joined_e_max")
        print(
            f"{row['case']:58s} {row['seconds']:9.3f} "
            f"{'' if 'cpu_seconds' not in row else format(row['cpu_seconds'], '9.3f'):>9s} "
            f"{row.get('design', '')!s:>13s} "
            f"{'' if row['e_max'] is None else format(row['e_max'], '9.4f'):>9s} "
            f"{'' if joined is None else format(joined, '10.6f')}"
        )
    print(f"speed-up over the baseline (seat, one design's search): {slow / fast:.1f}x")
    for row in rows:
        if "speedup_over_baseline" in row:
            print(
                f"{row['case']}: {row['speedup_over_baseline']:.1f}x faster than the plain baseline "
                f"({row['cpu_speedup_over_baseline']:.1f}x in CPU time)"
            )
    out = Path(__file__).parent / "results" / "bench_synthesis.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    report = {
        "machine": {
            "python": platform.python_version(),
            "processor": platform.processor(),
            "system": platform.system(),
            "cores": os.cpu_count(),
            "load_averages": load(),
        },
        "rows": rows,
        "speedup_over_baseline": slow / fast,
    }
    out.write_text(json.dumps(report, indent=2) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
