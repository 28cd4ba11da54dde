"""What every command shares: turning linkwork errors into one clear line and exit code 2, and safe output."""

from __future__ import annotations

from collections.abc import Callable
from functools import wraps
from typing import Any, ParamSpec, TypeVar

import typer
from rich.console import Console

from linkwork.errors import LinkworkError, RequestNotMetError

err_console = Console(stderr=True)

P = ParamSpec("P")
R = TypeVar("R")


def fail(message: str, code: int = 2) -> typer.Exit:
    """Print ``error: message`` on one line to stderr and return the exit to raise (code 2: bad input; 3: the
    request could not be met)."""
    err_console.print(f"[bold red]error:[/] {message}", highlight=False, soft_wrap=True)
    return typer.Exit(code=code)


def friendly_errors(func: Callable[P, R]) -> Callable[P, R]:
    """Decorate a command so that a :class:`LinkworkError` becomes one line on stderr and exit code 2, or 3 for a
    :class:`RequestNotMetError`."""

    @wraps(func)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        try:
            return func(*args, **kwargs)
        except RequestNotMetError as exc:
            raise fail(str(exc), code=3) from None
        except LinkworkError as exc:
            raise fail(str(exc)) from None

    return wrapper


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
