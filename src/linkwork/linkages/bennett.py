"""Bennett's 4R linkage: the only movable spatial loop of four revolute joints, built from its closed form.

In the DH convention of :func:`linkwork.kinematics.chains.from_dh` (``T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``,
closing when ``T_1 T_2 T_3 T_4 = I``) Bennett's conditions are: opposite links equal, ``a_1 = a_3``,
``a_2 = a_4``, ``alpha_1 = alpha_3``, ``alpha_2 = alpha_4``, all offsets ``d_i = 0``, and
``a_1 / sin(alpha_1) = a_2 / sin(alpha_2)``. Along the motion ``theta_3 = -theta_1``, ``theta_4 = -theta_2`` and

    tan(theta_1 / 2) tan(theta_2 / 2) = sin((alpha_2 + alpha_1) / 2) / sin((alpha_2 - alpha_1) / 2).
"""

from __future__ import annotations

import numpy as np

from linkwork.errors import SpecError
from linkwork.geometry.angles import wrap
from linkwork.kinematics.chains import from_dh
from linkwork.kinematics.mechanism import Mechanism
from linkwork.linkages.registry import LinkageEntry, Param, register

JOINTS = ("A", "B", "C", "D")


def wrap_angle(angle: float) -> float:
    """An angle brought into ``[-pi, pi)`` (:func:`linkwork.geometry.angles.wrap`)."""
    return float(wrap(angle))


def bennett_constant(alpha1: float, alpha2: float) -> float:
    """The right-hand side ``sin((alpha2 + alpha1) / 2) / sin((alpha2 - alpha1) / 2)`` of Bennett's relation.

    Raises :class:`SpecError` when the twists are equal (mod 2 pi): that loop is a parallelogram, not Bennett's.
    """
    den = np.sin((alpha2 - alpha1) / 2.0)
    if abs(den) < 1e-9:
        raise SpecError(
            f"bennett: the two twists must differ, got alpha1 = {np.degrees(alpha1):.6g} deg and "
            f"alpha2 = {np.degrees(alpha2):.6g} deg"
        )
    return float(np.sin((alpha2 + alpha1) / 2.0) / den)


def bennett_angles(theta1: float, alpha1: float, alpha2: float) -> tuple[float, float, float, float]:
    """The four joint angles of a Bennett loop at ``theta1`` (radians, each in ``(-pi, pi]``).

    ``tan(theta2 / 2) = K / tan(theta1 / 2)`` with ``K`` from :func:`bennett_constant`, written with ``atan2`` so
    that ``theta1 = 0`` gives ``theta2 = pi``; then ``theta3 = -theta1`` and
    ``theta4 = -theta2``.
    """
    k = bennett_constant(alpha1, alpha2)
    theta2 = wrap_angle(2.0 * np.arctan2(k * np.cos(theta1 / 2.0), np.sin(theta1 / 2.0)))
    theta1 = wrap_angle(theta1)
    return theta1, theta2, wrap_angle(-theta1), wrap_angle(-theta2)


def bennett(
    alpha1: float = np.radians(45.0),
    alpha2: float = np.radians(75.0),
    scale: float = 1.0,
    theta: float = np.radians(60.0),
) -> Mechanism:
    """Bennett's linkage at joint angle ``theta`` of joint A, joints ``A, B, C, D``.

    Parameters
    ----------
    alpha1, alpha2
        Twists of links AB (= CD) and BC (= DA), radians; they must differ.
    scale
        The common ratio ``a_i / sin(alpha_i)``: link lengths are ``scale * sin(alpha_i)`` (signed, as the DH
        convention allows).
    theta
        Start angle of joint A (radians); the others follow from the closed form.

    Returns
    -------
    Mechanism
        The assembled loop (closure residual at rounding level) with ``meta["linkage"] = "bennett"``.

    References
    ----------
    .. [1] G. T. Bennett, "A new mechanism", Engineering 76 (1903) 777-778.
    .. [2] G. T. Bennett, "The skew isogram mechanism", Proc. London Math. Soc. (2) 13 (1914) 151-173.
    .. [3] K. H. Hunt, Kinematic Geometry of Mechanisms, Clarendon Press, Oxford, 1978.
    """
    if scale == 0.0:
        raise SpecError("bennett: scale (a / sin alpha) must be non-zero")
    thetas = bennett_angles(theta, alpha1, alpha2)
    twists = (alpha1, alpha2, alpha1, alpha2)  # opposite links equal
    params = [
        {"theta": t, "d": 0.0, "a": scale * np.sin(al), "alpha": al}  # a_i / sin(alpha_i) = scale
        for t, al in zip(thetas, twists, strict=True)
    ]
    meta = {"linkage": "bennett", "alpha1": alpha1, "alpha2": alpha2, "scale": scale, "theta": theta}
    mech, _ = from_dh("Bennett linkage", params, joint_names=JOINTS, meta=meta)
    return mech


register(
    LinkageEntry(
        name="bennett",
        build=bennett,
        summary="Bennett's 4R linkage from its closed form (Bennett 1903, 1914)",
        params={
            "alpha1": Param(float(np.radians(45.0)), "deg", "twist of links AB and CD"),
            "alpha2": Param(float(np.radians(75.0)), "deg", "twist of links BC and DA (differs from alpha1)"),
            "scale": Param(1.0, "length", "a / sin(alpha), the same for every link"),
            "theta": Param(float(np.radians(60.0)), "deg", "start angle of joint A"),
        },
    )
)
