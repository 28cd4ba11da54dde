"""The gallery of a search (``gallery.html``): one card per candidate with an inline SVG drawing of its deployment,
its parameters and measures, and a link to its own offline viewer page. Plain text and SVG, no matplotlib; every
name a user wrote (parameters, joints, points, the study's name) is escaped."""

from __future__ import annotations

import html
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from linkwork.kinematics.deployment import Deployment
    from linkwork.kinematics.trace_result import Trace

Array = NDArray[np.float64]

#: Colours of the three configurations drawn: deployed, largest stretch, most folded.
COLOURS = {"deployed": "#1f3b73", "largest stretch": "#d9730d", "most folded": "#2a9d8f"}


def _frame(points: Array) -> tuple[Array, Array]:
    """Centre and principal axes ``(3, 3)`` (rows) of the deployed points: the first two span their plane."""
    centre = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - centre)
    if vt.shape[0] < 3:
        vt = np.vstack([vt, np.cross(vt[0], vt[-1] if vt.shape[0] > 1 else [0.0, 0.0, 1.0])])
    return centre, vt


def deployment_svg(trace: Trace, deployment: Deployment, width: int = 360, height: int = 170) -> str:
    """An inline SVG of the attachment points (joined in order) in the deployed configuration, at the largest
    stretch and in the most folded one: a view onto the deployed best-fit plane (left) and one edge-on (right)."""
    from linkwork.kinematics.deployment import attachment_positions

    mech = trace.mechanism
    configs = {
        "deployed": deployment.deployed_angles,
        "largest stretch": trace.angles[deployment.stretch_row],
        "most folded": trace.angles[deployment.bundle_row],
    }
    pts = {name: attachment_positions(mech, q[None, :])[0] for name, q in configs.items()}
    if len(pts["deployed"]) < 2:
        return f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}"></svg>'
    centre, axes = _frame(pts["deployed"])
    views = [(0, 1), (0, 2)]  # onto the plane; edge-on
    panel = width / 2
    every = np.concatenate([(p - centre) @ axes.T for p in pts.values()])
    span = float(np.max(np.abs(every[:, :3]))) or 1.0
    scale = 0.42 * min(panel, height) / span
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}">'
    ]
    for v, (a, b) in enumerate(views):
        cx, cy = panel * v + panel / 2, height / 2
        parts.append(
            f'<rect x="{panel * v + 1:.1f}" y="1" width="{panel - 2:.1f}" height="{height - 2}" fill="none" stroke="#ddd"/>'
        )
        for name, p in pts.items():
            local = (p - centre) @ axes.T
            xy = [(cx + scale * x, cy - scale * y) for x, y in zip(local[:, a], local[:, b], strict=True)]
            path = " ".join(f"{x:.1f},{y:.1f}" for x, y in xy)
            parts.append(
                f'<polygon points="{path}" fill="none" stroke="{COLOURS[name]}" stroke-width="1.6" opacity="0.9"/>'
            )
        label = "onto the deployed plane" if v == 0 else "edge-on"
        parts.append(
            f'<text x="{panel * v + 6:.1f}" y="{height - 6}" font-size="10" fill="#666">{label}</text>'
        )
    parts.append("</svg>")
    return "".join(parts)


def _cell(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    return html.escape(str(value))


def gallery_page(
    title: str,
    summary: str,
    cards: Sequence[tuple[dict[str, Any], str, str]],
    parameters: Sequence[str],
    measures: Sequence[str],
) -> str:
    """The gallery HTML: ``cards`` are ``(row, svg, viewer link)``; ``parameters`` and ``measures`` name the row
    entries shown. Self-contained (inline CSS and SVG)."""
    legend = " ".join(
        f'<span style="color:{colour}">&#9632; {html.escape(name)}</span>' for name, colour in COLOURS.items()
    )
    out = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{html.escape(title)}</title>",
        "<style>body{font-family:sans-serif;margin:1.5em;color:#222}"
        ".cards{display:flex;flex-wrap:wrap;gap:14px}.card{border:1px solid #ccc;border-radius:6px;padding:8px;"
        "width:370px}.card table{font-size:12px;border-collapse:collapse}.card td{padding:1px 6px}"
        ".card h3{margin:2px 0 6px;font-size:14px}.fail{color:#a33}</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
        f"<p>{html.escape(summary)}</p>",
        f"<p>{legend}</p>",
        '<div class="cards">',
    ]
    for row, svg, link in cards:
        head = f"#{row['rank']}" if row.get("rank") else f"candidate {row['index']}"
        out.append('<div class="card">')
        out.append(f'<h3>{html.escape(str(head))} &middot; <a href="{html.escape(link)}">viewer</a></h3>')
        out.append(svg)
        out.append("<table>")
        for key in [*parameters, *measures]:
            out.append(f"<tr><td>{html.escape(key)}</td><td>{_cell(row.get(key))}</td></tr>")
        if row.get("reason"):
            out.append(f'<tr><td>reason</td><td class="fail">{html.escape(str(row["reason"]))}</td></tr>')
        out.append("</table></div>")
    out += ["</div>", "</body></html>", ""]
    return "\n".join(out)
