"""What one step of the compiled march costs on the hexagon (``hedgepeth-rods``, n = 6, paper mode, 200 steps).

Prints the best time per trace and per step, then the kernels a step is made of, each timed alone in a compiled
loop (best of ``--repeats``): a closure evaluation (residual and Jacobian, G&P Eqs. (21), (23)), the corrector
from a predicted point one tangent step away (Eq. (28); Gauss-Newton with the drive held, Cholesky on the normal
equations; the march's cubic predictor usually leaves it one iteration), the tangent and test function as the
march runs it (one-sided Jacobi SVD warm-started from the previous point's right singular vectors, along the
trace's own Jacobians; the test function from the singular values and orientations) and, for comparison, the
same from a cold start and numba's ``np.linalg.svd`` of the 6x6 Jacobian (LAPACK ``gesdd``, what the march called
before). It also counts, with the plain-Python twins, how many of each a trace calls.

Run: ``python benchmarks/profile_march.py [--repeats 5]`` (single-threaded, on a quiet machine).
"""

from __future__ import annotations

import argparse
import collections
import os
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import njit

import linkwork as lw
from linkwork.kinematics import jit
from linkwork.kinematics import march as kernels
from linkwork.kinematics.rank import Tolerances
from linkwork.kinematics.workspace import Workspace
from linkwork.linkages.hedgepeth_rods import deployed_angles

STEPS = 200
LOOPS = 20000


@njit
def _evaluations(mech: Any, u: Any, q: Any, res: Any, jac: Any, n: int) -> float:
    acc = 0.0
    for _ in range(n):
        acc += kernels.evaluate(mech, u, q, res, jac)
    return acc


@njit
def _corrections(mech: Any, u0: Any, t: Any, corrector: Any, q: Any, res: Any, jac: Any, n: int) -> float:
    acc = 0.0
    for _ in range(n):
        u = u0 + 0.01 * t  # a predicted point one step along the tangent
        _, iterations, _ = kernels.correct(mech, u, 0, corrector, q, res, jac)
        acc += iterations
    return acc


@njit
def _tangents(jac: Any, t: Any, basis: Any, r_path: int, t_out: Any, sigma: Any, n: int) -> float:
    acc = 0.0
    for _ in range(n):
        acc += kernels.tangent_and_test(jac, t, basis.copy(), r_path, t_out, sigma, np.ones(t.shape[0]))
    return acc


@njit
def _warm_tangents(jacs: Any, t0: Any, basis0: Any, r_path: int, sigma: Any, n: int) -> float:
    """The march's tangent kernel along a trace's Jacobians, warm-started from row to row (per call: one row)."""
    acc = 0.0
    E, m = jacs.shape[1], jacs.shape[2]
    t, t_out = t0.copy(), np.empty(m)
    svd = kernels.svd_work(E, m)
    ones = np.ones(m)
    basis = basis0.copy()
    for i in range(n):
        k = i % jacs.shape[0]
        if k == 0:
            basis[:, :] = basis0
            t[:] = t0
        acc += kernels.tangent_and_test_in(jacs[k], t, basis, r_path, t_out, sigma, svd, ones)
        t[:] = t_out
    return acc


@njit
def _svds(jac: Any, n: int) -> float:
    acc = 0.0
    for _ in range(n):
        _, s, _ = np.linalg.svd(jac)
        acc += s[0]
    return acc


def best_of(call: Callable[[], object], repeats: int, per: int = 1) -> float:
    """Best seconds per unit of ``call`` (``per`` units a call) over ``repeats`` calls."""
    best = np.inf
    for _ in range(repeats):
        begin = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - begin)
    return best / per


def march_share(hexagon: lw.Mechanism, until: tuple[str, float], repeats: int) -> float:
    """Seconds inside the compiled march call(s) of the fastest of ``repeats`` traces."""
    from linkwork.kinematics.marcher import BranchMarcher

    original = BranchMarcher.march_chunk
    spent: list[float] = []

    def timed(self: BranchMarcher, *args: Any, **kwargs: Any) -> Any:
        begin = time.perf_counter()
        out = original(self, *args, **kwargs)
        spent.append(time.perf_counter() - begin)
        return out

    BranchMarcher.march_chunk = timed  # type: ignore[method-assign]
    best, inside = np.inf, np.nan
    try:
        for _ in range(repeats):
            spent.clear()
            begin = time.perf_counter()
            lw.trace(hexagon, until=until, steps=STEPS)
            total = time.perf_counter() - begin
            if total < best:
                best, inside = total, sum(spent)
    finally:
        BranchMarcher.march_chunk = original  # type: ignore[method-assign]
    return float(inside)


def counts(hexagon: lw.Mechanism, until: tuple[str, float]) -> dict[str, int]:
    """Calls of each kernel in one trace, counted on the plain-Python twins (the same statements)."""
    twin = jit.python_backend()
    found: collections.Counter[str] = collections.Counter()
    scopes = {"march": twin.march.__globals__}
    scopes["correct_in"] = scopes["march"]["correct_in"].__globals__
    patched = []
    for scope, name in (
        ("march", "correct_in"),
        ("march", "tangent_and_test_in"),
        ("correct_in", "evaluate_in"),
    ):
        original = scopes[scope][name]

        def counted(*args: Any, _fn: Any = original, _name: str = name) -> Any:
            found[_name] += 1
            return _fn(*args)

        scopes[scope][name] = counted
        patched.append((scope, name, original))
    previous = os.environ.get("LINKWORK_JIT")
    os.environ["LINKWORK_JIT"] = "python"
    try:
        lw.trace(hexagon, until=until, steps=STEPS)
    finally:
        for scope, name, original in patched:
            scopes[scope][name] = original
        if previous is None:
            os.environ.pop("LINKWORK_JIT")
        else:
            os.environ["LINKWORK_JIT"] = previous
    return dict(found)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    hexagon = lw.load("hedgepeth-rods", n=6)
    until = ("A", float(deployed_angles(6)[0]))
    lw.trace(hexagon, until=until, steps=STEPS)  # compiled (or loaded) before timing
    trace_s = best_of(lambda: lw.trace(hexagon, until=until, steps=STEPS), 20 * args.repeats)
    march_s = march_share(hexagon, until, 20 * args.repeats)
    ws = Workspace.of(hexagon, jit.compiled_backend())
    mech = ws.kernel_arrays()
    u = np.zeros(hexagon.n_unknowns)
    q, res, jac = np.empty(hexagon.n_joints), np.empty(hexagon.n_equations), ws.jac
    kernels.evaluate(mech, u, q, res, jac)
    U, _, Vt = np.linalg.svd(jac)
    r_path = hexagon.n_unknowns - 1
    basis, t = np.ascontiguousarray(U[:, :r_path]), Vt[-1].copy()
    t_out, sigma = np.empty_like(t), np.empty(min(jac.shape))
    corrector = Workspace.corrector(Tolerances())
    trace = lw.trace(hexagon, until=until, steps=STEPS)
    jacs = np.array([ws.evaluate(u)[2] for u in hexagon.u_from_q(hexagon.q_from_angles(trace.angles))])
    parts = {
        "closure evaluation": lambda: _evaluations(mech, u, q, res, jac.copy(), LOOPS),
        "corrector from a predicted point": lambda: _corrections(
            mech, u, t, corrector, q, res, jac.copy(), LOOPS
        ),
        "tangent and test function (warm)": lambda: _warm_tangents(jacs, t, basis, r_path, sigma, LOOPS),
        "  the same from a cold start": lambda: _tangents(jac, t, basis, r_path, t_out, sigma, LOOPS),
        "  np.linalg.svd (6x6), for comparison": lambda: _svds(jac, LOOPS),
    }
    for call in parts.values():
        call()  # compile the timing loops
    print(
        f"hexagon, paper mode, {STEPS} steps: {trace_s * 1e3:.3f} ms a trace, {trace_s / STEPS * 1e6:.2f} us a step"
    )
    print(
        f"  the compiled march call in the fastest trace: {march_s * 1e3:.3f} ms ({march_s / STEPS * 1e6:.2f} us a "
        "step); the rest is Python around it (set-up, scans of the rows, the Trace)"
    )
    for name, call in parts.items():
        print(f"  {name:36s} {best_of(call, args.repeats, LOOPS) * 1e6:7.2f} us")
    print("  calls in one trace:", counts(hexagon, until))


if __name__ == "__main__":
    main()
