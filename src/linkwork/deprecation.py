"""Old spellings kept working for one release, each with a :class:`DeprecationWarning` naming the new one."""

from __future__ import annotations

import warnings
from collections.abc import Callable
from functools import wraps
from typing import Any, TypeVar

F = TypeVar("F", bound=Callable[..., Any])


def trace_keyword(func: F) -> F:
    """Let ``func(path=...)`` still pass the traced result, now the parameter ``trace`` (renamed in 0.2.0 so that
    no parameter called ``path`` holds anything but a file path)."""

    @wraps(func)
    def accept(*args: Any, **kwargs: Any) -> Any:
        if "path" in kwargs:
            warnings.warn(
                f"{func.__qualname__}(path=...) is now {func.__qualname__}(trace=...)",
                DeprecationWarning,
                stacklevel=2,
            )
            kwargs["trace"] = kwargs.pop("path")
        return func(*args, **kwargs)

    return accept  # type: ignore[return-value]


def warn(old: str, new: str, stacklevel: int = 3) -> None:
    """Warn that the spelling ``old`` is deprecated in favour of ``new`` (a :class:`DeprecationWarning` pointing at
    the caller of the function that calls this)."""
    warnings.warn(f"{old} is deprecated: use {new}", DeprecationWarning, stacklevel=stacklevel)
