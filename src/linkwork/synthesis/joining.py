"""Joining the chain (Sec. 5): pose rigid segment shapes end to end so they best match one profile.

Per profile the unknowns are the chain's first point and one chord angle per segment (``q + 2``, Fig. 9b);
the shapes are fixed. The objective is the sum of squared distances between the chain's points and the target
points (Eq. 33). A closed profile adds ``end = start`` (Eq. 31), a fixed-end profile pins both ends (Eq. 32).
Joints held at a fixed relative angle (compound segments, Sec. 6) tie one angle to the one before it.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013),
Eqs. (21), (29)-(33).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares, minimize

from linkwork.errors import ConvergenceError
from linkwork.synthesis.frames import chord_angle, rotation
from linkwork.synthesis.result import JoinedProfile, Segment, TargetProfile

Array = NDArray[np.float64]
Fn = Callable[[Array], Array]

#: The closure or end constraint is satisfied to this residual after joining.
CONSTRAINT_TOL = 1e-12


def _perp(v: Array) -> Array:
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


class ChainPose:
    """The chain of fixed segment shapes as a function of its first point and chord angles.

    Parameters
    ----------
    shapes
        Per segment, its ``(n_e, 2)`` points in the local frame (first point at the origin).
    """

    def __init__(self, shapes: Sequence[Array]) -> None:
        self.shapes = [np.asarray(s, dtype=float) for s in shapes]
        loc = [self.shapes[0]] + [s[1:] for s in self.shapes[1:]]
        self.local = np.vstack(loc)
        self.seg = np.concatenate([np.full(len(pts), e) for e, pts in enumerate(loc)])
        self.ends = np.stack([s[-1] for s in self.shapes])  # local chord vectors
        self.first_index = np.concatenate([[0], np.cumsum([len(s) - 1 for s in self.shapes])])

    @property
    def q(self) -> int:
        """Number of segments."""
        return len(self.shapes)

    def joints(self, start: Array, theta: Array) -> Array:
        """``(q + 1, 2)`` segmentation points."""
        chords = np.einsum("qab,qb->qa", rotation(theta), self.ends)
        return np.vstack([start, start + np.cumsum(chords, axis=0)])

    def points(self, start: Array, theta: Array) -> Array:
        """``(n, 2)`` chain points, one per target point (Eq. 29)."""
        rl = np.einsum("nab,nb->na", rotation(theta)[self.seg], self.local)
        return self.joints(start, theta)[self.seg] + rl

    def jacobian_theta(self, theta: Array) -> Array:
        """``(n, 2, q)`` derivative of the points with respect to the chord angles."""
        rot = rotation(theta)
        rl = _perp(np.einsum("nab,nb->na", rot[self.seg], self.local))
        chords = _perp(np.einsum("qab,qb->qa", rot, self.ends))
        k = np.arange(self.q)
        later = (self.seg[:, None] > k[None, :])[:, None, :] * chords.T[None, :, :]
        own = (self.seg[:, None] == k[None, :])[:, None, :] * rl[:, :, None]
        return later + own

    def closure_jacobian(self, theta: Array) -> Array:
        """``(2, q)`` derivative of the chain's end point with respect to the chord angles."""
        return _perp(np.einsum("qab,qb->qa", rotation(theta), self.ends)).T


def angle_map(q: int, ties: Sequence[tuple[int, float]]) -> tuple[Array, Array]:
    """``(T, b)`` with ``theta = T @ phi + b``: joint ``i`` tied means ``theta_{i+1} = theta_i + offset``."""
    tie = dict(ties)
    cols: list[int] = []
    b = np.zeros(q)
    for e in range(q):
        if e - 1 in tie:
            cols.append(cols[-1])
            b[e] = b[e - 1] + tie[e - 1]
        else:
            cols.append(max(cols, default=-1) + 1)
    t = np.zeros((q, cols[-1] + 1))
    t[np.arange(q), cols] = 1.0
    return t, b


class _ChainFit:
    """The least-squares problem of posing one chain on one profile (Eqs. 29-33), over the unknowns ``u``.

    ``u`` holds the chain's first point (two entries, absent when the ends are pinned) and the free chord angles
    ``phi``; the chord angles are ``theta = T @ phi + b`` (:func:`angle_map`, the ties of compound segments).
    """

    def __init__(
        self,
        chain: ChainPose,
        target: Array,
        ties: Sequence[tuple[int, float]],
        closed: bool,
        ends: tuple[ArrayLike, ArrayLike] | None,
    ) -> None:
        self.chain = chain
        self.target = target
        self.t_map, self.b = angle_map(chain.q, ties)
        self.closed = closed
        self.fixed_start = None if ends is None else np.asarray(ends[0], dtype=float)
        self.end_point = None if ends is None else np.asarray(ends[1], dtype=float)
        self.nf = 0 if self.fixed_start is not None else 2  # unknowns of the first point
        self.constrained = closed or ends is not None

    def initial(self, start: ArrayLike, angles: ArrayLike) -> Array:
        """The unknowns of a first point and chord angles ``(q,)``."""
        theta0 = np.asarray(angles, dtype=float)
        # the free angles: least squares through the tie map, exact when theta0 already satisfies the ties
        phi0 = np.linalg.lstsq(self.t_map, theta0 - self.b, rcond=None)[0]
        return np.concatenate([np.asarray(start, dtype=float) if self.nf else np.zeros(0), phi0])

    def unpack(self, u: Array) -> tuple[Array, Array]:
        """``(start, theta)``: the chain's first point and its ``(q,)`` chord angles."""
        s = self.fixed_start if self.fixed_start is not None else u[:2]
        return s, self.t_map @ u[self.nf :] + self.b

    def residual(self, u: Array) -> Array:
        """Chain points minus target points, flattened (Eq. 33)."""
        s, th = self.unpack(u)
        return (self.chain.points(s, th) - self.target).ravel()  # Eq. (33)

    def jac(self, u: Array) -> Array:
        """Derivative of :meth:`residual`."""
        _, th = self.unpack(u)
        jt = self.chain.jacobian_theta(th).reshape(-1, self.chain.q) @ self.t_map
        if self.nf == 0:
            return jt
        js = np.tile(np.eye(2), (len(self.target), 1))
        return np.hstack([js, jt])

    def constraint(self, u: Array) -> Array:
        """The chain's end minus its start (closed, Eq. 31) or minus the pinned end point (Eq. 32)."""
        s, th = self.unpack(u)
        tip = self.chain.joints(s, th)[-1]
        return tip - (s if self.closed else self.end_point)  # Eq. (31) / Eq. (32)

    def constraint_jac(self, u: Array) -> Array:
        """Derivative of :meth:`constraint`."""
        _, th = self.unpack(u)
        g = self.chain.closure_jacobian(th) @ self.t_map
        return np.hstack([np.zeros((2, self.nf)), g]) if self.nf else g

    def check_reach(self) -> None:
        """Raise :class:`ConvergenceError` when no pose of the chain can meet Eq. 31 (closed) or Eq. 32.

        Segments tied at fixed joints form one rigid body; each body's chord is a link of the polygon
        inequality of :func:`reach_gap`.
        """
        chords = np.einsum("qab,qb->qa", rotation(self.b), self.chain.ends)
        lengths = np.linalg.norm(self.t_map.T @ chords, axis=1)
        span = 0.0 if self.closed else float(np.linalg.norm(self.end_point - self.fixed_start))  # type: ignore[operator]
        gap = reach_gap(lengths, span)
        if gap <= 1e-9 * max(float(lengths.sum()), 1.0):
            return
        what = "close on itself" if self.closed else f"span its fixed ends {span:.6g} apart"
        why = (
            "the chain is shorter than that"
            if span > lengths.sum()
            else "one segment's chord is longer than all the others' together"
        )
        text = ", ".join(f"{v:.4g}" for v in lengths)
        raise ConvergenceError(f"joining: a chain of chords {text} cannot {what} (short by {gap:.3g}): {why}")

    def target_start(self) -> Array:
        """Unknowns that put every segment's chord along the target's chord between its segmentation points."""
        chain, z, b = self.chain, self.target, self.b
        first = chain.first_index
        target_chords = z[first[1:]] - z[first[:-1]]
        theta = np.arctan2(target_chords[:, 1], target_chords[:, 0]) - np.arctan2(
            chain.ends[:, 1], chain.ends[:, 0]
        )
        theta = b + np.unwrap(theta - b)
        phi = np.linalg.lstsq(self.t_map, theta - b, rcond=None)[0]
        return np.concatenate([z[0] if self.nf else np.zeros(0), phi])

    def joined(self, u: Array) -> JoinedProfile:
        """The chain posed by ``u`` and each segment's largest point-to-point distance (Eq. 21)."""
        chain = self.chain
        s, th = self.unpack(u)
        pts = chain.points(s, th)
        dist = np.linalg.norm(pts - self.target, axis=1)
        first = chain.first_index
        errors = np.array([dist[first[e] : first[e + 1] + 1].max() for e in range(chain.q)])  # Eq. (21)
        return JoinedProfile(joints=chain.joints(s, th), points=pts, angles=th, errors=errors)


def join_profile(
    shapes: Sequence[Array],
    target: ArrayLike,
    start: ArrayLike,
    angles: ArrayLike,
    *,
    closed: bool = False,
    ends: tuple[ArrayLike, ArrayLike] | None = None,
    ties: Sequence[tuple[int, float]] = (),
) -> JoinedProfile:
    """Join the segments and pose the chain on one target profile (Sec. 5).

    Parameters
    ----------
    shapes
        Per segment, its points ``(m_j^e + 1, 2)`` in the local frame; piece counts sum to the profile's.
    target
        ``(m_j + 1, 2)`` target points.
    start, angles
        Initial guess: first point ``(2,)`` and chord angles ``(q,)`` (e.g. from the segmentation).
    closed
        Add the closure constraint ``end = start`` (Eq. 31).
    ends
        Pin the first and last chain points (Eq. 32).
    ties
        ``(i, offset)``: joint ``i`` is clamped, ``theta_{i+1} = theta_i + offset`` (Sec. 6).

    Raises
    ------
    ConvergenceError
        When the constrained optimiser fails or the constraint cannot be met.
    """
    chain = ChainPose(shapes)
    z = np.asarray(target, dtype=float)
    if len(chain.local) != len(z):
        raise ValueError(f"Expected {len(chain.local)} target points for these segments, got {len(z)}")
    fit = _ChainFit(chain, z, ties, closed, ends)
    u0 = fit.initial(start, angles)
    if not fit.constrained:
        sol = least_squares(fit.residual, u0, jac=fit.jac, method="lm", xtol=1e-14, ftol=1e-14, gtol=1e-14)
        return fit.joined(_polish(fit.residual, fit.jac, None, None, sol.x))
    fit.check_reach()
    starts = [u0, fit.target_start()]
    free_angles = slice(fit.nf, None)
    feasible = _constrained(fit.residual, fit.jac, fit.constraint, fit.constraint_jac, starts, free_angles)
    try:
        polished = _polish(fit.residual, fit.jac, fit.constraint, fit.constraint_jac, feasible)
        u = _project(fit.constraint, fit.constraint_jac, polished, free_angles)
    except ConvergenceError:
        u = feasible  # the polish left the constraint for good: keep the optimiser's feasible point
    return fit.joined(u)


def _polish(residual: Fn, jac: Fn, constraint: Fn | None, constraint_jac: Fn | None, u: Array) -> Array:
    """Gauss-Newton steps (with the linearised constraints, KKT form) to the optimum's last digits.

    The optimisers stop on the cost, which is quadratic in the unknowns, so their unknowns are good to about
    the square root of their tolerance; a few full steps from there converge to rounding.
    """
    cost = float(residual(u) @ residual(u))
    for _ in range(30):
        r, jm = residual(u), jac(u)
        if constraint is None:
            step = np.linalg.lstsq(jm, -r, rcond=None)[0]
        else:
            assert constraint_jac is not None
            g, gm = constraint(u), constraint_jac(u)
            n = len(u)
            kkt = np.block([[jm.T @ jm, gm.T], [gm, np.zeros((len(g), len(g)))]])
            step = np.linalg.lstsq(kkt, np.concatenate([-jm.T @ r, -g]), rcond=None)[0][:n]
        trial = u + step
        r_trial = residual(trial)
        trial_cost = float(r_trial @ r_trial)
        if trial_cost > cost * (1.0 + 1e-12) + 1e-300:
            break  # no longer a descent step: we are at rounding level
        settled = cost - trial_cost <= 1e-14 * cost
        u, cost = trial, trial_cost
        if settled:
            break  # the cost no longer falls beyond rounding
        if np.max(np.abs(step)) <= 1e-15 * (1.0 + np.max(np.abs(u))):
            break
    return u


def reach_gap(lengths: ArrayLike, span: float) -> float:
    """How far a chain of links of ``lengths`` is from reaching ``span`` between its ends (0 when it can).

    A planar chain of links reaches every end-to-end distance in ``[max(0, 2 l_max - sum l), sum l]`` and no
    other (a polygon inequality); a closed chain needs ``span = 0`` (Eq. 31), a fixed-end chain the distance of
    its pinned ends (Eq. 32).
    """
    ell = np.abs(np.asarray(lengths, dtype=float))
    total = float(ell.sum())
    shortest = max(0.0, 2.0 * float(ell.max(initial=0.0)) - total)
    return max(0.0, shortest - span, span - total)


def _newton_to_constraint(constraint: Fn, constraint_jac: Fn, u: Array) -> Array:
    """Minimum-norm Gauss-Newton steps on ``constraint(u) = 0``, each step halved until the residual drops."""
    g = constraint(u)
    norm = float(np.linalg.norm(g))
    for _ in range(100):
        if np.max(np.abs(g)) < CONSTRAINT_TOL:
            break
        step = np.linalg.lstsq(constraint_jac(u), g, rcond=None)[0]
        for _ in range(30):
            trial = u - step
            g_trial = constraint(trial)
            n_trial = float(np.linalg.norm(g_trial))
            if n_trial < norm:
                break
            step = step / 2.0
        else:
            break  # no step lowers the residual: a collinear (singular) configuration
        u, g, norm = trial, g_trial, n_trial
    return u


def _project(constraint: Fn, constraint_jac: Fn, u: Array, angles: slice | None = None) -> Array:
    """Move ``u`` onto ``constraint(u) = 0`` by damped minimum-norm Newton steps.

    When the steps stall (at a configuration whose chords are all parallel, where the constraint's Jacobian
    loses rank), restart from seeded random turns of the angles ``u[angles]`` of growing size.
    """
    rng = np.random.default_rng(0)
    best = u
    for attempt in range(12):
        trial = u.copy()
        if attempt and angles is not None:
            trial[angles] += rng.normal(0.0, 0.05 * attempt, size=trial[angles].shape)
        trial = _newton_to_constraint(constraint, constraint_jac, trial)
        if np.max(np.abs(constraint(trial))) < 1e3 * CONSTRAINT_TOL:
            return trial
        if np.linalg.norm(constraint(trial)) < np.linalg.norm(constraint(best)):
            best = trial
    g = constraint(best)
    raise ConvergenceError(
        f"joining: the chain cannot meet its closure/end constraint (residual {np.max(np.abs(g)):.3g})"
    )


def _constrained(
    residual: Fn, jac: Fn, constraint: Fn, constraint_jac: Fn, starts: Sequence[Array], angles: slice
) -> Array:
    """Minimise ``|residual|^2 / 2`` subject to ``constraint = 0``: SLSQP, then an exact projection.

    The first of ``starts`` that can be projected onto the constraint is the optimiser's start.
    """
    failure: ConvergenceError | None = None
    for u0 in starts:
        try:
            u_start = _project(constraint, constraint_jac, u0, angles)
            break
        except ConvergenceError as exc:
            failure = exc
    else:
        assert failure is not None
        raise failure

    def f(u: Array) -> float:
        r = residual(u)
        return 0.5 * float(r @ r)

    def grad(u: Array) -> Array:
        return jac(u).T @ residual(u)

    sol = minimize(
        f,
        u_start,
        jac=grad,
        method="SLSQP",
        constraints=[{"type": "eq", "fun": constraint, "jac": constraint_jac}],
        options={"ftol": 1e-15, "maxiter": 500},
    )
    u = sol.x if np.all(np.isfinite(sol.x)) else u_start
    try:
        u = _project(constraint, constraint_jac, u, angles)
    except ConvergenceError:
        u = u_start
    if f(u) > f(u_start):  # SLSQP wandered: keep the feasible start
        u = u_start
    return u


def join_chain(
    segments: Sequence[Segment],
    targets: Sequence[TargetProfile],
    kind: str,
    ties: Sequence[Sequence[tuple[int, float]]] | None = None,
    initial: Sequence[JoinedProfile] | None = None,
) -> tuple[JoinedProfile, ...]:
    """Join the segments on every profile (Sec. 5), each profile on its own.

    The initial guess is where the segmentation placed each segment (or ``initial``, a previous joining); when
    that cannot be moved onto the constraint, the chords along the target's chords between segmentation points.
    A fixed-end chain is pinned on each profile at that profile's own first and last points (Eq. 32).

    Raises
    ------
    ConvergenceError
        Naming the profile, when the chain cannot meet its closure or end constraint there.
    """
    out = []
    for j, target in enumerate(targets):
        shapes = [seg.local_points(j) for seg in segments]
        if initial is None:
            start = segments[0].instances[j][0]
            angles = np.array([chord_angle(seg.instances[j]) for seg in segments])
        else:
            start, angles = initial[j].joints[0], initial[j].angles
        ends = (target.points[0], target.points[-1]) if kind == "fixed-end" else None
        try:
            joined = join_profile(
                shapes,
                target.points,
                start,
                angles,
                closed=kind == "closed",
                ends=ends,
                ties=() if ties is None else ties[j],
            )
        except ConvergenceError as exc:
            name = target.name or str(j + 1)
            raise ConvergenceError(f"profile {name!r}: {exc}") from None
        out.append(joined)
    return tuple(out)
