"""A/B of the closed-form planar kernel: another revision's ``dyad_solver.closed_form_path`` against this tree's, in
one process, on the same arguments, timed in alternation (best of ``--repeats`` each), so that a load that comes
and goes on a shared machine hits both alike. Also checks that both return the same rows, bit for bit.

The other revision's ``kinematics/dyad_solver.py`` is taken from git (``git show REV:...``) into a temporary folder
and compiled with plain ``numba.njit`` (the other kernels it calls are this tree's). The arguments are those that
``lw.trace`` passes for one full turn of the crank in ``--positions`` steps (four-bar, slider-crank, the Watt II
six-bar of ``examples/specs``).

Run: ``python benchmarks/ab_closed_form.py --against main`` (``--positions``, ``--repeats``).
"""

from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

import linkwork as lw
from linkwork.kinematics import dyad_solver

ROOT = Path(__file__).resolve().parent.parent
SOURCE = "src/linkwork/kinematics/dyad_solver.py"
WATT = ROOT / "examples" / "specs" / "watt-six-bar.toml"


def other_kernel(rev: str, folder: Path) -> ModuleType:
    """``dyad_solver`` as of git revision ``rev``, its kernels compiled with ``numba.njit``."""
    text = subprocess.run(
        ["git", "show", f"{rev}:{SOURCE}"], cwd=ROOT, check=True, capture_output=True, text=True
    ).stdout
    text = text.replace(
        "from linkwork.kernel_cache import kernel\n",
        "import numba\n\n\ndef kernel(**options):\n    return numba.njit(**options)\n\n",
    )
    path = folder / "dyad_solver_ab.py"
    path.write_text(text)
    spec = importlib.util.spec_from_file_location("dyad_solver_ab", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def kernel_arguments(name: str, positions: int) -> tuple[Any, ...]:
    """The arguments of the longest ``closed_form_path`` call of one turn of ``name``'s crank."""
    mech = lw.load(name)
    until = ("A", float(mech.offsets[mech.index("A")] + 2.0 * np.pi))
    calls: list[tuple[Any, ...]] = []
    kernel = dyad_solver.closed_form_path

    def recorded(*args: Any) -> Any:
        calls.append(args)
        return kernel(*args)

    dyad_solver.closed_form_path = recorded
    try:
        lw.trace(mech, until=until, steps=positions, max_steps=10 * positions)
    finally:
        dyad_solver.closed_form_path = kernel
    return max(calls, key=lambda args: args[2][0][2])


def call_for(module: ModuleType, call: tuple[Any, ...]) -> tuple[Any, ...]:
    """This tree's arguments ``call`` for ``module``'s kernel: a revision before the joint values and the rank
    verdict moved into the kernel (no ``S_LOOSE``) takes the plan without its ``offsets`` (its settings array reads
    the first eight entries only)."""
    if hasattr(module, "S_LOOSE"):
        return call
    flat, plan, run = call
    return flat, plan[:5], run


def same_rows(a: tuple[Any, ...], b: tuple[Any, ...], call: tuple[Any, ...]) -> bool:
    """Whether two ``closed_form_path`` results carry the same rows, bit for bit: a result of a revision that
    returned the unknowns ``u`` (seven outputs) is compared through ``u[:, groups] + offsets`` (numpy's sum, the
    one the kernel now makes), without the rank verdict it did not have."""

    def rows(out: tuple[Any, ...]) -> tuple[Any, ...]:
        if len(out) == 8:
            return out[:7]
        groups, offsets = call[0][4], call[1][5]
        return (*out[:2], out[2][:, groups] + offsets, *out[3:])

    a, b = rows(a), rows(b)
    return bool(a[:2] == b[:2] and all(np.array_equal(x, y) for x, y in zip(a[2:], b[2:], strict=True)))


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", default="main", help="the git revision to compare with (default main)")
    parser.add_argument("--positions", type=int, default=3600)
    parser.add_argument("--repeats", type=int, default=400)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        other = other_kernel(args.against, Path(folder))
        for name, source in (
            ("four-bar", "four-bar"),
            ("slider-crank", "slider-crank"),
            ("watt-six-bar", str(WATT)),
        ):
            call = kernel_arguments(source, args.positions)
            their_call = call_for(other, call)
            theirs, ours = other.closed_form_path(*their_call), dyad_solver.closed_form_path(*call)
            same = same_rows(theirs, ours, call)
            best_theirs = best_ours = np.inf
            for _ in range(args.repeats):
                t0 = time.perf_counter()
                other.closed_form_path(*their_call)
                best_theirs = min(best_theirs, time.perf_counter() - t0)
                t0 = time.perf_counter()
                dyad_solver.closed_form_path(*call)
                best_ours = min(best_ours, time.perf_counter() - t0)
            points = call[2][0][2] + 1
            print(
                f"{name:13s} {args.against}: {best_theirs / points * 1e9:6.1f} ns a point   this tree: "
                f"{best_ours / points * 1e9:6.1f}   ratio {best_ours / best_theirs:.3f}   "
                f"rows {'bit-identical' if same else 'DIFFER'}"
            )


if __name__ == "__main__":
    sys.exit(main())
