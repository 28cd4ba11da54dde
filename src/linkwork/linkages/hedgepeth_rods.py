"""Hedgepeth's n-sided hoop built from its rods: the physical model that folds into a bundle and opens flat.

Gan & Pellegrino (2006), Sec. 3, describe the hardware: n rods of isosceles-triangle section with apex angle
``alpha1 = 360/n`` (Eq. (7)), so that in the folded bundle the n sections tile a regular n-gon around a common
apex line (Fig. 5(a)); the rod ends are cut at ``180/n`` to the rod (mitres of the flat n-gon) and "door hinges"
are mounted alternately on inner- and outer-facing faces (Fig. 5(b)). This module builds exactly that object:

* rod ``i`` (body ``link{i}``) runs from joint ``i`` to joint ``i + 1`` along its apex line (length 1); in the
  bundle all apex lines lie on the z-axis, rod ``i`` points along ``(-1)**(i+1) z`` and its section is the pie
  slice centred at azimuth ``(i + 1) * alpha1``;
* each end is cut by the mitre plane whose normal makes ``180/n`` with the rod, in the rod's base direction, so
  that the end section is the isosceles triangle of Eq. (9): base angles ``alpha3`` with
  ``tan alpha3 = cos^2(alpha1/2) / sin(alpha1/2)``;
* joint ``i`` is the edge where that cut meets the side face shared with rod ``i - 1`` in the bundle: a line
  through the common apex point, in the shared face, at angle ``gamma`` to the apex line with
  ``cos gamma = sin^2(beta) / sqrt(cos^2 beta + sin^4 beta)``, ``beta = 180/n``.

Joint angles are zero in the bundle and increase during deployment. Joints ``A, C, E, ...`` are the hinges on
the inner-facing faces of the deployed hoop, ``B, D, F, ...`` those on the outer-facing faces. The hoop reaches
the flat regular n-gon (apex lines the sides of a polygon of unit side, every section's apex on the same side) at

    theta_A = arccos(sin^2(alpha1) / 2 - 1),    theta_B = 360 deg - theta_A

(n = 4: 120 and 240 deg, theta_A as Eq. (10); n = 6: 128.682 and 231.318 deg). For n = 4 the rods coincide with the
printed Sec. 3 geometry (:func:`linkwork.linkages.hedgepeth.hedgepeth`); for n >= 6 the printed Euler angles and
Eq. (10) do not describe this object (docs/linkages.md, "Hedgepeth's hoops for n >= 6").
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from linkwork.errors import SpecError
from linkwork.geometry import line_twist
from linkwork.geometry.names import default_joint_names
from linkwork.kinematics.mechanism import Mechanism
from linkwork.linkages.hedgepeth import ROD_COUNT, check_rod_count, hoop_symmetry
from linkwork.linkages.registry import LinkageEntry, register

Array = NDArray[np.float64]


def rod_frame(n: int, i: int) -> Array:
    """The 4x4 frame of rod ``i`` (body ``link{i}``) in the bundle: origin at its start apex point, x along the apex
    line, z from the apex towards the middle of the section's base, y = z x x (the base direction)."""
    r = (
        i + 1
    )  # rod i is the (i+1)-th pie slice, so that joint A (between the last rod and rod 0) faces inwards
    c = r * 2.0 * np.pi / n
    x = np.array([0.0, 0.0, 1.0 if r % 2 == 0 else -1.0])
    z = np.array([np.cos(c), np.sin(c), 0.0])
    frame = np.eye(4)
    frame[:3, 0], frame[:3, 1], frame[:3, 2] = x, np.cross(z, x), z
    frame[:3, 3] = [0.0, 0.0, float(r % 2)]
    return frame


def start_face_sign(i: int) -> float:
    """Which side face of rod ``i`` (body y > 0 or y < 0) it shares with rod ``i - 1`` in the bundle."""
    return -1.0 if i % 2 == 0 else 1.0


def hinge_edge(n: int, sign: float) -> Array:
    """Unit direction, in a rod's body frame, of the edge where the start mitre meets the side face ``sign``.

    The start cut is the plane ``x cos(beta) + y sin(beta) = 0`` (the rod is longer on its y > 0 side, the outside
    of the flat n-gon); the side faces contain the apex line and the legs ``(0, +-sin beta, cos beta)``.
    """
    beta = np.pi / n
    edge = np.array([-sign * np.sin(beta) ** 2 / np.cos(beta), sign * np.sin(beta), np.cos(beta)])
    return edge / np.linalg.norm(edge)


def deployed_angles(n: int) -> tuple[float, float]:
    """Joint angles (radians) of the inner hinges ``A, C, ...`` and the outer hinges ``B, D, ...`` when the hoop is
    the flat regular n-gon."""
    theta = float(np.arccos(np.sin(2.0 * np.pi / n) ** 2 / 2.0 - 1.0))
    return theta, 2.0 * np.pi - theta


def hinge_angle_to_apex_line(n: int) -> float:
    """The angle gamma (radians) between every hinge and the apex lines of the two rods it joins."""
    beta = np.pi / n
    return float(np.arccos(np.sin(beta) ** 2 / np.sqrt(np.cos(beta) ** 2 + np.sin(beta) ** 4)))


def hedgepeth_rods(n: int = 6, couple: bool | None = None, width: float = 0.2) -> Mechanism:
    """Hedgepeth's n-rod hoop (n even, >= 4) as built from mitred triangular rods, in the folded bundle.

    ``width`` is the length of a section's equal sides (rod length 1), used only for drawing. As for
    :func:`~linkwork.linkages.hedgepeth.hedgepeth`, n >= 8 imposes n/2-fold symmetry by default (``A = C = ...``,
    ``B = D = ...``); ``couple=False`` gives the free loop.
    """
    check_rod_count("hedgepeth-rods", n)
    if not width > 0:
        raise SpecError(f"hedgepeth-rods: width must be positive, got {width}")
    twists = []
    for i in range(n):
        frame = rod_frame(n, i)
        sign = start_face_sign(i)
        direction = frame[:3, :3] @ hinge_edge(n, sign)
        # Orient every axis so that deployment is a positive rotation (rod i turns away from rod i-1).
        twists.append(line_twist(frame[:3, 3], -sign * direction))
    names = default_joint_names(n)
    inner, outer = deployed_angles(n)
    meta = {
        "linkage": "hedgepeth-rods",
        "n": n,
        "width": width,
        "deployed_A": inner,
        "deployed_B": outer,
    }
    mech = Mechanism.single_loop(f"Hedgepeth hoop (rods) n={n}", names, np.array(twists), meta=meta)
    return hoop_symmetry(mech, couple)


register(
    LinkageEntry(
        name="hedgepeth-rods",
        build=lambda n: hedgepeth_rods(int(n)),
        summary="Hedgepeth's hoop built from mitred triangular rods: bundle to flat n-gon (physical model)",
        params={"n": ROD_COUNT},
    )
)
