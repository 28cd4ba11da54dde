"""The normalised robustness ratio along a traced path: batched vs one point at a time, and vs the trace itself.

``Trace.condition()`` (report.json ``max_condition``) evaluates the normalised Jacobian at every point of a path.
This prints, for a few built-ins traced with ``branches=True``, the time of the batched
``linkwork.kinematics.normalization.condition_ratios`` against a plain per-point loop over
``normalized_jacobian`` (the baseline) and against the trace, and checks that both give the same ratios.

    python benchmarks/bench_normalization.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import linkwork as lw
from linkwork.kinematics.normalization import condition_ratios, normalized_jacobian, robustness_ratio

CASES = (("hedgepeth-rods", {"n": 6}), ("guest-frame", {}), ("sarrus", {}), ("goldberg", {}))


def per_point(mech: lw.Mechanism, angles: np.ndarray, rank: np.ndarray) -> np.ndarray:
    """The baseline: one normalised Jacobian and one SVD per point."""
    return np.array(
        [
            robustness_ratio(np.linalg.svd(normalized_jacobian(mech, a), compute_uv=False), int(r))
            for a, r in zip(angles, rank, strict=True)
        ]
    )


def best_of(repeats: int, run: object) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()  # type: ignore[operator]
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    print(
        f"{'linkage':<16}{'points':>8}{'trace s':>10}{'batched s':>11}{'per-point s':>13}{'speed-up':>10}{'max diff':>10}"
    )
    for name, params in CASES:
        mech = lw.load(name, **params)
        lw.trace(mech, branches=True)  # warm-up (numba cache load)
        t_trace = best_of(args.repeats, lambda m=mech: lw.trace(m, branches=True))
        path = lw.trace(mech, branches=True)
        batched = condition_ratios(mech, path.angles, path.rank)
        plain = per_point(mech, path.angles, path.rank)
        t_batch = best_of(args.repeats, lambda m=mech, p=path: condition_ratios(m, p.angles, p.rank))
        t_plain = best_of(args.repeats, lambda m=mech, p=path: per_point(m, p.angles, p.rank))
        finite = np.isfinite(plain)
        diff = float(np.max(np.abs(batched[finite] - plain[finite]) / plain[finite])) if finite.any() else 0.0
        print(
            f"{name:<16}{len(path.angles):>8}{t_trace:>10.3f}{t_batch:>11.4f}{t_plain:>13.4f}"
            f"{t_plain / t_batch:>9.1f}x{diff:>10.1e}"
        )


if __name__ == "__main__":
    main()
