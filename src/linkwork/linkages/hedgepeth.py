"""Hedgepeth's n-sided deployable hoops as Sec. 3 prints them: n rods of two mirror types, folded in a bundle.

For n >= 6 these printed equations do not describe a hoop that opens flat (docs/linkages.md); the hoop built from
its rods is :mod:`linkwork.linkages.hedgepeth_rods`.

The rods are the paper's isosceles-triangle rods (Eqs. (7)-(9)), each described by the transform
``[Rz(phi) Rx(omega) Rz(psi), v]`` with ``v = [cos a3, 0, sin a3]`` (unit rod length along the apex line), and the
loop is ``T1 T_A T2 T_B ... = I`` (Eq. (12)) with joint angles zero in the folded bundle.

References
----------
W. W. Gan, S. Pellegrino, Proc. IMechE Part C 220 (2006), Eqs. (7)-(10), (12).
"""

from __future__ import annotations

import numpy as np

from linkwork.errors import SpecError
from linkwork.geometry.names import default_joint_names
from linkwork.kinematics.chains import from_rods
from linkwork.kinematics.mechanism import Mechanism
from linkwork.linkages.registry import MAX_RODS, LinkageEntry, Param, register


def hedgepeth_angles(n: int) -> dict[str, float]:
    """The rod geometry of the n-sided hoop (radians): alpha1..3 and the type-1 Euler angles phi, omega, psi."""
    alpha1 = 2.0 * np.pi / n  # Eq. (7)
    alpha2 = np.pi / 2.0 - alpha1 / 2.0  # Eq. (8)
    alpha3 = np.arctan(np.cos(alpha1 / 2.0) ** 2 / np.sin(alpha1 / 2.0))  # Eq. (9)
    p = np.cos(alpha3) * np.tan(alpha3) - np.sin(alpha3) * np.cos(alpha1)
    q = np.sin(alpha3) * np.tan(alpha3) + np.cos(alpha3) * np.cos(alpha1)
    r = np.sin(alpha1)
    phi = -np.arctan(np.tan(alpha1 / 2.0) * np.sin(alpha3))
    omega = np.pi / 2.0 + np.arctan(q / np.sqrt(p * p + r * r))
    psi = -np.pi - phi
    return {"alpha1": alpha1, "alpha2": alpha2, "alpha3": alpha3, "phi": phi, "omega": omega, "psi": psi}


def deployed_angle(n: int) -> float:
    """Hinge angle theta_A of the deployed n-gon (radians), Eq. (10)."""
    g = hedgepeth_angles(n)
    a1, a3 = g["alpha1"], g["alpha3"]
    inner = np.sin(np.pi / 2.0 - np.pi / n) + np.sin(a1 / 2.0) ** 2 * np.tan(a3)
    return float(np.arccos(1.0 - 2.0 * np.cos(a3) ** 2 * inner**2))


def rod_transforms(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The constant 4x4 transforms of rod types 1 and 2 (type 2 has the Euler angles negated)."""
    from linkwork.kinematics.chains import rod_transform

    g = hedgepeth_angles(n)
    v = [np.cos(g["alpha3"]), 0.0, np.sin(g["alpha3"])]
    return (
        rod_transform(g["phi"], g["omega"], g["psi"], v),
        rod_transform(-g["phi"], -g["omega"], -g["psi"], v),
    )


def hedgepeth(n: int = 6, couple: bool | None = None) -> Mechanism:
    """Hedgepeth's n-rod hoop (n even, >= 4) in the folded bundle, joints ``A, B, C, ...`` at zero.

    For n >= 8 the hoop has mobility n - 5 at the bundle, so, as the paper does for its 10-sided hoop (Fig. 2),
    n/2-fold symmetry is imposed by default: ``A = C = E = ...`` and ``B = D = F = ...``. Pass ``couple=False`` to
    get the free loop, or ``couple=True`` to impose the symmetry also for n = 4, 6.
    """
    check_rod_count("hedgepeth", n)
    g = hedgepeth_angles(n)
    v = [float(np.cos(g["alpha3"])), 0.0, float(np.sin(g["alpha3"]))]
    rods = []
    for k in range(n):
        sign = 1.0 if k % 2 == 0 else -1.0
        rods.append({"phi": sign * g["phi"], "omega": sign * g["omega"], "psi": sign * g["psi"], "v": v})
    names = default_joint_names(n)
    meta = {"linkage": "hedgepeth", "n": n, "deployed_A": deployed_angle(n)}
    mech, _ = from_rods(f"Hedgepeth hoop n={n}", rods, [0.0] * n, joint_names=names, meta=meta)
    return hoop_symmetry(mech, couple)


ROD_COUNT = Param(
    6, "int", "number of rods (even, >= 4); n >= 8 imposes n/2-fold symmetry", low=4, high=MAX_RODS
)
"""The parameter ``n`` of both built-in hoops (``hedgepeth`` and ``hedgepeth-rods``)."""


def check_rod_count(linkage: str, n: int) -> None:
    """Raise :class:`SpecError` unless ``n`` is a hoop's number of rods: even and at least 4."""
    if n < 4 or n % 2:
        raise SpecError(f"{linkage}: n must be an even number >= 4, got {n}")


def hoop_symmetry(mech: Mechanism, couple: bool | None) -> Mechanism:
    """The hoop with its n/2-fold symmetry imposed (``A = C = E = ...``, ``B = D = F = ...``) when ``couple``;
    by default (``None``) for n >= 8."""
    names = list(mech.joint_names)
    if couple if couple is not None else len(names) >= 8:
        return mech.with_couplings([names[0::2], names[1::2]])
    return mech


register(
    LinkageEntry(
        name="hedgepeth",
        build=lambda n: hedgepeth(int(n)),
        summary="Hedgepeth's hoop from Sec. 3's equations as printed (Gan & Pellegrino 2006); for n >= 6 it does "
        "not open flat: see hedgepeth-rods",
        params={"n": ROD_COUNT},
    )
)
