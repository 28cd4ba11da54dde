"""One progress-callback protocol for every long computation: tracing, synthesis, mechanization, studies.

A callback is called as ``progress(done, total)``: the units of work finished so far (cumulative, never
decreasing) and the total expected (``None`` while unknown). The units are the computation's own: steps for a
trace (the total is the step budget), design vectors for a synthesis search, candidate designs for a
mechanization, samples or grid points for a study. A command-line progress bar is ``bar.update(task,
completed=done, total=total)``.
"""

from __future__ import annotations

from typing import Protocol


class Progress(Protocol):
    """``progress(done, total)``: cumulative work done and the total expected (``None`` while unknown)."""

    def __call__(self, done: int, total: int | None, /) -> None: ...
