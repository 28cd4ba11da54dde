"""The planar four-bar linkage: ground, crank, coupler and rocker joined by four parallel hinges.

Joints: ``A`` (ground - crank, at the origin), ``B`` (crank - coupler), ``C`` (coupler - rocker), ``D`` (ground -
rocker, at ``(ground, 0)``). ``A`` reads the crank's angle from the x-axis and ``D`` the rocker's, so driving ``A``
is turning the crank. The coupler carries the named point ``P`` (its coupler curve is in ``points.csv``) and the
transmission angle is the angle at ``C`` between coupler and rocker.
"""

from __future__ import annotations

import numpy as np

from linkwork.errors import SpecError
from linkwork.kinematics.mechanism import Mechanism
from linkwork.linkages.registry import LinkageEntry, Param, register


def four_bar_pose(
    ground: float, crank: float, coupler: float, rocker: float, theta: float, crossed: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """Pivots ``B`` and ``C`` (2-vectors) at crank angle ``theta``: ``C`` is where the circles about ``B``
    (radius ``coupler``) and about ``D`` (radius ``rocker``) meet, left of ``B -> D`` (open) or right (crossed)."""
    b = crank * np.array([np.cos(theta), np.sin(theta)])
    d = np.array([ground, 0.0])
    f = float(np.linalg.norm(d - b))
    if not abs(coupler - rocker) <= f <= coupler + rocker:
        raise SpecError(
            f"four-bar: cannot assemble at crank angle {np.degrees(theta):.6g} deg (diagonal {f:.6g} outside "
            f"[{abs(coupler - rocker):.6g}, {coupler + rocker:.6g}])"
        )
    along = (coupler**2 - rocker**2 + f**2) / (2.0 * f)  # from B towards D
    h = np.sqrt(max(coupler**2 - along**2, 0.0))
    u = (d - b) / f
    n = np.array([-u[1], u[0]]) * (-1.0 if crossed else 1.0)
    return b, b + along * u + h * n


def four_bar(
    ground: float = 2.0,
    crank: float = 1.0,
    coupler: float = 2.5,
    rocker: float = 2.0,
    theta: float = np.radians(60.0),
    point_along: float = 0.5,
    point_off: float = 0.8,
    crossed: bool = False,
) -> Mechanism:
    """A planar four-bar at crank angle ``theta`` (radians), with the coupler point ``P``.

    Parameters
    ----------
    ground, crank, coupler, rocker
        Link lengths ``d``, ``a``, ``b``, ``c`` (pivot to pivot).
    theta
        Start angle of the crank from the ground line (radians).
    point_along, point_off
        Coupler point ``P`` in the coupler's frame: ``point_along * coupler`` along ``B -> C`` and ``point_off *
        coupler`` to its left.
    crossed
        Assemble the crossed circuit instead of the open one.
    """
    lengths = {"ground": ground, "crank": crank, "coupler": coupler, "rocker": rocker}
    for key, value in lengths.items():
        if value <= 0.0:
            raise SpecError(f"four-bar: {key} must be positive, got {value}")
    b, c = four_bar_pose(ground, crank, coupler, rocker, theta, crossed)
    d = np.array([ground, 0.0])
    u = (c - b) / coupler
    p = b + coupler * (point_along * u + point_off * np.array([-u[1], u[0]]))
    th3 = np.arctan2(u[1], u[0])
    th4 = np.arctan2(c[1] - d[1], c[0] - d[0])
    z = (0.0, 0.0, 1.0)
    joints = [
        {"name": "A", "bodies": ("ground", "crank"), "point": (0.0, 0.0), "direction": z, "value": theta},
        {"name": "B", "bodies": ("crank", "coupler"), "point": b, "direction": z, "value": th3 - theta},
        {"name": "C", "bodies": ("coupler", "rocker"), "point": c, "direction": z, "value": th4 - th3},
        {"name": "D", "bodies": ("ground", "rocker"), "point": d, "direction": z, "value": th4},
    ]
    meta = {
        "linkage": "four-bar",
        **lengths,
        "theta": theta,
        "points": [{"name": "P", "body": "coupler", "position": [float(p[0]), float(p[1]), 0.0]}],
        "transmission": {"kind": "rocker", "joints": ["C", "B", "D"]},
    }
    return Mechanism.from_joints("four-bar", joints, planar=True, meta=meta)


register(
    LinkageEntry(
        name="four-bar",
        build=four_bar,
        summary="planar four-bar (crank A, rocker D) with coupler point P and transmission angle",
        params={
            "ground": Param(2.0, "length", "ground link A-D"),
            "crank": Param(1.0, "length", "crank A-B"),
            "coupler": Param(2.5, "length", "coupler B-C"),
            "rocker": Param(2.0, "length", "rocker C-D"),
            "theta": Param(float(np.radians(60.0)), "deg", "start angle of the crank"),
            "point_along": Param(0.5, "length", "coupler point P along B->C, fraction of the coupler"),
            "point_off": Param(0.8, "length", "coupler point P left of B->C, fraction of the coupler"),
        },
    )
)
