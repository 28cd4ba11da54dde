"""The synthesis viewer: a synthesised chain posed on every target profile, as one self-contained HTML page.

:func:`write_synthesis_viewer` draws the target profiles and the joined chain posed on one of them, with a slider
across the profiles, the segments coloured by type and the error of every segment (``docs/viewer.md``). The page
machinery is :mod:`linkwork.viz.viewer_page`; these names keep their :mod:`linkwork.viz.viewer` import path too.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from linkwork.viz.palette import TAB10
from linkwork.viz.viewer_page import ViewerAssets, page_html, write_page

if TYPE_CHECKING:
    from linkwork.synthesis.result import SynthesisResult

__all__ = ["joint_turns", "synthesis_viewer_data", "synthesis_viewer_page", "write_synthesis_viewer"]

_SYNTHESIS = ViewerAssets("synthesis.html", ("common.js", "synthesis.js"), "target profile")


def joint_turns(points: NDArray[np.float64], joints: list[int]) -> NDArray[np.float64]:
    """Relative angle (degrees) at each joint of a posed chain: the turn from the piece arriving at the joint
    point to the piece leaving it (positive to the left)."""
    pts = np.asarray(points, dtype=float)
    out = []
    for k in joints:
        a, b = pts[k] - pts[k - 1], pts[k + 1] - pts[k]
        out.append(math.degrees(math.atan2(a[0] * b[1] - a[1] * b[0], a @ b)))
    return np.array(out)


def synthesis_viewer_data(result: SynthesisResult, *, title: str | None = None) -> dict[str, Any]:
    """Everything the synthesis viewer page shows, as JSON-ready data (angles in degrees)."""

    def chain(profiles: Any) -> list[dict[str, Any]]:
        return [
            {
                "joints": np.asarray(prof.joints).tolist(),
                "points": np.asarray(prof.points).tolist(),
                "angles": np.degrees(prof.angles).tolist(),
                "errors": np.asarray(prof.errors).tolist(),
                "turns": joint_turns(
                    prof.points, [int(seg.starts[j]) for seg in result.segments[1:]]
                ).tolist(),
            }
            for j, prof in enumerate(profiles)
        ]

    segments = [
        {
            "kind": seg.kind,
            "pieces": [int(m) for m in seg.pieces],
            "starts": [int(k) for k in seg.starts],
            "radius": None if seg.radius is None or math.isinf(seg.radius) else float(seg.radius),
            "lengths": [float(v) for v in seg.lengths],
        }
        for seg in result.segments
    ]
    compound = result.compound
    return {
        "kind": "synthesis",
        "joint_colors": list(TAB10),
        "title": title or f"Shape-change synthesis: design {result.design}",
        "profile_kind": result.problem.kind,
        "design": result.design,
        "e_max": float(result.e_max),
        "e_mean": float(result.e_mean),
        "joined_e_max": float(result.joined_e_max),
        "piece_length": float(result.problem.piece_length),
        "targets": [
            {
                "name": t.name or f"profile {j + 1}",
                "points": np.asarray(t.points).tolist(),
                "arc_length": float(t.arc_length),
                "pieces": int(t.pieces),
            }
            for j, t in enumerate(result.targets)
        ],
        "segments": segments,
        "joined": chain(result.joined),
        "joined_errors": np.asarray(result.joined_error_matrix).tolist(),
        "compound": None
        if compound is None
        else {
            "merged": [int(i) for i in compound.merged],
            "merge_below": math.degrees(compound.threshold),
            "joint_ranges": np.degrees(compound.joint_ranges).tolist(),
            "joint_angles": np.degrees(compound.joint_angles).tolist(),
            "e_max": float(compound.e_max),
            "errors": np.asarray(compound.error_matrix).tolist(),
            "profiles": chain(compound.profiles),
            "notes": list(compound.notes),
        },
    }


def write_synthesis_viewer(result: SynthesisResult, file: str | Path, *, title: str | None = None) -> Path:
    """Write the interactive viewer of a synthesis result: one self-contained HTML file that works offline.

    The page draws the target profiles and the joined chain posed on one of them, with a slider (and a play
    button) across the profiles, the segments coloured by type (M rigid, C constant curvature), the joints,
    and the error of every segment on the profile shown. See ``docs/viewer.md``.

    Returns
    -------
    The path of the file written.
    """
    return write_page(file, synthesis_viewer_page(result, title=title))


def synthesis_viewer_page(result: SynthesisResult, *, title: str | None = None) -> str:
    """The HTML text of :func:`write_synthesis_viewer`'s page (for an inline view in a notebook)."""
    return page_html(_SYNTHESIS, synthesis_viewer_data(result, title=title))
