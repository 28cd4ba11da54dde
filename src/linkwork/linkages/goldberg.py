"""Goldberg's 5R linkage: two Bennett loops that share a link, merged, in the DH convention, from a closed form.

Construction (Goldberg 1943). Bennett loop 1 has links ``(a, alpha), (b, beta), (a, alpha), (b, beta)`` and
Bennett loop 2 has links ``(c, gamma), (b, beta), (c, gamma), (b, beta)``, with one ratio
``a / sin(alpha) = b / sin(beta) = c / sin(gamma)``. Place them so that they share their last ``(b, beta)`` link
(the same two joint axes, here called 4 and 1), remove that common link, and weld the two links that meet at
joint 4 (loop 1's third link and loop 2's last link) into one body: the remaining five joints form a movable
5R loop. Welding the two links with no angle between them (``theta_4`` of loop 1 equal to ``phi_4`` of loop 2)
makes the welded link a DH link of length ``a - c`` and twist ``alpha - gamma`` with no offsets, because both
common normals lie on one line (``Tx(a) Rx(alpha) Rx(-gamma) Tx(-c) = Tx(a - c) Rx(alpha - gamma)``).

Writing loop 1 as ``Z(t1) L(a, alpha) Z(t2) L(b, beta) Z(t3) L(a, alpha) Z(t4) L(b, beta) = I`` and loop 2 from
the same frame as ``Z(p1) L(c, gamma) Z(p5) L(b, beta) Z(p6) L(c, gamma) Z(p4) L(b, beta) = I`` (``Z = Rz``,
``L(l, t) = Tx(l) Rx(t)``) and eliminating the common link gives the Goldberg loop

    Z(t1 + pi - p1) L(a, alpha) Z(t2) L(b, beta) Z(t3) L(a - c, alpha - gamma) Z(pi - p6) L(b, beta)
    Z(-p5) L(c, gamma) = I,

using ``L(-l, -t) = Z(pi) L(l, t) Z(pi)`` for the reversed links. Bennett's relations give every angle from
``t1``: ``t2`` from ``tan(t1/2) tan(t2/2) = sin((beta + alpha)/2) / sin((beta - alpha)/2)``, ``t3 = -t1``,
``t4 = -t2``; the weld ``p4 = t4`` gives ``p5 = t2``; ``p1`` from
``tan(p1/2) tan(p5/2) = sin((beta + gamma)/2) / sin((beta - gamma)/2)``; ``p6 = -p1``.
"""

from __future__ import annotations

import numpy as np

from linkwork.errors import SpecError
from linkwork.kinematics.chains import from_dh
from linkwork.kinematics.mechanism import Mechanism
from linkwork.linkages.bennett import bennett_angles, wrap_angle
from linkwork.linkages.registry import LinkageEntry, Param, register

JOINTS = ("A", "B", "C", "D", "E")


def goldberg_links(alpha: float, beta: float, gamma: float, scale: float = 1.0) -> list[tuple[float, float]]:
    """The five DH links ``(a_i, alpha_i)`` of the Goldberg loop (every offset ``d_i`` is zero), lengths signed."""
    a, b, c = (
        scale * np.sin(t) for t in (alpha, beta, gamma)
    )  # a / sin(alpha) = b / sin(beta) = c / sin(gamma)
    return [(a, alpha), (b, beta), (a - c, alpha - gamma), (b, beta), (c, gamma)]


def goldberg_angles(theta: float, alpha: float, beta: float, gamma: float) -> list[float]:
    """The five joint angles of the Goldberg loop (signed-length DH links of :func:`goldberg_links`) at ``theta``.

    ``theta`` is the angle ``t1`` of the first Bennett loop at the shared joint A (see the module docstring).
    """
    t1, t2, t3, _t4 = bennett_angles(theta, alpha, beta)  # loop 1: twists alpha, beta
    p5 = t2  # the weld p4 = t4 = -t2, and loop 2 has p4 = -p5
    p1 = bennett_angles(p5, gamma, beta)[1]  # loop 2: tan(p1/2) tan(p5/2) = sin((b+g)/2) / sin((b-g)/2)
    p6 = -p1
    return [wrap_angle(t1 + np.pi - p1), t2, t3, wrap_angle(np.pi - p6), wrap_angle(-p5)]


def _positive_lengths(
    links: list[tuple[float, float]], thetas: list[float]
) -> tuple[list[tuple[float, float]], list[float]]:
    """Make every link length non-negative: ``L(-l, -t) = Z(pi) L(l, t) Z(pi)`` moves pi into both joints."""
    links = list(links)
    thetas = list(thetas)
    n = len(links)
    for i, (length, twist) in enumerate(links):
        if length < 0.0:
            links[i] = (-length, wrap_angle(-twist))
            thetas[i] = wrap_angle(thetas[i] + np.pi)
            thetas[(i + 1) % n] = wrap_angle(thetas[(i + 1) % n] + np.pi)
    return links, thetas


def goldberg(
    alpha: float = np.radians(45.0),
    beta: float = np.radians(75.0),
    gamma: float = np.radians(-20.0),
    scale: float = 1.0,
    theta: float = np.radians(60.0),
) -> Mechanism:
    """Goldberg's 5R linkage from two Bennett loops sharing a link, joints ``A..E``.

    Parameters
    ----------
    alpha, beta
        Twists of the first Bennett loop (radians); ``beta`` is the twist of the shared (removed) link.
    gamma
        The other twist of the second Bennett loop (radians). A negative ``gamma`` puts the second loop on the
        other side, and the welded link becomes the classical sum link (length ``a + |c|``, twist
        ``alpha + |gamma|``).
    scale
        The common ratio ``a / sin(alpha) = b / sin(beta) = c / sin(gamma)``.
    theta
        Start angle ``t1`` of the first Bennett loop at joint A (radians); every joint angle follows from it.

    Returns
    -------
    Mechanism
        The assembled 5R loop, lengths made non-negative (links with a negative length ``l`` are written as
        ``(-l, -twist)`` with ``pi`` moved into both neighbouring joints).

    Notes
    -----
    DH links in loop order, before making lengths positive: ``(a, alpha)``, ``(b, beta)``,
    ``(a - c, alpha - gamma)``, ``(b, beta)``, ``(c, gamma)``, all offsets zero (Goldberg 1943; Baker 1979).

    References
    ----------
    .. [1] M. Goldberg, "New five-bar and six-bar linkages in three dimensions", Trans. ASME 65 (1943) 649-661.
    .. [2] J. E. Baker, "The Bennett, Goldberg and Myard linkages: in perspective", Mech. Mach. Theory 14
       (1979) 239-253.
    .. [3] G. T. Bennett, "The skew isogram mechanism", Proc. London Math. Soc. (2) 13 (1914) 151-173.
    """
    if scale == 0.0:
        raise SpecError("goldberg: scale must be non-zero")
    for name, t in (("alpha", alpha), ("gamma", gamma)):
        if abs(np.sin((beta - t) / 2.0)) < 1e-9:
            raise SpecError(
                f"goldberg: {name} must differ from beta (mod 360 deg), or its loop is no Bennett loop"
            )
    if abs(np.sin((alpha - gamma) / 2.0)) < 1e-9:
        raise SpecError(
            "goldberg: gamma = alpha welds two identical links: the loop degenerates to Bennett's"
        )
    links, thetas = _positive_lengths(
        goldberg_links(alpha, beta, gamma, scale), goldberg_angles(theta, alpha, beta, gamma)
    )
    params = [
        {"theta": t, "d": 0.0, "a": float(a), "alpha": float(al)}
        for t, (a, al) in zip(thetas, links, strict=True)
    ]
    meta = {
        "linkage": "goldberg",
        "alpha": alpha,
        "beta": beta,
        "gamma": gamma,
        "scale": scale,
        "theta": theta,
    }
    mech, _ = from_dh("Goldberg 5R linkage", params, joint_names=JOINTS, meta=meta)
    return mech


register(
    LinkageEntry(
        name="goldberg",
        build=goldberg,
        summary="Goldberg's 5R linkage: two Bennett loops sharing a link (Goldberg 1943)",
        params={
            "alpha": Param(float(np.radians(45.0)), "deg", "first twist of Bennett loop 1"),
            "beta": Param(float(np.radians(75.0)), "deg", "twist of the shared (removed) link"),
            "gamma": Param(float(np.radians(-20.0)), "deg", "first twist of Bennett loop 2"),
            "scale": Param(1.0, "length", "a / sin(twist), the same for every link"),
            "theta": Param(float(np.radians(60.0)), "deg", "start angle of loop 1 at joint A"),
        },
    )
)
