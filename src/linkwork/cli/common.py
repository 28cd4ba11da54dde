"""What every command shares: turning linkwork errors into one clear line and exit code 2, and safe output."""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Callable, Iterator
from functools import wraps
from pathlib import Path
from typing import Any, ParamSpec, TypeVar

import typer
from rich.console import Console

from linkwork.errors import LinkworkError

console = Console()
err_console = Console(stderr=True)

P = ParamSpec("P")
R = TypeVar("R")


def fail(message: str) -> typer.Exit:
    """Print ``error: message`` on one line to stderr and return the exit (code 2) to raise."""
    err_console.print(f"[bold red]error:[/] {message}", highlight=False, soft_wrap=True)
    return typer.Exit(code=2)


def friendly_errors(func: Callable[P, R]) -> Callable[P, R]:
    """Decorate a command so that a :class:`LinkworkError` becomes one line on stderr and exit code 2."""

    @wraps(func)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        try:
            return func(*args, **kwargs)
        except LinkworkError as exc:
            raise fail(str(exc)) from None

    return wrapper


@contextlib.contextmanager
def staged_output(out: Path) -> Iterator[Path]:
    """Write a command's files into a temporary folder and move them into ``out`` only if all succeeded.

    A failure part way leaves ``out`` as it was: no half-written output.
    """
    out = Path(out)
    parent = out.resolve().parent
    parent.mkdir(parents=True, exist_ok=True)
    stage = Path(tempfile.mkdtemp(prefix=".linkwork-", dir=parent))
    try:
        yield stage
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
    out.mkdir(parents=True, exist_ok=True)
    for item in stage.iterdir():
        target = out / item.name
        if target.is_dir() and not target.is_symlink():
            shutil.rmtree(target)
        os.replace(item, target)
    shutil.rmtree(stage, ignore_errors=True)


def have_matplotlib() -> bool:
    """True when the optional plotting extra (``linkwork[viz]``) is installed."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True


def parse_assignments(items: list[str] | None, flag: str) -> dict[str, Any]:
    """Parse ``KEY=VALUE`` pairs of a repeated flag; values become int, float or str (never evaluated)."""
    out: dict[str, Any] = {}
    for item in items or []:
        key, sep, raw = item.partition("=")
        if not sep or not key.strip():
            raise fail(f"{flag} {item!r}: expected KEY=VALUE")
        value: Any
        try:
            value = int(raw)
        except ValueError:
            try:
                value = float(raw)
            except ValueError:
                value = raw
        out[key.strip()] = value
    return out
