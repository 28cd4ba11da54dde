"""``linkwork compile``: compile every kernel into the cache ahead of time, and the background compile of a cold run.

A fresh install traces with the plain-Python twins of the kernels until the cache is filled (see
:mod:`linkwork.kinematics.jit`). ``linkwork compile`` fills it now: in CI, in a container image, on every Dask
worker's image, so that no run meets a cold cache. The first ``linkwork`` command of a cold install starts the same
compile in a detached background process (:func:`compile_in_background`).
"""

from __future__ import annotations

import time
from collections.abc import Callable

from linkwork.cli.common import friendly_errors
from linkwork.errors import SpecError
from linkwork.messages import show_path
from linkwork.outputs.staging import console

BACKGROUND_COMMAND = "from linkwork.cli.kernels import compile_in_background; compile_in_background()"
"""What the detached background process runs (``python -c``)."""


def warm_tracing() -> None:
    """The tracing kernels, and the normalised ratio's (in this process: loaded or compiled)."""
    from linkwork.kinematics import jit, tracer

    jit.compile_now(tracer.warm_up)


def warm_synthesis() -> None:
    """The segment-matrix search's kernels (:mod:`linkwork.synthesis.compiled`,
    :mod:`linkwork.synthesis.compiled_search`), with the argument types the search uses."""
    import numpy as np

    from linkwork.synthesis.compiled_search import CompiledTables, compiled_rms_bound, compiled_search
    from linkwork.synthesis.error_kernels import ProfileTables

    t = np.linspace(0.0, 1.0, 9)
    curve = np.column_stack([t, 0.1 * np.sin(3.0 * t)])
    tables = ProfileTables([curve, 1.1 * curve], compiled=True)
    tables.mean_errors([0, 1], 4)
    tables.arc_errors([0, 1], [4, 5])
    compiled = CompiledTables.from_tables(tables)  # the segment-matrix search: 8 pieces on both profiles
    start = np.array([[4, 4], [4, 4]], dtype=np.int64)
    compiled_search("MC", [start], 2, compiled)
    compiled_rms_bound("MC", start, compiled)


def warm_studies() -> None:
    """The imperfection study's kernels (seeds, noise, misfit by Gauss-Newton, first-order prediction), on a short
    nominal path of a Bennett linkage."""
    import numpy as np

    from linkwork.io.spec import resolve_spec
    from linkwork.kinematics.tracer import trace
    from linkwork.studies.imperfections import ImperfectionModel
    from linkwork.studies.robustness import prepare, run_chunk

    mech = resolve_spec("bennett", {}).mechanism
    nominal = trace(mech, until=(mech.joint_names[0], float(mech.offsets[0]) + 0.2))
    for distribution in ("normal", "uniform"):
        model = ImperfectionModel(1e-3, float(np.radians(0.05)), distribution=distribution)
        run_chunk(prepare(mech, nominal, model, seed=1), 0, 2)


WARM_UPS: dict[str, Callable[[], None]] = {
    "tracing": warm_tracing,
    "synthesis": warm_synthesis,
    "studies": warm_studies,
}
"""Each group of the marker and what compiles it."""


def compile_all(report: Callable[[str, float], None] | None = None) -> float:
    """Compile (or load) every group of kernels and mark each ready in the cache; returns the seconds taken."""
    from linkwork.kernel_cache import CACHE

    begin = time.perf_counter()
    for group, warm in WARM_UPS.items():
        started = time.perf_counter()
        warm()
        CACHE.mark_ready([group])
        if report is not None:
            report(group, time.perf_counter() - started)
    CACHE.remove_stale()
    return time.perf_counter() - begin


def cache_folder_problem() -> str | None:
    """Why the kernels' cache folder cannot hold the compiled kernels (``$LINKWORK_CACHE_DIR`` naming a file, a
    name too long, a read-only place), or ``None`` when it can. Checked before compiling: numba only fails to
    write its cache after minutes of compiling."""
    import tempfile

    from linkwork.kernel_cache import CACHE

    try:
        CACHE.directory.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=CACHE.directory):
            pass
    except OSError as exc:
        return f"{show_path(CACHE.parent)}: cannot hold the compiled kernels ({exc.strerror or exc})"
    return None


def compile_in_background() -> None:
    """The detached background process: every kernel into the cache, holding the lock file meanwhile (nothing,
    at once, when the cache folder cannot be written: a compile there would be minutes of work lost)."""
    from linkwork.kinematics import jit

    if cache_folder_problem() is not None:
        return
    jit.hold_lock()
    try:
        compile_all()
    finally:
        jit.release_lock()


@friendly_errors
def compile_kernels() -> None:
    """Compile every kernel into linkwork's cache now (for CI, container images and Dask workers), so that no
    later run traces with the slower plain-Python kernels or compiles on its first call."""
    from linkwork.kernel_cache import CACHE

    problem = cache_folder_problem()
    if problem is not None:
        raise SpecError(
            f"{problem}; expected a folder linkwork may create and write into (set LINKWORK_CACHE_DIR)"
        )

    def report(group: str, seconds: float) -> None:
        console.print(f"{group}: ready ({seconds:.1f} s)")

    seconds = compile_all(report)
    console.print(f"kernels compiled in {seconds:.1f} s into {CACHE.directory}", soft_wrap=True)
