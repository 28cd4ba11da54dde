"""The one exception hierarchy of linkwork: every failure a user can cause or meet is one of these."""

from __future__ import annotations


class LinkworkError(Exception):
    """Base class of every error linkwork raises on purpose."""


class SpecError(LinkworkError, ValueError):
    """A bad input file or argument: says which file, which key or line, and what was expected."""

    def __init__(self, message: str, *, source: str | None = None, key: str | None = None) -> None:
        self.source = source
        self.key = key
        where = ": ".join(part for part in (source, key) if part)
        super().__init__(f"{where}: {message}" if where else message)


class AssemblyError(LinkworkError):
    """A start configuration that cannot be closed onto the loop; carries the closure residual."""

    def __init__(self, message: str, *, residual: float | None = None) -> None:
        self.residual = residual
        super().__init__(message)


class ConvergenceError(LinkworkError):
    """A corrector or optimiser that failed: says where and why."""
