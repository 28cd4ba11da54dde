"""The Python around the compiled kernels of one ``trace`` call: total time minus the kernels' own time.

For the three planar linkages of ``bench_planar.py`` (the four-bar and slider-crank built-ins, the Watt II six-bar
of ``examples/specs``; one full turn of the crank in ``--positions`` equal steps, the closed-form dyad path) and
the hexagon of ``bench_trace.py`` (Hedgepeth's n = 6 hoop, paper mode, 200 steps, the predictor-corrector), each
call of ``lw.trace`` is timed, and so is every compiled kernel it calls (the closed-form path
``dyad_solver.closed_form_path`` for the planar ones; for the hexagon every kernel of the trace's backend: march,
evaluate, correct, tangent_and_test). The difference is the Python around the kernels: set-up, checks, the
``Trace``. Printed per linkage: the best total, the kernels' time of that call, and the Python overhead (best of
``--repeats`` calls, in microseconds per call and per position). Timings on a loaded machine are only
indicative: run it on a quiet one, single-threaded as here.

Run: ``python benchmarks/profile_trace_call.py`` (``--positions``, ``--repeats``; ``--profile`` prints the top
of a cProfile of the Python per call as well).
"""

from __future__ import annotations

import argparse
import cProfile
import dataclasses
import pstats
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from threads import single_threaded

import linkwork as lw
from linkwork.kinematics import dyad_solver, tracer
from linkwork.kinematics.jit import ENTRY_POINTS, Backend
from linkwork.linkages.hedgepeth import deployed_angle, hedgepeth

ROOT = Path(__file__).resolve().parent
WATT = ROOT.parent / "examples" / "specs" / "watt-six-bar.toml"
HEXAGON_STEPS = 200


class KernelClock:
    """Seconds spent inside the compiled kernels during one call (reset before each)."""

    def __init__(self) -> None:
        self.seconds = 0.0

    def wrap(self, kernel: Callable[..., Any]) -> Callable[..., Any]:
        """``kernel`` with its time added to :attr:`seconds`."""

        def timed(*args: Any) -> Any:
            t0 = time.perf_counter()
            out = kernel(*args)
            self.seconds += time.perf_counter() - t0
            return out

        return timed


def overhead(run: Callable[[], Any], clock: KernelClock, repeats: int) -> tuple[float, float, float]:
    """``(total, kernels, python)`` seconds of the call with the least Python (best of ``repeats``)."""
    best = (np.inf, np.inf, np.inf)
    for _ in range(repeats):
        clock.seconds = 0.0
        t0 = time.perf_counter()
        run()
        total = time.perf_counter() - t0
        if total - clock.seconds < best[2]:
            best = (total, clock.seconds, total - clock.seconds)
    return best


def planar_call(mech: lw.Mechanism, positions: int) -> Callable[[], Any]:
    """One full turn of the crank ``A`` in ``positions`` equal steps."""
    until = ("A", float(mech.offsets[mech.index("A")] + 2.0 * np.pi))
    return lambda: lw.trace(mech, until=until, steps=positions, max_steps=10 * positions)


def hexagon_call() -> Callable[[], Any]:
    """The hexagon of ``bench_trace.py``: n = 6, paper mode, 200 steps."""
    mech = hedgepeth(6, couple=False)
    until = ("A", deployed_angle(6))
    return lambda: lw.trace(mech, until=until, steps=HEXAGON_STEPS)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--positions", type=int, default=3600, help="crank positions per turn (planar)")
    parser.add_argument("--repeats", type=int, default=200)
    parser.add_argument("--profile", action="store_true", help="also print a cProfile of each call")
    args = parser.parse_args(argv)
    single_threaded()
    cases: dict[str, tuple[Callable[[], Any], int]] = {
        "four-bar": (planar_call(lw.load("four-bar"), args.positions), args.positions),
        "slider-crank": (planar_call(lw.load("slider-crank"), args.positions), args.positions),
        "watt-six-bar": (planar_call(lw.load(str(WATT)), args.positions), args.positions),
        "hexagon": (hexagon_call(), HEXAGON_STEPS),
    }
    clock = KernelClock()
    for run, _ in cases.values():
        run()  # compile or load the kernels
    path_kernel = dyad_solver.closed_form_path
    select = tracer.select_backend

    def timed_backend(*a: Any, **k: Any) -> Backend:
        backend = select(*a, **k)
        return dataclasses.replace(
            backend, **{name: clock.wrap(getattr(backend, name)) for name in ENTRY_POINTS}
        )

    print(
        f"{'linkage':14s} {'positions':>9s} {'total us':>10s} {'kernels us':>11s} {'python us':>10s} {'us/pos':>8s}"
    )
    try:
        dyad_solver.closed_form_path = clock.wrap(path_kernel)
        tracer.select_backend = timed_backend
        for name, (run, positions) in cases.items():
            total, kernels, python = overhead(run, clock, args.repeats)
            print(
                f"{name:14s} {positions:9d} {total * 1e6:10.1f} {kernels * 1e6:11.1f} {python * 1e6:10.1f}"
                f" {python / positions * 1e6:8.4f}"
            )
            if args.profile:
                profiler = cProfile.Profile()
                profiler.enable()
                for _ in range(50):
                    run()
                profiler.disable()
                pstats.Stats(profiler).sort_stats("tottime").print_stats(15)
    finally:
        dyad_solver.closed_form_path = path_kernel
        tracer.select_backend = select
    print(
        "python = total - kernels, best of the calls; goal for the planar ones: <= 60 us a call (quiet machine)"
    )


if __name__ == "__main__":
    main()
