"""The ``deployment`` entry of ``report.json``: the deployment measures of a trace in file units (degrees).

Kept apart from :mod:`linkwork.io.results` so that ``report_dict`` needs one line for it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from linkwork.kinematics.deployment import Deployment
    from linkwork.kinematics.trace_result import Trace


def deployment_entry(trace: Trace, deployment: Deployment | None = None) -> dict[str, Any] | None:
    """``report.json``'s ``deployment``: attachment points, the deployed configuration, ``membrane_stretch``
    (value, pair, where), ``bundle_ratio`` (value, where), ``flatness``, ``bifurcations_on_path`` and
    ``mobility_on_path``; ``deployment`` defaults to ``trace.deployment()``. ``None`` for a trace without
    points on branch 0."""
    from linkwork.io.results import file_units

    if deployment is None:
        if not np.any(trace.branch == 0):
            return None
        deployment = trace.deployment()
    mech = trace.mechanism

    def named(angles: np.ndarray) -> dict[str, float]:
        return dict(zip(mech.joint_names, map(float, file_units(mech, angles)), strict=True))

    def where(row: int) -> dict[str, Any]:
        return {
            "branch": int(trace.branch[row]),
            "step": int(trace.step[row]),
            "angles": named(trace.angles[row]),
        }

    at = None
    if deployment.deployed_at is not None:
        joint, value = deployment.deployed_at
        j = mech.index(joint)
        at = {
            "joint": joint,
            "value": float(np.degrees(value)) if mech.joint_types[j] == "R" else float(value),
        }
    return {
        "attachment": list(deployment.attachment),
        "path_points": len(deployment.path),
        "deployed": {"at": at, "size": deployment.deployed_size, "angles": named(deployment.deployed_angles)},
        "membrane_stretch": {
            "value": _number(deployment.membrane_stretch),
            "pair": list(deployment.stretch_pair),
            **where(deployment.stretch_row),
        },
        "bundle_ratio": {"value": _number(deployment.bundle_ratio), **where(deployment.bundle_row)},
        "flatness": _number(deployment.flatness),
        "bifurcations_on_path": deployment.bifurcations_on_path,
        "mobility_on_path": deployment.mobility_on_path,
    }


def _number(value: float) -> float | None:
    """A finite number as it is, anything else (a bundle ratio with a deployed size of 0) as ``null``."""
    return float(value) if np.isfinite(value) else None
