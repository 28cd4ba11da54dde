"""Deployment measures of a traced path: membrane stretch, bundle ratio, flatness, bifurcations on the way.

Gan & Pellegrino (2006, Sec. 7) judge a deployable loop by more than its mobility: "if a thin, flat membrane were
to be attached to either of these structures, during deployment it would be required to stretch by a significant
amount", and they want structures that fold "into a tight bundle" and deploy "into a flat polygonal shape".
:func:`deployment` puts numbers on those words for any :class:`~linkwork.kinematics.trace_result.Trace`; the
formulas are in ``docs/deployment.md``.

The deployment path is branch 0 of the trace; the deployed configuration is its last point, or where a chosen
joint first reaches a chosen value on it (a structure traced from its flat, deployed start, such as a
``rect-frame``: ``deployed_at = ("A", 0.0)``). The attachment points are the named points of the spec (``[[points]]``) when it
declares any, else every joint's point, as written to ``points.csv``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from linkwork.errors import ConvergenceError, RequestNotMetError
from linkwork.kinematics.closure import closure_residual, jacobian
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.points import named_points, positions

if TYPE_CHECKING:
    from linkwork.kinematics.trace_result import Trace

Array = NDArray[np.float64]

COINCIDENT = 1e-9
"""Pairs of attachment points closer than this fraction of the deployed size in the deployed configuration are
left out of the stretch (their ratio has no meaning)."""

TIE = 1e-12
"""Relative difference below which two values of a measure along the path count as equal (round-off)."""

PAIR_BLOCK = 1 << 20
"""The most pair distances computed at once (points x pairs): about 50 MB of temporaries, whatever the number of
points."""


@dataclass(frozen=True)
class Deployment:
    """The deployment measures of a traced path (lengths in the mechanism's unit, angles in radians).

    Attributes
    ----------
    attachment
        Names of the attachment points (named points, else joints).
    path
        ``(K,)`` rows of the trace on the deployment path: branch 0.
    deployed_at
        ``(joint, value)`` when the deployed configuration was chosen by a joint value, else ``None`` (the last
        point of branch 0).
    deployed_angles
        ``(n,)`` joint values of the deployed configuration.
    deployed_size
        Largest distance between two attachment points in the deployed configuration.
    membrane_stretch
        ``max over the path and every pair (i, j) of |p_i - p_j| / |p_i - p_j|_deployed - 1``; zero when no
        distance ever exceeds its deployed value, positive when a membrane spanning the deployed shape must
        stretch.
    stretch_pair
        The pair of attachment points where the largest stretch occurs.
    stretch_row
        The trace row where it occurs.
    stretch_along
        ``(K,)`` the largest stretch over all pairs at every point of :attr:`path`.
    bundle_ratio
        ``min over the path of size / deployed_size`` (size: the largest distance between two attachment points):
        how compact the most folded configuration is.
    bundle_row
        The trace row of the most compact configuration.
    size_along
        ``(K,)`` the size at every point of :attr:`path`.
    flatness
        ``sigma_3 / sigma_1`` of the centred ``(m, 3)`` deployed attachment points: the RMS distance to their
        best-fit plane over their RMS spread along their main direction. Zero when they are coplanar.
    bifurcations_on_path
        Bifurcation points (and points where a higher-dimensional component is met) located on the path.
    mobility_on_path
        The largest mobility on the path, counting the rank drop at its located singular points.
    """

    attachment: tuple[str, ...]
    path: NDArray[np.int64]
    deployed_at: tuple[str, float] | None
    deployed_angles: Array
    deployed_size: float
    membrane_stretch: float
    stretch_pair: tuple[str, str]
    stretch_row: int
    stretch_along: Array
    bundle_ratio: float
    bundle_row: int
    size_along: Array
    flatness: float
    bifurcations_on_path: int
    mobility_on_path: int


def attachment_names(mech: Mechanism) -> tuple[str, ...]:
    """The attachment points' names: the spec's named points if it declares any, else the joints."""
    named = named_points(mech)
    return tuple(str(p["name"]) for p in named) if named else tuple(mech.joint_names)


def attachment_positions(mech: Mechanism, angles: Array) -> Array:
    """``(N, m, 3)`` world coordinates of the attachment points at joint values ``angles`` ``(N, n)``."""
    joints, named = positions(mech, np.atleast_2d(angles))
    return named if named.shape[1] else joints


def pair_extremes(points: Array, deployed: Array) -> tuple[Array, NDArray[np.int64], Array, Array]:
    """Over every pair of attachment points, at every configuration of ``points`` ``(N, m, 3)``:

    the largest ``|p_i - p_j| / |p_i - p_j|_deployed - 1`` ``(N,)``, the pair index where it occurs ``(N,)`` (into
    ``np.triu_indices(m, 1)``), the largest distance (size) ``(N,)``, and the deployed distances ``(P,)``.
    Vectorised, ``O(N m^2)`` time, memory bounded by :data:`PAIR_BLOCK`.
    """
    m = points.shape[1]
    i, j = np.triu_indices(m, 1)
    ref = np.linalg.norm(deployed[i] - deployed[j], axis=-1)
    n = len(points)
    stretch = np.zeros(n)
    where = np.zeros(n, dtype=np.int64)
    size = np.zeros(n)
    if len(i) == 0:
        return stretch, where, size, ref
    keep = ref > COINCIDENT * max(float(ref.max()), np.finfo(float).tiny)
    inverse = np.where(keep, 1.0 / np.where(keep, ref, 1.0), 0.0)
    coords = np.ascontiguousarray(np.moveaxis(points, 2, 0))  # (3, N, m): one coordinate at a time
    block = max(1, PAIR_BLOCK // len(i))
    for start in range(0, n, block):
        stop = min(n, start + block)
        squared = np.zeros((stop - start, len(i)))
        for c in coords:
            diff = c[start:stop, i] - c[start:stop, j]
            squared += diff * diff
        dist = np.sqrt(squared)  # (b, P)
        size[start:stop] = dist.max(axis=1)
        ratio = np.where(keep, dist * inverse - 1.0, -np.inf)
        where[start:stop] = np.argmax(ratio, axis=1)
        stretch[start:stop] = ratio[np.arange(stop - start), where[start:stop]]
    if not np.any(keep):
        stretch[:] = 0.0
    return stretch, where, size, ref


def flatness_of(points: Array) -> float:
    """``sigma_3 / sigma_1`` of the centred ``(m, 3)`` points (0 for fewer than three points or a single point)."""
    if len(points) < 3:
        return 0.0
    s = np.linalg.svd(points - points.mean(axis=0), compute_uv=False)
    return float(s[2] / s[0]) if s[0] > 0 else 0.0


def deployment(
    trace: Trace,
    deployed_at: tuple[str, float] | None = None,
) -> Deployment:
    """The deployment measures of ``trace`` (see :class:`Deployment`).

    Parameters
    ----------
    trace
        A traced path; its branch 0 is the deployment path.
    deployed_at
        ``(joint, value)`` (radians, or a length for a prismatic joint): the deployed configuration is where that
        joint first reaches ``value`` on branch 0 (between two traced points it is solved onto the loop with the
        joint held there, and counts as a point of the path). Default: the last point of branch 0.

    Raises
    ------
    RequestNotMetError
        ``value`` is not reached on branch 0 (the message gives the joint's range there).
    """
    mech = trace.mechanism
    rows = np.flatnonzero(trace.branch == 0)
    if len(rows) == 0:
        raise RequestNotMetError("the trace has no branch 0 to measure")
    extra_end: Array | None = None
    if deployed_at is None:
        deployed = trace.angles[rows[-1]]
    else:
        deployed, extra_end = _deployed_at(trace, rows, deployed_at)
    angles = trace.angles[rows] if extra_end is None else np.vstack([trace.angles[rows], extra_end])
    pts = attachment_positions(mech, angles)
    dep_pts = attachment_positions(mech, deployed[None, :])[0]
    stretch, where, size, ref = pair_extremes(pts, dep_pts)
    names = attachment_names(mech)
    pi, pj = np.triu_indices(len(names), 1)
    # The first point within round-off of the extreme: a plateau (the bundle before it opens) reports its start.
    k = int(np.flatnonzero(stretch >= stretch.max() - TIE * max(1.0, abs(float(stretch.max()))))[0])
    deployed_size = float(ref.max()) if len(ref) else 0.0
    bundle = int(np.flatnonzero(size <= size.min() * (1.0 + TIE))[0])
    last_step = int(trace.step[rows[-1]])
    located = [b for b in trace.bifurcations if b.branch == 0 and b.step <= last_step and b.kind != "fold"]
    mobility = int(trace.mobility[rows].max())
    for b in located:
        mobility = max(mobility, mech.n_unknowns - int(b.rank))
    path_rows = np.asarray(rows, dtype=np.int64)
    row_of = np.append(path_rows, path_rows[-1]) if extra_end is not None else path_rows
    pair = (names[pi[where[k]]], names[pj[where[k]]]) if len(pi) else ("", "")
    return Deployment(
        attachment=names,
        path=path_rows,
        deployed_at=deployed_at,
        deployed_angles=np.array(deployed, dtype=float),
        deployed_size=deployed_size,
        membrane_stretch=float(max(stretch[k], 0.0)),
        stretch_pair=pair,
        stretch_row=int(row_of[k]),
        stretch_along=stretch[: len(path_rows)],
        bundle_ratio=float(size[bundle] / deployed_size) if deployed_size > 0 else float("nan"),
        bundle_row=int(row_of[bundle]),
        size_along=size[: len(path_rows)],
        flatness=flatness_of(dep_pts),
        bifurcations_on_path=len(located),
        mobility_on_path=mobility,
    )


def _deployed_at(
    trace: Trace, rows: NDArray[np.int64], deployed_at: tuple[str, float]
) -> tuple[Array, Array | None]:
    """The configuration where joint ``deployed_at[0]`` first reaches ``deployed_at[1]`` on branch 0 (``rows``),
    and the same again when it falls between two traced points (an extra point of the path)."""
    mech = trace.mechanism
    name, value = deployed_at
    j = mech.index(name)
    values = trace.angles[rows, j]
    exact = np.flatnonzero(values == value)
    crossing = np.flatnonzero((values[:-1] - value) * (values[1:] - value) < 0)
    first = min([*exact[:1].tolist(), *(crossing[:1] + 0.5).tolist()], default=None)
    if first is None:
        revolute = mech.joint_types[j] == "R"
        unit, scale = (" deg", 180.0 / np.pi) if revolute else ("", 1.0)
        raise RequestNotMetError(
            f"deployed at {name}={value * scale:.6g}{unit}: not on the deployment path; on branch 0 {name} goes "
            f"from {values.min() * scale:.6g} to {values.max() * scale:.6g}{unit}"
        )
    if float(first).is_integer():
        return trace.angles[rows[int(first)]], None
    k = int(first - 0.5)
    a, b = trace.angles[rows[k]], trace.angles[rows[k + 1]]
    t = (value - a[j]) / (b[j] - a[j])
    guess = a + t * (b - a)
    solved = _close_with_joint(mech, guess, j, value)
    return solved, solved


def _close_with_joint(mech: Mechanism, angles: Array, j: int, value: float) -> Array:
    """Joint values near ``angles`` that close the loops with joint ``j`` at ``value`` (Gauss-Newton on the
    unknowns, as the tracer's corrector, G&P Eq. (28))."""
    C = mech.coupling_matrix()
    q = np.array(angles - mech.offsets, dtype=float)
    target = value - mech.offsets[j]
    for _ in range(30):
        residual = np.append(closure_residual(mech, q), q[j] - target)
        if np.linalg.norm(residual) < 1e-13:
            return mech.offsets + q
        jac = np.vstack([jacobian(mech, q) @ C, C[j]])
        q = q - C @ np.linalg.lstsq(jac, residual, rcond=None)[0]
    if np.linalg.norm(np.append(closure_residual(mech, q), q[j] - target)) < 1e-10:
        return mech.offsets + q
    raise ConvergenceError(f"cannot close the loop with {mech.joint_names[j]} at the deployed value")
