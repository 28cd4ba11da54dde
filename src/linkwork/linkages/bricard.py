"""Bricard's movable 6R loops (line-symmetric, plane-symmetric, trihedral, threefold-symmetric) in the DH convention.

Each constructor takes DH parameters satisfying the classical conditions of its type (Bricard 1927; Baker 1980;
Chen, You & Tarnai 2005), written here with ``a_i, alpha_i`` the link from joint ``i`` to joint ``i + 1`` and
``d_i`` the offset along joint ``i`` (Baker's ``a_{i,i+1}``, ``alpha_{i,i+1}``, ``R_i``), and the DH convention
``T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``, ``T_1 ... T_6 = I``. The start configuration is found by
fixing joint A at ``theta`` and solving the loop closure for the other angles (scipy least squares, within the
symmetry of the type where it has one), then closing it to 1e-12 with :func:`linkwork.kinematics.chains.from_dh`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import least_squares

from linkwork.errors import AssemblyError, SpecError
from linkwork.geometry import log_se3
from linkwork.kinematics.chains import dh_transform, from_dh
from linkwork.kinematics.mechanism import Array, Mechanism
from linkwork.linkages.registry import LinkageEntry, Param, register

JOINTS = ("A", "B", "C", "D", "E", "F")

#: A link ``(d_i, a_i, alpha_i)``: offset along joint i, then length and twist of the link to joint i + 1.
Link = tuple[float, float, float]


def dh_loop_residual(thetas: ArrayLike, links: Sequence[Link]) -> Array:
    """The twist ``log(T_1 ... T_n)`` (6,) of a DH loop; zero exactly when it closes."""
    g = np.eye(4)
    for theta, (d, a, alpha) in zip(np.asarray(thetas, dtype=float), links, strict=True):
        g = g @ dh_transform(theta, d, a, alpha)
    return log_se3(g)


ASSEMBLY_BUDGET = 4000
"""The most closure-residual evaluations :func:`solve_start` spends looking for an assembly."""


def solve_start(
    name: str,
    links: Sequence[Link],
    theta: float,
    expand: Callable[[float, Array], Array],
    n_unknowns: int,
    *,
    tries: int = 400,
    tolerance: float = 1e-11,
) -> Array:
    """Joint angles closing a DH loop with joint A at ``theta``: ``expand(theta, x)`` maps the unknowns to all angles.

    Guesses come from a seeded generator (reproducible); the first that converges below ``tolerance`` wins.
    Raises :class:`AssemblyError` when none does: the loop cannot be assembled with joint A at ``theta``.
    """
    rng = np.random.default_rng(20050301)
    best = np.inf
    spent, started = 0, 0
    for _ in range(tries):
        if spent >= ASSEMBLY_BUDGET:
            break  # a stated bound on the search: a loop that does not close is reported in seconds
        x0 = rng.uniform(-np.pi, np.pi, n_unknowns)
        fit = least_squares(
            lambda x: dh_loop_residual(expand(theta, x), links),
            x0,
            method="lm",
            xtol=1e-15,
            ftol=1e-15,
            gtol=1e-15,
            max_nfev=100,
        )
        spent, started = spent + fit.nfev, started + 1
        residual = float(np.linalg.norm(fit.fun))
        best = min(best, residual)
        if residual < tolerance:
            thetas = expand(theta, fit.x)
            return np.pi - np.mod(np.pi - thetas, 2.0 * np.pi)  # into (-pi, pi]
    raise AssemblyError(
        f"{name}: no assembly found with joint A at {np.degrees(theta):.6g} deg (smallest closure residual "
        f"{best:.3g} over {started} starts, a budget of {ASSEMBLY_BUDGET} residual evaluations); try another "
        "start angle theta",
        residual=best,
    )


def _build(
    name: str, title: str, links: Sequence[Link], thetas: Array, values: dict[str, float]
) -> Mechanism:
    """The assembled mechanism of a solved DH loop, with the parameters recorded in ``meta``."""
    params = [
        {"theta": float(t), "d": float(d), "a": float(a), "alpha": float(al)}
        for t, (d, a, al) in zip(thetas, links, strict=True)
    ]
    mech, _ = from_dh(title, params, joint_names=JOINTS, meta={"linkage": name, **values})
    return mech


# ------------------------------------------------------------------------------------------------------------
# line-symmetric
def bricard_line_links(a: Sequence[float], alpha: Sequence[float], d: Sequence[float]) -> list[Link]:
    """DH links of the line-symmetric Bricard loop: ``a_{i+3} = a_i``, ``alpha_{i+3} = alpha_i``, ``d_{i+3} = d_i``."""
    half = [(float(d[i]), float(a[i]), float(alpha[i])) for i in range(3)]
    return half + half  # Bricard (1927); Baker (1980), line-symmetric case


def bricard_line(
    a1: float = 1.0,
    a2: float = 1.4,
    a3: float = 0.7,
    alpha1: float = np.radians(45.0),
    alpha2: float = np.radians(110.0),
    alpha3: float = np.radians(-65.0),
    d1: float = 0.3,
    d2: float = 0.5,
    d3: float = -0.2,
    theta: float = np.radians(30.0),
) -> Mechanism:
    """Bricard's line-symmetric 6R loop, joints ``A..F``, with joint A at ``theta``.

    Conditions: ``a_4 = a_1``, ``a_5 = a_2``, ``a_6 = a_3``; ``alpha_4 = alpha_1``, ``alpha_5 = alpha_2``,
    ``alpha_6 = alpha_3``; ``d_4 = d_1``, ``d_5 = d_2``, ``d_6 = d_3``. The loop then has a half-turn symmetry
    about a line, and opposite joints turn equally: ``theta_4 = theta_1``, ``theta_5 = theta_2``,
    ``theta_6 = theta_3`` (used as the ansatz of the start solve; the loop product is then ``(T_1 T_2 T_3)^2``).

    Parameters
    ----------
    a1, a2, a3, alpha1, alpha2, alpha3, d1, d2, d3
        The first half of the DH parameters (lengths; twists in radians); the second half repeats them.
    theta
        Start angle of joint A (radians).

    References
    ----------
    .. [1] R. Bricard, Leçons de cinématique, Tome II, Gauthier-Villars, Paris, 1927.
    .. [2] J. E. Baker, "An analysis of the Bricard linkages", Mech. Mach. Theory 15 (1980) 267-286.
    """
    links = bricard_line_links((a1, a2, a3), (alpha1, alpha2, alpha3), (d1, d2, d3))

    def expand(t1: float, x: Array) -> Array:
        return np.array([t1, x[0], x[1], t1, x[0], x[1]])  # theta_{i+3} = theta_i

    thetas = solve_start("bricard-line", links, theta, expand, 2)
    values = dict(a1=a1, a2=a2, a3=a3, alpha1=alpha1, alpha2=alpha2, alpha3=alpha3, d1=d1, d2=d2, d3=d3)
    return _build("bricard-line", "Bricard line-symmetric", links, thetas, {**values, "theta": theta})


# ------------------------------------------------------------------------------------------------------------
# plane-symmetric
def bricard_plane_links(a: Sequence[float], alpha: Sequence[float], d2: float, d3: float) -> list[Link]:
    """DH links of the plane-symmetric Bricard loop (symmetry plane through joints 1 and 4).

    ``a_6 = a_1``, ``a_5 = a_2``, ``a_4 = a_3``; ``alpha_6 = -alpha_1``, ``alpha_5 = -alpha_2``,
    ``alpha_4 = -alpha_3`` (Baker's ``alpha_{61} = 2 pi - alpha_{12}``, ...); ``d_1 = d_4 = 0``,
    ``d_6 = -d_2``, ``d_5 = -d_3``.
    """
    a1, a2, a3 = (float(x) for x in a)
    al1, al2, al3 = (float(x) for x in alpha)
    return [
        (0.0, a1, al1),
        (float(d2), a2, al2),
        (float(d3), a3, al3),
        (0.0, a3, -al3),
        (-float(d3), a2, -al2),
        (-float(d2), a1, -al1),
    ]


def bricard_plane(
    a1: float = 1.0,
    a2: float = 1.4,
    a3: float = 0.8,
    alpha1: float = np.radians(40.0),
    alpha2: float = np.radians(110.0),
    alpha3: float = np.radians(130.0),
    d2: float = 0.3,
    d3: float = -0.4,
    theta: float = np.radians(30.0),
) -> Mechanism:
    """Bricard's plane-symmetric 6R loop, joints ``A..F``, with joint A at ``theta``.

    Conditions (Baker 1980, in this module's indexing): ``a_6 = a_1``, ``a_5 = a_2``, ``a_4 = a_3``;
    ``alpha_1 + alpha_6 = alpha_2 + alpha_5 = alpha_3 + alpha_4 = 2 pi``; ``d_1 = d_4 = 0``, ``d_6 = -d_2``,
    ``d_5 = -d_3``. The loop is mirror-symmetric in a plane containing joints A and D, and the mirrored joints
    turn equally, ``theta_6 = theta_2``, ``theta_5 = theta_3`` (the ansatz of the start solve).

    Parameters
    ----------
    a1, a2, a3, alpha1, alpha2, alpha3
        Lengths and twists (radians) of links AB, BC, CD; FA, EF, DE mirror them.
    d2, d3
        Offsets at joints B and C; F and E have the opposite offsets, A and D none.
    theta
        Start angle of joint A (radians).

    References
    ----------
    .. [1] R. Bricard, Leçons de cinématique, Tome II, Gauthier-Villars, Paris, 1927.
    .. [2] J. E. Baker, "An analysis of the Bricard linkages", Mech. Mach. Theory 15 (1980) 267-286.
    """
    links = bricard_plane_links((a1, a2, a3), (alpha1, alpha2, alpha3), d2, d3)

    def expand(t1: float, x: Array) -> Array:
        return np.array([t1, x[0], x[1], x[2], x[1], x[0]])  # theta_6 = theta_2, theta_5 = theta_3

    thetas = solve_start("bricard-plane", links, theta, expand, 3)
    values = dict(a1=a1, a2=a2, a3=a3, alpha1=alpha1, alpha2=alpha2, alpha3=alpha3, d2=d2, d3=d3)
    return _build("bricard-plane", "Bricard plane-symmetric", links, thetas, {**values, "theta": theta})


# ------------------------------------------------------------------------------------------------------------
# trihedral
def trihedral_last_length(a1: float, a2: float, a3: float, a4: float, a5: float) -> float:
    """``a_6`` from the trihedral condition ``a_1^2 + a_3^2 + a_5^2 = a_2^2 + a_4^2 + a_6^2``."""
    square = a1 * a1 + a3 * a3 + a5 * a5 - a2 * a2 - a4 * a4
    if square <= 0.0:
        raise SpecError(
            "bricard-trihedral: the lengths need a1^2 + a3^2 + a5^2 > a2^2 + a4^2 "
            f"(got {a1 * a1 + a3 * a3 + a5 * a5:.6g} <= {a2 * a2 + a4 * a4:.6g}) so that a6 is real"
        )
    return float(np.sqrt(square))


def bricard_trihedral_links(lengths: Sequence[float]) -> list[Link]:
    """DH links of the trihedral Bricard loop: ``alpha`` alternately ``pi/2`` and ``3 pi/2``, every ``d_i = 0``."""
    return [(0.0, float(a), np.pi / 2.0 if i % 2 == 0 else 1.5 * np.pi) for i, a in enumerate(lengths)]


def bricard_trihedral(
    a1: float = 1.0,
    a2: float = 1.1,
    a3: float = 1.2,
    a4: float = 0.8,
    a5: float = 0.9,
    theta: float = np.radians(30.0),
) -> Mechanism:
    """Bricard's trihedral 6R loop, joints ``A..F``, with joint A at ``theta``.

    Conditions (Bricard 1927; Baker 1980): ``alpha_1 = alpha_3 = alpha_5 = pi/2``,
    ``alpha_2 = alpha_4 = alpha_6 = 3 pi/2``, every ``d_i = 0``, and
    ``a_1^2 + a_3^2 + a_5^2 = a_2^2 + a_4^2 + a_6^2``, which fixes ``a_6``. The loop has no angle symmetry, so the
    start solve has five unknowns.

    Parameters
    ----------
    a1, a2, a3, a4, a5
        Link lengths AB..EF; FA follows from the condition.
    theta
        Start angle of joint A (radians).

    References
    ----------
    .. [1] R. Bricard, Leçons de cinématique, Tome II, Gauthier-Villars, Paris, 1927.
    .. [2] J. E. Baker, "An analysis of the Bricard linkages", Mech. Mach. Theory 15 (1980) 267-286.
    """
    a6 = trihedral_last_length(a1, a2, a3, a4, a5)
    links = bricard_trihedral_links((a1, a2, a3, a4, a5, a6))

    def expand(t1: float, x: Array) -> Array:
        return np.concatenate([[t1], x])

    thetas = solve_start("bricard-trihedral", links, theta, expand, 5)
    values = dict(a1=a1, a2=a2, a3=a3, a4=a4, a5=a5, a6=a6, theta=theta)
    return _build("bricard-trihedral", "Bricard trihedral", links, thetas, values)


# ------------------------------------------------------------------------------------------------------------
# threefold-symmetric
def bricard_threefold_links(length: float, alpha: float) -> list[Link]:
    """DH links of the threefold-symmetric Bricard loop: equal lengths, twists ``alpha, 2 pi - alpha, ...``, no offsets."""
    return [
        (0.0, float(length), float(alpha) if i % 2 == 0 else 2.0 * np.pi - float(alpha)) for i in range(6)
    ]


def bricard_threefold(
    length: float = 1.0,
    alpha: float = np.radians(60.0),
    theta: float = np.radians(60.0),
) -> Mechanism:
    """The threefold-symmetric Bricard 6R loop (Chen, You & Tarnai 2005), joints ``A..F``, joint A at ``theta``.

    Conditions: ``a_1 = ... = a_6 = length``; ``alpha_1 = alpha_3 = alpha_5 = alpha``,
    ``alpha_2 = alpha_4 = alpha_6 = 2 pi - alpha``; every ``d_i = 0``. It is a plane-symmetric Bricard loop in
    three planes at once (so it satisfies :func:`bricard_plane_links`' conditions), and with ``alpha = pi/2`` also
    a trihedral one. Along its motion ``theta_1 = theta_3 = theta_5`` and ``theta_2 = theta_4 = theta_6`` (the
    ansatz of the start solve: one unknown).

    Parameters
    ----------
    length
        Length of every link.
    alpha
        Twist of links AB, CD, EF (radians); BC, DE, FA have ``2 pi - alpha``.
    theta
        Start angle of joints A, C, E (radians).

    References
    ----------
    .. [1] Y. Chen, Z. You, T. Tarnai, "Threefold-symmetric Bricard linkages for deployable structures",
       Int. J. Solids Struct. 42 (2005) 2287-2301.
    .. [2] J. E. Baker, "An analysis of the Bricard linkages", Mech. Mach. Theory 15 (1980) 267-286.
    """
    if length == 0.0:
        raise SpecError("bricard-threefold: length must be non-zero")
    links = bricard_threefold_links(length, alpha)

    def expand(t1: float, x: Array) -> Array:
        return np.array([t1, x[0]] * 3)  # theta_1 = theta_3 = theta_5, theta_2 = theta_4 = theta_6

    thetas = solve_start("bricard-threefold", links, theta, expand, 1)
    values = dict(length=length, alpha=alpha, theta=theta)
    return _build("bricard-threefold", "Bricard threefold-symmetric", links, thetas, values)


_BAKER = "(Bricard 1927; Baker 1980)"

register(
    LinkageEntry(
        name="bricard-line",
        build=bricard_line,
        summary=f"Bricard's line-symmetric 6R loop {_BAKER}",
        params={
            "a1": Param(1.0, "length", "length of links AB and DE"),
            "a2": Param(1.4, "length", "length of links BC and EF"),
            "a3": Param(0.7, "length", "length of links CD and FA"),
            "alpha1": Param(float(np.radians(45.0)), "deg", "twist of links AB and DE"),
            "alpha2": Param(float(np.radians(110.0)), "deg", "twist of links BC and EF"),
            "alpha3": Param(float(np.radians(-65.0)), "deg", "twist of links CD and FA"),
            "d1": Param(0.3, "length", "offset at joints A and D"),
            "d2": Param(0.5, "length", "offset at joints B and E"),
            "d3": Param(-0.2, "length", "offset at joints C and F"),
            "theta": Param(float(np.radians(30.0)), "deg", "start angle of joint A"),
        },
    )
)

register(
    LinkageEntry(
        name="bricard-plane",
        build=bricard_plane,
        summary=f"Bricard's plane-symmetric 6R loop {_BAKER}",
        params={
            "a1": Param(1.0, "length", "length of links AB and FA"),
            "a2": Param(1.4, "length", "length of links BC and EF"),
            "a3": Param(0.8, "length", "length of links CD and DE"),
            "alpha1": Param(float(np.radians(40.0)), "deg", "twist of AB (FA has 360 - alpha1)"),
            "alpha2": Param(float(np.radians(110.0)), "deg", "twist of BC (EF has 360 - alpha2)"),
            "alpha3": Param(float(np.radians(130.0)), "deg", "twist of CD (DE has 360 - alpha3)"),
            "d2": Param(0.3, "length", "offset at joint B (F has -d2)"),
            "d3": Param(-0.4, "length", "offset at joint C (E has -d3)"),
            "theta": Param(float(np.radians(30.0)), "deg", "start angle of joint A"),
        },
    )
)

register(
    LinkageEntry(
        name="bricard-trihedral",
        build=bricard_trihedral,
        summary=f"Bricard's trihedral 6R loop {_BAKER}",
        params={
            "a1": Param(1.0, "length", "length of link AB"),
            "a2": Param(1.1, "length", "length of link BC"),
            "a3": Param(1.2, "length", "length of link CD"),
            "a4": Param(0.8, "length", "length of link DE"),
            "a5": Param(0.9, "length", "length of link EF (FA follows from a1^2+a3^2+a5^2 = a2^2+a4^2+a6^2)"),
            "theta": Param(float(np.radians(30.0)), "deg", "start angle of joint A"),
        },
    )
)

register(
    LinkageEntry(
        name="bricard-threefold",
        build=bricard_threefold,
        summary="Threefold-symmetric Bricard 6R loop (Chen, You & Tarnai 2005)",
        params={
            "length": Param(1.0, "length", "length of every link"),
            "alpha": Param(float(np.radians(60.0)), "deg", "twist of AB, CD, EF (the others 360 - alpha)"),
            "theta": Param(float(np.radians(60.0)), "deg", "start angle of joints A, C, E"),
        },
    )
)
