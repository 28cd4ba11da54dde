"""Where a written mechanism's joints are, read from its spec file and placed by the kinematic core's body poses."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np

from linkwork.io.spec import load_spec
from linkwork.kinematics.closure import body_poses


def joint_positions(folder: Path, values: dict[str, float]) -> dict[str, np.ndarray]:
    """World positions of every joint of ``folder/mechanism.toml`` at joint values in file units (degrees for
    revolute joints, lengths for prismatic ones), from the spec file's joint points."""
    mech = load_spec(folder / "mechanism.toml").mechanism
    spec = tomllib.loads((folder / "mechanism.toml").read_text())["mechanism"]["joints"]
    kinds = zip(mech.joint_names, mech.joint_types, strict=True)
    q = np.array([math.radians(values[n]) if t == "R" else values[n] for n, t in kinds])
    poses = body_poses(mech, q=q)
    out = {}
    for joint in spec:
        x, y = joint["point"][:2]
        out[joint["name"]] = (poses[joint["bodies"][1]] @ np.array([x, y, 0.0, 1.0]))[:2]
    return out


def triangle_angle(c: np.ndarray, m: np.ndarray, p: np.ndarray) -> float:
    """The angle at ``m`` of the triangle ``c m p`` by the law of cosines, degrees, folded to at most 90."""
    a, b, opposite = math.dist(m, c), math.dist(m, p), math.dist(c, p)
    angle = math.degrees(math.acos(max(-1.0, min(1.0, (a * a + b * b - opposite * opposite) / (2 * a * b)))))
    return min(angle, 180.0 - angle)
