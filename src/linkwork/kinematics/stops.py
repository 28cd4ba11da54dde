"""Why a march or a branch stopped: one enum shared by the compiled kernels (as plain ints) and Python.

The compiled march (:func:`linkwork.kinematics.march.march`) returns one of the first eight values; the marcher
adds the reasons only it can see (a known point reached, a higher-dimensional component entered, a branch that
could not leave its bifurcation point, a signal the command line held). Every traced branch ends with an
:class:`End`: its kind, the joint the reason is about and that joint's value there, and the sentence a person
reads (``Branch.end_reason``).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum


class StopReason(IntEnum):
    """Why a march or a branch stopped. Values ``0``-``7`` are the compiled march's stop codes."""

    BUDGET = 0
    """The step budget (``max_steps``) ran out."""
    TARGET = 1
    """The drive reached its target exactly."""
    CLOSED = 2
    """The path came back to its start (revolute angles modulo a full turn)."""
    FAILED = 3
    """The corrector did not converge (paper mode: at a fixed drive step; adaptive: the step was halved below
    ``min_step``)."""
    SIGN_CHANGE = 4
    """The bifurcation test function changed sign (the march stops so that the point is located)."""
    LIMIT = 5
    """A joint passed one of its limits (the branch then ends on the limit)."""
    TURNING = 6
    """Paper mode: the drive turned back (a fold), equal drive steps cannot go on."""
    NO_PROGRESS = 7
    """Adaptive mode: the last ``stall_steps`` steps together advanced less than ``stall_length`` of a step."""
    KNOWN_POINT = 8
    """A branch from a bifurcation point reached an already located point."""
    COMPONENT = 9
    """The branch entered a higher-dimensional component of the configuration space."""
    NOT_LEFT = 10
    """A queued branch could not leave its bifurcation point (no corrected first step)."""
    INTERRUPTED = 11
    """A SIGINT or SIGTERM arrived while the command line held them (:func:`linkwork.interrupts.held_signals`):
    the branch ends at the last point marched, which is kept (the text names the signal)."""

    @property
    def text(self) -> str:
        """The short sentence a person reads for this reason (the march's own wording)."""
        return _TEXT[self]


_TEXT = {
    StopReason.BUDGET: "step budget",
    StopReason.TARGET: "reached target",
    StopReason.CLOSED: "closed path",
    StopReason.FAILED: "corrector failed",
    StopReason.SIGN_CHANGE: "bifurcation",
    StopReason.LIMIT: "joint limit",
    StopReason.TURNING: "drive turning point",
    StopReason.NO_PROGRESS: "no progress",
    StopReason.KNOWN_POINT: "reached bifurcation",
    StopReason.COMPONENT: "entered a component",
    StopReason.NOT_LEFT: "could not leave the bifurcation",
    StopReason.INTERRUPTED: "interrupted",
}


@dataclass(frozen=True)
class End:
    """How a branch ended: ``kind``; ``joint`` the joint the reason is about (the limited joint for ``LIMIT``,
    otherwise the drive) and ``value`` its joint value at the branch's last point (radians, or length for a
    prismatic joint); ``point`` the located point for ``KNOWN_POINT``, ``COMPONENT`` and ``NOT_LEFT``; ``text`` the
    sentence a person reads (``Branch.end_reason``)."""

    kind: StopReason
    text: str
    joint: str | None = None
    value: float | None = None
    point: int | None = None
