"""The one exception hierarchy of linkwork: every failure a user can cause or meet is one of these.

The command line maps them to exit codes: :class:`RequestNotMetError` (and its subclasses) to 3, "the request
could not be met" (a target not reached, no design or mechanism passes); every other :class:`LinkworkError` to 2,
bad input. Exit 0 means done as asked.
"""

from __future__ import annotations


class LinkworkError(Exception):
    """Base class of every error linkwork raises on purpose."""


class SpecError(LinkworkError, ValueError):
    """A bad input file or argument: says which file, which key or line, and what was expected."""

    def __init__(self, message: str, *, source: str | None = None, key: str | None = None) -> None:
        self.source = source
        self.key = key
        self.detail = message  # what is wrong, without the file and the key (a reader may re-key it)
        where = ": ".join(part for part in (source, key) if part)
        super().__init__(f"{where}: {message}" if where else message)


class AssemblyError(LinkworkError):
    """A start configuration that cannot be closed onto the loop; carries the closure residual."""

    def __init__(self, message: str, *, residual: float | None = None) -> None:
        self.residual = residual
        super().__init__(message)


class RigidStartError(LinkworkError):
    """A start configuration that cannot move: rigid to first order (the Jacobian's rank is the number of
    unknowns, ``order`` 1) or to second order (an isolated point, or a shaky structure: mobile to first order
    only, ``order`` 2)."""

    def __init__(self, message: str, *, order: int) -> None:
        self.order = order
        super().__init__(message)


class ConvergenceError(LinkworkError):
    """A corrector or optimiser that failed: says where and why."""


class RequestNotMetError(LinkworkError):
    """Valid input, but what was asked cannot be met (a target the path never reaches, no design that passes).

    The command line prints its message on one line and exits with code 3, after writing what was computed.
    """


class MechanizationError(RequestNotMetError):
    """No mechanism design passes: says which body or which check stopped every candidate (exit code 3)."""
