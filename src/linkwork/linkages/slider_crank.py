"""The planar slider-crank: crank, connecting rod and a slider on a straight guide.

Joints: ``A`` (ground - crank, at the origin, reads the crank angle), ``B`` (crank - rod), ``C`` (rod - slider),
``D`` (prismatic, ground - slider along x on the line ``y = offset``; reads the slider's x). The transmission
angle is the angle between the rod and the normal to the guide.
"""

from __future__ import annotations

import numpy as np

from linkwork.errors import SpecError
from linkwork.kinematics.mechanism import Mechanism
from linkwork.linkages.registry import LinkageEntry, Param, register


def slider_position(crank: float, rod: float, offset: float, theta: float) -> float:
    """Slider x at crank angle ``theta``: ``r cos(theta) + sqrt(l^2 - (r sin(theta) - e)^2)`` (closed form)."""
    rise = crank * np.sin(theta) - offset
    if abs(rise) > rod:
        raise SpecError(
            f"slider-crank: the rod cannot reach the guide at crank angle {np.degrees(theta):.6g} deg"
        )
    return float(crank * np.cos(theta) + np.sqrt(rod * rod - rise * rise))


def slider_crank(
    crank: float = 1.0, rod: float = 3.0, offset: float = 0.0, theta: float = np.radians(30.0)
) -> Mechanism:
    """A slider-crank at crank angle ``theta`` (radians).

    Parameters
    ----------
    crank, rod
        Crank radius ``r`` and connecting-rod length ``l``.
    offset
        The guide's distance ``e`` from the crank pivot (0: an in-line slider-crank).
    theta
        Start angle of the crank from the guide's direction (radians).
    """
    if crank <= 0.0 or rod <= 0.0:
        raise SpecError(f"slider-crank: crank and rod must be positive, got {crank}, {rod}")
    x = slider_position(crank, rod, offset, theta)
    b = crank * np.array([np.cos(theta), np.sin(theta)])
    c = np.array([x, offset])
    phi = np.arctan2(c[1] - b[1], c[0] - b[0])
    z = (0.0, 0.0, 1.0)
    joints = [
        {"name": "A", "bodies": ("ground", "crank"), "point": (0.0, 0.0), "direction": z, "value": theta},
        {"name": "B", "bodies": ("crank", "rod"), "point": b, "direction": z, "value": phi - theta},
        {"name": "C", "bodies": ("rod", "slider"), "point": c, "direction": z, "value": -phi},
        {"name": "D", "type": "P", "bodies": ("ground", "slider"), "point": c, "direction": (1.0, 0.0, 0.0),
         "value": x},
    ]  # fmt: skip
    meta = {
        "linkage": "slider-crank",
        "crank": crank,
        "rod": rod,
        "offset": offset,
        "theta": theta,
        "transmission": {"kind": "slider", "joints": ["C", "B", "D"]},
    }
    return Mechanism.from_joints("slider-crank", joints, planar=True, meta=meta)


register(
    LinkageEntry(
        name="slider-crank",
        build=slider_crank,
        summary="planar slider-crank (crank A, slider D along x) with transmission angle",
        params={
            "crank": Param(1.0, "length", "crank radius A-B"),
            "rod": Param(3.0, "length", "connecting rod B-C"),
            "offset": Param(0.0, "length", "distance of the guide from the crank pivot"),
            "theta": Param(float(np.radians(30.0)), "deg", "start angle of the crank"),
        },
    )
)
