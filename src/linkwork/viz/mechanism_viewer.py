"""The mechanism viewer: the trace viewer of a mechanized chain with the target profiles drawn over it.

The page is the offline trace viewer (:mod:`linkwork.viz.viewer`) of the traced motion from the first profile to
the last; it opens with the ground fixed, framed on the target profiles (not on the whole linkage: an arc
slide's centre can lie many chords away), and draws every target profile as a dashed polyline, so one sees the
chain pass through each of them.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from linkwork.viz.palette import TAB10

if TYPE_CHECKING:
    from linkwork.mechanization import Mechanization

#: Colours of the target profiles drawn over the chain (profile 1 first).
TARGET_COLORS = TAB10


def chain_bounds(points: np.ndarray, pad: float = 0.08) -> dict[str, Any]:
    """Box and bounding sphere (the viewer's ``bounds`` entry) of the planar ``points`` ``(n, 2)``, padded."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    grow = pad * float(np.max(hi - lo))
    lo3 = np.array([lo[0] - grow, lo[1] - grow, 0.0])
    hi3 = np.array([hi[0] + grow, hi[1] + grow, 0.0])
    centre = (lo3 + hi3) / 2
    return {
        "center": centre.tolist(),
        "radius": max(float(np.linalg.norm(hi3 - centre)), 1e-9),
        "min": lo3.tolist(),
        "max": hi3.tolist(),
    }


def mechanism_viewer_data(found: Mechanization, *, title: str | None = None) -> dict[str, Any]:
    """The trace viewer's data for a mechanized chain, with ``overlays`` (the target profiles, and every link's
    moving pivot on the profiles), the bounds of the fixed view framed on the profiles and every link's pivots on
    every profile, and ``view = "fixed"``.

    Raises
    ------
    ValueError
        When the design was not traced (more than one DOF): there is no motion to show.
    """
    from linkwork.viz.viewer import trace_viewer_data

    check = found.verification
    if not check.paths:
        raise ValueError("the mechanism viewer needs a traced design (one DOF)")
    path = check.paths[-1]  # every trace starts at profile 1; the last one runs through to the last profile
    chain = found.design.chain
    data = trace_viewer_data(path, title=title or f"{found.design.name}: mechanism over the target profiles")
    names = [f"profile {j + 1}" for j in range(chain.count)]
    data["overlays"] = [
        {
            "name": name,
            "color": TARGET_COLORS[j % len(TARGET_COLORS)],
            "points": np.column_stack([t, np.zeros(len(t))]).tolist(),
        }
        for j, (name, t) in enumerate(zip(names, chain.targets, strict=True))
    ]
    # every binary link's pivots on every profile (mechanization.json's profiles[k].pivots): the moving pivot's
    # positions on the profiles, joined in profile order
    from linkwork.mechanization.verify import link_pivots

    mech = found.design.mechanism()
    at = [link_pivots(found.design, mech, state.values) for state in check.states]
    for link in found.design.links:
        moving = np.array([pivots[link.name][1] for pivots in at])
        data["overlays"].append(
            {
                "name": f"{link.name} moving pivot on profiles 1-{chain.count}",
                "color": "#d62728",
                "points": np.column_stack([moving, np.zeros(len(moving))]).tolist(),
            }
        )
    every = np.array([point for pivots in at for pair in pivots.values() for point in pair]).reshape(-1, 2)
    frame = np.vstack([*chain.targets, every])
    data["bounds"]["fixed"] = chain_bounds(frame)
    data["view"] = "fixed"
    return data


def write_mechanism_viewer(found: Mechanization, file: str | Path, *, title: str | None = None) -> Path:
    """Write ``mechanism.html``: the offline viewer of the mechanism moving through the target profiles."""
    from linkwork.viz.viewer import trace_page
    from linkwork.viz.viewer_page import write_page

    return write_page(file, trace_page(mechanism_viewer_data(found, title=title)))
