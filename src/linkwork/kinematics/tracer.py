"""Tracing a mechanism's motion: the predictor-corrector of Secs. 4-6 run branch by branch.

:func:`trace` marches from the start configuration with the compiled kernel (:mod:`linkwork.kinematics.march`),
stops at a target drive value (landing exactly on it), a closed path, a step budget, a joint limit or a reported
corrector failure; locates every sign change of the test function to ``Tolerances.locate``; and, with
``branches=True``, computes every branch tangent there and traces each new branch in both directions.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from linkwork.errors import LinkworkError, SpecError
from linkwork.kinematics.bifurcation import (
    Workspace,
    branch_tangents,
    correct_on_plane,
    locate,
    locate_minimum,
    polish,
)
from linkwork.kinematics.march import FAILED, SIGN_CHANGE, STOP_REASONS
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import DEFAULT, Tolerances, numerical_rank, numerical_ranks
from linkwork.kinematics.trace_result import Bifurcation, Branch, Trace

Array = NDArray[np.float64]
Progress = Callable[[float, str], None]


@dataclass
class _Rows:
    """Growing per-point storage, one block of rows per compiled march call."""

    u: list[Array] = field(default_factory=list)
    sigma: list[Array] = field(default_factory=list)
    res: list[Array] = field(default_factory=list)
    tau: list[Array] = field(default_factory=list)
    s: list[Array] = field(default_factory=list)
    branch: list[NDArray[np.int64]] = field(default_factory=list)
    step: list[NDArray[np.int64]] = field(default_factory=list)

    def add_point(self, u: Array, sigma: Array, res: float, branch: int) -> None:
        """Append one point (a bifurcation point opening a branch: arclength 0, step 0, test 0)."""
        self.u.append(u[None, :].copy())
        self.sigma.append(sigma[None, :].copy())
        self.res.append(np.array([res]))
        self.tau.append(np.zeros(1))
        self.s.append(np.zeros(1))
        self.branch.append(np.array([branch], dtype=np.int64))
        self.step.append(np.zeros(1, dtype=np.int64))

    def count(self) -> int:
        """Number of points stored."""
        return sum(len(b) for b in self.branch)


def trace(
    mech: Mechanism,
    drive: str | int | None = None,
    until: tuple[str | int, float] | None = None,
    steps: int | None = None,
    *,
    max_step: float = np.radians(2.0),
    min_step: float = 1e-9,
    max_turn: float = np.radians(10.0),
    max_steps: int = 5000,
    branches: bool = False,
    limits: Mapping[str, tuple[float, float]] | None = None,
    tol: Tolerances = DEFAULT,
    progress: Progress | None = None,
) -> Trace:
    """Trace the motion of ``mech`` from its start (reference) configuration.

    Parameters
    ----------
    mech
        The mechanism; its reference configuration is the start and must close.
    drive
        The joint that orients the path and counts the steps (default: the target's joint, else the first free
        joint).
    until
        ``(joint, value)``: stop exactly when that joint reaches ``value`` (radians, or length for a prismatic
        joint).
    steps
        Paper mode: ``steps`` equal steps of the drive from its start value to ``until`` (Sec. 5 uses 200);
        otherwise adaptive arclength steps no longer than ``max_step``.
    branches
        Locate bifurcations and trace every branch in both directions; without it bifurcations are still
        located and reported, and the path goes straight on through them.
    limits
        Joint limits ``{name: (low, high)}`` (radians); the path stops when one is passed.
    """
    # Workspace.of picks compiled or plain-Python kernels (and compiles them, if asked) before the clock starts.
    ws = Workspace.of(mech)
    started = time.perf_counter()
    m = mech.n_unknowns
    if m == 0:
        raise LinkworkError(f"{mech.name}: every joint is fixed; nothing can move")
    if until is not None and drive is None:
        drive = until[0]
    if drive is None:
        drive = mech.joint_names[int(np.flatnonzero(mech.groups >= 0)[0])]
    d_joint = mech.index(drive)
    d_unknown = int(mech.groups[d_joint])
    if d_unknown < 0:
        raise SpecError(f"the drive joint {mech.joint_names[d_joint]} is fixed; choose a free joint")
    target = None
    if until is not None:
        t_joint = mech.index(until[0])
        if t_joint != d_joint and mech.groups[t_joint] != d_unknown:
            raise SpecError(
                f"until names joint {mech.joint_names[t_joint]} but the drive is {mech.joint_names[d_joint]}; "
                "they must be the same joint (or coupled)"
            )
        target = float(until[1]) - mech.offsets[t_joint]
    if steps is not None and (target is None or steps < 1):
        raise SpecError("steps (the paper's equal drive steps) needs until=(joint, value) and steps >= 1")

    r0, _, jac0 = ws.evaluate(np.zeros(m))
    if r0 > 1e3 * tol.closure:
        raise LinkworkError(f"{mech.name}: the start does not close (residual {r0:.3g}); assemble it first")
    U0, s0, Vt0 = np.linalg.svd(jac0)
    r_path = numerical_rank(s0, tol)
    mobility = m - r_path
    if mobility == 0:
        raise LinkworkError(
            f"{mech.name}: the start is rigid (Jacobian rank {r_path} = number of unknowns); "
            "an over-constrained loop needs its exact geometry to move"
        )
    if mobility > 1:
        raise LinkworkError(
            f"{mech.name}: mobility {mobility} at the start (rank {r_path}, {m} unknowns); the tracer follows "
            "one-parameter paths: couple or fix joints (couple=..., fixed=... / --couple A=C=E)"
        )
    t_start = Vt0[-1].copy()
    sign = 1.0
    if target is not None:
        sign = 1.0 if target >= 0 else -1.0
    if t_start[d_unknown] * sign < 0:
        t_start = -t_start
    n_sigma = min(jac0.shape)

    lo = np.full(m, -np.inf)
    hi = np.full(m, np.inf)
    for name, (a, b) in (limits or {}).items():
        j = mech.index(name)
        g = mech.groups[j]
        if g >= 0:
            lo[g], hi[g] = a - mech.offsets[j], b - mech.offsets[j]
    periodic = np.array([mech.joint_types[mech.group_members()[g][0]] == "R" for g in range(m)])

    rows = _Rows()
    found: list[Bifurcation] = []
    branch_list: list[Branch] = []
    budget = [max_steps]
    queue: list[tuple[int | None, int | None, Array, Array, int]] = []

    def run_branch(
        branch_id: int,
        u0: Array,
        t0: Array,
        basis: Array,
        paper: bool,
        h0: float,
        stop_at_known: bool,
        step_offset: int = 0,
    ) -> tuple[int, str]:
        """March one branch to its end, locating bifurcations on the way; returns (steps, end reason).

        ``step_offset``: step number of ``u0`` in its branch (1 when the branch opens at a bifurcation point).
        """
        u, t = u0.copy(), t0.copy()
        u_home = u0.copy()
        n_steps = 0
        first = True
        while True:
            chunk = min(budget[0], 100 if progress else budget[0])
            if chunk <= 0 and not first:
                return n_steps, STOP_REASONS[0]
            N = max(chunk, 0)
            out_u = np.empty((N + 1, m))
            out_t = np.empty((N + 1, m))
            out_sigma = np.empty((N + 1, n_sigma))
            out_res = np.empty(N + 1)
            out_tau = np.empty(N + 1)
            out_s = np.empty(N + 1)
            basis_prev = basis.copy()
            count, code, h = ws.kernels.march(
                ws.twists, ws.loop_joint, ws.loop_sign, ws.loop_ptr, ws.rows, ws.groups,
                u, t, u_home, basis, paper, d_unknown, h0, min_step, max_step, np.cos(max_turn),
                0.0 if target is None else target, target is not None,
                tol.closure, tol.truncate, 25, N, r_path, periodic, lo, hi, True,
                target is None, out_u, out_t, out_sigma, out_res, out_tau, out_s,
            )  # fmt: skip
            s_base = rows.s[-1][-1] if (not first and rows.s) else 0.0
            begin = 0 if first else 1
            rows.u.append(out_u[begin:count])
            rows.sigma.append(out_sigma[begin:count])
            rows.res.append(out_res[begin:count])
            rows.tau.append(out_tau[begin:count])
            rows.s.append(s_base + out_s[begin:count])
            rows.branch.append(np.full(count - begin, branch_id, dtype=np.int64))
            rows.step.append(n_steps + np.arange(begin, count) - begin + (0 if first else 1))
            n_steps += count - 1
            budget[0] -= count - 1
            # Rank drops where the test function keeps its sign: local minima of sigma_r / sigma_1.
            if r_path >= 1 and count >= 3:
                ratio = out_sigma[:count, r_path - 1] / out_sigma[:count, 0]
                for k in range(1, count - 1):
                    if not (ratio[k] <= ratio[k - 1] and ratio[k] < ratio[k + 1] and ratio[k] < 1e-2):
                        continue
                    if out_tau[k - 1] * out_tau[k] < 0.0 or out_tau[k] * out_tau[k + 1] < 0.0:
                        continue  # a sign change: located by the test function
                    u_min, r_min = locate_minimum(
                        ws, out_u[k - 1], out_t[k - 1], out_u[k + 1], out_t[k + 1], r_path, tol
                    )
                    if r_min <= tol.loose and _match(found, u_min, periodic) is None:
                        step_k = n_steps - (count - 1) + k + step_offset
                        bif = _make_bifurcation(
                            mech, ws, len(found), branch_id, step_k, u_min, 0.0, tol, r_path - 1
                        )
                        found.append(bif)
                        if branches:
                            for tb in bif.tangents_u:  # type: ignore[attr-defined]
                                if abs(tb @ out_t[k]) < 0.99:
                                    for direction in (1, -1):
                                        queue.append((branch_id, bif.id, u_min, direction * tb, direction))
            first = False
            if progress:
                progress(count - 1, f"branch {branch_id}")
            if code == SIGN_CHANGE:
                # Locate between the last two points; the basis before the change orients the test function.
                basis_a = _basis_before(ws, out_u[count - 2], out_t[count - 2], basis_prev, r_path)
                u_star, width = locate(
                    ws,
                    out_u[count - 2],
                    out_t[count - 2],
                    basis_a,
                    out_u[count - 1],
                    out_t[count - 1],
                    r_path,
                    tol,
                    n_sigma,
                )
                known = _match(found, u_star, periodic)
                if known is None:
                    bif = _make_bifurcation(
                        mech, ws, len(found), branch_id, n_steps + step_offset, u_star, width, tol, r_path - 1
                    )
                    found.append(bif)
                    if branches:
                        for tb in bif.tangents_u:  # type: ignore[attr-defined]
                            if abs(tb @ out_t[count - 2]) < 0.99:
                                for direction in (1, -1):
                                    queue.append((branch_id, bif.id, u_star, direction * tb, direction))
                elif stop_at_known:
                    # End the branch exactly on the known point (its last row overshot it by part of a step).
                    before = out_u[count - 2]
                    diff = found[known].u - before
                    diff[periodic] = (diff[periodic] + np.pi) % (2.0 * np.pi) - np.pi
                    point = before + diff  # the same point, in this branch's continuous angles
                    r_known, _, j_known = ws.evaluate(point)
                    rows.u[-1][-1] = point
                    rows.sigma[-1][-1] = np.linalg.svd(j_known, compute_uv=False)[:n_sigma]
                    rows.res[-1][-1] = r_known
                    rows.tau[-1][-1] = 0.0
                    return n_steps, f"reached bifurcation {known}"
                u, t = out_u[count - 1].copy(), out_t[count - 1].copy()
                h0 = h
                if budget[0] <= 0:
                    return n_steps, STOP_REASONS[0]
                continue
            if code == 0 and budget[0] > 0:
                u, t = out_u[count - 1].copy(), out_t[count - 1].copy()
                h0 = h
                continue
            reason = STOP_REASONS[code]
            if code == FAILED:
                reason = (
                    "corrector failed at a fixed drive step (the drive cannot take that value here)"
                    if paper
                    else f"corrector failed (step halved below {min_step:.1e} without converging)"
                )
            return n_steps, reason

    paper = steps is not None
    h_start = (target / steps) if (paper and target is not None and steps) else max_step / 4.0
    basis0 = np.ascontiguousarray(U0[:, :r_path])
    # Paper mode keeps the sign: equal drive steps towards a target below the start value are negative.
    n0, reason0 = run_branch(0, np.zeros(m), t_start, basis0.copy(), paper, h_start, False)
    branch_list.append(Branch(0, None, None, 1, n0, reason0))
    if branches and target is None and reason0 != STOP_REASONS[2]:
        # The start is in the middle of its branch: trace the other direction too.
        n1, reason1 = run_branch(1, np.zeros(m), -t_start, basis0.copy(), False, max_step / 4.0, True)
        branch_list.append(Branch(1, None, None, -1, n1, reason1))
    while queue and budget[0] > 0:
        parent, bif_id, u_star, t_dir, direction = queue.pop(0)
        bid = len(branch_list)
        h = max_step / 4.0
        u1, _r, ok = correct_on_plane(ws, u_star + h * t_dir, t_dir, tol)
        if not ok:
            branch_list.append(Branch(bid, parent, bif_id, direction, 0, "could not leave the bifurcation"))
            continue
        _, _, jac1 = ws.evaluate(u1)
        U1, _, Vt1 = np.linalg.svd(jac1)
        t1 = Vt1[-1] if Vt1[-1] @ t_dir > 0 else -Vt1[-1]
        # Record the bifurcation point itself as the branch's first point, then march on.
        r_star, _, jst = ws.evaluate(u_star)
        rows.add_point(
            u_star, np.asarray(np.linalg.svd(jst, compute_uv=False)[:n_sigma], dtype=float), r_star, bid
        )
        s_off = float(np.linalg.norm(u1 - u_star))
        start_len = len(rows.u)
        nb, rb = run_branch(bid, u1, t1, np.ascontiguousarray(U1[:, :r_path]), False, h, True, 1)
        for i in range(start_len, len(rows.u)):
            rows.s[i] = rows.s[i] + s_off
            rows.step[i] = rows.step[i] + 1
        branch_list.append(Branch(bid, parent, bif_id, direction, nb + 1, rb))

    U = np.concatenate(rows.u, axis=0)
    q = mech.q_from_u(U)
    sigma = np.concatenate(rows.sigma, axis=0)
    ranks = numerical_ranks(sigma, tol)
    return Trace(
        mechanism=mech,
        drive=mech.joint_names[d_joint],
        angles=mech.angles_from_q(q),
        sigma=sigma,
        residual=np.concatenate(rows.res),
        branch=np.concatenate(rows.branch),
        step=np.concatenate(rows.step),
        arclength=np.concatenate(rows.s),
        test=np.concatenate(rows.tau),
        rank=ranks,
        bifurcations=tuple(found),
        branches=tuple(branch_list),
        stats={
            "seconds": time.perf_counter() - started,
            "points": len(U),
            "start_rank": r_path,
            "start_mobility": mobility,
            "mode": "paper" if paper else "adaptive",
        },
    )


def _basis_before(ws: Workspace, u: Array, t: Array, basis_prev: Array, r_path: int) -> Array:
    """The oriented range basis at point ``u`` (as the march kept it), recomputed for the locator."""
    _, _, jac = ws.evaluate(u)
    basis = basis_prev.copy()
    tt = np.empty_like(t)
    ws.kernels.tangent_and_test(jac, t.copy(), basis, r_path, tt, np.empty(min(jac.shape)))
    return basis


def _match(found: list[Bifurcation], u: Array, periodic: NDArray[np.bool_], tol: float = 1e-6) -> int | None:
    """Id of an already located bifurcation at ``u`` (angles compared modulo a full turn), if any."""
    for b in found:
        diff = b.u - u
        diff[periodic] = (diff[periodic] + np.pi) % (2.0 * np.pi) - np.pi
        if np.linalg.norm(diff) < tol * max(1.0, float(np.linalg.norm(u))):
            return b.id
    return None


def _make_bifurcation(
    mech: Mechanism,
    ws: Workspace,
    ident: int,
    branch: int,
    step: int,
    u: Array,
    width: float,
    tol: Tolerances,
    rank_hint: int,
) -> Bifurcation:
    """Classify a located point: rank, singular values, branch tangents (over the joints and the unknowns)."""
    tangents_u, method, rank, sigma = branch_tangents(mech, ws, u, tol, rank_hint=rank_hint)
    if len(tangents_u) == 2:
        polished, gap = polish(ws, u, tangents_u, tol)
        if np.isfinite(gap) and gap < 1e-8:
            u = polished
            width = gap
            tangents_u, method, rank, sigma = branch_tangents(mech, ws, u, tol, rank_hint=rank_hint)
    res_norm, _, _ = ws.evaluate(u)
    C = mech.coupling_matrix()
    over_joints = np.array([C @ t / np.linalg.norm(C @ t) for t in tangents_u]).reshape(
        len(tangents_u), mech.n_joints
    )
    bif = Bifurcation(
        id=ident,
        branch=branch,
        step=step,
        u=u.copy(),
        angles=mech.angles_from_q(mech.q_from_u(u)),
        rank=rank,
        sigma=sigma,
        tangents=over_joints,
        method=method,
        residual=res_norm,
        bracket=width,
    )
    object.__setattr__(bif, "tangents_u", tangents_u)
    return bif
