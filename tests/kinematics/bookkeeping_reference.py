"""An independent reference for the bookkeeping properties: loop products by scipy's matrix exponential and the
closure Jacobian by central finite differences of them, the same Jacobian in closed form (Rodrigues' exponential and
the adjoint, :func:`fresh_rows`), plus generators of linkages from their closed forms.

Nothing here calls linkwork's own closure, Jacobian or kernels: the twists of a :class:`Mechanism` (its written
geometry) are the only input taken from the code under test.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

from linkwork.kinematics.chains import from_dh
from linkwork.kinematics.mechanism import Mechanism


def hat(xi: np.ndarray) -> np.ndarray:
    """The 4x4 matrix of a twist ``(omega, v)``."""
    w, v = xi[:3], xi[3:]
    out = np.zeros((4, 4))
    out[:3, :3] = [[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]]
    out[:3, 3] = v
    return out


def vee(M: np.ndarray) -> np.ndarray:
    """The twist ``(omega, v)`` of a 4x4 matrix of se(3) (its skew part averaged)."""
    S = 0.5 * (M[:3, :3] - M[:3, :3].T)
    return np.array([S[2, 1], S[0, 2], S[1, 0], *M[:3, 3]])


def loop_products(mech: Mechanism, q: np.ndarray) -> list[np.ndarray]:
    """Each loop's product ``prod exp(s xi_j q_j)`` by ``scipy.linalg.expm``."""
    out = []
    for loop in mech.loops:
        g = np.eye(4)
        for j, s in zip(loop.joints, loop.signs, strict=True):
            g = g @ expm(hat(s * mech.twists[j] * q[j]))
        out.append(g)
    return out


def residual(mech: Mechanism, angles: np.ndarray) -> float:
    """2-norm of the kept rows of every loop's ``P - I`` (zero exactly where the loops close)."""
    q = angles - mech.offsets
    rows = list(mech.rows)
    parts = [vee(P - np.eye(4))[rows] for P in loop_products(mech, q)]
    return float(np.linalg.norm(np.concatenate(parts)))


def jacobian(mech: Mechanism, angles: np.ndarray, step: float = 1e-6) -> np.ndarray:
    """The reduced closure Jacobian at joint values ``angles``: central differences of the loop products,
    right-trivialised (``dP P^-1``), in the unknowns (couplings summed, fixed joints left out)."""
    q = angles - mech.offsets
    C = mech.coupling_matrix()
    rows = list(mech.rows)
    P0 = loop_products(mech, q)
    cols = []
    for a in range(mech.n_unknowns):
        plus = loop_products(mech, q + step * C[:, a])
        minus = loop_products(mech, q - step * C[:, a])
        col = [
            vee((Pp - Pm) / (2.0 * step) @ np.linalg.inv(P))[rows]
            for Pp, Pm, P in zip(plus, minus, P0, strict=True)
        ]
        cols.append(np.concatenate(col))
    return np.array(cols).T


def singular_values(mech: Mechanism, angles: np.ndarray) -> np.ndarray:
    """numpy's singular values of :func:`jacobian`."""
    return np.linalg.svd(jacobian(mech, angles), compute_uv=False)


def rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation by ``angle`` about ``axis``."""
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * K @ K


def exp_twist(xi: np.ndarray, theta: float) -> np.ndarray:
    """``exp(xi theta)`` as a 4x4 matrix in closed form (Rodrigues; a pure translation for ``omega = 0``); for a
    revolute twist ``|omega| = 1``."""
    w, v = xi[:3], xi[3:]
    g = np.eye(4)
    if not np.any(w):
        g[:3, 3] = v * theta
        return g
    R = rotation(w, theta)
    g[:3, :3] = R
    g[:3, 3] = (np.eye(3) - R) @ np.cross(w, v) + np.outer(w, w) @ v * theta
    return g


def adjoint(g: np.ndarray) -> np.ndarray:
    """The 6x6 adjoint of a rigid transform acting on twists ``(omega, v)``."""
    R, p = g[:3, :3], g[:3, 3]
    P = np.array([[0.0, -p[2], p[1]], [p[2], 0.0, -p[0]], [-p[1], p[0], 0.0]])
    out = np.zeros((6, 6))
    out[:3, :3] = out[3:, 3:] = R
    out[3:, :3] = P @ R
    return out


def fresh_rows(mech: Mechanism, angles: np.ndarray) -> tuple[np.ndarray, float]:
    """Singular values of the reduced closure Jacobian at ``angles`` and the closure residual (2-norm of the kept
    rows of ``P - I``), from the twists alone: ``dP P^-1 = sum_j Ad(e_1 ... e_(j-1)) xi_j dq_j`` per loop (the
    spatial product-of-exponentials Jacobian, Murray, Li and Sastry 1994, Sec. 3.4)."""
    q = angles - mech.offsets
    rows = list(mech.rows)
    blocks, misfit = [], []
    for loop in mech.loops:
        g, block = np.eye(4), np.zeros((6, mech.n_joints))
        for j, sign in zip(loop.joints, loop.signs, strict=True):
            xi = sign * mech.twists[j]
            block[:, j] += adjoint(g) @ xi
            g = g @ exp_twist(xi, q[j])
        blocks.append(block[rows])
        misfit.append(vee(g - np.eye(4))[rows])
    jac = np.concatenate(blocks) @ mech.coupling_matrix()
    return np.linalg.svd(jac, compute_uv=False), float(np.linalg.norm(np.concatenate(misfit)))


def wrapped(x: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi)."""
    return (x + np.pi) % (2.0 * np.pi) - np.pi


# ------------------------------------------------------------------------------------ generated linkages
def bennett(alpha1: float, alpha2: float, theta1: float, scale: float = 1.0) -> Mechanism:
    """Bennett's linkage from its closed form (DH, radians): ``a_i = scale sin(alpha_i)``,
    ``tan(t1/2) tan(t2/2) = sin((a2 + a1)/2) / sin((a2 - a1)/2)``, ``t3 = -t1``, ``t4 = -t2``."""
    k = np.sin((alpha2 + alpha1) / 2.0) / np.sin((alpha2 - alpha1) / 2.0)
    theta2 = 2.0 * np.arctan(k / np.tan(theta1 / 2.0))
    alphas = (alpha1, alpha2, alpha1, alpha2)
    thetas = (theta1, theta2, -theta1, -theta2)
    params = [
        {"theta": t, "a": float(scale * np.sin(a)), "alpha": a} for t, a in zip(thetas, alphas, strict=True)
    ]
    return from_dh("Bennett", params)[0]


def planar_four_bar(ground: float, crank: float, coupler: float, rocker: float, theta: float) -> Mechanism:
    """A planar four-bar assembled by circle intersection (elbow up): ground pivots at (0, 0) and (ground, 0),
    the crank at ``theta``."""
    O2, O4 = np.array([0.0, 0.0]), np.array([ground, 0.0])
    A = crank * np.array([np.cos(theta), np.sin(theta)])
    d = float(np.linalg.norm(O4 - A))
    x = (coupler**2 - rocker**2 + d * d) / (2.0 * d)
    y = np.sqrt(max(coupler**2 - x * x, 0.0))
    e = (O4 - A) / d
    B = A + x * e + y * np.array([-e[1], e[0]])
    joints = [
        {"name": "A", "bodies": ["ground", "crank"], "point": O2, "direction": [0, 0, 1]},
        {"name": "B", "bodies": ["crank", "coupler"], "point": A, "direction": [0, 0, 1]},
        {"name": "C", "bodies": ["coupler", "rocker"], "point": B, "direction": [0, 0, 1]},
        {"name": "D", "bodies": ["rocker", "ground"], "point": O4, "direction": [0, 0, 1]},
    ]
    return Mechanism.from_joints("four-bar", joints, planar=True)


def spherical_four_bar(ground: float, crank: float, coupler: float, rocker: float, theta: float) -> Mechanism:
    """A spherical 4R (every hinge line through the origin): link arcs in radians, the crank at ``theta`` about
    the first ground axis; the coupler axis found on the sphere by intersecting two circles (unit vectors)."""
    a = np.array([0.0, 0.0, 1.0])
    d = np.array([np.sin(ground), 0.0, np.cos(ground)])
    b = np.array([np.sin(crank) * np.cos(theta), np.sin(crank) * np.sin(theta), np.cos(crank)])
    # c: unit, c.b = cos(coupler), c.d = cos(rocker)
    M = np.array([b, d])
    rhs = np.array([np.cos(coupler), np.cos(rocker)])
    c0 = np.linalg.lstsq(M, rhs, rcond=None)[0]
    n = np.cross(b, d)
    n /= np.linalg.norm(n)
    t = np.sqrt(max(1.0 - c0 @ c0, 0.0))
    c = c0 + t * n
    joints = [
        {"name": "A", "bodies": ["ground", "crank"], "direction": a},
        {"name": "B", "bodies": ["crank", "coupler"], "direction": b},
        {"name": "C", "bodies": ["coupler", "rocker"], "direction": c},
        {"name": "D", "bodies": ["rocker", "ground"], "direction": d},
    ]
    return Mechanism.from_joints("spherical 4R", joints)


def stephenson_six_bar(theta: float, spread: float = 0.0) -> Mechanism:
    """A Stephenson six-bar: a crank-rocker four-bar (ground 2, crank 0.6, coupler 2.2, rocker 2) whose coupler
    carries a third pivot E, joined to a second ground pivot G by the dyad E-F-G with equal links longer than
    half the largest distance from E to G (so it assembles all the way round); the crank A starts at ``theta``
    and reads ``theta`` there. ``spread`` (-1..1) moves G along a line below the ground."""
    four = planar_four_bar(2.0, 0.6, 2.2, 2.0, theta)
    pts = {four.joint_names[j]: np.cross(four.twists[j, :3], four.twists[j, 3:]) for j in range(4)}
    B, C = pts["B"][:2], pts["C"][:2]
    along = (C - B) / np.linalg.norm(C - B)
    E = B + 0.5 * (C - B) + 0.8 * np.array([-along[1], along[0]])
    G = np.array([1.0 + 1.5 * spread, -2.5])
    half = 0.5 * float(np.linalg.norm(E - G))
    link = 4.0  # > half of the largest |E - G| over the crank's turn (below 4 here)
    mid = 0.5 * (E + G)
    normal = np.array([-(E - G)[1], (E - G)[0]]) / (2.0 * half)
    F = mid + np.sqrt(link**2 - half**2) * normal
    joints = [
        {"name": "A", "bodies": ["ground", "crank"], "point": pts["A"][:2], "value": theta},
        {"name": "B", "bodies": ["crank", "coupler"], "point": B},
        {"name": "C", "bodies": ["coupler", "rocker"], "point": C},
        {"name": "D", "bodies": ["rocker", "ground"], "point": pts["D"][:2]},
        {"name": "E", "bodies": ["coupler", "link5"], "point": E},
        {"name": "F", "bodies": ["link5", "link6"], "point": F},
        {"name": "G", "bodies": ["link6", "ground"], "point": G},
    ]
    for j in joints:
        j["direction"] = [0.0, 0.0, 1.0]
    return Mechanism.from_joints("Stephenson six-bar", joints, planar=True)
