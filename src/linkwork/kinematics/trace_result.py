"""The result of tracing a mechanism: every point of every branch, its located bifurcation points and branches.

:class:`Trace` is what :func:`linkwork.kinematics.tracer.trace` returns (``lw.trace``); :class:`Bifurcation` and
:class:`Branch` describe the branch graph. Angles are radians, as everywhere in the Python API.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.normalization import condition_ratios
from linkwork.kinematics.stops import End, StopReason
from linkwork.kinematics.trace_stats import TraceStats

if TYPE_CHECKING:
    from linkwork.kinematics.deployment import Deployment

Array = NDArray[np.float64]

ARCLENGTH_WEIGHTS = "arclength weights"
"""The key :func:`arclength_weights` keeps its value under on a mechanism (a twin in its own frame is given its
user's, :func:`linkwork.kinematics.own_frame.twin`)."""


def arclength_weights(mech: Mechanism) -> Array:
    """``(2, m)``: each unknown's weight in the two arclengths a trace sums step by step (every part of a paper
    row included): row 0 :attr:`Trace.arclength`'s (1: radians and the length unit), row 1
    :attr:`Trace.arclength_in_file_units`' (``degrees(1)`` for a revolute unknown, 1 for a prismatic one). A
    step's increment in either is ``|w * du|`` over the unknowns' change ``du``. A twin traced in its own frame
    measures its lengths in its user's unit (``L`` the user's length per twin length), so that its trace reports
    the user's arclengths. Read-only, once per mechanism."""

    def build() -> Array:
        revolute = np.array([mech.joint_types[j] == "R" for j in mech.first_joints], dtype=bool)
        weights = np.ones((2, len(revolute)))
        weights[1, revolute] = np.degrees(1.0)
        weights.flags.writeable = False
        return weights

    return mech.derived(ARCLENGTH_WEIGHTS, build)


def has_file_arclength(mech: Mechanism) -> bool:
    """Whether a trace of ``mech`` has an arclength in file units of its own (a prismatic unknown: the file
    units are then not ``degrees`` of the unknowns' own; :attr:`Trace.arclength_in_file_units`), once per
    mechanism."""
    return mech.derived(
        "file arclength kept", lambda: any(mech.joint_types[j] != "R" for j in mech.first_joints)
    )


@dataclass(frozen=True)
class Bifurcation:
    """A located bifurcation point.

    ``angles`` are the joint values (radians) there, ``tangents`` the branch tangents as unit vectors over the
    joints (one per line through the point) and ``tangents_u`` the same over the unknowns, ``sigma`` the
    Jacobian's singular values; ``u`` is the point in the tracer's unknowns (displacements from the reference
    configuration, one per independent joint). ``kind`` is ``"bifurcation"`` (an isolated point with two or more branch
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
    ``end_reason`` is the sentence a person reads; the same end, structured: ``end_kind`` (a
    :class:`~linkwork.kinematics.stops.StopReason`), ``end_joint`` the joint it is about (the limited joint for
    a limit, otherwise the drive) and ``end_value`` that joint's value at the branch's last point (radians, or
    length for a prismatic joint), ``end_point`` the located point it ended on (a known point, a component) or
    could not leave.
    """

    id: int
    parent: int | None
    bifurcation: int | None
    direction: int
    steps: int
    end_reason: str
    mobility: int = 1
    end_kind: StopReason | None = None
    end_joint: str | None = None
    end_value: float | None = None
    end_point: int | None = None

    @classmethod
    def ended(
        cls, id: int, parent: int | None, bifurcation: int | None, direction: int, steps: int, end: End
    ) -> Branch:
        """A branch that ended as ``end`` says."""
        return cls(
            id, parent, bifurcation, direction, steps, end.text,
            end_kind=end.kind, end_joint=end.joint, end_value=end.value, end_point=end.point,
        )  # fmt: skip

    @property
    def end(self) -> End | None:
        """How the branch ended, structured (``None`` for a branch built without a kind)."""
        if self.end_kind is None:
            return None
        return End(self.end_kind, self.end_reason, self.end_joint, self.end_value, self.end_point)


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
        ``(N,)`` arclength in the unknowns along each branch (radians for revolute unknowns, the length unit for
        prismatic ones).
    arclength_in_file_units
        ``(N,)`` the same arclength with revolute unknowns measured in degrees (``path.csv``'s ``s``, the viewer's
        arclength axis), summed by the tracer over every part of each step as :attr:`arclength` is (a long paper
        row's parts turn, so its chord does not give it); ``None`` where the rows give it
        (:func:`linkwork.io.results.file_arclength`): ``degrees(arclength)`` without a prismatic unknown, and
        each row's increment of :attr:`arclength` times its chord ratio where every row is one step of the sum
        (the closed form's short rows).
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
    stats: TraceStats = field(default_factory=TraceStats)
    folds: tuple[Fold, ...] = ()
    arclength_in_file_units: Array | None = None

    @property
    def mobility(self) -> NDArray[np.int64]:
        """``(N,)`` number of unknowns minus rank at every point."""
        return self.mechanism.n_unknowns - self.rank

    @property
    def max_condition(self) -> float:
        """Largest robustness ratio along the path (Sec. 5), on the normalised Jacobian.

        The ratio of the largest to the smallest non-zero singular value of the closure Jacobian with moments
        about the linkage's own centre and lengths in its own scale
        (:mod:`linkwork.kinematics.normalization`): unchanged when the linkage is moved, turned, scaled or
        relabelled. :attr:`max_condition_raw` is the same ratio of the raw singular values in :attr:`sigma`.
        """
        ratios = self.condition()
        return float(np.nanmax(ratios)) if np.any(np.isfinite(ratios)) else float("nan")

    def condition(self) -> Array:
        """``(N,)`` robustness ratio at every point, on the normalised Jacobian (see :attr:`max_condition`)."""
        return self._normalized_condition.copy()

    @cached_property
    def _normalized_condition(self) -> Array:
        return condition_ratios(self.mechanism, self.angles, self.rank)

    @property
    def max_condition_raw(self) -> float:
        """Largest ratio of the raw singular values (:attr:`sigma`, base frame and file units) along the path."""
        ratios = self.condition_raw()
        return float(np.nanmax(ratios)) if np.any(np.isfinite(ratios)) else float("nan")

    def condition_raw(self) -> Array:
        """``(N,)`` ratio of the largest to the smallest non-zero raw singular value at every point."""
        out = np.full(len(self.rank), np.nan)
        for i, (s, r) in enumerate(zip(self.sigma, self.rank, strict=True)):
            if r > 0 and s[r - 1] > 0:
                out[i] = s[0] / s[r - 1]
        return out

    def of_branch(self, branch: int) -> NDArray[np.bool_]:
        """Boolean mask of the points of one branch."""
        return self.branch == branch

    # ---------------------------------------------------------------------------------------- notebook use
    def positions(self) -> Array:
        """``(N, n, 3)`` world coordinates of every joint at every point, in ``mechanism.joint_names`` order.

        A joint's point is a fixed point on its axis (see :mod:`linkwork.kinematics.positions`), placed by the
        pose of its body; the reference offsets are taken care of.
        """
        from linkwork.kinematics.positions import joint_positions

        return joint_positions(self.mechanism, self.angles, self.poses())

    def poses(self) -> dict[str, Array]:
        """``{body: (N, 4, 4)}`` the world pose of every body at every point (displacement from the reference
        configuration, the first body or the ground held still)."""
        from linkwork.kinematics.positions import poses_along

        return poses_along(self.mechanism, self.angles)

    def deployment(self, deployed_at: tuple[str, float] | None = None) -> Deployment:
        """The deployment measures of branch 0 (membrane stretch, bundle ratio, flatness, bifurcations on the
        path; :func:`linkwork.kinematics.deployment.deployment`). ``deployed_at = (joint, value)`` in radians
        chooses the deployed configuration (default: the last point of branch 0)."""
        from linkwork.kinematics.deployment import deployment

        return deployment(self, deployed_at)

    def plot(self, kind: str = "angles", *, branch: int = 0) -> Any:
        """A matplotlib ``Figure``: ``kind="angles"`` (every hinge angle against the drive, all branches) or
        ``"singular_values"`` (the Jacobian's singular values along ``branch``). Needs ``linkwork[viz]``."""
        from linkwork.viz import trace_plots

        if kind == "angles":
            return trace_plots.angles_figure(self)
        if kind == "singular_values":
            return trace_plots.singular_values_figure(self, branch)
        raise ValueError(f"Expected kind 'angles' or 'singular_values', got {kind!r}")

    def __repr__(self) -> str:
        """A few lines a notebook user can read: size, joints, branches, the range of the drive, accuracy."""
        return "\n".join(_summary_lines(self))

    def _repr_html_(self) -> str:
        """The interactive viewer (the same page ``linkwork trace --html`` writes), inline in Jupyter, its path
        thinned to stay under :data:`linkwork.viz.inline.INLINE_BYTES` (the data here stay whole)."""
        from linkwork.viz.inline import trace_html

        return trace_html(self)


def _names(names: tuple[str, ...], most: int = 12) -> str:
    """Joint names, shortened in the middle when there are many."""
    if len(names) <= most:
        return ", ".join(names)
    return ", ".join(names[: most - 2]) + f", ... , {names[-1]}"


def _num(value: float, digits: int = 6) -> str:
    """A joint value for a summary: ``digits`` significant digits, round-off next to zero shown as 0."""
    return f"{0.0 if abs(value) < 5e-10 else value:.{digits}g}"


def _branch_motion(trace: Trace, branch: int) -> str:
    """What moves along one branch: the drive from its first to its last value, or, where the drive stays put
    (a branch of a bifurcation on which the drive is locked), the joint that moves most."""
    mech = trace.mechanism
    on = trace.branch == branch
    if not np.any(on):
        return ""
    scale = np.where(np.array(mech.joint_types) == "R", 180.0 / np.pi, 1.0)
    values = trace.angles[on] * scale
    units = ["deg" if t == "R" else "" for t in mech.joint_types]
    d = mech.index(trace.drive)
    first, last = values[0, d], values[-1, d]
    lo, hi = values[:, d].min(), values[:, d].max()
    if hi - lo > 1e-6:
        passed = f" (via {_num(lo, 5)} to {_num(hi, 5)})" if hi - lo > abs(last - first) + 1e-6 else ""
        return f", {trace.drive} {_num(first, 5)} -> {_num(last, 5)} {units[d]}".rstrip() + passed
    j = int(np.argmax(np.ptp(values, axis=0)))
    return (
        f", {trace.drive} at {_num(first, 5)} {units[d]}".rstrip()
        + f", {mech.joint_names[j]} {_num(values[0, j], 5)} -> {_num(values[-1, j], 5)} {units[j]}".rstrip()
    )


def _summary_lines(trace: Trace) -> list[str]:
    mech = trace.mechanism
    n_points = len(trace.angles)
    d = mech.index(trace.drive)
    unit, scale = ("deg", 180.0 / np.pi) if mech.joint_types[d] == "R" else ("", 1.0)
    drive = trace.angles[:, d] * scale if n_points else np.zeros(1)
    mobility = trace.mobility
    several = len(trace.branches) > 1
    if several and n_points:  # the first and last points are on different branches: give the range covered
        extent = f"over {_num(drive.min())} to {_num(drive.max())} {unit} on all branches"
    else:
        extent = f"from {_num(drive[0])} to {_num(drive[-1])} {unit}"
    lines = [
        f"Trace of {mech.name!r}: {n_points} points, {len(trace.branches)} branch(es), "
        f"{len(trace.bifurcations)} bifurcation point(s)",
        f"  joints ({mech.n_joints}): {_names(mech.joint_names)}; drive {trace.drive} {extent}".rstrip(),
    ]
    if n_points:
        lines.append(
            f"  mobility {int(mobility.min())}..{int(mobility.max())}; max closure residual "
            f"{float(np.max(trace.residual)):.2e}; max condition {trace.max_condition:.4g}"
        )
    for br in trace.branches[:4]:
        origin = "start" if br.parent is None else f"bifurcation {br.bifurcation} (branch {br.parent})"
        run = _branch_motion(trace, br.id) if several else ""
        lines.append(f"  branch {br.id}: {br.steps} steps from {origin}{run}; {br.end_reason}")
    if len(trace.branches) > 4:
        lines.append(f"  ... {len(trace.branches) - 4} more branches (trace.branches)")
    lines.append("  .angles (N, n) rad, .positions() (N, n, 3), .poses(), .plot(), .sigma, .bifurcations")
    return lines
