"""Figures of shape-change synthesis, after Shamsudin et al. (2013): design and target profiles (their
Fig. 3), an M-segment's registration (Fig. 6), a C-segment's arcs (Fig. 7), the chain before and after joining
(Fig. 8) and after merging joints into compound segments (Fig. 10).

matplotlib is imported inside the functions (it is an optional extra) and only its object-oriented API is used
(``matplotlib.figure.Figure``, drawn by the Agg renderer): nothing is ever displayed and no global pyplot
state is touched. Every figure has equal axes, labelled axes and a legend.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Kinematic synthesis of planar, shape-changing,
rigid body mechanisms for design profiles with significant differences in arc length, Mech. Mach. Theory 70
(2013) 425-440.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from linkwork.synthesis.result import JoinedProfile, Segment, SynthesisResult
from linkwork.viz.labels import plain
from linkwork.viz.palette import PROFILE_COLORS

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

Array = NDArray[np.float64]

DPI = 100
"""Resolution of the PNG files (the figures are about 8 x 5 inches: PNGs of 30-120 kB)."""


# --------------------------------------------------------------------------------------------- helpers


def _colour(j: int) -> str:
    """Profile ``j``'s colour (:data:`linkwork.viz.palette.PROFILE_COLORS`, cycling)."""
    return PROFILE_COLORS[j % len(PROFILE_COLORS)]


def _name(result: SynthesisResult, j: int) -> str:
    return plain(result.targets[j].name) or f"profile {j + 1}"


def _segment_piece(result: SynthesisResult, e: int, j: int) -> Array:
    """The target points segment ``e`` spans on profile ``j``."""
    segment = result.segments[e]
    start = int(segment.starts[j])
    return result.targets[j].points[start : start + int(segment.pieces[j]) + 1]


def _extent(arrays: Sequence[Array]) -> tuple[float, float]:
    """Width and height of the bounding box of all points."""
    everything = np.vstack([np.asarray(a).reshape(-1, 2) for a in arrays])
    width, height = np.ptp(everything, axis=0)
    return float(width), float(height)


def length_unit(result: SynthesisResult) -> str:
    """The profiles' length unit for labels: the problem's ``units``, else "profile unit"."""
    return result.problem.units or "profile unit"


def _figure(
    panels: int, extent: tuple[float, float], *, width: float = 8.0, unit: str = "profile unit"
) -> tuple[Figure, list[Axes]]:
    """A figure of ``panels`` equal-aspect axes, stacked when the drawing is wide, side by side when tall, its
    axes labelled in ``unit``."""
    from matplotlib.figure import Figure

    aspect = extent[1] / extent[0] if extent[0] > 0 else 1.0
    aspect = min(max(aspect, 0.15), 2.0)
    wide = aspect < 0.8 or panels == 1
    rows, cols = (panels, 1) if wide else (1, panels)
    panel_width = width / cols
    height = min(8.0, max(2.2, rows * panel_width * aspect + 0.9 * rows + 0.4))
    figure = Figure(figsize=(width, height), dpi=DPI, layout="constrained")
    axes = figure.subplots(rows, cols, squeeze=False).ravel().tolist()
    for ax in axes:
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel(f"x ({unit})")
        ax.set_ylabel(f"y ({unit})")
        ax.grid(True, linewidth=0.3, alpha=0.5)
    return figure, axes


def _legend(ax: Axes, **kwargs: Any) -> None:
    """A small legend; beside the axes (outside the drawing) when the drawing is wide and flat."""
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    if (y1 - y0) < 0.45 * (x1 - x0):
        kwargs = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), **kwargs}
    ax.legend(fontsize="small", framealpha=0.85, **kwargs)


def _draw_chain(
    ax: Axes, chain: JoinedProfile, colour: str, label: str, *, merged: Sequence[int] = ()
) -> None:
    """The chain's points, its two ends as dots and its revolute joints as open circles (``merged`` joints,
    0-based, fused into compound segments, as small crosses)."""
    ax.plot(*chain.points.T, "-", color=colour, linewidth=1.8, label=label)
    ax.plot(*chain.joints[[0, -1]].T, ".", color="black", markersize=6, zorder=5)
    interior = chain.joints[1:-1]
    live = [i for i in range(len(interior)) if i not in merged]
    ax.plot(*interior[live].T, "o", markersize=5, markerfacecolor="white", markeredgecolor="black", zorder=5)
    if merged:
        ax.plot(*interior[list(merged)].T, "x", color="black", markersize=4, zorder=5)


def _segment_figure(
    result: SynthesisResult, index: int, kind: str, panels: int
) -> tuple[Segment, list[Array], Figure, Any]:
    """Segment ``index``, checked to be of ``kind`` (``ValueError`` if not), its piece of every target profile,
    and a figure of ``panels`` axes framed on the pieces and the segment's instances."""
    segment = result.segments[index]
    if segment.kind != kind:
        article = "an" if kind == "M" else "a"
        raise ValueError(
            f"Expected {article} {kind}-segment, segment {index + 1} is a {segment.kind}-segment"
        )
    pieces = [_segment_piece(result, index, j) for j in range(len(result.targets))]
    figure, axes = _figure(panels, _extent(pieces + list(segment.instances)), unit=length_unit(result))
    return segment, pieces, figure, axes


def _draw_fit(ax: Axes, piece: Array, instance: Array, j: int, piece_label: str | None, label: str) -> None:
    """Profile ``j``'s target points (dots) and the segment placed on them (a line)."""
    ax.plot(*piece.T, ".", color=_colour(j), markersize=3, label=piece_label)
    ax.plot(*instance.T, "-", color=_colour(j), linewidth=1.5, label=label)


def _titles_and_legends(axes: Any, *titles: str) -> None:
    """Each panel's title (one per axes, in order), then its legend."""
    for ax, title in zip(axes, titles, strict=True):
        ax.set_title(title, fontsize="medium")
        _legend(ax)


def _draw_targets(ax: Axes, result: SynthesisResult, *, label: bool = True) -> None:
    for j, target in enumerate(result.targets):
        ax.plot(
            *target.points.T,
            "--",
            color=_colour(j),
            linewidth=0.8,
            alpha=0.6,
            label=f"target {_name(result, j)}" if label else None,
        )


# ---------------------------------------------------------------------------------------------- figures


def plot_profiles(result: SynthesisResult) -> Figure:
    """Design profiles (solid), target profiles (dots) and segmentation points (black) (paper's Fig. 3)."""
    figure, (ax,) = _figure(1, _extent(result.problem.profiles), unit=length_unit(result))
    for j, (design, target) in enumerate(zip(result.problem.profiles, result.targets, strict=True)):
        ax.plot(
            *design.T,
            "-",
            color=_colour(j),
            linewidth=1.0,
            label=f"{_name(result, j)}: C = {target.arc_length:.4g}",
        )
        ax.plot(
            *target.points.T,
            ".",
            color=_colour(j),
            markersize=3,
            label=f"target: {target.pieces} pieces of {target.target_length:.4g}",
        )
    for e, segment in enumerate(result.segments):
        for j, target in enumerate(result.targets):
            ax.plot(
                *target.points[int(segment.starts[j])],
                "o",
                color="black",
                markersize=4,
                label="segmentation points" if e == 0 and j == 0 else None,
            )
    for target in result.targets:
        ax.plot(*target.points[-1], "o", color="black", markersize=4)
    figure.suptitle(
        f"Design and target profiles (desired piece length {result.problem.piece_length:g} {length_unit(result)})"
    )
    _legend(ax, ncols=2)
    return figure


def plot_mean_segment(result: SynthesisResult, index: int) -> Figure:
    """An M-segment's construction (paper's Fig. 6): (a) its piece on every profile, (b) registered onto
    profile 1, (c) the mean of corresponding points, (d) the mean moved back onto every profile.

    Raises
    ------
    ValueError
        If segment ``index`` is not an M-segment.
    """
    from linkwork.geometry.fit import register

    segment, pieces, figure, axes = _segment_figure(result, index, "M", 4)
    moved = [pieces[0]] + [register(piece, pieces[0]).apply(piece) for piece in pieces[1:]]
    mean = np.mean(moved, axis=0)
    panels = (
        "(a) pieces on the target profiles",
        "(b) registered onto profile 1",
        "(c) mean segment",
        "(d) mean moved back onto each profile",
    )
    for j, piece in enumerate(pieces):
        axes[0].plot(*piece.T, ".-", color=_colour(j), linewidth=1.0, markersize=3, label=_name(result, j))
        axes[1].plot(*moved[j].T, ".-", color=_colour(j), linewidth=1.0, markersize=3, label=_name(result, j))
        axes[2].plot(*moved[j].T, "-", color=_colour(j), linewidth=0.6, alpha=0.5)
        fitted = f"mean on {_name(result, j)}: E = {segment.errors[j]:.3g}"
        _draw_fit(axes[3], piece, segment.instances[j], j, f"{_name(result, j)} target", fitted)
    axes[2].plot(*mean.T, "k.-", linewidth=1.5, markersize=3, label="mean segment")
    _titles_and_legends(axes, *panels)
    figure.suptitle(f"M-segment {index + 1}: {int(segment.pieces[0])} pieces on every profile")
    return figure


def plot_arc_segment(result: SynthesisResult, index: int) -> Figure:
    """A C-segment (paper's Fig. 7): (a) its pieces on every profile, (b) arcs of one radius and different
    lengths placed on each.

    Raises
    ------
    ValueError
        If segment ``index`` is not a C-segment.
    """
    segment, pieces, figure, axes = _segment_figure(result, index, "C", 2)
    lengths = segment.lengths
    for j, piece in enumerate(pieces):
        axes[0].plot(
            *piece.T,
            ".-",
            color=_colour(j),
            linewidth=1.0,
            markersize=3,
            label=f"{_name(result, j)}: {int(segment.pieces[j])} pieces",
        )
        fitted = f"L = {lengths[j]:.3g}, E = {segment.errors[j]:.3g}"
        _draw_fit(axes[1], piece, segment.instances[j], j, None, fitted)
    radius = segment.radius
    shown = "straight (r = inf)" if radius is None or math.isinf(radius) else f"r = {radius:.4g}"
    _titles_and_legends(axes, "(a) pieces on the target profiles", f"(b) arcs of one radius, {shown}")
    figure.suptitle(f"C-segment {index + 1}: mean piece length {segment.piece_length:.4g}")
    return figure


def plot_chain(result: SynthesisResult) -> Figure:
    """The chain on every profile before and after joining (paper's Fig. 8): segments where each fits best,
    then moved to unite their end points at revolute joints."""
    figure, axes = _figure(2, _extent([t.points for t in result.targets]), unit=length_unit(result))
    _draw_targets(axes[0], result)
    _draw_targets(axes[1], result, label=False)
    for e, segment in enumerate(result.segments):
        for j, instance in enumerate(segment.instances):
            axes[0].plot(
                *instance.T,
                "-",
                color=_colour(j),
                linewidth=1.8,
                label=f"segments on {_name(result, j)}" if e == 0 else None,
            )
            axes[0].plot(*instance[[0, -1]].T, "|", color="black", markersize=7)
    for j, chain in enumerate(result.joined):
        _draw_chain(axes[1], chain, _colour(j), f"chain on {_name(result, j)}")
    unit = length_unit(result)
    _titles_and_legends(
        axes,
        f"(a) segments {result.design}, before joining: E_max = {result.e_max:.3g} {unit}",
        f"(b) joined by revolute joints (o): E_max = {result.joined_e_max:.3g} {unit}",
    )
    return figure


def plot_compound(result: SynthesisResult) -> Figure:
    """The joined chain and the chain after merging small-motion joints into compound segments (paper's
    Fig. 10), with each joint's range of motion (Eq. 34).

    A result without a compound stage (``merge_below = 0``) gets the joined chain alone, with the same ranges,
    which say which joints a ``merge_below`` would merge.
    """
    from linkwork.synthesis.compound import joint_angles, joint_ranges

    compound = result.compound
    unit = length_unit(result)
    panels = 1 if compound is None else 2
    figure, axes = _figure(panels, _extent([t.points for t in result.targets]), unit=unit)
    if compound is None:
        ranges = joint_ranges(joint_angles(result.joined, result.segment_matrix))
        stages: list[tuple[Any, tuple[int, ...]]] = [(result.joined, ())]
    else:
        ranges = compound.joint_ranges
        stages = [(result.joined, ()), (compound.profiles, compound.merged)]
    for ax, (chains, fused) in zip(axes, stages, strict=True):
        _draw_targets(ax, result, label=ax is axes[0])
        for j, chain in enumerate(chains):
            _draw_chain(ax, chain, _colour(j), f"chain on {_name(result, j)}", merged=fused)
    merged = () if compound is None else compound.merged
    # Label every joint with its range of motion (Eq. 34) next to its position on profile 1.
    for i, motion in enumerate(ranges):
        x, y = result.joined[0].joints[i + 1]
        is_merged = i in merged
        axes[0].annotate(
            f"{i + 1}: {math.degrees(motion):.1f}°",
            (x, y),
            xytext=(6, 6),
            textcoords="offset points",
            fontsize="small",
            color="black" if is_merged else "dimgray",
            weight="bold" if is_merged else "normal",
        )
    joined = f"(a) joined, joint ranges in degrees: E_max = {result.joined_e_max:.3g} {unit}"
    if compound is None:
        _titles_and_legends(axes, joined.removeprefix("(a) ") + " (no joints merged: merge_below = 0)")
        return figure
    merged_list = ", ".join(str(i + 1) for i in compound.merged) or "none"
    _titles_and_legends(
        axes,
        joined,
        f"(b) joints merged (< {math.degrees(compound.threshold):.3g}°): {merged_list}; "
        f"E_max = {compound.e_max:.3g} {unit}",
    )
    return figure


def plot_errors(result: SynthesisResult) -> Figure:
    """The error of every segment on every profile (Eq. 21: the largest point-to-point distance), after
    segmentation (pale, left) and after joining (solid, right), with E_max of the joined chain (Eq. 22) dashed."""
    from matplotlib.figure import Figure

    q, p = result.joined_error_matrix.shape
    figure = Figure(figsize=(8.0, 4.2), dpi=DPI, layout="constrained")
    ax = figure.subplots()
    width = 0.8 / p
    x = np.arange(q)
    for j in range(p):
        centre = x - 0.4 + (j + 0.5) * width
        ax.bar(centre - width / 4, result.error_matrix[:, j], width / 2, color=_colour(j), alpha=0.35)
        ax.bar(
            centre + width / 4,
            result.joined_error_matrix[:, j],
            width / 2,
            color=_colour(j),
            label=_name(result, j),
        )
    ax.axhline(result.joined_e_max, color="black", linestyle="--", linewidth=0.9)
    ax.set_xticks(x, [f"{e + 1} {kind}" for e, kind in enumerate(result.design)])
    ax.set_xlabel("segment (M: rigid, C: constant curvature)")
    ax.set_ylabel("error E (profile length units)")
    ax.set_title(
        f"segment errors, pale: segmented (E_max = {result.e_max:.3g}); "
        f"solid: joined (E_max = {result.joined_e_max:.3g}, dashed)",
        fontsize="medium",
    )
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize="small")
    return figure


# ----------------------------------------------------------------------------------------------- writer


def _save(figure: Figure, out_dir: Path, stem: str) -> list[Path]:
    import matplotlib

    paths = [out_dir / f"{stem}.png", out_dir / f"{stem}.svg"]
    # A fixed hash salt and no date make the SVG files reproducible byte for byte.
    with matplotlib.rc_context({"svg.hashsalt": "linkwork", "svg.fonttype": "none"}):
        figure.savefig(paths[0], dpi=DPI, metadata={"Software": None})
        figure.savefig(paths[1], metadata={"Date": None, "Creator": None})
    return paths


def write_synthesis_figures(result: SynthesisResult, out_dir: str | Path) -> list[Path]:
    """Write every synthesis figure as PNG and SVG into ``out_dir`` and return the paths written.

    Files: ``profiles`` (Fig. 3), ``m_segment`` (Fig. 6, the first M-segment, if any), ``c_segment`` (Fig. 7,
    the first C-segment, if any), ``chain`` (Fig. 8) and ``compound`` (Fig. 10, when joints were merged).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figures: list[tuple[str, Figure]] = [("profiles", plot_profiles(result))]
    kinds = [segment.kind for segment in result.segments]
    if "M" in kinds:
        figures.append(("m_segment", plot_mean_segment(result, kinds.index("M"))))
    if "C" in kinds:
        figures.append(("c_segment", plot_arc_segment(result, kinds.index("C"))))
    figures.append(("chain", plot_chain(result)))
    if result.compound is not None and result.compound.merged:
        figures.append(("compound", plot_compound(result)))
    written: list[Path] = []
    for stem, figure in figures:
        written += _save(figure, out, stem)
    return written
