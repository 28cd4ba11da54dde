"""What a trace counted and measured besides its points: :class:`TraceStats`, the record ``Trace.stats`` holds."""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from typing import Any

from linkwork.deprecation import warn


@dataclass(frozen=True)
class TraceStats:
    """Counts and measures of one trace.

    Attributes
    ----------
    start_rank, start_mobility
        Rank of the Jacobian at the start and the mobility there (unknowns minus rank).
    mode
        ``"paper"`` (equal drive steps) or ``"adaptive"`` (arclength steps).
    closure_tol
        The closure accepted (``Tolerances.closure``); ``max_misfit`` the largest residual met.
    sign_changes_without_rank_drop
        Sign changes of the test function where no rank drop was found (not reported as points).
    branches_not_retraced
        Queued branches not traced: an arc already traced, run the other way.
    has_target, unmet
        Whether ``until`` was given, and why it was not reached (one line; ``None`` when it was, or without a
        target). The command line exits with code 3 when ``unmet`` is set.
    points, seconds
        Rows of the result, and the seconds tracing took (compiling or loading kernels excluded).
    stopped
        Why the trace stopped before its end, ``"interrupted (SIGTERM)"`` (a signal the command line held, see
        :func:`linkwork.interrupts.held_signals`: what was traced is kept); ``None`` when it ran to its end.

    Read access by key (``stats["unmet"]``, ``"unmet" in stats``, ``stats.get(...)``) still works for one release,
    with a :class:`DeprecationWarning`: ``"unmet" in stats`` is true only when the target was not met, as when
    ``stats`` was a dict.
    """

    start_rank: int = 0
    start_mobility: int = 0
    mode: str = "adaptive"
    closure_tol: float = 0.0
    max_misfit: float = 0.0
    sign_changes_without_rank_drop: int = 0
    branches_not_retraced: int = 0
    has_target: bool = False
    unmet: str | None = None
    points: int = 0
    seconds: float = 0.0
    stopped: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """Every field by name (``unmet`` ``None`` when the target was met)."""
        return asdict(self)

    # ---- the dict-like reading of 0.1, deprecated
    def _present(self, key: str) -> bool:
        names = {f.name for f in fields(self)}
        return key in names and not (key == "unmet" and self.unmet is None)

    def _warn(self, how: str) -> None:
        warn(f"Trace.stats {how}", "the attribute of the TraceStats record (stats.unmet, ...)", 4)

    def __getitem__(self, key: str) -> Any:
        self._warn("stats[key]")
        if not self._present(key):
            raise KeyError(key)
        return getattr(self, key)

    def get(self, key: str, default: Any = None) -> Any:
        """``stats.get(key)`` as on the dict of 0.1 (deprecated: read the attribute)."""
        self._warn("stats.get(key)")
        return getattr(self, key) if self._present(key) else default

    def __contains__(self, key: object) -> bool:
        self._warn("'key' in stats")
        return isinstance(key, str) and self._present(key)
