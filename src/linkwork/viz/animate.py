"""Animations of a traced motion: the shaded solids of :mod:`linkwork.viz.snapshots`, frame by frame, as GIF/MP4.

GIF frames are written with pillow; an MP4 is also written when an ffmpeg executable is found
(:func:`find_ffmpeg`: ``ffmpeg`` on ``PATH``, else the static binary of the ``imageio-ffmpeg`` package of the
``viz`` extra) and skipped, with the reason recorded in the result, when none is. matplotlib, pillow and
imageio-ffmpeg are imported inside the functions.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from linkwork.deprecation import trace_keyword
from linkwork.errors import LinkworkError
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.trace_result import Trace
from linkwork.viz.snapshots import (
    bounds,
    branch_indices,
    default_view,
    draw_meshes,
    drive_label,
    set_limits,
    steady_transforms,
)
from linkwork.viz.solids import body_meshes, hinge_pins, place


@dataclass(frozen=True)
class Animation:
    """What :func:`animate_path` wrote: the GIF, the MP4 (or None and why not), the number of frames."""

    gif: Path | None
    mp4: Path | None
    frames: int
    mp4_skipped: str = ""


@trace_keyword
def path_frames(trace: Trace, branch: int | None = None, max_frames: int = 120) -> NDArray[np.int64]:
    """Indices of the path points to animate: one branch, or every branch in turn (id order), at most
    ``max_frames`` in all, spread over the branches in proportion to their number of points."""
    branches = sorted({int(b) for b in trace.branch}) if branch is None else [branch]
    orders = [branch_indices(trace, b, 0) for b in branches]
    total = sum(len(o) for o in orders)
    if total == 0:
        raise LinkworkError("the path has no points to animate")
    picks = []
    for order in orders:
        k = max(2, round(max_frames * len(order) / total)) if len(order) > 1 else 1
        k = min(k, len(order))
        picks.append(order[np.linspace(0, len(order) - 1, k).round().astype(np.int64)])
    return np.concatenate(picks)


@trace_keyword
def animate_path(
    trace: Trace,
    out_file: str | Path,
    branch: int | None = None,
    fps: int = 20,
    max_frames: int = 120,
    *,
    view: tuple[float, float] | None = None,
    size: int = 360,
) -> Animation:
    """Animate a traced path: one branch, or every branch in sequence when ``branch`` is None.

    Parameters
    ----------
    trace
        A traced path.
    out_file
        ``name.gif`` (a ``name.mp4`` is written next to it when ffmpeg is available) or ``name.mp4`` (then a GIF
        is written next to it only if ffmpeg is missing, so that something is always written).
    fps, max_frames
        Frame rate and the most frames in all (points are subsampled evenly along each branch).
    view
        Camera ``(elevation, azimuth)`` in degrees (default per linkage style).
    size
        Frame width and height in pixels.
    """
    idx = path_frames(trace, branch, max_frames)
    labels = []
    several = len({int(trace.branch[i]) for i in idx}) > 1
    for i in idx:
        text = drive_label(trace, int(i))
        labels.append(f"branch {int(trace.branch[i])}   {text}" if several else text)
    # Steady the drawing on every point of the drawn branches (consecutive points are close), then subsample.
    moves = np.zeros((len(idx), 4, 4))
    for b in sorted({int(trace.branch[i]) for i in idx}):
        every = branch_indices(trace, b, 0)
        T = steady_transforms(trace.mechanism, trace.angles[every])
        at = {int(j): k for k, j in enumerate(every)}
        for k, i in enumerate(idx):
            if int(trace.branch[i]) == b:
                moves[k] = T[at[int(i)]]
    return animate_configurations(
        trace.mechanism,
        trace.angles[idx],
        out_file,
        fps=fps,
        labels=labels,
        view=view,
        size=size,
        moves=moves,
    )


def animate_configurations(
    mech: Mechanism,
    angles: ArrayLike,
    out_file: str | Path,
    *,
    fps: int = 20,
    labels: Sequence[str] | None = None,
    view: tuple[float, float] | None = None,
    size: int = 360,
    moves: ArrayLike | None = None,
) -> Animation:
    """Animate ``mech`` through the configurations ``angles`` ``(N, n)`` (radians): e.g. a synthesised
    mechanism through its profiles. ``moves`` ``(N, 4, 4)``: rigid motions applied per frame (default: a steady
    fit, :func:`linkwork.viz.snapshots.steady_transforms`)."""
    out = Path(out_file)
    suffix = out.suffix.lower()
    if suffix not in {".gif", ".mp4"}:
        raise LinkworkError(f"animations are written as .gif or .mp4, got {out.name!r}")
    angles = np.atleast_2d(np.asarray(angles, dtype=float))
    moves_arr = steady_transforms(mech, angles) if moves is None else np.asarray(moves, dtype=float)
    images = render_frames(mech, angles, moves_arr, labels=labels, view=view, size=size)
    ffmpeg = find_ffmpeg()
    gif = mp4 = None
    skipped = ""
    out.parent.mkdir(parents=True, exist_ok=True)
    if suffix == ".gif" or ffmpeg is None:
        gif = write_gif(images, out.with_suffix(".gif"), fps)
    if ffmpeg is None:
        skipped = (
            "ffmpeg is not on PATH and no imageio-ffmpeg binary was found (pip install imageio-ffmpeg): "
            "MP4 skipped"
        )
    else:
        mp4 = write_mp4(images, out.with_suffix(".mp4"), fps, ffmpeg)
    return Animation(gif=gif, mp4=mp4, frames=len(images), mp4_skipped=skipped)


def find_ffmpeg() -> str | None:
    """The ffmpeg executable to write MP4s with: ``ffmpeg`` on ``PATH`` first, else the static binary shipped
    in the ``imageio-ffmpeg`` wheel (``imageio_ffmpeg.get_ffmpeg_exe()``, which honours ``IMAGEIO_FFMPEG_EXE``)
    if that package imports and the file exists, else None."""
    on_path = shutil.which("ffmpeg")
    if on_path is not None:
        return on_path
    try:
        import imageio_ffmpeg

        exe = imageio_ffmpeg.get_ffmpeg_exe()
    except (ImportError, RuntimeError):  # not installed, or no binary for this platform
        return None
    return exe if exe and os.path.isfile(exe) and os.access(exe, os.X_OK) else None


def render_frames(
    mech: Mechanism,
    angles: NDArray[np.float64],
    moves: NDArray[np.float64],
    *,
    labels: Sequence[str] | None = None,
    view: tuple[float, float] | None = None,
    size: int = 360,
) -> list[NDArray[np.uint8]]:
    """RGB images ``(size, size, 3)`` of every configuration, drawn with one camera and one box for all."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    view = view or default_view(mech)
    bodies, pins = body_meshes(mech), hinge_pins(mech)
    frames = [
        [m.transformed(T) for m in place(mech, bodies, pins, row)]
        for row, T in zip(angles, moves, strict=True)
    ]
    low, high = bounds(frames)
    dpi = 100
    fig = Figure(figsize=(size / dpi, size / dpi), dpi=dpi)
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_axes((0.0, 0.0, 1.0, 0.94), projection="3d")
    title = fig.text(0.5, 0.965, "", ha="center", va="center", fontsize=9)
    set_limits(ax, low, high, view)
    images = []
    collection = None
    for k, meshes in enumerate(frames):
        if collection is not None:
            collection.remove()
        collection = draw_meshes(ax, meshes, view)
        title.set_text(labels[k] if labels is not None else "")
        canvas.draw()
        images.append(np.asarray(canvas.buffer_rgba())[..., :3].copy())
    return images


def write_gif(images: Sequence[NDArray[np.uint8]], out: Path, fps: int) -> Path:
    """A looping GIF, one shared 64-colour palette (small files), ``fps`` frames per second."""
    from PIL import Image

    frames = [Image.fromarray(img) for img in images]
    # One palette from a strip of a few frames, so that every frame's colours (and the white ground) are in it.
    sample = [frames[i] for i in np.linspace(0, len(frames) - 1, min(4, len(frames))).round().astype(int)]
    strip = Image.new("RGB", (sum(f.width for f in sample), sample[0].height), "white")
    for k, f in enumerate(sample):
        strip.paste(f, (k * f.width, 0))
    palette = strip.quantize(colors=64, method=Image.Quantize.MEDIANCUT)
    quantized = [f.quantize(palette=palette, dither=Image.Dither.NONE) for f in frames]
    quantized[0].save(
        out,
        save_all=True,
        append_images=quantized[1:],
        duration=max(1, round(1000 / fps)),
        loop=0,
        optimize=True,
        disposal=1,
    )
    return out


def write_mp4(images: Sequence[NDArray[np.uint8]], out: Path, fps: int, ffmpeg: str) -> Path:
    """An H.264 MP4 through ffmpeg's stdin (raw RGB frames); the file is removed if ffmpeg fails."""
    h, w, _ = images[0].shape
    w2, h2 = w - w % 2, h - h % 2  # yuv420p needs even sides
    cmd = [
        ffmpeg, "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{w2}x{h2}",
        "-r", str(fps), "-i", "-", "-an", "-vcodec", "libx264", "-pix_fmt", "yuv420p", str(out),
    ]  # fmt: skip
    data = b"".join(np.ascontiguousarray(img[:h2, :w2]).tobytes() for img in images)
    result = subprocess.run(cmd, input=data, capture_output=True, check=False)
    if result.returncode != 0:
        out.unlink(missing_ok=True)
        raise LinkworkError(
            f"ffmpeg failed writing {out.name}: {result.stderr.decode(errors='replace').strip()}"
        )
    return out
