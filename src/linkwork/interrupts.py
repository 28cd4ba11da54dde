"""Signals that never land inside the compiler.

A Ctrl-C (SIGINT) or SIGTERM is turned into a Python exception by a Python-level handler, which runs at the next
bytecode of the main thread, wherever that is. When it is inside numba or llvmlite loading or compiling a kernel
(the first call of a kernel reads it from the cache), the exception leaves their C state half-built: the process
then crashes with a segmentation fault instead of stopping cleanly, and nothing removes its staging folder (one
Ctrl-C in about thirty during ``linkwork demo``, measured). :func:`when_safe` wraps a handler so that a signal
arriving there is held and delivered again a moment later, until it lands in code outside the compiler; every
handler linkwork installs goes through it.
"""

from __future__ import annotations

import os
import signal
import threading
from collections.abc import Callable
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
    """Make Ctrl-C raise :class:`KeyboardInterrupt` only outside the compiler (the command line's default; in
    the main thread only, where Python runs signal handlers)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, when_safe(signal.default_int_handler))
