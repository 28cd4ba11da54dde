"""Figures of a traced path: hinge angles against the drive angle (like the paper's Figs. 9, 10, 12) and the
Jacobian's singular values along the path (like Fig. 15). matplotlib is imported inside the functions, and only
its object-oriented API is used: :func:`angles_figure` and :func:`singular_values_figure` return a
``matplotlib.figure.Figure`` (what ``Trace.plot()`` shows in a notebook), :func:`plot_angles` and
:func:`plot_singular_values` write it as PNG and SVG."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from linkwork.kinematics.trace_result import Trace
from linkwork.viz.labels import plain

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def _unwrap_branch(path: Trace, mask: np.ndarray) -> np.ndarray:
    return np.degrees(path.angles[mask])


def _save(fig: Figure, file: Path) -> Path:
    fig.savefig(file, dpi=120)
    fig.savefig(Path(file).with_suffix(".svg"))
    return Path(file)


def plot_angles(path: Trace, file: Path) -> Path:
    """Write :func:`angles_figure` to ``file`` (PNG) and next to it as SVG; returns ``file``."""
    return _save(angles_figure(path), file)


def angles_figure(path: Trace) -> Figure:
    """Every hinge angle against the drive angle, one colour per joint, one line style per branch."""
    import matplotlib
    from matplotlib.figure import Figure

    mech = path.mechanism
    d = mech.index(path.drive)
    fig = Figure(figsize=(7.5, 5.0), layout="constrained")
    ax = fig.subplots()
    colors = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]
    styles = ["-", "--", ":", "-."]
    for br in path.branches:
        mask = path.of_branch(br.id)
        deg = _unwrap_branch(path, mask)
        for j, name in enumerate(mech.joint_names):
            if j == d:
                continue
            # One line style per joint, so that coincident curves (B = D = F) stay visible as dashes.
            ax.plot(
                deg[:, d],
                deg[:, j],
                styles[j % len(styles)],
                color=colors[j % len(colors)],
                lw=2.2 - 0.3 * (j % len(styles)) if br.id == 0 else 0.8,
                alpha=1.0 if br.id == 0 else 0.45,
                label=f"θ{plain(name)}" if br.id == 0 else None,
            )
    for b in path.bifurcations:
        a = np.degrees(b.angles)
        ax.plot(np.full(len(a) - 1, a[d]), np.delete(a, d), "ko", ms=4)
    ax.set_xlabel(f"θ{plain(str(path.drive))} (deg)")
    ax.set_ylabel("hinge angle (deg)")
    title = f"{plain(mech.name)}: hinge angles"
    if len(path.branches) > 1:
        title += f" ({len(path.branches)} branches, {len(path.bifurcations)} bifurcation points ●)"
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(ncol=2, fontsize=8)
    return fig


def plot_singular_values(path: Trace, file: Path, branch: int = 0) -> Path:
    """Write :func:`singular_values_figure` to ``file`` (PNG) and next to it as SVG; returns ``file``."""
    return _save(singular_values_figure(path, branch), file)


def singular_values_figure(path: Trace, branch: int = 0) -> Figure:
    """Singular values of the Jacobian along one branch against the drive angle (log scale), like Fig. 15."""
    from matplotlib.figure import Figure

    mech = path.mechanism
    d = mech.index(path.drive)
    mask = path.of_branch(branch)
    x = np.degrees(path.angles[mask, d])
    s = path.sigma[mask]
    fig = Figure(figsize=(10.0, 4.2), layout="constrained")
    axes = fig.subplots(1, 2)
    steps = path.step[mask]
    rank = int(path.stats.get("start_rank", s.shape[1]))
    # Left: the non-zero singular values on a linear scale against the step (as the paper's Fig. 15);
    # right: all of them on a log scale, the null ones at round-off.
    for i in range(min(rank, s.shape[1])):
        axes[0].plot(steps, s[:, i], lw=1.3, label=f"σ{i + 1}")
    axes[0].set_xlabel("step")
    axes[0].set_ylim(0, None)
    for i in range(s.shape[1]):
        axes[1].semilogy(steps, np.maximum(s[:, i], 1e-17), lw=1.3, label=f"σ{i + 1}")
    axes[1].set_xlabel(f"step (θ{plain(str(path.drive))} from {x[0]:.4g}° to {x[-1]:.4g}°)")
    axes[1].set_ylim(1e-17, None)
    for ax in axes:
        ax.set_ylabel("singular value")
        ax.grid(alpha=0.3, which="both")
    for b in path.bifurcations:
        if b.branch == branch:
            axes[0].axvline(b.step, color="k", lw=0.8, ls="--")
            axes[1].axvline(b.step, color="k", lw=0.8, ls="--")
    axes[1].legend(fontsize=8, ncol=2)
    fig.suptitle(f"{plain(mech.name)}: singular values of the Jacobian along branch {branch}", fontsize=10)
    return fig


def write_trace_figures(path: Trace, out: Path) -> list[Path]:
    """All trace figures into folder ``out``; returns the PNG paths."""
    out = Path(out)
    return [plot_angles(path, out / "angles.png"), plot_singular_values(path, out / "singular_values.png")]
