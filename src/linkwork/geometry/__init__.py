"""Rigid-body geometry: SE(3) exponential, logarithm, adjoint and twists (numpy, batched over leading axes)."""

from linkwork.geometry.se3 import (
    adjoint,
    bracket,
    exp_se3,
    exp_so3,
    hat3,
    inverse,
    line_twist,
    log_se3,
    log_so3,
    rot_x,
    rot_z,
    translation,
    twist_hat,
)

__all__ = [
    "adjoint",
    "bracket",
    "exp_se3",
    "exp_so3",
    "hat3",
    "inverse",
    "line_twist",
    "log_se3",
    "log_so3",
    "rot_x",
    "rot_z",
    "translation",
    "twist_hat",
]
