"""The Sarrus linkage: two plates joined by two limbs of three parallel hinges, in the hinge-lines form.

Each limb is a planar 3R chain, so it lets the top plate move only in its own plane (a rotation about the limb's
hinge direction and translations perpendicular to it). With the two hinge directions not parallel, the only
motion both limbs allow is a translation along their common perpendicular: the top plate rises and falls without
turning (Sarrus 1853). The loop has six joints and mobility one; its Jacobian has rank five everywhere the knees
are bent (three twists per limb, sharing only the translation along the common perpendicular).
"""

from __future__ import annotations

import numpy as np

from linkwork.errors import SpecError
from linkwork.geometry import line_twist
from linkwork.kinematics.mechanism import Mechanism
from linkwork.linkages.registry import LinkageEntry, Param, register

JOINTS = ("A", "B", "C", "D", "E", "F")


def sarrus_hinges(link: float, height: float, beta: float) -> tuple[np.ndarray, np.ndarray]:
    """Hinge points ``(6, 3)`` and directions ``(6, 3)`` of the Sarrus loop at plate separation ``height``.

    Limb ``k`` has hinge direction ``u_k`` (horizontal; ``u_1 = x``, ``u_2`` at angle ``beta`` from x) and lies in
    the vertical plane through the z-axis along ``n_k = z x u_k``: top hinge at ``r n_k + height z``, knee at
    ``(r + e) n_k + height / 2 z`` with ``e = sqrt(link^2 - (height / 2)^2)``, bottom hinge at ``r n_k``, where
    ``r = link / 2`` is the hinges' distance from the plates' centre line. The direction signs make every
    angle grow as the plates close (see the docstring of :func:`sarrus`).
    """
    half = height / 2.0
    e = np.sqrt(link * link - half * half)
    r = link / 2.0
    z = np.array([0.0, 0.0, 1.0])
    u1 = np.array([1.0, 0.0, 0.0])
    u2 = np.array([np.cos(beta), np.sin(beta), 0.0])
    n1, n2 = np.cross(z, u1), np.cross(z, u2)
    points = np.array(
        [
            r * n1 + height * z,  # A: top plate -> upper link 1
            (r + e) * n1 + half * z,  # B: knee of limb 1
            r * n1,  # C: lower link 1 -> bottom plate
            r * n2,  # D: bottom plate -> lower link 2
            (r + e) * n2 + half * z,  # E: knee of limb 2
            r * n2 + height * z,  # F: upper link 2 -> top plate
        ]
    )
    # Closing the plates by dh turns each upper link by +delta about u_k relative to its plate, each lower link by
    # -delta, so the knee opens by 2 delta: these signs make the six angles (delta, 2 delta, delta, ...) positive.
    directions = np.array([u1, -u1, u1, -u2, u2, -u2])
    return points, directions


def sarrus(link: float = 1.0, height: float = 1.2, beta: float = np.radians(90.0)) -> Mechanism:
    """The Sarrus linkage with its plates ``height`` apart, joints ``A..F`` at zero.

    Joints in loop order: A (top plate to limb 1), B (knee 1), C (limb 1 to bottom plate), D (bottom plate to
    limb 2), E (knee 2), F (limb 2 to top plate). Each angle is the turn of the body after the joint relative to
    the body before it, measured from the start; all six grow as the plates close, in the ratio 1 : 2 : 1 per limb.

    Parameters
    ----------
    link
        Length of each of the four limb links (hinge to knee).
    height
        Distance between the plates at the start; ``0 < height < 2 link`` (the knees bent).
    beta
        Angle between the two limbs' hinge directions (radians); any value but 0 and 180 deg.

    References
    ----------
    .. [1] P. T. Sarrus, "Note sur la transformation des mouvements rectilignes alternatifs, en mouvements
       circulaires; et réciproquement", C. R. Acad. Sci. Paris 36 (1853) 1036-1038.
    .. [2] K. H. Hunt, Kinematic Geometry of Mechanisms, Clarendon Press, Oxford, 1978.
    """
    if link <= 0.0:
        raise SpecError(f"sarrus: link must be positive, got {link}")
    if not 0.0 < height < 2.0 * link:
        raise SpecError(f"sarrus: height must lie in (0, 2 * link) = (0, {2.0 * link:.6g}), got {height}")
    if abs(np.sin(beta)) < 1e-6:
        raise SpecError(
            f"sarrus: the hinge directions must not be parallel, got beta = {np.degrees(beta):.6g} deg"
        )
    points, directions = sarrus_hinges(link, height, beta)
    twists = line_twist(points, directions)
    meta = {"linkage": "sarrus", "link": link, "height": height, "beta": beta, "convention": "hinge-lines"}
    return Mechanism.single_loop("Sarrus linkage", JOINTS, twists, meta=meta)


register(
    LinkageEntry(
        name="sarrus",
        build=sarrus,
        summary="Sarrus linkage: two limbs of three parallel hinges (Sarrus 1853)",
        params={
            "link": Param(1.0, "length", "length of each limb link"),
            "height": Param(1.2, "length", "distance between the plates at the start (0 < height < 2 link)"),
            "beta": Param(float(np.radians(90.0)), "deg", "angle between the two limbs' hinge directions"),
        },
    )
)
