"""Snapshots of a traced motion: shaded 3-D drawings of the solids, one panel per configuration.

:func:`deployment_sequence` draws a branch from its first to its last point the way Gan & Pellegrino's Figs. 11,
13 and 16 do (six frames from folded to deployed); :func:`draw_meshes` is the one shaded-mesh painter that the
snapshots and the animations (:mod:`linkwork.viz.animate`) share. matplotlib is imported inside the functions.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.deprecation import trace_keyword
from linkwork.errors import LinkworkError
from linkwork.geometry.angles import wrap
from linkwork.geometry.fit import kabsch
from linkwork.geometry.se3 import exp_se3, inverse, log_se3
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.trace_result import Trace
from linkwork.viz.labels import plain, subscript
from linkwork.viz.solids import Mesh, body_meshes, hinge_pins, place

Array = NDArray[np.float64]

#: Direction the light comes from (a unit vector in the view's frame: towards the viewer, up and to the left).
LIGHT = np.array([-0.35, 0.45, 0.82])
#: Default camera (elevation, azimuth) in degrees, per drawing style.
VIEWS = {"hedgepeth": (30.0, -60.0), "guest-frame": (28.0, -58.0)}
DEFAULT_VIEW = (25.0, -60.0)


def default_view(mech: Mechanism) -> tuple[float, float]:
    """The camera ``(elev, azim)`` in degrees used when none is given."""
    return VIEWS.get(str(mech.meta.get("linkage", "")), DEFAULT_VIEW)


@trace_keyword
def branch_indices(trace: Trace, branch: int, frames: int) -> NDArray[np.int64]:
    """Indices of ``frames`` points of ``branch`` equally spaced in arclength, first and last included (all if 0)."""
    idx = np.flatnonzero(trace.of_branch(branch))
    if idx.size == 0:
        known = sorted({int(b) for b in trace.branch})
        raise LinkworkError(f"no branch {branch} in this path; branches are {known}")
    order = idx[np.argsort(trace.step[idx], kind="stable")]
    if frames <= 0:  # every point
        return order
    s = np.abs(trace.arclength[order] - trace.arclength[order[0]])
    if frames <= 1 or s[-1] <= 0:
        return order[np.linspace(0, len(order) - 1, max(frames, 1)).round().astype(np.int64)]
    targets = np.linspace(0.0, s[-1], frames)
    picks = np.searchsorted(s, targets).clip(0, len(order) - 1)
    return order[picks]


def shaded_colors(meshes: Sequence[Mesh], view: tuple[float, float]) -> tuple[Array, Array]:
    """All triangles ``(F, 3, 3)`` of ``meshes`` and their lit RGBA colours ``(F, 4)`` for a camera ``view``.

    Lambert shading with a light fixed to the camera (so every panel and frame is lit alike), two-sided.
    """
    from matplotlib.colors import to_rgb

    elev, azim = np.radians(view)
    # Camera frame: towards the viewer, right, up (matplotlib's elev/azim convention).
    eye = np.array([np.cos(elev) * np.cos(azim), np.cos(elev) * np.sin(azim), np.sin(elev)])
    right = np.array([-np.sin(azim), np.cos(azim), 0.0])
    up = np.cross(eye, right)
    light = LIGHT[0] * right + LIGHT[1] * up + LIGHT[2] * eye
    light /= np.linalg.norm(light)
    tris, colors = [], []
    for mesh in meshes:
        t = mesh.triangles
        n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
        n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
        lit = 0.35 + 0.65 * np.abs(n @ light)
        rgb = np.clip(np.outer(lit, to_rgb(mesh.color)), 0.0, 1.0)
        tris.append(t)
        colors.append(np.column_stack([rgb, np.ones(len(t))]))
    return np.concatenate(tris), np.concatenate(colors)


def draw_meshes(ax: Any, meshes: Sequence[Mesh], view: tuple[float, float]) -> Any:
    """Add ``meshes`` to a 3-D axes as one shaded, depth-sorted ``Poly3DCollection``; returns the collection."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    tris, colors = shaded_colors(meshes, view)
    collection = Poly3DCollection(tris, facecolors=colors, edgecolors=colors, linewidths=0.2)
    ax.add_collection3d(collection)
    return collection


def set_limits(ax: Any, low: ArrayLike, high: ArrayLike, view: tuple[float, float]) -> None:
    """Equal-aspect cube around the box ``[low, high]``, the camera ``view``, no axes."""
    low, high = np.asarray(low, dtype=float), np.asarray(high, dtype=float)
    centre, half = (low + high) / 2.0, 0.5 * float(np.max(high - low)) * 1.02
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, strict=True):
        setter(c - half, c + half)
    ax.set_box_aspect((1.0, 1.0, 1.0), zoom=1.3)
    ax.view_init(elev=view[0], azim=view[1])
    ax.set_axis_off()


def configuration_meshes(mech: Mechanism, angles: ArrayLike, steady: bool = True) -> list[list[Mesh]]:
    """Posed meshes for every row of ``angles`` ``(N, n)`` (meshes built once).

    With ``steady`` the frames are also moved rigidly as a whole (see :func:`steady_transforms`) so that the
    mechanism neither drifts nor tumbles from frame to frame, centred, its flattest configuration level.
    """
    angles = np.atleast_2d(np.asarray(angles, dtype=float))
    bodies, pins = body_meshes(mech), hinge_pins(mech)
    frames = [place(mech, bodies, pins, row) for row in angles]
    if not steady:
        return frames
    moves = steady_transforms(mech, angles)
    return [[m.transformed(T) for m in frame] for frame, T in zip(frames, moves, strict=True)]


def steady_transforms(mech: Mechanism, angles: ArrayLike) -> Array:
    """Rigid motions ``(N, 4, 4)`` of the whole mechanism, one per configuration, for a steady drawing.

    A grounded mechanism (:attr:`Mechanism.grounded`: a four-bar, a slider-crank, a mechanized chain) is drawn on
    its ground: one and the same move for every row. Otherwise body poses hold the first body still, so a hoop seen
    that way tumbles as it deploys: each configuration is instead fitted (least squares, Kabsch) onto the previous
    one as a whole and centred at the origin, which keeps a symmetric motion's symmetry axis still. Chained fits
    drift: a path that comes back to its first configuration would end in another pose, so the drift is spread
    back along the path (:func:`close_drift`) and the same configuration is drawn the same way at both ends.
    Finally everything is turned so that the normal of the flattest (most spread-out) configuration points up
    (+z). Consecutive rows should be close: pass the whole branch and pick frames afterwards.
    """
    angles = np.atleast_2d(np.asarray(angles, dtype=float))
    clouds = mesh_clouds(mech, angles)
    if mech.grounded:
        centre = np.eye(4)
        centre[:3, 3] = -clouds.reshape(-1, 3).mean(axis=0)
        moves = np.repeat(centre[None], len(clouds), axis=0)
    else:
        moves = close_drift(mech, angles, follow(clouds))
    return np.einsum("ij,njk->nik", leveling(clouds, moves), moves)


#: Two rows of joint values closer than this (radians or lengths, revolute joints modulo a turn) are one
#: configuration.
SAME_CONFIGURATION = 1e-7


def close_drift(mech: Mechanism, angles: Array, moves: Array) -> Array:
    """``moves`` corrected so that a path ending where it began (the same configuration, revolute joints modulo
    a full turn) is drawn in the same pose at both ends: the mismatch ``C = moves[0] moves[-1]^-1`` is applied in
    growing fractions ``exp(t log C)``, ``t`` the fraction of the path's length in the joints, so no frame jumps."""
    if len(angles) < 3:
        return moves
    step = np.diff(angles, axis=0)
    revolute = np.array([t == "R" for t in mech.joint_types])
    gap = angles[-1] - angles[0]
    gap[revolute] = wrap(gap[revolute])
    if np.max(np.abs(gap)) > SAME_CONFIGURATION:
        return moves
    mismatch = log_se3(moves[0] @ inverse(moves[-1]))
    length = np.concatenate([[0.0], np.cumsum(np.linalg.norm(step, axis=1))])
    t = length / length[-1] if length[-1] > 0 else np.linspace(0.0, 1.0, len(angles))
    return np.array([exp_se3(f * mismatch) @ m for f, m in zip(t, moves, strict=True)])


def mesh_clouds(mech: Mechanism, angles: ArrayLike) -> Array:
    """``(N, V, 3)`` every body mesh's vertices at each configuration (the cloud the steadying fits)."""
    angles = np.atleast_2d(np.asarray(angles, dtype=float))
    bodies = body_meshes(mech)
    return np.array([np.concatenate([m.vertices for m in place(mech, bodies, [], row)]) for row in angles])


def follow(clouds: Array, reference: Array | None = None) -> Array:
    """``(N, 4, 4)``: each cloud fitted onto the previous one as moved; the first one onto ``reference`` (a cloud
    already placed, e.g. the same configuration on a parent branch) or, without one, centred at the origin."""
    out = np.zeros((len(clouds), 4, 4))
    prev = reference
    for k, cloud in enumerate(clouds):
        if prev is None:
            T = np.eye(4)
            T[:3, 3] = -cloud.mean(axis=0)
        else:
            T = kabsch(cloud, prev)
        out[k] = T
        prev = cloud @ T[:3, :3].T + T[:3, 3]
    return out


def leveling(clouds: Array, moves: Array) -> Array:
    """A 4x4 rotation turning the most spread-out of the moved clouds so that its least principal direction is
    +z (a deployed hoop lies level)."""
    spreads = [np.linalg.svd(c - c.mean(axis=0), compute_uv=False) for c in clouds]
    k = int(np.argmax([s[0] * s[1] for s in spreads]))
    moved = clouds[k] @ moves[k][:3, :3].T + moves[k][:3, 3]
    _, _, Vt = np.linalg.svd(moved - moved.mean(axis=0))
    R = Vt.copy()
    if np.linalg.det(R) < 0:
        R[0] *= -1.0
    level = np.eye(4)
    level[:3, :3] = R  # rows: principal directions -> x, y, z
    return level


def bounds(frames: Sequence[Sequence[Mesh]]) -> tuple[Array, Array]:
    """Box ``(low, high)`` holding every mesh of every frame."""
    pts = np.concatenate([m.vertices for frame in frames for m in frame])
    return pts.min(axis=0), pts.max(axis=0)


@trace_keyword
def label_joint(trace: Trace, branch: int) -> int:
    """The joint to label a branch's frames with: the drive, or, where the drive stays put along the branch
    (Guest's frame leaves its bifurcation at a fixed theta_A), the joint that moves the most."""
    mech = trace.mechanism
    d = mech.index(trace.drive)
    values = trace.angles[trace.of_branch(branch)]
    spans = np.ptp(values, axis=0) if len(values) else np.zeros(mech.n_joints)
    return d if spans[d] > 1e-6 * max(float(spans.max()), 1e-300) else int(np.argmax(spans))


@trace_keyword
def drive_label(trace: Trace, i: int, joint: int | None = None) -> str:
    """``"theta_A = 12.3°"``: a joint's value at point ``i`` (degrees, or length for a slider); default the
    joint :func:`label_joint` picks for the point's branch."""
    mech = trace.mechanism
    d = label_joint(trace, int(trace.branch[i])) if joint is None else joint
    name = mech.joint_names[d]
    value = trace.angles[i, d]
    from linkwork.viz.labels import number

    if mech.joint_types[d] == "P":
        return f"{plain(name)} = {number(value, '.3g')}"
    return f"{subscript(chr(92) + 'theta', name)} = {number(np.degrees(value), '.1f')}°"


@trace_keyword
def deployment_sequence(
    trace: Trace,
    out_file: str | Path,
    frames: int = 6,
    branch: int = 0,
    view: tuple[float, float] | None = None,
    *,
    columns: int | None = None,
    panel_size: float = 2.4,
    dpi: int = 110,
    title: str | None = None,
) -> Path:
    """Draw ``frames`` configurations of one branch, first to last point, one panel each (Figs. 11, 13, 16).

    Parameters
    ----------
    trace
        The traced result (:func:`linkwork.kinematics.tracer.trace`).
    out_file
        The figure; PNG, SVG or PDF by its suffix.
    frames
        Number of panels, equally spaced in arclength along the branch.
    branch
        Which branch of ``trace`` to draw.
    view
        Camera ``(elevation, azimuth)`` in degrees, the same in every panel (default per linkage style).

    Returns
    -------
    The path of the written file.
    """
    from matplotlib.figure import Figure

    out = Path(out_file)
    if out.suffix.lower() not in {".png", ".svg", ".pdf"}:
        raise LinkworkError(f"deployment_sequence writes .png, .svg or .pdf, got {out.name!r}")
    mech = trace.mechanism
    view = view or default_view(mech)
    idx = branch_indices(trace, branch, frames)
    every = branch_indices(trace, branch, 0)  # the whole branch in order, for a steady fit
    moves = steady_transforms(mech, trace.angles[every])
    at = {int(i): k for k, i in enumerate(every)}
    posed = [
        [m.transformed(moves[at[int(i)]]) for m in frame]
        for i, frame in zip(idx, configuration_meshes(mech, trace.angles[idx], steady=False), strict=True)
    ]
    low, high = bounds(posed)
    cols = columns or min(len(idx), 3)
    rows = int(np.ceil(len(idx) / cols))
    fig = Figure(figsize=(panel_size * cols, panel_size * rows + (0.35 if title else 0.0)), dpi=dpi)
    for k, (i, meshes) in enumerate(zip(idx, posed, strict=True)):
        ax = fig.add_subplot(rows, cols, k + 1, projection="3d")
        draw_meshes(ax, meshes, view)
        set_limits(ax, low, high, view)
        ax.set_title(f"({chr(ord('a') + k)}) " + drive_label(trace, int(i)), fontsize=9, pad=-2)
    if title:
        fig.suptitle(plain(title), fontsize=10)
    fig.subplots_adjust(left=0.0, right=1.0, bottom=0.0, top=0.93 if title else 0.97, wspace=0.0, hspace=0.08)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=dpi)
    return out
