"""Figures of a mechanized chain, in the spirit of Shamsudin et al. (2013), Fig. 14: the mechanism drawn on
every profile (chain, binary links, ground pivots, the target profile), and a GIF of it moving through them.

matplotlib (and pillow for the GIF) are imported inside the functions; only the object-oriented API is used.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from linkwork.mechanization.chain import apply
from linkwork.viz.labels import plain
from linkwork.viz.palette import TAB10

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from linkwork.kinematics.mechanism import Mechanism
    from linkwork.mechanization.mechanize import Mechanization

Array = NDArray[np.float64]

DPI = 80


def _draw(
    ax: Axes, found: Mechanization, mech: Mechanism, values: Array, profile: int, *, target: bool
) -> None:
    """Draw the mechanism at joint displacements ``values`` (chain points counted as on ``profile``)."""
    from linkwork.mechanization.verify import chain_displacements

    design = found.design
    chain = design.chain
    disp = chain_displacements(design, mech, values)
    if target:
        t = chain.targets[profile]
        ax.plot(t[:, 0], t[:, 1], color="0.65", lw=3.0, zorder=1, label="target profile")
    pts = chain.points(disp, profile)
    ax.plot(pts[:, 0], pts[:, 1], color=TAB10[0], lw=1.6, zorder=3, label="chain")
    joints = np.array(
        [
            apply(disp[jt.bodies[1]] if jt.bodies[1] != "ground" else np.zeros(3), jt.point)
            for jt in chain.joints
            if jt.role != "slide"
        ]
    ).reshape(-1, 2)
    if len(joints):
        ax.plot(joints[:, 0], joints[:, 1], "o", ms=4, mfc="white", mec=TAB10[0], zorder=4)
    for k, link in enumerate(design.links):
        body = disp[link.body]
        m = apply(body, link.circle)
        if link.kind == "PR":  # a slider: its guide, drawn about where the slider is
            assert link.direction is not None
            d = apply(np.array([0.0, 0.0, disp[link.anchor][2]]), link.direction)
            reach = 0.08 * chain.size
            ax.plot(*np.column_stack([m - reach * d, m + reach * d]), color="#2ca02c", lw=2.4, zorder=2)
            ax.plot([m[0]], [m[1]], "s", ms=5, color="#2ca02c", zorder=4)
            continue
        if link.kind == "RR":
            c = apply(disp[link.name], link.centre)
        else:
            c = apply(disp[f"{link.name}c"], link.centre)
        colour = "#d62728" if link.kind == "RR" else "#2ca02c"
        outline = apply(body, chain.body(link.body).outline)
        near = outline[int(np.argmin(np.linalg.norm(outline - m, axis=1)))]
        ax.plot([near[0], m[0]], [near[1], m[1]], color=TAB10[0], lw=0.8, ls=":", zorder=2)  # bracket
        ax.plot(
            [c[0], m[0]],
            [c[1], m[1]],
            color=colour,
            lw=1.2,
            zorder=2,
            label="binary links" if k == 0 else None,
        )
        ax.plot([m[0]], [m[1]], "o", ms=3.5, color=colour, zorder=4)
        ground = link.anchor == "ground"
        ax.plot(
            [c[0]],
            [c[1]],
            "^" if ground else "s",
            ms=6 if ground else 4,
            color="k" if ground else colour,
            zorder=4,
            label="ground pivots" if k == 0 and ground else None,
        )


def _limits(found: Mechanization) -> tuple[Array, Array]:
    """Box holding the target profiles and every pivot on every profile."""
    from linkwork.mechanization.verify import chain_displacements

    design = found.design
    mech = design.mechanism()
    pts = [np.vstack(design.chain.targets)]
    for state in found.verification.states:
        disp = chain_displacements(design, mech, state.values)
        for link in design.links:
            side = link.name if link.kind in ("RR", "PR") else f"{link.name}c"
            pts.append(np.vstack([apply(disp[side], link.centre), apply(disp[link.body], link.circle)]))
    allp = np.vstack(pts)
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    pad = 0.06 * float(np.max(hi - lo))
    return lo - pad, hi + pad


def plot_profiles_mechanism(found: Mechanization) -> Figure:
    """One panel per profile: the mechanism in that profile's configuration over the target profile."""
    from matplotlib.figure import Figure

    from linkwork.viz.labels import number

    design, check = found.design, found.verification
    mech = design.mechanism()
    p = len(check.states)
    lo, hi = _limits(found)
    width, height = hi - lo
    panel = 3.6
    fig = Figure(figsize=(panel * p, panel * height / width + 0.8), layout="constrained")
    axes = fig.subplots(1, p, squeeze=False)[0]
    revolute = mech.joint_types[mech.index(design.drive)] == "R"
    for j, (ax, state) in enumerate(zip(axes, check.states, strict=True)):
        _draw(ax, found, mech, state.values, j, target=True)
        value = (
            f"{number(math.degrees(state.drive_value), '.2f')} deg" if revolute else number(state.drive_value)
        )
        ax.set_title(
            f"profile {j + 1}: {plain(str(design.drive))} = {value}\nE_max = {state.e_max:.3g} (profile unit)",
            fontsize=9,
        )
        ax.set_aspect("equal")
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_xlabel("x (profile unit)")
        ax.tick_params(labelsize=7)
        if j == 0:
            ax.set_ylabel("y (profile unit)")
            ax.legend(fontsize=7, loc="best")
        else:  # the same y range as the first panel, which labels it
            ax.tick_params(labelleft=False)
    fig.suptitle(f"{plain(design.name)}: DOF {check.dof}, drive {plain(str(design.drive))}", fontsize=10)
    return fig


def animation_frames(found: Mechanization, frames: int = 20) -> Array:
    """``(k, n)`` joint displacements along the traced path from profile 1 to the last, about evenly spaced."""
    paths = found.verification.paths
    if not paths:
        return np.array([s.values for s in found.verification.states])
    path = paths[-1].angles
    idx = np.unique(np.linspace(0, len(path) - 1, frames).round().astype(int))
    return path[idx]


def write_animation(
    found: Mechanization, path: str | Path, *, frames: int = 20, mp4: bool = True
) -> list[Path]:
    """A GIF of the mechanism moving from profile 1 through every profile (there and back), and with ``mp4`` the
    same frames as an MP4 next to it when an ffmpeg is found (:func:`linkwork.viz.animate.find_ffmpeg`).
    Returns the files written."""
    from io import BytesIO

    from matplotlib.figure import Figure
    from PIL import Image

    design = found.design
    mech = design.mechanism()
    lo, hi = _limits(found)
    width, height = hi - lo
    values = animation_frames(found, frames)
    drive = mech.index(design.drive)
    marks = [s.drive_value for s in found.verification.states]
    images = []
    rgb = []
    for q in values:
        fig = Figure(figsize=(4.2, max(1.6, 4.2 * height / width)), layout="constrained")
        ax = fig.subplots()
        # the chain's piece counts: those of the nearest profile along the drive
        j = int(np.argmin([abs(q[drive] - m) for m in marks]))
        for k in range(len(marks)):
            t = design.chain.targets[k]
            ax.plot(t[:, 0], t[:, 1], color="0.8", lw=1.0, zorder=1)
        _draw(ax, found, mech, q, j, target=False)
        ax.set_aspect("equal")
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_axis_off()
        buffer = BytesIO()
        fig.savefig(buffer, format="png", dpi=48)
        buffer.seek(0)
        frame = Image.open(buffer).convert("RGB")
        rgb.append(np.asarray(frame, dtype=np.uint8))
        images.append(frame.convert("P", palette=Image.Palette.ADAPTIVE, colors=16))
    images += images[-2:0:-1]
    rgb += rgb[-2:0:-1]
    out = Path(path)
    images[0].save(out, save_all=True, append_images=images[1:], duration=120, loop=0, optimize=True)
    written = [out]
    if mp4:
        from linkwork.viz.animate import find_ffmpeg, write_mp4

        ffmpeg = find_ffmpeg()
        if ffmpeg is not None:
            written.append(write_mp4(rgb, out.with_suffix(".mp4"), 8, ffmpeg))
    return written


def write_mechanism_figures(found: Mechanization, out_dir: str | Path) -> list[Path]:
    """Write ``mechanism.png`` (and ``.svg``), the mechanism on every profile, ``mechanism.gif`` and, when an
    ffmpeg is found, ``mechanism.mp4``."""
    import matplotlib

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fig = plot_profiles_mechanism(found)
    paths = [out / "mechanism.png", out / "mechanism.svg"]
    with matplotlib.rc_context({"svg.hashsalt": "linkwork", "svg.fonttype": "none"}):
        fig.savefig(paths[0], dpi=DPI, metadata={"Software": None})
        fig.savefig(paths[1], metadata={"Date": None, "Creator": None})
    paths += write_animation(found, out / "mechanism.gif")
    return paths
