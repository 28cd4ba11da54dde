"""Compiled kernels or their plain-Python twins: chosen once when a call starts, kept for the whole call.

The tracing kernels (:mod:`linkwork.kinematics.march` and :mod:`linkwork.kinematics.kernels`) are numba functions
cached on disk (:mod:`linkwork.kernel_cache`: one directory keyed to the kernels' sources, and a marker that says
which groups of kernels are compiled into it). :func:`select_backend` is called once at the start of a trace (and
of a normalised-ratio computation) and returns a :class:`Backend`, which the trace keeps to its end:

* ``LINKWORK_JIT=python``: the plain-Python twins (numba's ``py_func`` of every kernel, rebound so that they call
  each other as Python too: the same statements, no compile).
* The marker says the tracing kernels are compiled (the usual case after the first run, after
  ``linkwork compile``, or in this process after a compile): the compiled kernels, loaded from the cache before
  the trace's clock starts.
* The cache is cold and the command line asked for background compiles (:func:`enable_background_compile`; only
  the ``linkwork`` script does, never a library call from a notebook or a Dask worker): the plain-Python twins,
  and one detached process compiles every kernel into the cache for the next run.
* Otherwise (a library call, or ``LINKWORK_JIT=compiled``) the kernels are compiled in this process first,
  announced (a warning of the ``linkwork.jit`` logger) and kept out of the trace's reported time.

``linkwork compile`` fills the cache ahead of time (CI, container images, Dask workers). Announcements go to the
``linkwork.jit`` logger (the command line prints them on stderr); a foreground compile is announced as a warning,
which Python prints on stderr even where logging is not set up (a script, a notebook).
"""

from __future__ import annotations

import logging
import os
import subprocess
import sys
import time
import types
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from numba.core.registry import CPUDispatcher

from linkwork.kernel_cache import CACHE

log = logging.getLogger("linkwork.jit")

MODES = ("auto", "compiled", "python")
ENTRY_POINTS = ("march", "evaluate", "correct", "tangent_and_test", "closure_jacobian")
"""The kernels the tracer, the marcher, the locators and the normalised ratio call."""

GROUP = "tracing"
"""The marker's group of these kernels."""

LOCK_STALE_SECONDS = 600.0

_state: dict[str, Any] = {"loaded": False, "compiling": False, "spawned": False, "compile_seconds": 0.0}
_background: list[list[str]] = []  # the command a cold CLI run starts (set by enable_background_compile)


@dataclass(frozen=True)
class Backend:
    """One implementation of the tracing kernels: compiled (``compiled=True``) or their plain-Python twins."""

    compiled: bool
    march: Callable[..., Any]
    evaluate: Callable[..., Any]
    correct: Callable[..., Any]
    tangent_and_test: Callable[..., Any]
    closure_jacobian: Callable[..., Any]


def mode() -> str:
    """The kernel mode from ``LINKWORK_JIT`` (``auto`` when unset); an unknown value is reported and ignored."""
    value = os.environ.get("LINKWORK_JIT")
    if value is None:  # the usual case, read on every trace: no string work
        return "auto"
    value = value.strip().lower() or "auto"
    if value not in MODES:
        log.warning("LINKWORK_JIT=%s is not one of %s; using auto", value, ", ".join(MODES))
        return "auto"
    return value


def python_twin(functions: dict[str, CPUDispatcher]) -> types.SimpleNamespace:
    """The plain-Python versions of compiled ``functions``, calling each other (and every kernel they call) as
    plain Python: numba's ``py_func`` of each, re-bound to globals in which every dispatcher is replaced by its
    twin. The arithmetic is the same statements in the same order, so results agree with the compiled kernels to
    round-off."""
    memo: dict[int, types.FunctionType] = {}

    def twin(dispatcher: CPUDispatcher) -> types.FunctionType:
        key = id(dispatcher)
        if key in memo:
            return memo[key]
        py = dispatcher.py_func
        scope = dict(py.__globals__)
        fn = types.FunctionType(py.__code__, scope, py.__name__, py.__defaults__, py.__closure__)
        fn.__doc__, fn.__qualname__ = py.__doc__, py.__qualname__
        memo[key] = fn  # before the globals, so that recursion and mutual calls resolve to the twin
        for name, value in py.__globals__.items():
            if isinstance(value, CPUDispatcher):
                scope[name] = twin(value)
        return fn

    return types.SimpleNamespace(**{name: twin(d) for name, d in functions.items()})


def _dispatchers() -> dict[str, CPUDispatcher]:
    from linkwork.kinematics import kernels, march

    found = {name: getattr(march, name) for name in ENTRY_POINTS if name != "closure_jacobian"}
    found["closure_jacobian"] = kernels.closure_jacobian
    return found


_BACKENDS: dict[bool, Backend] = {}


def compiled_backend() -> Backend:
    """The compiled kernels (compiled on their first call when the cache does not have them)."""
    if True not in _BACKENDS:
        _BACKENDS[True] = Backend(True, **_dispatchers())
    return _BACKENDS[True]


def python_backend() -> Backend:
    """The plain-Python twins of the kernels (built once per process)."""
    if False not in _BACKENDS:
        _BACKENDS[False] = Backend(False, **vars(python_twin(_dispatchers())))
    return _BACKENDS[False]


def select_backend(chosen: str | None = None, warm_up: Callable[[], None] | None = None) -> Backend:
    """The kernels a call runs from start to end, chosen now (see the module's docstring): by ``chosen`` (default
    :func:`mode`), the marker of the cache and whether this process may start a background compile.

    ``warm_up`` runs every kernel once with a trace's argument types (the tracer passes
    :func:`linkwork.kinematics.tracer.warm_up`): it loads or compiles them before the caller's clock starts.
    Without it the compiled kernels load or compile on their first call."""
    chosen = chosen or mode()
    if chosen == "python":
        return python_backend()
    if _state["loaded"] or _state["compiling"]:
        return compiled_backend()
    if CACHE.ready(GROUP):
        if warm_up is not None:
            compile_now(warm_up)  # loads the cached machine code now: the trace's clock counts tracing only
        return compiled_backend()
    if chosen == "auto" and _background:
        start_background_compile()
        return python_backend()
    if warm_up is not None:
        compile_now(warm_up, announce=True)
    return compiled_backend()


def compile_now(warm_up: Callable[[], None], announce: bool = False) -> float:
    """Compile the tracing kernels in this process (into the cache), or load them from it when they are there,
    by running ``warm_up`` (tracing a small linkage with them); marks the group ready and returns the seconds it
    took (their sum is :func:`compile_seconds`)."""
    if announce:  # a warning, so that a script or a notebook without logging set up sees why it waits
        log.warning("compiling kernels, first run only (linkwork compile does it ahead of time) ...")
    started = time.perf_counter()
    _state["compiling"] = True
    try:
        warm_up()
    finally:
        _state["compiling"] = False
    _state["loaded"] = True
    if not CACHE.ready(GROUP):
        try:
            CACHE.mark_ready([GROUP])
        except OSError as exc:  # a read-only cache: this process is compiled, the next one compiles again
            log.warning("could not write the kernel cache's marker %s: %s", CACHE.marker, exc)
    seconds = time.perf_counter() - started
    _state["compile_seconds"] += seconds
    if announce:
        log.info("compiled kernels in %.1f s (cached in %s)", seconds, CACHE.directory)
    return seconds


def compile_seconds() -> float:
    """Seconds this process has spent compiling kernels, or loading them from the cache, before tracing."""
    return float(_state["compile_seconds"])


# ---- the command line's background compile
def enable_background_compile(command: Sequence[str]) -> None:
    """Let a cold ``auto`` run trace with the plain-Python twins and start ``command`` (a detached process that
    compiles every kernel into the cache and writes the marker). Called by the ``linkwork`` script only."""
    _background[:] = [list(command)]


def disable_background_compile() -> None:
    """Undo :func:`enable_background_compile` (cold library calls compile in the foreground again)."""
    _background.clear()


def compile_under_way() -> bool:
    """Whether a fresh lock file says that a process is compiling the kernels into the cache."""
    try:
        return time.time() - CACHE.lock.stat().st_mtime < LOCK_STALE_SECONDS
    except OSError:
        return False


def hold_lock() -> None:
    """Write the lock file (a background compile is under way)."""
    try:
        CACHE.lock.parent.mkdir(parents=True, exist_ok=True)
        CACHE.lock.touch()
    except OSError:
        pass


def release_lock() -> None:
    """Remove the lock file."""
    CACHE.lock.unlink(missing_ok=True)


LAUNCHER = (
    "import subprocess, sys; "
    "subprocess.Popen(sys.argv[1:], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, "
    "stderr=subprocess.DEVNULL, start_new_session=True)"
)
"""The launcher's source: start its arguments as a command in a new session, detached, and exit."""


def start_background_compile(runner: Callable[..., Any] | None = None) -> bool:
    """Start (at most once per process, and not while another process is at it) the detached background compile
    of :func:`enable_background_compile`; returns whether one was started."""
    if _state["spawned"] or not _background:
        return False
    _state["spawned"] = True
    if compile_under_way():
        log.info("kernels are compiling in another process; tracing with the Python kernels meanwhile")
        return False
    hold_lock()  # at once, so that a process started meanwhile does not compile too
    log.info(
        "compiling kernels, first run only: in the background for next time; this run uses the Python kernels"
    )
    env = dict(os.environ, LINKWORK_JIT="compiled")
    # A short-lived launcher starts the detached compile and exits at once, and we wait for the launcher: this
    # process then holds no handle on a still-running child (whose Popen would warn when collected).
    (runner or subprocess.run)(
        [sys.executable, "-c", LAUNCHER, *_background[0]],
        env=env,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        timeout=60,
        check=False,
    )
    return True
