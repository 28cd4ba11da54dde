"""The result of tracing a mechanism: every point of every branch, its located bifurcation points and branches.

:class:`Trace` is what :func:`linkwork.kinematics.tracer.trace` returns (``lw.trace``); :class:`Bifurcation` and
:class:`Branch` describe the branch graph. Angles are radians, as everywhere in the Python API.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from linkwork.kinematics.mechanism import Mechanism

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Bifurcation:
    """A located bifurcation point.

    ``angles`` are the joint values (radians) there, ``tangents`` the branch tangents as unit vectors over the
    joints (one per line through the point) and ``tangents_u`` the same over the unknowns, ``sigma`` the
    Jacobian's singular values. ``kind`` is ``"bifurcation"`` (an isolated point with two or more branch
    tangents), ``"fold"`` (a rank drop with fewer than two real branch tangents: the path touches the singular
    set and no other branch leaves it) or ``"component"`` (where the path meets a higher-dimensional component of
    the configuration space: ``dimension`` is its dimension, the mobility on it; no branch is switched to there).
    """

    id: int
    branch: int
    step: int
    u: Array
    angles: Array
    rank: int
    sigma: Array
    tangents: Array
    method: str
    residual: float
    bracket: float
    tangents_u: Array = field(default_factory=lambda: np.zeros((0, 0)))
    kind: str = "bifurcation"
    dimension: int = 0


@dataclass(frozen=True)
class Fold:
    """A fold (limit point) of the drive on a branch: the drive stops and turns back there.

    ``value`` is the drive's extreme value (radians, or length for a prismatic drive), ``angles`` every joint
    there, ``step`` the step of the branch just before it.
    """

    branch: int
    step: int
    value: float
    angles: Array


@dataclass(frozen=True)
class Branch:
    """One traced branch: where it starts (parent branch and bifurcation, or the start), direction, end.

    ``mobility`` is the mobility (unknowns minus rank) that holds along the branch away from its ends.
    """

    id: int
    parent: int | None
    bifurcation: int | None
    direction: int
    steps: int
    end_reason: str
    mobility: int = 1


@dataclass(frozen=True)
class Trace:
    """A traced motion: every point of every branch, in the order traced.

    Attributes
    ----------
    angles
        ``(N, n)`` joint values in radians (``mech.joint_names`` order), ``offsets + q``.
    sigma
        ``(N, k)`` singular values of the reduced Jacobian, descending.
    residual
        ``(N,)`` closure residual (2-norm of the stacked loop logarithms).
    branch, step
        ``(N,)`` branch id and step number of each point.
    arclength
        ``(N,)`` arclength in the unknowns along each branch.
    test
        ``(N,)`` the signed bifurcation test function.
    rank
        ``(N,)`` numerical rank of the Jacobian at each point; ``mobility = n_unknowns - rank``.
    """

    mechanism: Mechanism
    drive: str
    angles: Array
    sigma: Array
    residual: Array
    branch: NDArray[np.int64]
    step: NDArray[np.int64]
    arclength: Array
    test: Array
    rank: NDArray[np.int64]
    bifurcations: tuple[Bifurcation, ...]
    branches: tuple[Branch, ...]
    stats: Mapping[str, Any] = field(default_factory=dict)
    folds: tuple[Fold, ...] = ()

    @property
    def mobility(self) -> NDArray[np.int64]:
        """``(N,)`` number of unknowns minus rank at every point."""
        return self.mechanism.n_unknowns - self.rank

    @property
    def max_condition(self) -> float:
        """Largest ratio of largest to smallest non-zero singular value along the path (Sec. 5)."""
        ratios = [
            s[0] / s[r - 1] for s, r in zip(self.sigma, self.rank, strict=True) if r > 0 and s[r - 1] > 0
        ]
        return float(max(ratios)) if ratios else float("nan")

    def condition(self) -> Array:
        """``(N,)`` ratio of the largest to the smallest non-zero singular value at every point."""
        out = np.full(len(self.rank), np.nan)
        for i, (s, r) in enumerate(zip(self.sigma, self.rank, strict=True)):
            if r > 0 and s[r - 1] > 0:
                out[i] = s[0] / s[r - 1]
        return out

    def of_branch(self, branch: int) -> NDArray[np.bool_]:
        """Boolean mask of the points of one branch."""
        return self.branch == branch
