"""Compiled or plain-Python kernels: which implementation of the tracing hot loop a trace runs, and when to compile.

The tracing kernels (:mod:`linkwork.kinematics.march` and :mod:`linkwork.kinematics.kernels`) are numba functions
cached on disk. On a fresh install that cache is empty and compiling them takes longer than most traces. So, by
default (``LINKWORK_JIT=auto``), a process that finds the cache cold traces with the *same* functions run as plain
Python (numba's ``py_func``, rebound so that they call each other as Python too: identical arithmetic, no
compile) and starts one background process that compiles the kernels into the cache for the next run; a long trace
moves to the compiled kernels as soon as they are there (:class:`SwitchingKernels`). When the cache is warm, the
kernels are loaded before the trace's clock starts, so a trace's reported time is tracing only.

The hook: :class:`linkwork.kinematics.workspace.Workspace` holds ``kernels = march_kernels()``; the marcher, the
bifurcation locator and ``Workspace.evaluate`` call ``ws.kernels.march``, ``.evaluate``, ``.correct`` and
``.tangent_and_test``.

``LINKWORK_JIT=compiled`` always uses the compiled kernels, compiling them first in this process when the cache is
cold (announced, and excluded from the trace's reported time); ``LINKWORK_JIT=python`` always uses plain Python.
Announcements go to the ``linkwork.jit`` logger (the command line prints them on stderr).
"""

from __future__ import annotations

import logging
import os
import subprocess
import sys
import time
import types
from collections.abc import Callable
from pathlib import Path
from typing import Any

from numba.core.registry import CPUDispatcher

log = logging.getLogger("linkwork.jit")

MODES = ("auto", "compiled", "python")
ENTRY_POINTS = ("march", "evaluate", "correct", "tangent_and_test")
"""The functions of :mod:`linkwork.kinematics.march` that the tracer, the marcher and the locators call."""

LOCK_NAME = "linkwork-compiling.lock"
BACKGROUND_COMMAND = (
    "from linkwork.kinematics.jit import compile_in_background; compile_in_background(); "
    "from linkwork.synthesis.compiled import warm_up; warm_up()"
)
"""The background process: the tracing kernels first (holding the lock), then the synthesis search's, so that a
later ``linkwork synth`` finds them cached too."""
LOCK_STALE_SECONDS = 600.0

_state: dict[str, Any] = {"compiling": False, "spawned": False, "compile_seconds": 0.0, "ready": False}


def mode() -> str:
    """The kernel mode from ``LINKWORK_JIT`` (``auto`` when unset); an unknown value is reported and ignored."""
    value = os.environ.get("LINKWORK_JIT", "auto").strip().lower() or "auto"
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


def is_cached(dispatcher: CPUDispatcher) -> bool:
    """Whether ``dispatcher`` is compiled in this process or has a compiled version in numba's on-disk cache
    (an index written by numba for this very source; a stale index reads as empty)."""
    if dispatcher.signatures:
        return True
    try:
        return bool(dispatcher._cache._cache_file._load_index())  # type: ignore[attr-defined]
    except Exception:  # numba internals moved: assume warm, i.e. behave as before this module existed
        return True


def _march_dispatchers() -> dict[str, CPUDispatcher]:
    from linkwork.kinematics import march

    return {name: getattr(march, name) for name in ENTRY_POINTS}


def kernels_cached() -> bool:
    """Whether every tracing kernel is ready without compiling (in this process or in the on-disk cache)."""
    return all(is_cached(d) for d in _march_dispatchers().values())


_TWIN: dict[str, types.SimpleNamespace] = {}


def march_kernels() -> Any:
    """The implementation of :data:`ENTRY_POINTS` a trace should run now: the compiled module or its
    plain-Python twin, by :func:`mode` and the state of the cache (see the module's docstring)."""
    from linkwork.kinematics import march

    chosen = mode()
    if _state["compiling"]:
        return march
    if chosen == "python":
        return plain_march_kernels()
    if _state["ready"]:  # loaded in this process: no need to read the cache's index again (0.2 ms a kernel)
        return march
    if kernels_cached():
        if not march.march.signatures:
            compile_now()  # loads the cached machine code now, so that the trace's clock counts tracing only
        _state["ready"] = True
        return march
    if chosen == "compiled":
        compile_now(announce=True)
        return march
    start_background_compile()
    return SwitchingKernels()


class SwitchingKernels:
    """The plain-Python kernels until the background compile has filled the cache, then the compiled ones.

    Looked up at every call of an entry point (``kernels.march(...)``); the cache is checked at most once every
    :attr:`CHECK_SECONDS`, so that a long first trace moves to compiled code as soon as it exists. Both give the
    same numbers (see :func:`python_twin`), so a trace may switch halfway.
    """

    CHECK_SECONDS = 1.0

    def __init__(self) -> None:
        self._compiled: Any = None
        self._checked = time.monotonic()

    def __getattr__(self, name: str) -> Any:
        if name not in ENTRY_POINTS:
            raise AttributeError(name)
        if self._compiled is None and time.monotonic() - self._checked > self.CHECK_SECONDS:
            self._checked = time.monotonic()
            if background_compile_finished():
                from linkwork.kinematics import march

                self._compiled = march
        return getattr(self._compiled or plain_march_kernels(), name)


def background_compile_finished() -> bool:
    """Whether no compile is under way (no fresh lock file) and the kernels are in the cache."""
    return not _compile_under_way() and kernels_cached()


def plain_march_kernels() -> types.SimpleNamespace:
    """The plain-Python twin of the tracing kernels (built once per process)."""
    if "march" not in _TWIN:
        _TWIN["march"] = python_twin(_march_dispatchers())
    return _TWIN["march"]


def compile_now(announce: bool = False) -> float:
    """Compile the tracing kernels in this process (into numba's cache), or load them from it when they are
    there, by tracing a small linkage with them; returns the seconds it took (their sum is
    ``compile_seconds()``)."""
    if announce:
        log.info("compiling kernels, first run only ...")
    started = time.perf_counter()
    _state["compiling"] = True
    try:
        _warm_up()
    finally:
        _state["compiling"] = False
    seconds = time.perf_counter() - started
    _state["compile_seconds"] += seconds
    if announce:
        log.info("compiled kernels in %.1f s (cached for next time)", seconds)
    return seconds


def compile_seconds() -> float:
    """Seconds this process has spent compiling kernels, or loading them from the cache, before tracing."""
    return float(_state["compile_seconds"])


def _warm_up() -> None:
    """Run every entry point with the argument types a trace uses: adaptive traces of a Bennett linkage with a
    target (and its normalised condition ratio), without one and up to a joint limit, and a paper-mode trace."""
    import math

    from linkwork.io.spec import resolve_spec
    from linkwork.kinematics.tracer import trace

    mech = resolve_spec("bennett", {}).mechanism
    a, start = mech.joint_names[0], float(mech.offsets[0])
    trace(mech, until=(a, start + 0.3)).condition()  # the normalised ratio's Jacobian kernel too
    trace(mech, until=(a, start + 0.3), steps=4)
    trace(mech, max_steps=8, max_step=math.radians(5.0))
    trace(mech, max_steps=20, limits={a: (start - 1.0, start + 0.05)})  # a limit: the marcher's own correct()
    planar = resolve_spec("four-bar", {}).mechanism  # the closed-form dyad solver of planar paper-mode traces
    trace(planar, until=("A", float(planar.offsets[0]) + 0.3), steps=4)


def _compile_under_way() -> bool:
    """Whether a fresh lock file says that a process is compiling the kernels into the cache."""
    lock = _lock_path()
    try:
        return lock is not None and time.time() - lock.stat().st_mtime < LOCK_STALE_SECONDS
    except OSError:
        return False


def _touch_lock() -> None:
    lock = _lock_path()
    if lock is not None:
        try:
            lock.parent.mkdir(parents=True, exist_ok=True)
            lock.touch()
        except OSError:
            pass


def _lock_path() -> Path | None:
    try:
        from linkwork.kinematics import march

        return Path(march.march._cache._cache_path) / LOCK_NAME  # type: ignore[attr-defined]
    except Exception:
        return None


LAUNCHER = (
    "import subprocess, sys; "
    "subprocess.Popen([sys.argv[1], '-c', sys.argv[2]], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, "
    "stderr=subprocess.DEVNULL, start_new_session=True)"
)
"""The launcher's source: start ``python -c BACKGROUND_COMMAND`` in a new session, detached, and exit."""


def start_background_compile(runner: Callable[..., Any] | None = None) -> bool:
    """Start (at most once per process, and not while another process is at it) a detached Python process
    running :func:`compile_in_background`, which fills the cache; returns whether one was started."""
    if _state["spawned"]:
        return False
    _state["spawned"] = True
    if _compile_under_way():
        log.info("kernels are compiling in another process; tracing with the Python kernels meanwhile")
        return False
    _touch_lock()  # at once, so that a process started meanwhile does not compile too
    log.info(
        "compiling kernels, first run only: in the background for next time; this run uses the Python kernels"
    )
    env = dict(os.environ, LINKWORK_JIT="compiled")
    # A short-lived launcher starts the detached compile and exits at once, and we wait for the launcher: this
    # process then holds no handle on a still-running child (whose Popen would warn when collected).
    (runner or subprocess.run)(
        [sys.executable, "-c", LAUNCHER, sys.executable, BACKGROUND_COMMAND],
        env=env,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        timeout=60,
        check=False,
    )
    return True


def compile_in_background() -> None:
    """Compile the tracing kernels into the cache holding the lock file (the background process's first job)."""
    _touch_lock()
    try:
        compile_now()
    finally:
        lock = _lock_path()
        if lock is not None:
            lock.unlink(missing_ok=True)
