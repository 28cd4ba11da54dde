"""A synthesised chain's outline on every profile, for CAD: one SVG drawing or one DXF drawing.

The chain drawn is the final one (:func:`final_chain`): after merging joints into compound segments when any were
merged (S13 Sec. 6), else the joined chain (S13 Sec. 5). Lengths are in the problem's ``units``.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from linkwork.io.curves import bounding_size
from linkwork.io.drawing import new_dxf, svg_d, svg_document, svg_path, xml_escape
from linkwork.names import dxf_layers

if TYPE_CHECKING:
    from linkwork.synthesis.result import JoinedProfile, SynthesisResult

__all__ = ["final_chain", "write_outline_dxf", "write_outline_svg"]


def final_chain(result: SynthesisResult) -> tuple[JoinedProfile, ...]:
    """The chain as built, posed on every profile: after merging joints into compound segments when any were
    merged (Sec. 6 of the paper), else the joined chain (Sec. 5)."""
    if result.compound is not None and result.compound.merged:
        return result.compound.profiles
    return result.joined


def write_outline_svg(path: str | Path, result: SynthesisResult) -> None:
    """Write the chain's outline on every profile as one SVG drawing (y up, profile coordinates).

    One group per profile (``id`` the profile's name) holds its target profile (dashed), the chain (solid) and
    its joints and two ends (circles); the chain is the final one (:func:`final_chain`), without the joints
    merged into compound segments.
    """
    chains = final_chain(result)
    joints = _live_joints(result)
    extents = [t.points for t in result.targets] + [c.points for c in chains]
    radius = 0.006 * bounding_size(np.vstack(extents))
    body = []
    for j, (target, chain) in enumerate(zip(result.targets, chains, strict=True)):
        name = target.name or f"profile {j + 1}"
        colour = _OUTLINE_COLOURS[j % len(_OUTLINE_COLOURS)]
        body.append(f'<g id="{xml_escape(name)}">')
        body.append(svg_path(svg_d(target.points), "#7f7f7f", dashed=True, label=f"{name}: target profile"))
        body.append(svg_path(svg_d(chain.points), colour, label=f"{name}: chain {result.design}"))
        body += [
            f'<circle cx="{x:.12g}" cy="{-y:.12g}" r="{radius:.6g}" fill="white" stroke="black" '
            f'stroke-width="1" vector-effect="non-scaling-stroke"/>'
            for x, y in chain.joints[joints]
        ]
        body.append("</g>")
    units = result.problem.units
    Path(path).write_text(svg_document(body, extents, units=units), encoding="utf-8")


def write_outline_dxf(path: str | Path, result: SynthesisResult) -> None:
    """Write the chain's outline on every profile as one DXF drawing for CAD.

    Per profile ``NAME``: layer ``NAME-target`` holds the target profile, ``NAME-chain`` the chain (an
    LWPOLYLINE through the chain's points) and ``NAME-joints`` a circle at every joint and at both ends; the
    chain is the final one (:func:`final_chain`), without the joints merged into compound segments. Lengths are
    in the problem's ``units`` (``$INSUNITS``).
    """
    chains = final_chain(result)
    joints = _live_joints(result)
    radius = 0.006 * bounding_size(np.vstack([t.points for t in result.targets]))
    document = new_dxf(result.problem.units)
    space = document.modelspace()
    layers = _dxf_layer_names([t.name or f"profile {j + 1}" for j, t in enumerate(result.targets)])
    for j, (target, chain) in enumerate(zip(result.targets, chains, strict=True)):
        name = layers[j]
        colour = j % 6 + 1  # AutoCAD colour index 1..6
        for suffix in ("target", "chain", "joints"):
            document.layers.add(f"{name}-{suffix}", color=8 if suffix == "target" else colour)
        space.add_lwpolyline(target.points, format="xy", dxfattribs={"layer": f"{name}-target"})
        space.add_lwpolyline(chain.points, format="xy", dxfattribs={"layer": f"{name}-chain"})
        for x, y in chain.joints[joints]:
            space.add_circle((float(x), float(y)), radius, dxfattribs={"layer": f"{name}-joints"})
    document.saveas(str(path))


def _live_joints(result: SynthesisResult) -> list[int]:
    """Rows of ``JoinedProfile.joints`` that are joints of the final chain: the two ends and every revolute
    joint not merged into a compound segment."""
    merged = set(result.compound.merged) if result.compound is not None else set()
    count = len(result.joined[0].joints)
    return [k for k in range(count) if k in (0, count - 1) or (k - 1) not in merged]


_OUTLINE_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b")


def _dxf_layer_names(names: Sequence[str]) -> list[str]:
    """One distinct layer name per profile (the name policy's :func:`linkwork.names.dxf_layers`: the characters
    DXF forbids become ``_``, and since DXF layer names ignore case a repeat gets ``_2``, ``_3``, ...); a profile
    without a name is ``profile``."""
    layers: list[str] = []
    taken: set[str] = set()
    for name in names:
        layer = dxf_layers([name or "profile"], taken=taken)[name or "profile"]
        taken.add(layer)
        layers.append(layer)
    return layers
