"""Figures of a traced path: hinge angles against the drive angle (like the paper's Figs. 9, 10, 12) and the
Jacobian's singular values along the path (like Fig. 15). matplotlib is imported inside the functions, and only
its object-oriented API is used: :func:`angles_figure` and :func:`singular_values_figure` return a
``matplotlib.figure.Figure`` (what ``Trace.plot()`` shows in a notebook), :func:`plot_angles` and
:func:`plot_singular_values` write it as PNG and SVG."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from linkwork.deprecation import trace_keyword
from linkwork.kinematics.trace_result import Trace
from linkwork.viz.labels import plain, plain_log_ticks

if TYPE_CHECKING:
    from matplotlib.figure import Figure


@trace_keyword
def branch_degrees(trace: Trace, mask: np.ndarray) -> np.ndarray:
    """Joint values of the points ``mask`` for plotting: revolute joints in degrees wrapped into [-180, 180)
    (:func:`linkwork.geometry.angles.wrap`), prismatic joints as they are. Guest's 7 branches, which turn
    hinges through whole revolutions, stay in one window."""
    return display_degrees(trace, trace.angles[mask])


@trace_keyword
def display_degrees(trace: Trace, values: np.ndarray) -> np.ndarray:
    """``values`` (radians, ``(..., n)``) with the revolute joints wrapped into [-180, 180) deg."""
    from linkwork.geometry.angles import wrap

    out = np.array(values, dtype=float)
    revolute = np.array([t == "R" for t in trace.mechanism.joint_types])
    out[..., revolute] = np.degrees(wrap(out[..., revolute]))
    return out


def broken_at_wraps(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``x``, ``y`` with a NaN put between points where either jumps by more than 180 (a wrap), so the plotted
    line breaks there instead of crossing the figure."""
    if len(x) < 2:
        return x, y
    jumps = np.flatnonzero((np.abs(np.diff(x)) > 180.0) | (np.abs(np.diff(y)) > 180.0)) + 1
    return np.insert(x.astype(float), jumps, np.nan), np.insert(y.astype(float), jumps, np.nan)


def _save(fig: Figure, file: Path) -> Path:
    fig.savefig(file, dpi=120)
    fig.savefig(Path(file).with_suffix(".svg"))
    return Path(file)


@trace_keyword
def plot_angles(trace: Trace, file: Path) -> Path:
    """Write :func:`angles_figure` to ``file`` (PNG) and next to it as SVG; returns ``file``."""
    return _save(angles_figure(trace), file)


@trace_keyword
def angles_figure(trace: Trace) -> Figure:
    """Every hinge angle against the drive angle, one colour per joint, one line style per branch."""
    import matplotlib
    from matplotlib.figure import Figure

    mech = trace.mechanism
    d = mech.index(trace.drive)
    fig = Figure(figsize=(7.5, 5.0), layout="constrained")
    ax = fig.subplots()
    colors = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]
    styles = ["-", "--", ":", "-."]
    for br in trace.branches:
        deg = branch_degrees(trace, trace.of_branch(br.id))
        for j, name in enumerate(mech.joint_names):
            if j == d:
                continue
            # One line style per joint, so that coincident curves (B = D = F) stay visible as dashes.
            ax.plot(
                *broken_at_wraps(deg[:, d], deg[:, j]),
                styles[j % len(styles)],
                color=colors[j % len(colors)],
                lw=2.2 - 0.3 * (j % len(styles)) if br.id == 0 else 0.8,
                alpha=1.0 if br.id == 0 else 0.45,
                label=f"θ{plain(name)}" if br.id == 0 else None,
            )
    for b in trace.bifurcations:
        a = display_degrees(trace, b.angles)
        ax.plot(np.full(len(a) - 1, a[d]), np.delete(a, d), "ko", ms=4)
    ax.set_xlabel(f"θ{plain(str(trace.drive))} (deg, wrapped to [-180, 180))")
    ax.set_ylabel("hinge angle (deg, wrapped to [-180, 180))")
    title = f"{plain(mech.name)}: hinge angles"
    if len(trace.branches) > 1:
        title += f" ({len(trace.branches)} branches, {len(trace.bifurcations)} bifurcation points ●)"
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(ncol=2, fontsize=8)
    return fig


@trace_keyword
def plot_singular_values(trace: Trace, file: Path, branch: int = 0) -> Path:
    """Write :func:`singular_values_figure` to ``file`` (PNG) and next to it as SVG; returns ``file``."""
    return _save(singular_values_figure(trace, branch), file)


ROUND_OFF = 1e-12
"""A singular value below this times the largest at the same point is zero (round-off of the SVD)."""

ZERO_FLOOR = 1e-16
"""Where the log panel of :func:`singular_values_figure` draws a zero singular value."""


@trace_keyword
def singular_values_figure(trace: Trace, branch: int = 0) -> Figure:
    """Singular values of the Jacobian along one branch against the step (linear, like Fig. 15, and log scale,
    where a zero singular value, one at round-off, is drawn at :data:`ZERO_FLOOR`)."""
    from matplotlib.figure import Figure

    from linkwork.viz.labels import number

    mech = trace.mechanism
    d = mech.index(trace.drive)
    mask = trace.of_branch(branch)
    x = branch_degrees(trace, mask)[:, d]
    s = trace.sigma[mask]
    fig = Figure(figsize=(10.0, 4.2), layout="constrained")
    axes = fig.subplots(1, 2)
    steps = trace.step[mask]
    rank = int(trace.stats.start_rank or s.shape[1])
    # Left: the non-zero singular values on a linear scale against the step (as the paper's Fig. 15);
    # right: all of them on a log scale, the null ones at round-off.
    for i in range(min(rank, s.shape[1])):
        axes[0].plot(steps, s[:, i], lw=1.3, label=f"σ{i + 1}")
    axes[0].set_xlabel(f"step along branch {branch} (count)")
    axes[0].set_ylim(0, None)
    # A singular value at round-off (below ROUND_OFF * sigma_1) is a zero: drawn on the floor, not as the noise
    # of the SVD, which reads on a log scale as spikes of several decades.
    zero = s < ROUND_OFF * s[:, :1]
    shown = np.where(zero, ZERO_FLOOR, np.maximum(s, ZERO_FLOOR))
    for i in range(s.shape[1]):
        axes[1].semilogy(steps, shown[:, i], lw=1.3, label=f"σ{i + 1}")
    unit = "°" if mech.joint_types[d] == "R" else ""
    span = float(np.ptp(x)) if len(x) else 1.0
    low, high = (number(v, scale=max(span, 1.0)) for v in (x[0], x[-1]))
    axes[1].set_xlabel(f"step (count), θ{plain(str(trace.drive))} from {low}{unit} to {high}{unit}")
    axes[1].set_ylim(ZERO_FLOOR / 10.0, None)
    plain_log_ticks(axes[1].yaxis)
    for ax in axes:
        ax.set_ylabel("singular value (1 and length per rad)")
        ax.grid(alpha=0.3, which="both")
    for b in trace.bifurcations:
        if b.branch == branch:
            axes[0].axvline(b.step, color="k", lw=0.8, ls="--")
            axes[1].axvline(b.step, color="k", lw=0.8, ls="--")
    axes[1].legend(fontsize=8, ncol=2)
    fig.suptitle(f"{plain(mech.name)}: singular values of the Jacobian along branch {branch}", fontsize=10)
    return fig


@trace_keyword
def plot_points(trace: Trace, file: Path) -> Path:
    """Paths of the named points (a four-bar's coupler curve) and of the joints in the plane, and the transmission
    angle against the drive angle when the mechanism declares one."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from linkwork.kinematics.points import named_points, positions, transmission_angles

    mech = trace.mechanism
    joints, named = positions(mech, trace.angles)
    mu = transmission_angles(mech, joints)
    fig, axes = plt.subplots(
        1, 2 if mu is not None else 1, figsize=(10.0, 4.4), layout="constrained", squeeze=False
    )
    ax = axes[0, 0]
    for j, name in enumerate(mech.joint_names):
        ax.plot(joints[:, j, 0], joints[:, j, 1], lw=0.8, color="0.6")
        ax.annotate(plain(name), joints[0, j, :2], fontsize=8)
    for k, point in enumerate(named_points(mech)):
        ax.plot(named[:, k, 0], named[:, k, 1], lw=1.6, label=plain(f"{point['name']} (on {point['body']})"))
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (length unit of the mechanism)")
    ax.set_ylabel("y (length unit of the mechanism)")
    ax.set_title("paths of the joints (grey) and named points", fontsize=10)
    if named.shape[1]:
        ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    if mu is not None:
        d = mech.index(trace.drive)
        for br in trace.branches:
            mask = trace.of_branch(br.id)
            axes[0, 1].plot(np.degrees(trace.angles[mask, d]), np.degrees(mu[mask]), lw=1.4)
        axes[0, 1].axhline(40.0, color="k", lw=0.8, ls="--", label="40 deg, a common lower limit")
        axes[0, 1].set_xlabel(f"θ{plain(str(trace.drive))} (deg)")
        axes[0, 1].set_ylabel("transmission angle (deg)")
        axes[0, 1].set_title("transmission angle", fontsize=10)
        axes[0, 1].legend(fontsize=8)
        axes[0, 1].grid(alpha=0.3)
    fig.suptitle(f"{plain(mech.name)}: positions", fontsize=10)
    fig.savefig(file, dpi=120)
    fig.savefig(Path(file).with_suffix(".svg"))
    plt.close(fig)
    return Path(file)


@trace_keyword
def write_trace_figures(trace: Trace, out: Path) -> list[Path]:
    """All trace figures into folder ``out``; returns the PNG paths (``points.png`` for a planar mechanism or one
    with named points)."""
    out = Path(out)
    figures = [
        plot_angles(trace, out / "angles.png"),
        plot_singular_values(trace, out / "singular_values.png"),
    ]
    if trace.mechanism.moves_in_xy or trace.mechanism.meta.get("points"):
        figures.append(plot_points(trace, out / "points.png"))
    return figures
