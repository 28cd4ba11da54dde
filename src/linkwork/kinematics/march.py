"""The compiled predictor-corrector march: the hot loop of tracing, one call for many steps.

Each step: the predictor moves along the null vector of the reduced Jacobian (Sec. 4.1, oriented so consecutive
tangents agree, ``t_k . t_{k-1} > 0``); the corrector is Gauss-Newton with the truncated-SVD pseudo-inverse
(Eq. (28)), either minimum-norm over all unknowns (Moore-Penrose continuation) or with the drive joint held at
its predicted value (the paper's equal steps of the drive). A signed test function, the determinant of the
Jacobian restricted to its range (basis kept continuous) and bordered by the tangent, is recorded at every
point: a sign change brackets a bifurcation.

Stop codes returned by :func:`march`: the values of :class:`linkwork.kinematics.stops.StopReason`.

References
----------
W. W. Gan, S. Pellegrino, Proc. IMechE Part C 220 (2006), Eq. (28).
"""

from __future__ import annotations

import numpy as np

from linkwork.kernel_cache import kernel
from linkwork.kinematics.kernels import cholesky_in_place, cholesky_solve, closure_pass, expand, work_arrays
from linkwork.kinematics.small_svd import det_sign_in_place, jacobi_svd
from linkwork.kinematics.stops import StopReason

# The stop codes the march returns, as the plain ints numba freezes into the kernels (see StopReason).
BUDGET = int(StopReason.BUDGET)
TARGET = int(StopReason.TARGET)
CLOSED = int(StopReason.CLOSED)
FAILED = int(StopReason.FAILED)
SIGN_CHANGE = int(StopReason.SIGN_CHANGE)
LIMIT = int(StopReason.LIMIT)
TURNING = int(StopReason.TURNING)
NO_PROGRESS = int(StopReason.NO_PROGRESS)
NO_EVENT = -1  # step_event: the step ends nothing
TURNED = -2  # predict's ``held`` when the drive has turned back in paper mode
MAX_PARTS = 1024
"""Paper mode: the most equal parts a row's drive step is taken in where the whole step jumps or fails (next to
a fold of the drive the path moves as the square root of the drive's distance to the fold); beyond, the march
fails there."""
PART_SLACK = 1e-9
"""Paper mode: a drive step longer than ``hmax`` by less than this fraction of it (a step of ``hmax`` to
round-off) is taken whole, not in two parts."""
PART_SHIFT = 0.3819660112501051
"""Paper mode: the parts of a row's drive step end this fraction of a part short of the equal division (2 minus the
golden ratio; the last part is that much longer): a part never lands on a round drive value where a row does not,
such as a parallelogram's crossing at 180 deg met by the equal parts of 170 -> 190 deg, where the tangent has no
direction and the next part went on along the other branch (or failed, reported as a turning point)."""
NEAR_CROSSING = 1e-2
"""Paper mode: an inner part of a row that lands where the path's smallest kept singular value is below this
fraction of the largest (``Tolerances.local_min``'s default: next to a singular point) and whose tangent turned by
more than an adaptive step may is taken again in more parts (see :func:`march`)."""
SINGULAR_START = 1e-5
"""Paper mode: a point whose smallest kept singular value is below this fraction of the largest
(``Tolerances.loose``'s default) is taken as singular, its tangent without a direction: a part from it is not
judged by its turn (:data:`NEAR_CROSSING`)."""
MAX_CLOSES = 64
"""Paper mode: the most closing parts a row's own drive value is approached in, from the same side, where its
landing next to a singular point turned the tangent (see :func:`march`); beyond, the row is taken again in more
parts."""
MAX_CROSSINGS = 64
"""The most sign changes of the test function within one row whose brackets the march hands back (``crossings``
in its ``out`` tuple). The sign is compared step by step, a paper row's parts included, so that two crossings
passed within one row (a parallelogram's at 180 and 360 deg in one equal step of 340 deg) do not cancel; every
bracket, up to this many in a row, is located by the marcher. (A row of a thousand parts of a parallelogram turned
many times over meets the same two points every turn: they are counted, and the first brackets located.)"""

MECHANISM = ("twists", "loop_joint", "loop_sign", "loop_ptr", "rows", "groups")
"""The members of the mechanism tuple every kernel takes (see :mod:`linkwork.kinematics.kernels`)."""
CORRECTOR = ("tol", "exact", "roundoff", "truncate", "max_iter")
"""The members of :func:`correct`'s settings tuple."""
MARCH_ARGUMENTS = {
    "mech": MECHANISM,
    "start": ("u0", "t0", "u_home", "basis", "reach", "before"),
    "steps": (
        "paper", "drive", "h0", "hmin", "hmax", "cos_turn", "target", "has_target", "advance", "stall_steps",
        "stall_length", "max_steps", "r_path", "detect", "check_closed",
    ),
    "corrector": CORRECTOR,
    "bounds": ("periodic", "lo", "hi", "weight", "measure"),
    "out": ("out_u", "out_t", "out_sigma", "out_res", "out_tau", "out_s", "crossings"),
}  # fmt: skip
CROSSINGS = ("cross_u", "cross_t", "cross_basis", "cross_n")
"""The members of ``out``'s last one, the sign changes of the test function within the last row written:
``cross_u (K, 2, m)`` and ``cross_t (K, 2, m)`` the points and tangents before and after each step (a paper row's
part, or the row) over which the sign changed, ``cross_basis (K, E, r)`` the oriented range basis before it,
``cross_n (1,)`` how many there were (``K`` = :data:`MAX_CROSSINGS` at most are written)."""
"""The tuples :func:`march` takes, in order, and their members."""


@kernel()
def evaluate(mech, u, q, res, jac):
    """Residual norm, residual and reduced Jacobian at unknowns ``u`` of ``mech`` (the tuple of
    :mod:`~linkwork.kinematics.kernels`; ``q``, ``res``, ``jac`` are work arrays, ``res`` and ``jac`` the
    results)."""
    matrices, vectors = work_arrays()
    return evaluate_in(mech, u, (q, res, jac, matrices, vectors, solve_work(jac.shape[1])))


@kernel()
def evaluate_in(mech, u, work):
    """:func:`evaluate` with every work array given, ``work = (q, res, jac, matrices, vectors, solve)``
    (``matrices`` and ``vectors`` from :func:`~linkwork.kinematics.kernels.work_arrays`, ``solve`` the
    corrector's, :func:`solve_work`): the march allocates them once per call, not once per evaluation (a third
    of an evaluation's time on a small loop)."""
    q, res, jac, matrices, vectors = work[0], work[1], work[2], work[3], work[4]
    expand(u, mech[5], q)
    closure_pass(mech, q, None, res, jac, matrices, vectors)
    return np.sqrt(np.sum(res * res))


@kernel()
def correct(mech, u, held, corrector, q, res, jac):
    """:func:`correct_in` with work arrays of its own beside ``q``, ``res``, ``jac``."""
    matrices, vectors = work_arrays()
    return correct_in(mech, u, held, corrector, (q, res, jac, matrices, vectors, solve_work(jac.shape[1])))


@kernel()
def solve_work(m):
    """Work arrays of :func:`least_squares_step` for ``m`` unknowns: ``(idx, A, b, y)``."""
    return np.empty(m, dtype=np.int64), np.empty((m, m)), np.empty(m), np.empty(m)


GOING, FAILED_SOLVE, CONVERGED = -1, 0, 1
"""What :func:`verdict` says of a corrector iteration."""


@kernel(inline="always")
def verdict(r, prev, it, exact, accept, max_iter):
    """The corrector's stopping rule after iteration ``it`` left residual ``r`` (``prev`` the one before):
    :data:`CONVERGED` below ``exact``, or stalled (fell by less than half) below ``accept``; :data:`FAILED_SOLVE`
    not finite, out of iterations, or growing after two; else :data:`GOING`. One rule for every corrector."""
    if not np.isfinite(r):
        return FAILED_SOLVE
    if r < exact:
        return CONVERGED
    if r < accept and r > 0.5 * prev:
        return CONVERGED
    if it == max_iter or (it >= 2 and r > prev):
        return FAILED_SOLVE
    return GOING


@kernel()
def correct_in(mech, u, held, corrector, work):
    """Gauss-Newton with the truncated-SVD pseudo-inverse (Eq. (28)), in place on ``u`` (``work`` as in
    :func:`evaluate_in`; its ``res`` and ``jac`` are the last evaluation's).

    ``corrector`` is ``(tol, exact, roundoff, truncate, max_iter)`` (:data:`CORRECTOR`).
    ``held`` is the unknown kept fixed (-1: none, minimum-norm correction over all unknowns). Returns
    ``(converged, iterations, residual)``. Converged: a residual below ``exact``, or one that stalls (falls by
    less than half in an iteration) below ``max(tol, roundoff * exact)``: the least-squares closure of a loop
    whose parameters are off by up to ``tol`` (``Tolerances.closure``), or the round-off floor of a very long
    loop.
    """
    tol, exact, roundoff, truncate, max_iter = corrector
    res, jac = work[1], work[2]
    m = u.shape[0]
    prev = np.inf
    accept = max(tol, roundoff * exact)
    for it in range(max_iter + 1):
        r = evaluate_in(mech, u, work)
        state = verdict(r, prev, it, exact, accept, max_iter)
        if state != GOING:
            return state == CONVERGED, it, r
        prev = r
        if held >= 0:
            for e in range(jac.shape[0]):
                jac[e, held] = 0.0
            # With the drive held the remaining columns have full rank away from singular points, and Eq. (28)
            # keeps every singular value: its pseudo-inverse step is then the least-squares step, solved here
            # by Cholesky on the normal equations; an ill-conditioned case falls back to the truncated SVD.
            if least_squares_step(jac, res, held, u, work[5]):
                continue
        U, s, Vt = np.linalg.svd(jac)
        cut = truncate * s[0]
        for i in range(s.shape[0]):
            if s[i] <= cut:
                break
            c = 0.0
            for e in range(res.shape[0]):
                c += U[e, i] * res[e]
            c /= s[i]
            # The held unknown stays exactly where it is: its column is zero, but Vt's entries for it are round-off,
            # which a small singular value next to a singular point scales up (a paper step 1e-8 deg off its value).
            for a in range(m):
                if a != held:
                    u[a] -= Vt[i, a] * c  # Eq. (28): - sum_i w_i u_i^T e / v_ii
    return False, max_iter, prev


@kernel()
def correct_across(mech, u, t, corrector, work, weight):
    """Gauss-Newton for the closure in the hyperplane through the predicted ``u`` normal to the tangent ``t``
    (pseudo-arclength), in place on ``u`` (``work`` as in :func:`evaluate_in`); returns ``(converged,
    iterations, residual)`` as :func:`correct_in`.

    Each step is the truncated-SVD least-squares solution (Eq. (28)) of the closure's Jacobian bordered by
    ``t``: the point it converges to, where the path crosses that hyperplane, does not depend on how the closure
    equations are weighted, so the steps are the same whatever the length unit and wherever the linkage stands
    (a minimum-norm correction over all unknowns lands elsewhere on the path for each weighting). The hyperplane
    is normal in the step's metric (``weight``, :func:`weighted_norm`), so it is the same in any length unit.
    """
    tol, exact, roundoff, truncate, max_iter = corrector
    res, jac = work[1], work[2]
    m = u.shape[0]
    E = res.shape[0]
    u0 = u.copy()
    A = np.empty((E + 1, m))
    b = np.empty(E + 1)
    prev = np.inf
    accept = max(tol, roundoff * exact)
    for it in range(max_iter + 1):
        r = evaluate_in(mech, u, work)
        state = verdict(r, prev, it, exact, accept, max_iter)
        if state != GOING:
            return state == CONVERGED, it, r
        prev = r
        gap = 0.0
        for a in range(m):
            for e in range(E):
                A[e, a] = jac[e, a]
            A[E, a] = t[a] * (weight[a] * weight[a])
            gap += A[E, a] * (u[a] - u0[a])
        for e in range(E):
            b[e] = res[e]
        b[E] = gap
        U, s, Vt = np.linalg.svd(A)
        cut = truncate * s[0]
        for i in range(min(s.shape[0], m)):
            if s[i] <= cut:
                break
            c = 0.0
            for e in range(E + 1):
                c += U[e, i] * b[e]
            c /= s[i]
            for a in range(m):
                u[a] -= Vt[i, a] * c
    return False, max_iter, prev


@kernel()
def least_squares_step(jac, res, held, u, solve):
    """``u -= argmin |J du + r|`` over the unknowns other than ``held``, by Cholesky of ``J^T J`` (``solve``: the
    work arrays of :func:`solve_work`).

    Returns False (and leaves ``u`` alone) when a pivot is below ``1e-10`` of the largest diagonal, i.e. when
    the condition number exceeds about 1e5: then the truncated SVD must decide what to keep.
    """
    E, m = jac.shape
    k = m - 1
    idx, A, b, y = solve
    c = 0
    for a in range(m):
        if a != held:
            idx[c] = a
            c += 1
    for i in range(k):
        for j in range(i + 1):
            acc = 0.0
            for e in range(E):
                acc += jac[e, idx[i]] * jac[e, idx[j]]
            A[i, j] = acc
        acc = 0.0
        for e in range(E):
            acc += jac[e, idx[i]] * res[e]
        b[i] = acc
    dmax = 0.0
    for i in range(k):
        dmax = max(dmax, A[i, i])
    if not cholesky_in_place(A[:k, :k], 1e-10 * dmax, 0.0):
        return False
    cholesky_solve(A[:k, :k], b[:k], y[:k])
    for i in range(k):
        u[idx[i]] -= y[i]
    return True


JACOBI_UNKNOWNS = 12
"""Up to this many unknowns the tangent's SVD is the compiled one-sided Jacobi of
:mod:`~linkwork.kinematics.small_svd` (warm-started, allocation-free); beyond, LAPACK's (its cost grows more slowly
with the size)."""


@kernel()
def svd_work(E, m):
    """Work arrays of :func:`tangent_and_test_in` for an ``(E, m)`` Jacobian: ``(V, W, norms, order, G)``, ``V``
    the identity (a cold start)."""
    return np.eye(m), np.empty((E, m)), np.empty(m), np.empty(m, dtype=np.int64), np.empty((m, m))


@kernel()
def tangent_and_test(jac, t_prev, basis, r_path, t_out, sigma_out, weight):
    """Oriented null vector, singular values and the signed test function at the current Jacobian.

    ``basis (E, r_path)`` is the previous oriented range basis, updated in place; the tangent is oriented to
    agree with ``t_prev`` in the step's metric (``weight``, :func:`weighted_norm`). Returns the test value
    (0 when the path is not of mobility one with rank ``r_path``). :func:`tangent_and_test_in` from a cold
    start, with work arrays of its own.
    """
    return tangent_and_test_in(
        jac, t_prev, basis, r_path, t_out, sigma_out, svd_work(jac.shape[0], jac.shape[1]), weight
    )


@kernel()
def tangent_and_test_in(jac, t_prev, basis, r_path, t_out, sigma_out, svd, weight):
    """:func:`tangent_and_test` with the SVD's work arrays ``svd = (V, W, norms, order, G)`` given (see
    :func:`svd_work`); ``V`` holds the right singular vectors of the last call (the warm start of the next).

    The SVD ``J = W V^T`` (one-sided Jacobi, :func:`~linkwork.kinematics.small_svd.jacobi_svd`) gives the
    singular values (``W``'s column norms), the tangent (``V``'s column of the smallest, oriented so that
    ``t . t_prev > 0`` in the step's metric, ``sum_a t_a t_prev_a weight_a^2``: in the plain metric a path
    whose tangent is mostly a slider's, in a small length unit, would be oriented by the slider alone, and turn
    back where the slider does) and the range basis ``U_r`` (the largest ``r`` columns of ``W``, normalised, its
    orientation kept continuous with ``basis``: ``det(basis^T U_r) > 0``). The test function
    ``det([U_r^T J; t^T])`` is then, since ``U_r^T J = S_r V_r^T``, the product of the ``r`` largest singular
    values times ``det([V_r^T; t^T]) = +-det V = +-1``: its sign from the orientations alone.
    """
    E, m = jac.shape
    if m > JACOBI_UNKNOWNS:
        return tangent_and_test_lapack(jac, t_prev, basis, r_path, t_out, sigma_out, weight)
    V, W, norms, order, G = svd
    perm = jacobi_svd(jac, V, W, norms, order)
    k = min(E, m)
    for i in range(sigma_out.shape[0]):
        sigma_out[i] = norms[i] if i < k else 0.0
    last = order[m - 1]
    dot = 0.0
    for a in range(m):
        dot += V[a, last] * t_prev[a] * (weight[a] * weight[a])
    orient = -1.0 if dot < 0.0 else 1.0
    for a in range(m):
        t_out[a] = orient * V[a, last]
    if r_path + 1 != m or r_path > E or not norms[r_path - 1] > 0.0:
        return 0.0
    # Keep the range basis continuous: align the new one's orientation with the previous one's.
    for i in range(r_path):
        for j in range(r_path):
            c = order[j]
            acc = 0.0
            for e in range(E):
                acc += basis[e, i] * W[e, c]
            G[i, j] = acc / norms[j]
    flip = -1.0 if det_sign_in_place(G, r_path) < 0.0 else 1.0
    tau = orient * perm * flip
    for j in range(r_path):
        c = order[j]
        scale = (flip if j == r_path - 1 else 1.0) / norms[j]
        for e in range(E):
            basis[e, j] = W[e, c] * scale
        tau *= norms[j]
    return tau


@kernel()
def tangent_and_test_lapack(jac, t_prev, basis, r_path, t_out, sigma_out, weight):
    """:func:`tangent_and_test` by LAPACK's SVD (``gesdd``) and two determinants: a Jacobian of more than
    :data:`JACOBI_UNKNOWNS` columns."""
    m = jac.shape[1]
    U, s, Vt = np.linalg.svd(jac)
    k = min(s.shape[0], sigma_out.shape[0])
    for i in range(sigma_out.shape[0]):
        sigma_out[i] = s[i] if i < k else 0.0
    dot = 0.0
    for a in range(m):
        t_out[a] = Vt[m - 1, a]
        dot += t_out[a] * t_prev[a] * (weight[a] * weight[a])
    if dot < 0.0:
        for a in range(m):
            t_out[a] = -t_out[a]
    if r_path + 1 != m or r_path > U.shape[1]:
        return 0.0
    E = jac.shape[0]
    # Keep the range basis continuous: align the new one's orientation with the previous one's.
    Ur = np.ascontiguousarray(U[:, :r_path])
    M = basis.T @ Ur
    if np.linalg.det(M) < 0.0:
        for e in range(E):
            Ur[e, r_path - 1] = -Ur[e, r_path - 1]
    for e in range(E):
        for i in range(r_path):
            basis[e, i] = Ur[e, i]
    A = np.empty((m, m))
    A[:r_path, :] = Ur.T @ jac
    A[r_path, :] = t_out
    return np.linalg.det(A)


@kernel()
def wrapped_distance(a, b, periodic, weight):
    """Distance between unknowns ``a`` and ``b`` with periodic (angle) differences wrapped to [-pi, pi), each
    difference times its ``weight`` (1 for an angle, ``1 / L`` for a length: see :func:`weighted_norm`)."""
    d = 0.0
    for i in range(a.shape[0]):
        diff = a[i] - b[i]
        if periodic[i]:
            diff = (diff + np.pi) % (2.0 * np.pi) - np.pi  # compiled copy of linkwork.geometry.angles.wrap
        diff = diff * weight[i]
        d += diff * diff
    return np.sqrt(d)


@kernel()
def step_geometry(u, t, u_try, t_new, weight, weighted):
    """``(turn, dist, ahead)`` of a corrected step: the cosine between the tangents, the step's length and how far
    it went along the old tangent, in the step's metric (``weight``, see :func:`weighted_norm`; the unit tangents
    as they are where every weight is 1)."""
    turn = 0.0
    dist = 0.0
    ahead = 0.0
    for a in range(u.shape[0]):
        w2 = weight[a] * weight[a]
        du = u_try[a] - u[a]
        turn += t_new[a] * t[a] * w2
        dist += du * du * w2
        ahead += t[a] * du * w2
    if weighted:
        tn = weighted_norm(t, weight)
        turn /= tn * weighted_norm(t_new, weight)
        ahead /= tn
    return turn, np.sqrt(dist), ahead


@kernel(inline="always")
def measured_length(u, u_try, w):
    """The length of the step from ``u`` to ``u_try`` with each unknown weighted by ``w`` (a row of the march's
    ``measure``: the reported arclengths'; the step control's metric is :func:`weighted_norm`'s). With every
    weight 1 it is the Euclidean length in the unknowns as they are, bit for bit."""
    acc = 0.0
    for a in range(u.shape[0]):
        du = (u_try[a] - u[a]) * w[a]
        acc += du * du
    return np.sqrt(acc)


@kernel(inline="always")
def weighted_norm(t, weight):
    """The length of ``t`` in the step's metric: each unknown times its weight, 1 for an angle and ``1 / L`` for
    a length (``L`` the linkage's own length, :func:`linkwork.kinematics.normalization.length_scale`), so that
    the steps are the same in any length unit."""
    acc = 0.0
    for a in range(t.shape[0]):
        x = t[a] * weight[a]
        acc += x * x
    return np.sqrt(acc)


@kernel()
def correction(u, t, step, u_try, weight):
    """How far the corrector moved the predicted point ``u + step t`` to ``u_try`` (in the step's metric)."""
    acc = 0.0
    for a in range(u.shape[0]):
        d = (u_try[a] - u[a] - step * t[a]) * weight[a]
        acc += d * d
    return np.sqrt(acc)


@kernel()
def snap_home(u, u_home, periodic, out):
    """``out``: the start ``u_home`` written in the continuous angles of ``u`` (revolute unknowns differ from it
    by whole turns), the last row of a closed path."""
    for a in range(u.shape[0]):
        turns = np.round((u[a] - u_home[a]) * (0.5 / np.pi)) if periodic[a] else 0.0
        # the start itself where no whole turn separates them (bit for bit), else the start plus the turns
        out[a] = u_home[a] + 2.0 * np.pi * turns if turns != 0.0 else u_home[a]


@kernel()
def predict(u, t, h, paper, drive, target, has_target, first, u_try, tn):
    """The predictor (Sec. 4.1): ``u_try = u + step t``; returns ``(step, landing, held)``.

    Paper mode: ``step`` moves the drive by exactly ``h`` (on the first step ``t`` is turned, in place, to
    point that way), the corrector holds the drive (``held``); ``held == TURNED`` means the drive has turned
    back.
    Adaptive mode: ``step = h / tn`` along the tangent (``tn`` its length in the step's metric: a step of length
    ``h`` there). Either way a step that would pass the target is shortened to
    land on it (``landing``; the drive then held at the target).
    """
    m = u.shape[0]
    landing = False
    held = -1
    if paper:
        if abs(t[drive]) < 1e-9:
            return 0.0, False, TURNED
        step = h / t[drive]
        if step < 0.0:
            if not first:
                return 0.0, False, TURNED
            for a in range(m):  # first step: orient the tangent along the drive direction
                t[a] = -t[a]
            step = h / t[drive]
        if has_target and abs(u[drive] + h - target) < 1e-9 * max(1.0, abs(target)):
            landing = True
        held = drive
    else:
        step = h / tn
        if has_target and abs(t[drive]) > 1e-12:
            to_go = (target - u[drive]) / t[drive]
            if 0.0 <= to_go <= step:
                step = to_go
                landing = True
                held = drive
    for a in range(m):
        u_try[a] = u[a] + step * t[a]
    if landing:
        u_try[drive] = target
    return step, landing, held


@kernel(inline="always")
def passes(a, b, target, slope):
    """Whether an adaptive step moving the drive from ``a`` to ``b`` passed strictly over ``target`` in the
    direction the tangent's drive component ``slope`` points (so that the tangent's prediction reaches it)."""
    if abs(slope) <= 1e-12 or (target - a) * slope <= 0.0:
        return False
    return (target - a) * (b - target) > 0.0


@kernel(inline="always")
def extrapolate(u_prev, t_prev, u, t, drive, u_try, cap):
    """Paper mode's predictor from the last two points: the cubic (Hermite) through ``u_prev`` and ``u`` with
    their tangents ``t_prev`` and ``t`` (as derivatives in the drive), at the drive value of the tangent
    predictor's ``u_try``, replaces ``u_try`` when it is within ``cap`` of it; returns whether it did.

    Its error is fourth order in the step (the tangent's is second), so one Gauss-Newton iteration usually
    closes the loop to round-off. The corrector holds the drive at ``u_try``'s value either way, and so
    converges to the same point of the path: only the work changes. Where the two predictors disagree by more
    than ``cap`` (high curvature, a fold or a bifurcation near) the tangent's prediction is kept.
    """
    m = u.shape[0]
    d = u[drive] - u_prev[drive]
    if d == 0.0 or abs(t[drive]) < 1e-9 or abs(t_prev[drive]) < 1e-9:
        return False
    s = 1.0 + (u_try[drive] - u[drive]) / d
    s2 = s * s
    h00 = (2.0 * s - 3.0) * s2 + 1.0  # the cubic Hermite basis at s (s = 0 at u_prev, 1 at u)
    h10 = (s2 - 2.0 * s + 1.0) * s * d / t_prev[drive]
    h01 = (3.0 - 2.0 * s) * s2
    h11 = (s - 1.0) * s2 * d / t[drive]
    gap = 0.0
    for a in range(m):
        x = h00 * u_prev[a] + h10 * t_prev[a] + h01 * u[a] + h11 * t[a] - u_try[a]
        gap += x * x
    if not gap <= cap * cap:
        return False
    for a in range(m):
        if a != drive:
            u_try[a] = h00 * u_prev[a] + h10 * t_prev[a] + h01 * u[a] + h11 * t[a]
    return True


@kernel()
def march(mech, start, steps, corrector, bounds, out):
    """March from ``(u0, t0)`` for at most ``max_steps`` steps; row 0 of the outputs is the start.

    The arguments are tuples (:data:`MARCH_ARGUMENTS` names their members): ``mech`` the mechanism's arrays (see
    :mod:`~linkwork.kinematics.kernels`); ``start = (u0, t0, u_home, basis, reach)``; ``steps = (paper, drive, h0,
    hmin, hmax, cos_turn, target, has_target, advance, stall_steps, stall_length, max_steps, r_path, detect,
    check_closed)``; ``corrector = (tol, exact, roundoff, truncate, max_iter)``; ``bounds = (periodic, lo, hi, weight,
    measure)``; ``out = (out_u, out_t, out_sigma, out_res, out_tau, out_s, crossings)``, the rows written and the
    brackets of the sign changes of the test function within the last row (:data:`CROSSINGS`). numba unpacks each
    tuple once per call; the inner kernels get the tuples they need.

    ``out_s (n, 2)`` are two arclengths from the call's start, each the sum of every accepted step's length (a
    paper row's parts and closing parts one by one, so that a long row's turning parts count, not its chord) with
    the unknowns weighted by a row of ``measure (2, m)``: column 0 with ``measure[0]`` (``Trace.arclength``'s),
    column 1 with ``measure[1]`` (the file units', ``Trace.arclength_in_file_units``;
    :func:`linkwork.kinematics.trace_result.arclength_weights`).

    ``u_home`` is where the path began and ``reach = [far, longest, t_home...]`` how far the path has gone from it,
    its longest step and its tangent there (``2 + m`` zeros for a new path; updated in place), for closed-path
    detection across several calls. ``before`` ``(2, m)`` is the row before ``u0`` and its tangent when the call
    goes on with a path another call marched (NaN: none): paper mode's first step then extrapolates from it as
    every later step does from its two last rows, so a path marched in several calls has the rows of one call.

    An adaptive step is rejected (and halved) when the corrected point advanced less than ``advance * h`` along
    the tangent (the corrector pulled it back); an adaptive march stops with ``NO_PROGRESS`` when its last
    ``stall_steps`` steps together advanced less than ``stall_length * hmax`` (a paper-mode step always moves the
    drive by its fixed amount).

    ``paper``: fixed steps of ``h0`` in the drive unknown (signed: negative steps move the drive down), corrector
    with the drive held (the paper's mode);
    otherwise adaptive arclength steps in ``[hmin, hmax]`` with the minimum-norm corrector. Returns
    ``(count, code, h)``: rows written, the stop code and the last step length.
    """
    u0, t0, u_home, basis, reach, before = start
    (
        paper, drive, h0, hmin, hmax, cos_turn, target, has_target, advance, stall_steps, stall_length,
        max_steps, r_path, detect, check_closed,
    ) = steps  # fmt: skip
    periodic, lo, hi, weight, measure = bounds
    weighted = False  # a prismatic unknown, measured in the linkage's own length (weight 1 / L)
    for a in range(u0.shape[0]):
        weighted = weighted or weight[a] != 1.0
    out_sigma = out[2]
    cross_u, cross_t, cross_basis, cross_n = out[6]
    loop_ptr, rows, groups = mech[3], mech[4], mech[5]
    m = u0.shape[0]
    E = (loop_ptr.shape[0] - 1) * rows.shape[0]
    q = np.empty(groups.shape[0])
    res = np.empty(E)
    jac = np.empty((E, m))
    u = u0.copy()
    t = t0.copy()
    t_new = np.empty(m)
    sig = np.empty(out_sigma.shape[1])
    u_try = np.empty(m)
    h = h0
    # ---- the start: row 0, its tangent oriented along t0
    matrices, vectors = work_arrays()
    work = (q, res, jac, matrices, vectors, solve_work(m))  # every evaluation's work arrays, once per call
    r0 = evaluate_in(mech, u, work)
    svd = svd_work(E, m)  # the tangent's SVD work arrays; its right singular vectors carried from row to row
    tau = tangent_and_test_in(jac, t, basis, r_path, t_new, sig, svd, weight)
    if not (paper and singular_at(sig, r_path)):
        # (paper mode: a start on a singular point, a row landed on a crossing, goes on along the tangent it came
        # in with, however little the SVD's turned from it: its null vector is any of a plane's. An adaptive start
        # there, such as a point of a higher-dimensional component, takes the null vector the SVD gives, as before)
        t[:] = t_new
    write_row(out, 0, u, t, sig, r0, tau, 0.0, 0.0)
    # The test function's sign is compared step by step, every part of a paper row included (two sign changes
    # within one row would cancel between its rows): ``tau_last`` at the last point accepted, ``tau_row`` at the
    # row's start (a row taken again starts from it), ``n_cross`` the sign changes in the row so far.
    tau_last, tau_row, n_cross = tau, tau, 0
    # whether the last point accepted (and the row's start) is singular, its tangent without a direction
    singular_last = singular_at(sig, r_path)
    singular_row = singular_last
    cross_n[0] = 0
    if (
        reach[1] == 0.0
    ):  # a new path (no step taken yet): its tangent at the start, for the closure's alignment
        reach[2:] = t
    t_home = reach[2:]
    s_total, s_file = 0.0, 0.0  # the two arclengths of out_s
    basis_try = basis.copy()
    far = max(reach[0], wrapped_distance(u0, u_home, periodic, weight))
    longest = reach[1]  # the longest step of the path (a closed path has gone several of them from its start)
    recent = np.zeros(max(stall_steps, 1))  # lengths of the last stall_steps steps (a ring)
    count = 1
    # Paper mode: a row's equal drive step is taken in ``parts`` equal parts where one step jumps or fails (next
    # to a fold the tangent's prediction ``h / t_drive`` is far too long); only the last part writes a row. The
    # row's start is kept to go back to. A step longer than ``hmax`` (the drive's part of it, in the step's metric)
    # is taken in parts no longer than that from the start (``base``): one long step could land beyond a gap of the
    # path where the drive turns back and comes round again (a triple rocker's input, 150 -> 215 deg across its
    # extremes at +-157.8 deg), where short steps meet the fold. At most MAX_PARTS (a step of many turns).
    base = min(MAX_PARTS, max(1, int(np.ceil(abs(h) * weight[drive] / hmax - PART_SLACK)))) if paper else 1
    parts, part = base, 0
    u_row, t_row, basis_row = u.copy(), t.copy(), basis.copy()
    # Paper mode: a row's own drive value landed next to a singular point with the tangent turned is approached
    # again from the same side (see the acceptance below): ``close_frac`` the fraction of the drive's distance
    # left that the next closing part goes (0: the next step is no closing part), ``closes`` the closing parts
    # tried in this row, ``approached`` those accepted (the row's landing is then predicted from the last one).
    close_frac, closes, approached = 0.0, 0, 0
    while count <= max_steps:
        # ---- predictor (Sec. 4.1)
        first = count == 1 and part == 0
        tn = weighted_norm(t, weight) if weighted else 1.0  # the tangent's length in the step's metric
        step, landing, held = predict(u, t, h / parts, paper, drive, target, has_target, first, u_try, tn)
        along = step * tn  # the prediction's length in that metric
        if held == TURNED:  # paper mode: the drive has turned back, equal drive steps cannot go on
            return count, TURNING, h
        # a part's drive value from the row's, not a running sum of parts (which drifts over many rows); the last
        # part ends on the row's value, the target when it is there
        closing = close_frac > 0.0
        if paper and (closing or approached > 0):
            # closing in on the row's value: a closing part goes ``close_frac`` of the drive's distance left, and
            # the landing follows from the last point reached, each predicted along the tangent from there
            value = u_row[drive] + h
            landing = False
            if has_target and abs(value - target) < 1e-9 * max(1.0, abs(target)):
                value = target
                landing = not closing
            goal = u[drive] + close_frac * (value - u[drive]) if closing else value
            step = (goal - u[drive]) / t[drive]
            along = step * tn
            for a in range(m):
                u_try[a] = u[a] + step * t[a]
            u_try[drive] = goal
        elif paper and parts > 1:
            landing = False
            if part < parts - 1:
                u_try[drive] = u_row[drive] + (part + 1 - PART_SHIFT) * (h / parts)
            else:
                u_try[drive] = u_row[drive] + h
                if has_target and abs(u_try[drive] - target) < 1e-9 * max(1.0, abs(target)):
                    landing = True
                    u_try[drive] = target
        elif (
            paper and parts == 1
        ):  # the last two points and their tangents predict better than the tangent alone
            if count >= 2:
                extrapolate(out[0][count - 2], out[1][count - 2], u, t, drive, u_try, 0.1 * abs(step))
            elif not np.isnan(before[0, 0]):  # the row before this call's start
                extrapolate(before[0], before[1], u, t, drive, u_try, 0.1 * abs(step))
        # ---- corrector (Sec. 4.2, Eq. (28)), then the new tangent and the adaptive step's acceptance
        if held < 0:  # adaptive: on the hyperplane through the prediction normal to the tangent (scale-free)
            ok, _, r = correct_across(mech, u_try, t, corrector, work, weight)
            if ok and has_target and passes(u[drive], u_try[drive], target, t[drive]):
                # The prediction fell short of the target but the corrected point is beyond it (the path curves
                # towards it): the step lands on the target instead, the drive held there, from the tangent's
                # prediction at the target's drive value (else the target would be stepped over, never reached).
                step = (target - u[drive]) / t[drive]
                along = step * tn
                for a in range(m):
                    u_try[a] = u[a] + step * t[a]
                u_try[drive] = target
                landing, held = True, drive
                ok, _, r = correct_in(mech, u_try, held, corrector, work)
        else:
            ok, _, r = correct_in(mech, u_try, held, corrector, work)
        turn, dist, tau_new = 1.0, 0.0, 0.0
        easy = ok and correction(u, t, step, u_try, weight) <= 0.1 * abs(along)
        if ok:
            basis_try[:, :] = basis
            tau_new = tangent_and_test_in(jac, t, basis_try, r_path, t_new, sig, svd, weight)
            turn, dist, ahead = step_geometry(u, t, u_try, t_new, weight, weighted)
            # A step from a point whose tangent has a direction that lands next to a singular point with its tangent
            # turned by more than an adaptive step may has likely met the other branch: the corrector with the
            # drive held meets both within the prediction's error there (a parallelogram's part 1e-5 rad short of
            # 360 deg, or a row 1e-4 deg short of it, went on along the other branch). (Sharp turns away from
            # singular points, next to a fold, are the path's own; so is a turn from a point whose tangent has no
            # direction, a row landed on a crossing.)
            turned = (
                turn < cos_turn
                and not singular_last
                and r_path >= 1
                and r_path <= sig.shape[0]
                and sig[r_path - 1] <= NEAR_CROSSING * sig[0]
            )
            if not paper and not landing and h > hmin:
                ok = step_acceptable(turn, dist, ahead, along, cos_turn, advance)
            elif not paper:
                # a landing on the target (or a step of the least length): a landing that turned is approached again
                # in shorter steps, from the same side
                ok = not (turned and landing and h > hmin)
            elif (
                turned
                and not jumps(u, u_try, periodic)
                and (closing or part == parts - 1)
                and closes < MAX_CLOSES
            ):
                # The row's own drive value is fixed (retaking the row in more parts lands on it from the same
                # distance as before): it is approached again from this point in closing parts, each a fraction of
                # the distance left, until the landing from the last of them is short enough to keep to its branch
                # (its prediction's error below the branches' gap there) or starts from a point whose tangent has
                # no direction (the row then lands on the crossing, to round-off). A closing part that turned
                # too goes half as far.
                close_frac = (1.0 - PART_SHIFT) if not closing else 0.5 * close_frac
                closes += 1
                continue
            else:
                # An inner part's drive value is the march's own choice, not a row's: one that turned is taken
                # again in more parts, which moves it.
                ok = not jumps(u, u_try, periodic) and not turned
        if ok and singular_at(sig, r_path) and (paper or (landing and turn < cos_turn)):
            # Landed on a singular point, to round-off (a row on a crossing): its null vector is any of a plane's,
            # so the path goes on along the tangent it came in with, the branch it came along. In paper mode also
            # where the SVD's turned by less than an adaptive step may: from a row 1e-6 deg short of a crossing it
            # turned 9.8 deg, and the next part, not judged (from a point whose tangent has no direction), went on
            # along the other branch.
            for a in range(m):
                t_new[a] = t[a]
        if not ok:
            if paper:  # the row's step again from its start, in twice as many parts and one
                if parts >= MAX_PARTS:
                    return count, FAILED, h
                # An odd count moves every inner part's drive value: a part that failed on a singular point (a
                # change-point four-bar's crossing at 180 deg, met exactly by the parts of 60 -> 190 deg in 65,
                # 130, 260, ... parts) is not met exactly again, where doubling met it every time.
                parts, part = 2 * parts + 1, 0
                close_frac, closes, approached = 0.0, 0, 0
                u[:] = u_row
                t[:] = t_row
                basis[:, :] = basis_row
                tau_last, n_cross, singular_last = tau_row, 0, singular_row
                continue
            h *= 0.5
            if h < hmin:
                return count, FAILED, h
            continue
        # ---- accept the step
        if detect and tau_new * tau_last < 0.0:  # a sign change over this step: its bracket, for the locator
            if n_cross < cross_u.shape[0]:
                cross_u[n_cross, 0, :] = u
                cross_u[n_cross, 1, :] = u_try
                cross_t[n_cross, 0, :] = t
                cross_t[n_cross, 1, :] = t_new
                cross_basis[n_cross, :, :] = basis
            n_cross += 1
        tau_last = tau_new
        singular_last = singular_at(sig, r_path)
        # the arclengths reported, every part of a row summed: in the unknowns as they are (lengths in the length
        # unit, as the closed form's) and in the file units
        s_total += measured_length(u, u_try, measure[0])
        s_file += measured_length(u, u_try, measure[1])
        longest = max(longest, dist)
        reach[1] = longest
        for a in range(m):
            u[a] = u_try[a]
            t[a] = t_new[a]
        basis[:, :] = basis_try
        if closing:  # a closing part: the row's value is landed on from here next
            close_frac = 0.0
            approached += 1
            continue
        if paper and part < parts - 1:  # a part of the row's step: on to the next, no row
            part += 1
            continue
        if paper:
            parts, part = base, 0
            closes, approached = 0, 0
            u_row[:] = u
            t_row[:] = t
            basis_row[:, :] = basis
        write_row(out, count, u, t, sig, r, tau_new, s_total, s_file)
        recent[count % recent.shape[0]] = dist
        count += 1
        cross_n[0] = n_cross  # the sign changes within the row just written (an even number leaves its sign)
        crossed = -1.0 if n_cross > 0 else 1.0
        tau_row, n_cross, singular_row = tau_new, 0, singular_last
        # ---- events that end the march
        if not paper and count > recent.shape[0] and np.sum(recent) < stall_length * hmax:
            return count, NO_PROGRESS, h
        code = step_event(u, landing, lo, hi, detect, crossed)
        if code != NO_EVENT:
            return count, code, h
        if check_closed:
            d = wrapped_distance(u, u_home, periodic, weight)  # to the start of the path
            far = max(far, d)
            reach[0] = far
            align = 0.0
            for a in range(m):
                align += t[a] * t_home[a] * (weight[a] * weight[a])
            if weighted:  # the cosine in the step's metric
                align /= weighted_norm(t, weight) * weighted_norm(t_home, weight)
            aligned = align > 2.0 * cos_turn * cos_turn - 1.0  # within two steps' largest turn of the start's
            if aligned and back_home(u, u_home, periodic, d, far, longest, h, paper, drive):
                close_path(u, u_home, periodic, count - 1, out, measure)
                return count, CLOSED, h
        # ---- step control: grow an easy adaptive step (judged in the unknowns, so that it does not depend on the
        # length unit or where the linkage stands: the corrector moved the point by under a tenth of the step)
        if not paper and easy and turn > np.sqrt(cos_turn):
            h = min(h * 1.5, hmax)
    return count, BUDGET, h


@kernel(inline="always")
def singular_at(sig, r_path):
    """Whether a point with singular values ``sig`` is singular (:data:`SINGULAR_START`): its path's smallest kept
    singular value ``sig[r_path - 1]`` below that fraction of the largest, its tangent without a direction."""
    return r_path >= 1 and r_path <= sig.shape[0] and sig[r_path - 1] <= SINGULAR_START * sig[0]


@kernel(inline="always")
def jumps(u, u_try, periodic):
    """Whether a paper-mode step from ``u`` to ``u_try`` turned a revolute unknown by more than a quarter turn:
    the corrector went to another part of the path (or the same configuration counted whole turns on), where a
    step along the path would have moved it less; the step is then taken in parts."""
    for a in range(u.shape[0]):
        if periodic[a] and abs(u_try[a] - u[a]) > 0.5 * np.pi:
            return True
    return False


@kernel(inline="always")
def back_home(u, u_home, periodic, d, far, longest, h, paper, drive):
    """Whether the point ``u``, ``d`` from the path's start ``u_home`` (``far`` the farthest the path went), closes
    the path (its tangent aligned with the start's, checked before: a branch crossing the start's branch through a
    bifurcation point next to the start passes near it at an angle).

    Adaptive steps: within one and a half steps of the start after going more than four of the longest steps
    taken away (so that a small closed loop, shorter than a few ``hmax``, is recognised too). Paper mode: the
    drive back at its start value to round-off after whole turns, and every other unknown within half a step
    (equal drive steps close a path only by landing on its start: a step near the start, or the one before the
    last of a full turn, is not the start)."""
    if not paper:
        return far > 4.0 * longest and d < 1.5 * abs(h)
    turned = u[drive] - u_home[drive]
    if not periodic[drive] or abs(turned) < np.pi:
        return False
    off = (turned + np.pi) % (2.0 * np.pi) - np.pi
    return abs(off) <= 1e-9 * max(1.0, abs(turned)) and d < 0.5 * abs(h)


@kernel(inline="always")
def write_row(out, row, u, t, sig, r, tau, s, s_file):
    """Row ``row`` of the march's outputs ``out``: the point, its tangent, singular values, residual, test value
    and the two arclengths (``out_s``'s columns, see :func:`march`)."""
    out_u, out_t, out_sigma, out_res, out_tau, out_s = out[0], out[1], out[2], out[3], out[4], out[5]
    out_u[row, :] = u
    out_t[row, :] = t
    out_sigma[row, :] = sig
    out_res[row] = r
    out_tau[row] = tau
    out_s[row, 0] = s
    out_s[row, 1] = s_file


@kernel(inline="always")
def step_acceptable(turn, dist, ahead, step, cos_turn, advance):
    """Whether an adaptive step is kept: the tangent turned by less than ``acos(cos_turn)``, the corrector neither
    jumped (more than twice the step away) nor pulled the point back (less than ``advance`` of the step ahead)."""
    jumped = dist > 2.0 * step + 1e-300
    pulled_back = ahead < advance * step
    return not (turn < cos_turn or jumped or pulled_back)


@kernel(inline="always")
def step_event(u, landing, lo, hi, detect, tau_product):
    """The stop code an accepted step ends the march with (the target reached, a joint limit passed, a sign change
    of the test function within the step, ``tau_product`` negative: -1 when its sign changed at least once over
    the row's steps or parts, compared one by one), ``NO_EVENT`` for none. A joint limit passed comes first, also
    on the step that lands on the target (the branch ends on the limit, short of the target: a limit is a stop the
    user set, and the target beyond it is not reached). A step
    landing on the target over which the test function changed sign ends with the sign change (the bifurcation it
    passed is located; the march then ends on the target it reached, ``BranchMarcher``)."""
    for a in range(u.shape[0]):
        if u[a] < lo[a] or u[a] > hi[a]:
            return LIMIT
    if landing:
        if detect and tau_product < 0.0:
            return SIGN_CHANGE
        return TARGET
    if detect and tau_product < 0.0:
        return SIGN_CHANGE
    return NO_EVENT


@kernel(inline="always")
def close_path(u, u_home, periodic, row, out, measure):
    """Make row ``row`` of the outputs ``out`` (written at the march's point ``u``) the start again (in ``u``'s
    continuous angles, see :func:`snap_home`): the path closed. Its arclengths (``measure``, see :func:`march`) are
    the march's to ``u`` with the last step's chord from the row before moved from ``u`` to the start: an adaptive
    step that came near the start was longer or shorter than the one to it, and a paper row lands on the start
    (to round-off) after parts whose lengths are summed (the chord of a long row is shorter than its path)."""
    out_u, out_sigma, out_res, out_tau, out_s = out[0], out[2], out[3], out[4], out[5]
    snap_home(u, u_home, periodic, out_u[row])
    out_sigma[row, :] = out_sigma[0, :]
    out_res[row] = out_res[0]
    out_tau[row] = out_tau[0]
    if row > 0:
        for k in range(2):
            w = measure[k]
            moved = measured_length(out_u[row - 1], out_u[row], w) - measured_length(out_u[row - 1], u, w)
            out_s[row, k] = out_s[row, k] + moved
