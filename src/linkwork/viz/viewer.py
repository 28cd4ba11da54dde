"""Interactive viewers: one self-contained HTML file per result, that a browser opens offline.

:func:`write_trace_viewer` shows a traced path: the linkage's solids in 3-D (a small canvas renderer, no library),
a slider along the path, a play button, a branch selector, and the hinge-angle and singular-value plots linked to
the slider. :func:`write_synthesis_viewer` shows a synthesised chain posed on every target profile.

Everything the page needs is inlined (:mod:`linkwork.viz.viewer_page`): the script and style from
``viewer_assets/``, and the data as JSON with the bulky arrays as little-endian base64. The page fetches nothing,
from no host. The trace viewer sends each body's mesh once (reference configuration) and its 3x4 pose per path
point, so a path of ``N`` points over ``b`` bodies costs ``48 N b`` bytes before base64. This module holds the
trace viewer; the synthesis viewer is :mod:`linkwork.viz.synthesis_viewer` (its names are importable from here).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from linkwork.deprecation import trace_keyword
from linkwork.geometry.angles import wrap
from linkwork.io.results import file_arclength, file_units
from linkwork.kinematics.closure import body_poses
from linkwork.viz.palette import TAB10
from linkwork.viz.synthesis_viewer import (
    joint_turns,
    synthesis_viewer_data,
    synthesis_viewer_page,
    write_synthesis_viewer,
)
from linkwork.viz.viewer_page import (
    DATA_ID,
    ViewerAssets,
    packed_array,
    page_html,
    script_json,
    unpack,
    write_page,
)

if TYPE_CHECKING:
    from linkwork.kinematics.mechanism import Mechanism
    from linkwork.kinematics.trace_result import Bifurcation, Trace

#: Joint colours of the plots and labels (the one palette, so the viewer matches the PNG figures).
JOINT_COLORS = TAB10

#: Points per viewer above which each branch is thinned evenly (ends and bifurcation points always kept).
MAX_POINTS = 20000

#: Two path points closer than this (radians, per joint) are the same configuration (bifurcation visits):
#: a branch leaves a located point after a polish that may move it by a few 1e-6.
SAME_POINT = 1e-5

__all__ = [
    "DATA_ID",
    "JOINT_COLORS",
    "MAX_POINTS",
    "SAME_POINT",
    "Part",
    "joint_labels",
    "joint_turns",
    "linkage_parts",
    "script_json",
    "synthesis_viewer_data",
    "synthesis_viewer_page",
    "trace_viewer_data",
    "trace_viewer_page",
    "unpack",
    "write_synthesis_viewer",
    "write_trace_viewer",
]

_TRACE = ViewerAssets("trace.html", ("common.js", "scene.js", "trace.js"), "position along the branch")


@dataclass(frozen=True)
class Part:
    """A triangle mesh fixed to one body, in the reference configuration: what the 3-D view draws."""

    body: int
    name: str
    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    color: str


# ----------------------------------------------------------------------------------------------- geometry


def linkage_parts(mech: Mechanism) -> list[Part]:
    """The solids of every body and the hinge pins (:mod:`linkwork.viz.solids`), each fixed to one body.

    A pin moves with the body after its joint, as :func:`linkwork.viz.solids.place` moves it.
    """
    from linkwork.viz.solids import body_meshes, hinge_pins

    index = {name: i for i, name in enumerate(mech.bodies)}
    parts = [
        Part(index[name], name, mesh.vertices, mesh.faces, _hex(mesh.color))
        for name, mesh in body_meshes(mech).items()
    ]
    for pin in hinge_pins(mech):
        after = mech.joint_bodies[mech.index(pin.name)][1]
        parts.append(Part(index[after], f"pin {pin.name}", pin.vertices, pin.faces, _hex(pin.color)))
    return parts


def _hex(color: Any) -> str:
    """A colour as ``#rrggbb`` from a hex string or an RGB(A) tuple in 0..1."""
    if isinstance(color, str):
        return color if color.startswith("#") else "#888888"
    rgb = [min(255, max(0, round(255 * float(c)))) for c in tuple(color)[:3]]
    return "#{:02x}{:02x}{:02x}".format(*rgb)


def joint_labels(mech: Mechanism, parts: list[Part]) -> list[tuple[int, NDArray[np.float64]]]:
    """Where to label each joint: ``(body, point)`` at the reference, the centre of its pin if it has one,
    else the point of its axis nearest the origin (:func:`linkwork.viz.solids.joint_lines`)."""
    from linkwork.viz.solids import joint_lines

    points, _ = joint_lines(mech)
    pins = {p.name: p for p in parts if p.name.startswith("pin ")}
    out = []
    for j, name in enumerate(mech.joint_names):
        pin = pins.get(f"pin {name}")
        if pin is not None:
            out.append((pin.body, pin.vertices.mean(axis=0)))
        else:
            out.append((mech.bodies.index(mech.joint_bodies[j][1]), points[j]))
    return out


def _pose_rows(mech: Mechanism, angles: NDArray[np.float64]) -> NDArray[np.float64]:
    """``(N, b, 12)``: for each point and body, the rows of its rotation then its translation."""
    out = np.empty((len(angles), len(mech.bodies), 12))
    for i, a in enumerate(angles):
        poses = body_poses(mech, angles=a)
        for b, name in enumerate(mech.bodies):
            T = poses[name]
            out[i, b, :9] = T[:3, :3].ravel()
            out[i, b, 9:] = T[:3, 3]
    return out


def _centres(parts: list[Part], poses: NDArray[np.float64]) -> NDArray[np.float64]:
    """``(N, 3)`` the mean of the bodies' mesh centroids at every pose: what the view follows when centred."""
    bodies = [p for p in parts if not p.name.startswith("pin ")] or parts
    if not bodies:
        return np.zeros((len(poses), 3))
    out = np.zeros((len(poses), 3))
    for part in bodies:
        c = part.vertices.mean(axis=0)
        R = poses[:, part.body, :9].reshape(-1, 3, 3)
        out += R @ c + poses[:, part.body, 9:]
    return out / len(bodies)


def _bounds(parts: list[Part], poses: NDArray[np.float64], shift: NDArray[np.float64]) -> dict[str, Any]:
    """Box and bounding sphere of every part at (a sample of) every pose, each pose moved by ``-shift``."""
    pick = np.unique(np.linspace(0, len(poses) - 1, min(len(poses), 300)).astype(int))
    sample, offset = poses[pick], shift[pick]
    clouds = []
    for part in parts:
        R = sample[:, part.body, :9].reshape(-1, 3, 3)
        t = sample[:, part.body, 9:] - offset
        clouds.append((np.einsum("kij,vj->kvi", R, part.vertices) + t[:, None, :]).reshape(-1, 3))
    cloud = np.concatenate(clouds) if clouds else np.zeros((1, 3))
    lo, hi = cloud.min(axis=0), cloud.max(axis=0)
    centre = (lo + hi) / 2
    radius = float(np.max(np.linalg.norm(cloud - centre, axis=1)))
    return {"center": centre.tolist(), "radius": max(radius, 1e-9), "min": lo.tolist(), "max": hi.tolist()}


# ----------------------------------------------------------------------------------------------- trace viewer


def _steady_rows(trace: Trace, per_branch: list[NDArray[np.int64]]) -> NDArray[np.float64]:
    """``(N, 12)`` per point sent to the page, the rigid motion of the whole mechanism that keeps the drawing
    steady (rotation rows, then translation): each branch fitted point by point
    (:func:`linkwork.viz.snapshots.follow`), a branch leaving a bifurcation point starting from the pose its
    parent has there, and everything levelled by the flattest configuration of the first branch. A grounded
    mechanism (:attr:`Mechanism.grounded`) is held by its ground: no motion at all."""
    from linkwork.viz.snapshots import close_drift, follow, leveling, mesh_clouds

    mech = trace.mechanism
    if mech.grounded:
        count = sum(len(idx) for idx in per_branch)
        return np.tile(np.array([1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0, 0, 0, 0]), (count, 1))
    revolute = np.array([t == "R" for t in mech.joint_types])
    index = {br.id: bi for bi, br in enumerate(trace.branches)}
    done: dict[int, tuple[NDArray[np.float64], NDArray[np.float64]]] = {}  # branch index -> (clouds, moves)
    for bi, idx in enumerate(per_branch):
        clouds = mesh_clouds(mech, trace.angles[idx])
        reference = None
        parent = trace.branches[bi].parent
        if parent is not None and index.get(parent) in done and len(idx):
            pbi = index[parent]
            d = _difference(trace.angles[per_branch[pbi]], trace.angles[idx[0]], revolute)
            k = int(np.argmin(np.linalg.norm(d, axis=1)))
            p_clouds, p_moves = done[pbi]
            reference = p_clouds[k] @ p_moves[k][:3, :3].T + p_moves[k][:3, 3]
        # a branch that ends where it began is drawn in the same pose at both ends (snapshots.close_drift)
        done[bi] = (clouds, close_drift(mech, trace.angles[idx], follow(clouds, reference)))
    if not done:
        return np.zeros((0, 12))
    level = leveling(*done[0])
    moves = np.concatenate([np.einsum("ij,njk->nik", level, done[bi][1]) for bi in range(len(per_branch))])
    return np.concatenate([moves[:, :3, :3].reshape(-1, 9), moves[:, :3, 3]], axis=1)


def _compose(steady: NDArray[np.float64], poses: NDArray[np.float64]) -> NDArray[np.float64]:
    """Body pose rows ``(N, b, 12)`` moved by the whole-mechanism motions ``steady`` ``(N, 12)``."""
    S, s = steady[:, :9].reshape(-1, 1, 3, 3), steady[:, None, 9:]
    R, t = poses[:, :, :9].reshape(*poses.shape[:2], 3, 3), poses[:, :, 9:]
    out = np.empty_like(poses)
    out[:, :, :9] = (S @ R).reshape(*poses.shape[:2], 9)
    out[:, :, 9:] = np.einsum("nij,nbj->nbi", S[:, 0], t) + s
    return out


def _kept_points(trace: Trace, max_points: int, must: set[int]) -> list[NDArray[np.int64]]:
    """Per branch, the indices of its points sent to the page, in path order: all of them, or thinned evenly
    when the path has more than ``max_points`` (ends and the points in ``must`` kept)."""
    n = len(trace.branch)
    out = []
    for br in trace.branches:
        idx = np.flatnonzero(trace.of_branch(br.id))
        if n > max_points and len(idx) > 2:
            share = max(2, round(max_points * len(idx) / n))
            chosen = set(idx[np.unique(np.linspace(0, len(idx) - 1, share).round().astype(int))].tolist())
            idx = np.array(sorted(chosen | (must & set(idx.tolist()))), dtype=np.int64)
        out.append(idx)
    return out


def _difference(
    a: NDArray[np.float64], b: NDArray[np.float64], revolute: NDArray[np.bool_]
) -> NDArray[np.float64]:
    """Rows of ``a`` minus configuration ``b``, revolute joints wrapped into [-pi, pi)."""
    d = a - b
    d[:, revolute] = wrap(d[:, revolute])
    return d


def _same(a: NDArray[np.float64], b: NDArray[np.float64], revolute: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Rows of ``a`` that are configuration ``b`` (revolute joints compared modulo a full turn)."""
    return np.all(np.abs(_difference(a, b, revolute)) < SAME_POINT, axis=1)


def _visits(trace: Trace, bif: Bifurcation, revolute: NDArray[np.bool_]) -> NDArray[np.int64]:
    """Indices of the points at a bifurcation point: where branches leave or reach it, and the point of the
    branch it was found on at its step (the point is located between two steps, not inserted into it)."""
    same = set(np.flatnonzero(_same(trace.angles, bif.angles, revolute)).tolist())
    on = np.flatnonzero(trace.of_branch(bif.branch) & (trace.step == bif.step))
    same |= set(on[:1].tolist())
    for br in trace.branches:
        if br.bifurcation == bif.id:
            same |= set(np.flatnonzero(trace.of_branch(br.id))[:1].tolist())
    return np.array(sorted(same), dtype=np.int64)


@trace_keyword
def trace_viewer_data(
    trace: Trace, *, title: str | None = None, max_points: int = MAX_POINTS
) -> dict[str, Any]:
    """Everything the trace viewer page shows, as JSON-ready data (angles in degrees).

    Parameters
    ----------
    trace
        A traced path, one branch or several.
    title
        Heading of the page; the mechanism's name by default.
    max_points
        Above this many points, each branch is thinned evenly (its ends and bifurcation points are kept).
    """
    mech = trace.mechanism
    revolute = np.array([t == "R" for t in mech.joint_types])
    # Every place the path passes through each bifurcation point: where it was found, where branches leave
    # it and where branches end on it. The page offers a jump between them.
    visits_all = [_visits(trace, b, revolute) for b in trace.bifurcations]
    per_branch = _kept_points(trace, max_points, {int(i) for v in visits_all for i in v})
    keep = np.concatenate(per_branch) if per_branch else np.zeros(0, dtype=np.int64)
    parts = linkage_parts(mech)
    poses = _pose_rows(mech, trace.angles[keep])
    centres = _centres(parts, poses)
    steady = _steady_rows(trace, per_branch)
    return {
        "kind": "trace",
        "title": title or mech.name,
        "mechanism": mech.name,
        "drive": mech.index(trace.drive) if trace.drive in mech.joint_names else 0,
        "planar": bool(mech.moves_in_xy),
        "joints": _joint_entries(mech, joint_labels(mech, parts)),
        "bodies": list(mech.bodies),
        "parts": [_part_entry(p) for p in parts],
        "bounds": {
            "fixed": _bounds(parts, poses, np.zeros_like(centres)),
            "centred": _bounds(parts, _compose(steady, poses), np.zeros_like(centres)),
        },
        "fixed_body": mech.ground,
        "centres": packed_array(centres, "f4"),
        "steady": packed_array(steady, "f4"),
        "points": len(keep),
        "points_traced": len(trace.branch),
        "poses": packed_array(poses, "f4"),
        "angles": packed_array(file_units(mech, trace.angles[keep]), "f4"),
        "sigma": packed_array(trace.sigma[keep], "f8"),
        "rank": packed_array(trace.rank[keep], "i4"),
        "step": packed_array(trace.step[keep], "i4"),
        "arclength": packed_array(file_arclength(trace)[keep], "f4"),
        "residual": packed_array(trace.residual[keep], "f4"),
        "unknowns": mech.n_unknowns,
        "branches": _branch_entries(trace, per_branch),
        "bifurcations": _bifurcation_entries(trace, visits_all, per_branch),
    }


def _joint_entries(mech: Mechanism, labels: list[tuple[int, NDArray[np.float64]]]) -> list[dict[str, Any]]:
    """Per joint: name, type, plot colour and dash (the one palette), and where its label sits on which body."""
    return [
        {
            "name": name,
            "type": kind,
            "color": JOINT_COLORS[j % len(JOINT_COLORS)],
            "dash": j // len(JOINT_COLORS) + (j % 4),
            "body": labels[j][0],
            "point": labels[j][1].tolist(),
        }
        for j, (name, kind) in enumerate(zip(mech.joint_names, mech.joint_types, strict=True))
    ]


def _part_entry(part: Part) -> dict[str, Any]:
    """A part's mesh for the page: vertices as float32, faces as 16-bit indices when they fit."""
    return {
        "body": part.body,
        "name": part.name,
        "color": part.color,
        "vertices": packed_array(part.vertices, "f4"),
        "faces": packed_array(part.faces, "u2" if len(part.vertices) < 65536 else "u4"),
    }


def _branch_entries(trace: Trace, per_branch: list[NDArray[np.int64]]) -> list[dict[str, Any]]:
    """Per branch: how it was found and ended, and which run of the page's points (``start``, ``count``) it is."""
    starts = np.cumsum([0] + [len(idx) for idx in per_branch])
    return [
        {
            "id": br.id,
            "parent": br.parent,
            "bifurcation": br.bifurcation,
            "direction": br.direction,
            "steps": br.steps,
            "end": br.end_reason,
            "start": int(starts[bi]),
            "count": len(per_branch[bi]),
        }
        for bi, br in enumerate(trace.branches)
    ]


def _bifurcation_entries(
    trace: Trace, visits_all: list[NDArray[np.int64]], per_branch: list[NDArray[np.int64]]
) -> list[dict[str, Any]]:
    """Per bifurcation point: where it was found, its rank and tangents, its angles in file units, and its visits
    as ``[branch index, row within the branch]`` among the page's points."""
    where = {int(k): (bi, row) for bi, idx in enumerate(per_branch) for row, k in enumerate(idx)}
    return [
        {
            "id": b.id,
            "branch": b.branch,
            "step": b.step,
            "rank": b.rank,
            "method": b.method,
            "tangents": len(b.tangents),
            "angles": file_units(trace.mechanism, b.angles).tolist(),
            "visits": [list(where[int(k)]) for k in visits if int(k) in where],
        }
        for b, visits in zip(trace.bifurcations, visits_all, strict=True)
    ]


@trace_keyword
def write_trace_viewer(
    trace: Trace, file: str | Path, *, title: str | None = None, max_points: int = MAX_POINTS
) -> Path:
    """Write the interactive viewer of a traced path: one self-contained HTML file that works offline.

    The page shows the linkage in 3-D at a point of the path (drag to orbit, wheel to zoom), a slider along the
    path and a play button, a branch selector when the path has several branches, and the hinge angles
    (degrees) and the Jacobian's singular values against the step along the branch, with a cursor that follows
    the slider and the bifurcation points marked. See ``docs/viewer.md``.

    Parameters
    ----------
    trace
        A traced path (:func:`linkwork.trace`).
    file
        The HTML file to write (its folder is created).
    title
        Heading of the page; the mechanism's name by default.
    max_points
        Above this many points, each branch is thinned evenly (its ends and bifurcation points are kept).

    Returns
    -------
    The path of the file written.
    """
    return write_page(file, trace_viewer_page(trace, title=title, max_points=max_points))


@trace_keyword
def trace_viewer_page(trace: Trace, *, title: str | None = None, max_points: int = MAX_POINTS) -> str:
    """The HTML text of :func:`write_trace_viewer`'s page (for an inline view in a notebook)."""
    return trace_page(trace_viewer_data(trace, title=title, max_points=max_points))


def trace_page(data: dict[str, Any]) -> str:
    """The trace viewer's page around ``data`` (:func:`trace_viewer_data`, or the mechanism viewer's)."""
    return page_html(_TRACE, data)
