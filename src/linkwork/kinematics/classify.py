"""What a located singular point is: a bifurcation point with its branch tangents, or where the path meets a
higher-dimensional component of the configuration space; and where the drive folds back.

A point where the Jacobian's rank drops is a bifurcation point when the solution set near it is a finite set of
curves (two or more branch tangents, Kumar & Pellegrino 2000). When the solution set near it has dimension two or
more (e.g. the Sarrus linkage folded flat, where two hinge lines coincide), it is not a point of a branch graph but
an entry into a component of that dimension: reported once, with no branch switching along it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from linkwork.kinematics.bifurcation import (
    branch_tangents,
    correct_on_plane,
    hermite,
    polish,
    refine_singular,
)
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import Tolerances, numerical_rank
from linkwork.kinematics.trace_result import Bifurcation
from linkwork.kinematics.workspace import Workspace

if TYPE_CHECKING:
    from linkwork.kinematics.marcher import MarchSettings

Array = NDArray[np.float64]

#: Directions sampled in the null space to tell an isolated point from a higher-dimensional component.
COMPONENT_SAMPLES = 12
#: Distance (in the unknowns) of those samples from the point.
COMPONENT_RADIUS = 1e-3
#: More lines through a point than this, found by sampling a small sphere around it, are a continuum: a
#: rounded Sarrus linkage's point where two 2-dimensional components meet gave 34, and as many branches each way.
CONTINUUM_LINES = 4
#: How far (in the unknowns) a located point may move onto the singular point next to it.
NODE_RADIUS = 1e-2


def component_dimension(ws: Workspace, u: Array, tol: Tolerances) -> int:
    """Dimension of the configuration space near ``u`` when it is 2 or more, else 0.

    Points at distance :data:`COMPONENT_RADIUS` along directions of the Jacobian's null space are corrected onto
    the loop; when (nearly) every direction leads to a configuration, and the mobility there is 2 or more, ``u``
    lies on a component of that dimension. Near an isolated bifurcation point the corrected points lie on its
    branches, where the mobility is one.
    """
    _, _, jac = ws.evaluate(u)
    _, s, Vt = np.linalg.svd(jac)
    m = jac.shape[1]
    nullity = m - numerical_rank(s, tol)
    if nullity < 2:
        return 0
    N = Vt[m - nullity :].T
    rng = np.random.default_rng(0)
    mobilities = []
    for a in rng.normal(size=(COMPONENT_SAMPLES, nullity)):
        direction = N @ (a / np.linalg.norm(a))
        v, _r, ok = correct_on_plane(ws, u + COMPONENT_RADIUS * direction, direction, tol)
        if not ok or np.linalg.norm(v - u) > 3.0 * COMPONENT_RADIUS:
            continue
        _, _, jv = ws.evaluate(v)
        mobilities.append(m - numerical_rank(np.linalg.svd(jv, compute_uv=False), tol))
    if len(mobilities) < 0.75 * COMPONENT_SAMPLES:
        return 0
    dim = int(np.median(mobilities))
    return dim if dim >= 2 else 0


def classify_point(
    mech: Mechanism,
    ws: Workspace,
    ident: int,
    branch: int,
    step: int,
    u: Array,
    width: float,
    cfg: MarchSettings,
) -> Bifurcation:
    """Classify a located point: rank, singular values, branch tangents (over the joints and the unknowns), or
    the dimension of the component it lies on.

    ``kind``: ``"component"`` (the configuration space has dimension 2 or more there), ``"bifurcation"`` (two or
    more branch tangents), or ``"fold"`` (fewer than two real branch tangents: the path only touches the singular
    set there and no other branch leaves it)."""
    tol = cfg.tol
    dim = component_dimension(ws, u, tol)
    if dim >= 2:
        _, _, jac = ws.evaluate(u)
        sigma = np.asarray(np.linalg.svd(jac, compute_uv=False), dtype=float)
        tangents_u = np.zeros((0, len(u)))
        method, rank = "component", numerical_rank(sigma, tol)
    else:
        tangents_u, method, rank, sigma = branch_tangents(mech, ws, u, tol, rank_hint=cfg.r_path - 1)
        if len(tangents_u) < 2 and sigma[cfg.r_path - 1] < tol.local_min * sigma[0]:
            moved = _onto_node(mech, ws, u, cfg)
            if moved is not None:
                width = float(np.linalg.norm(moved[0] - u))
                u, (tangents_u, method, rank, sigma) = moved
        if method == "sphere" and len(tangents_u) > CONTINUUM_LINES:
            # The solution set crosses the small sphere in a curve, not in a few points: a continuum of
            # directions leaves the point, which lies on a set of dimension 2 or more (a component whose
            # corrected samples did not all converge: an over-constrained loop written with rounded numbers).
            dim, method = 2, "component"
            tangents_u = np.zeros((0, len(u)))
        if len(tangents_u) == 2:
            polished, gap, accuracy = polish(ws, u, tangents_u, tol)
            if np.isfinite(gap) and gap < tol.polish_gap:
                u, width = polished, accuracy
                tangents_u, method, rank, sigma = branch_tangents(mech, ws, u, tol, rank_hint=cfg.r_path - 1)
    res_norm, _, _ = ws.evaluate(u)
    C = mech.coupling_matrix()
    over_joints = np.array([C @ t / np.linalg.norm(C @ t) for t in tangents_u]).reshape(
        len(tangents_u), mech.n_joints
    )
    return Bifurcation(
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
        tangents_u=tangents_u,
        kind="component" if dim >= 2 else ("bifurcation" if len(tangents_u) >= 2 else "fold"),
        dimension=dim,
    )


def _onto_node(
    mech: Mechanism, ws: Workspace, u: Array, cfg: MarchSettings
) -> tuple[Array, tuple[Array, str, int, Array]] | None:
    """The singular point next to a located point whose rank has nearly dropped, with its branch tangents, when
    there is one within :data:`NODE_RADIUS` with two or more tangents
    (:func:`linkwork.kinematics.bifurcation.refine_singular`); otherwise None."""
    tol = cfg.tol
    node = refine_singular(ws, u, cfg.r_path - 1, tol)
    if node is None or np.linalg.norm(node - u) > NODE_RADIUS:
        return None
    found = branch_tangents(mech, ws, node, tol, rank_hint=cfg.r_path - 1)
    return (node, found) if len(found[0]) >= 2 else None


def locate_fold(
    ws: Workspace,
    u_a: Array,
    t_a: Array,
    u_b: Array,
    t_b: Array,
    drive: int,
    tol: Tolerances,
    weight: Array | None = None,
) -> Array:
    """The fold of the drive between path points ``a`` and ``b``: where the tangent's drive component vanishes.

    Bisection on ``h``, the distance along ``t_a`` in the step's metric (``weight``, each unknown's weight: 1 for
    an angle, ``1 / L`` for a length; None: all 1), to ``tol.locate`` in that metric; each trial point is
    predicted by the cubic Hermite curve through the two points and corrected in the hyperplane of its ``h``
    (as :func:`linkwork.kinematics.bifurcation.locate`), and its tangent oriented along ``t_a`` in that metric,
    so that the fold found does not depend on the length unit (in the plain metric a slider in a small unit
    outweighs every angle, and its tangent flipped on the far side of the slider's extreme).
    """
    w2 = np.ones_like(t_a) if weight is None else np.asarray(weight) ** 2
    axis = w2 * t_a / np.sqrt(float(t_a @ (w2 * t_a)))
    sign_a = np.sign(t_a[drive])
    lo, hi = (0.0, u_a, t_a), (float(axis @ (u_b - u_a)), u_b, t_b)
    best = u_a
    for _ in range(100):
        if abs(hi[0] - lo[0]) < tol.locate:
            break
        x = 0.5 * (lo[0] + hi[0])
        u_x, _, ok = correct_on_plane(ws, hermite(x, lo, hi, axis), axis, tol)
        if not ok:
            break
        _, _, jac = ws.evaluate(u_x)
        t_x = np.linalg.svd(jac)[2][-1]
        t_x = t_x if t_x @ (w2 * t_a) > 0 else -t_x
        best = u_x
        if np.sign(t_x[drive]) == sign_a:
            lo = (x, u_x, t_x)
        else:
            hi = (x, u_x, t_x)
    return best
