"""How good a verified mechanized design is to build: the quality factor that ranks the designs found.

The quality factor of a design is the product of four numbers between 0 and 1 (1 is best):

``Q = sin(mu_min) * (L_min / L_max) * f_stroke * f_shape``

* ``mu_min``: the smallest transmission angle of the design's binary links over the profiles as traced (the
  angle between a link and the direction its moving pivot is free to move in; 90 degrees is best, 0 a dead
  centre), and for a linear actuator the angle between it and its pivot's path;
* ``L_min / L_max``: the link-length ratio, shortest over longest binary link (a linear actuator counts with its
  shortest and longest length; a slider has no length and does not count);
* ``f_stroke``: the actuator stroke. For a linear actuator ``min(1, L_retracted / stroke)`` (a single-stage
  actuator cannot extend by more than its retracted length); for a revolute drive ``min(1, 180 deg / sweep)``
  (a crank, or any revolute joint driving, that turns more than half a revolution between the first and last
  profile needs a gear); 1 for a slider's drive.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from linkwork.mechanization.assemble import Design
from linkwork.mechanization.verify import Verification


@dataclass(frozen=True)
class Quality:
    """The quality factor of a design and its four parts.

    Attributes
    ----------
    factor
        ``Q``, the product of the four parts (higher is better).
    min_transmission
        ``mu_min``, radians.
    link_ratio
        ``L_max / L_min`` (>= 1).
    stroke
        The drive's travel between the first and the last profile: radians (revolute) or a length (prismatic).
    stroke_factor
        ``f_stroke``.
    shape_factor
        ``f_shape``.
    """

    factor: float
    min_transmission: float
    link_ratio: float
    stroke: float
    stroke_factor: float
    shape_factor: float = 1.0

    def to_dict(self, drive_type: str) -> dict[str, float | str]:
        """JSON-ready, angles in degrees."""
        return {
            "quality": self.factor,
            "min_transmission_deg": math.degrees(self.min_transmission),
            "link_ratio": self.link_ratio,
            "stroke": math.degrees(self.stroke) if drive_type == "R" else self.stroke,
            "stroke_unit": "deg" if drive_type == "R" else "length",
            "stroke_factor": self.stroke_factor,
            "shape_factor": self.shape_factor,
        }


def quality(design: Design, check: Verification) -> Quality:
    """The quality factor of ``design`` as traced (``check``), see the module docstring."""
    names = design.joint_names()
    lengths: list[float] = []
    mu = math.pi / 2
    for link in design.links:
        mu = min(mu, link.transmission)
        if link.kind == "RR":
            lengths.append(link.length)
        elif link.kind == "RPR":
            slide = names.index(f"{link.name}s")
            extent = link.length + np.array([s.values[slide] for s in check.states])
            lengths += [float(extent.min()), float(extent.max())]
    ratio = max(lengths) / min(lengths) if lengths else 1.0
    drive = [s.drive_value for s in check.states]
    stroke = float(max(drive) - min(drive)) if drive else 0.0
    if any(link.kind == "RPR" and design.drive == f"{link.name}s" for link in design.links):
        actuator = next(link for link in design.links if design.drive == f"{link.name}s")
        slide = names.index(design.drive)
        retracted = actuator.length + min(s.values[slide] for s in check.states)
        f_stroke = min(1.0, retracted / stroke) if stroke > 0 else 1.0
    elif next(str(j["type"]) for j in design.joint_specs() if j["name"] == design.drive) == "R":
        f_stroke = min(1.0, math.pi / stroke) if stroke > 0 else 1.0
    else:  # a slider or the chain's own prismatic joint: its guide is as long as it must be
        f_stroke = 1.0
    slack = SHAPE_SLACK * design.chain.size
    f_shape = min(
        (min(1.0, (float(joined) + slack) / s.e_max) if s.e_max > 0 else 1.0)
        for s, joined in zip(check.states, design.chain.joined_errors, strict=False)
    )
    factor = math.sin(max(0.0, mu)) / ratio * f_stroke * f_shape
    return Quality(factor, mu, ratio, stroke, f_stroke, f_shape)


#: ``f_shape`` is 1 while the mechanism keeps within this fraction of the size of the joined chain's error.
SHAPE_SLACK = 0.01
