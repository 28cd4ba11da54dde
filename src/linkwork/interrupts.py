"""Signals that never land inside the compiler.

A Ctrl-C (SIGINT) or SIGTERM is turned into a Python exception by a Python-level handler, which runs at the next
bytecode of the main thread, wherever that is. When it is inside numba or llvmlite loading or compiling a kernel
(the first call of a kernel reads it from the cache), the exception leaves their C state half-built: the process
then crashes with a segmentation fault instead of stopping cleanly, and nothing removes its staging folder (one
Ctrl-C in about thirty during ``linkwork demo``, measured). :func:`when_safe` wraps a handler so that a signal
arriving there is held and delivered again a moment later, until it lands in code outside the compiler; every
handler linkwork installs goes through it.

:func:`held_signals` is the other half: while a long computation runs, the first SIGINT or SIGTERM is only
recorded (:func:`requested`), and the computation, which looks at it between its steps (the tracer between two
calls of its compiled march), ends there with what it computed, its end saying so; the command writes that and
exits with :func:`exit_code` (130 or 143). A second signal raises :class:`Interrupted` at once. Every long
command holds them this way: ``trace``, ``synth``, ``mechanize``, and the studies (``sweep``, ``robustness``,
``search``) through their engine (:func:`linkwork.studies.engine.map_chunks`). A step that is kept only whole (one
chunk of a study, one design's verification by tracing) runs under :func:`whole`: the tracer inside it does not see
the request, and the loop around it stops after it.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Callable, Iterator
from types import FrameType
from typing import Any

COMPILER_PACKAGES = ("numba", "llvmlite")
"""Packages whose code a signal's exception must not interrupt."""
RETRY_SECONDS = 0.02
"""How long a held signal waits before it is sent again."""

Handler = Callable[[int, FrameType | None], Any]


def in_compiler(frame: FrameType | None) -> bool:
    """Whether ``frame`` or any frame that called it runs code of a :data:`COMPILER_PACKAGES` package."""
    while frame is not None:
        package = str(frame.f_globals.get("__name__", "")).partition(".")[0]
        if package in COMPILER_PACKAGES:
            return True
        frame = frame.f_back
    return False


def send_again(signum: int) -> None:
    """Send ``signum`` to this process after :data:`RETRY_SECONDS` (from a daemon thread)."""
    timer = threading.Timer(RETRY_SECONDS, os.kill, (os.getpid(), signum))
    timer.daemon = True
    timer.start()


def when_safe(handler: Handler) -> Handler:
    """``handler``, run only when the signal lands outside the compiler; inside, the signal is sent again
    :data:`RETRY_SECONDS` later (and again, until it lands outside)."""

    def held(signum: int, frame: FrameType | None) -> Any:
        if in_compiler(frame):
            send_again(signum)
            return None
        return handler(signum, frame)

    held.__doc__ = handler.__doc__
    return held


def install_safe_interrupt() -> None:
    """Make Ctrl-C raise :class:`KeyboardInterrupt`, and SIGTERM :class:`Interrupted`, only outside the compiler
    (the command line's default; in the main thread only, where Python runs signal handlers). SIGTERM's default
    ends the process on the spot, without a word and without running any ``finally``; as an exception it ends the
    command with one line and exit code 143, cleaning up on the way (a Dask cluster shut down, a staging folder
    removed)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, when_safe(signal.default_int_handler))
        signal.signal(signal.SIGTERM, when_safe(_terminate))


def _terminate(signum: int, frame: FrameType | None) -> None:
    """SIGTERM where no signal is held: stop the command at once (see :func:`install_safe_interrupt`)."""
    raise Interrupted(signum, again=False)


EXIT_SIGINT = 130
"""The exit code of a command stopped by Ctrl-C (SIGINT): ``128 + 2``, the shell's."""
EXIT_SIGTERM = 143
"""The exit code of a command stopped by SIGTERM: ``128 + 15``, the shell's."""


class Interrupted(BaseException):
    """SIGINT or SIGTERM that stops a command at once (a :class:`BaseException`, like :class:`KeyboardInterrupt`):
    ``again``, a second signal while the first is held (:func:`held_signals`, a study's run); otherwise a SIGTERM
    where none is held (:func:`install_safe_interrupt`)."""

    def __init__(self, signum: int, *, again: bool = True) -> None:
        self.signum = signum
        self.again = again
        super().__init__(signal.Signals(signum).name)


class Terminated(SystemExit):
    """SIGTERM or SIGHUP while files are written (:mod:`linkwork.io.writer` removes its staging on the way out):
    a ``SystemExit`` with code ``128 + signum``, so that a script ends as the shell expects, and the command line
    says why in one line."""

    def __init__(self, signum: int) -> None:
        self.signum = signum
        super().__init__(exit_code(signum))


def exit_code(signum: int) -> int:
    """The exit code of a command stopped by ``signum``, the shell's ``128 + signum``: :data:`EXIT_SIGINT` for
    SIGINT, :data:`EXIT_SIGTERM` for SIGTERM."""
    return 128 + int(signum)


def stop_text(signum: int) -> str:
    """The words of a stop by ``signum``: ``interrupted (SIGTERM)``."""
    return f"interrupted ({signal.Signals(signum).name})"


class Hold:
    """What :func:`held_signals` recorded: ``signum``, the first SIGINT or SIGTERM received while it held them
    (0: none), kept after the block ends."""

    def __init__(self) -> None:
        self.signum = 0

    @property
    def stopped(self) -> str:
        """``interrupted (SIGTERM)``, or ``""`` when no signal came."""
        return stop_text(self.signum) if self.signum else ""


_CURRENT: list[Hold] = []
"""The hold in force (at most one: a nested :func:`held_signals` shares the outer one)."""


_WHOLE: list[int] = [0]
"""How many :func:`whole` blocks are open (while any is, computations inside see no request)."""


def requested() -> int:
    """The SIGINT or SIGTERM received while :func:`held_signals` holds them (0: none, and always 0 outside it or
    inside :func:`whole`): a computation that sees it ends at its next step, keeping what it computed."""
    return _CURRENT[0].signum if _CURRENT and not _WHOLE[0] else 0


def holding() -> bool:
    """Whether :func:`held_signals` holds the signals now, outside :func:`whole` (a computation then returns to
    Python often enough to look at :func:`requested`)."""
    return bool(_CURRENT) and not _WHOLE[0]


@contextlib.contextmanager
def whole() -> Iterator[None]:
    """A step that is kept only whole: while the block runs, :func:`requested` is 0 for the computation inside
    (a trace in it runs to its own end instead of stopping at the held signal), so the loop around it keeps the
    step and stops after it. The hold still records a signal, and a second one still raises :class:`Interrupted`
    at once."""
    _WHOLE[0] += 1
    try:
        yield
    finally:
        _WHOLE[0] -= 1


@contextlib.contextmanager
def held_signals() -> Iterator[Hold]:
    """While the block runs, the first SIGINT or SIGTERM is recorded (:func:`requested`, and the :class:`Hold`
    handed out) instead of stopping the process, so that the computation ends at its next step with what it
    has; a second raises :class:`Interrupted` at once. Only in the main thread (elsewhere nothing is held and the
    hold stays empty); nested, the outer hold is handed out again."""
    if _CURRENT:
        yield _CURRENT[0]
        return
    hold = Hold()
    if threading.current_thread() is not threading.main_thread():
        yield hold
        return

    def record(signum: int, frame: FrameType | None) -> None:
        if hold.signum:
            raise Interrupted(signum)
        hold.signum = signum

    before = {sig: signal.signal(sig, when_safe(record)) for sig in (signal.SIGINT, signal.SIGTERM)}
    _CURRENT.append(hold)
    try:
        yield hold
    finally:
        _CURRENT.clear()
        for sig, handler in before.items():
            signal.signal(sig, handler)
