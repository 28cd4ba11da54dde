"""The figure of a deployment: the largest membrane stretch and the size of the attachment points along the
deployment path (``stretch.png``). matplotlib is imported inside the functions."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from linkwork.viz.labels import plain

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from linkwork.kinematics.deployment import Deployment
    from linkwork.kinematics.trace_result import Trace


def stretch_figure(trace: Trace, deployment: Deployment | None = None) -> Figure:
    """Left: the largest stretch over every pair of attachment points (percent) against the step along the
    deployment path, its maximum marked; right: the size (largest pair distance) over the deployed size, the
    bundle ratio marked. Located bifurcation points are dashed lines."""
    from matplotlib.figure import Figure

    dep = trace.deployment() if deployment is None else deployment
    steps = trace.step[dep.path]
    fig = Figure(figsize=(10.0, 4.2), layout="constrained")
    axes = fig.subplots(1, 2)
    axes[0].plot(steps, 100.0 * dep.stretch_along, lw=1.3)
    k = int(np.flatnonzero(dep.path == dep.stretch_row)[0])
    pair = "-".join(plain(name) for name in dep.stretch_pair)
    axes[0].plot(
        [steps[k]],
        [100.0 * dep.stretch_along[k]],
        "o",
        label=f"max {100 * dep.membrane_stretch:.3g}% ({pair})",
    )
    axes[0].set_ylabel("largest stretch over the pairs of points (%)")
    size = dep.size_along / dep.deployed_size if dep.deployed_size > 0 else dep.size_along
    axes[1].plot(steps, size, lw=1.3)
    b = int(np.flatnonzero(dep.path == dep.bundle_row)[0])
    axes[1].plot([steps[b]], [size[b]], "o", label=f"bundle ratio {dep.bundle_ratio:.3g}")
    axes[1].set_ylabel("size / deployed size (ratio)")
    for ax in axes:
        ax.set_xlabel("step along branch 0 (count)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        for bif in trace.bifurcations:
            if bif.branch == 0 and bif.step <= steps[-1] and bif.kind != "fold":
                ax.axvline(bif.step, color="k", lw=0.8, ls="--")
    fig.suptitle(
        f"{plain(trace.mechanism.name)}: membrane stretch and size along the deployment", fontsize=10
    )
    return fig


def plot_stretch(trace: Trace, file: Path, deployment: Deployment | None = None) -> Path:
    """Write :func:`stretch_figure` to ``file`` (PNG) and next to it as SVG; returns ``file``."""
    fig = stretch_figure(trace, deployment)
    fig.savefig(file, dpi=120)
    fig.savefig(Path(file).with_suffix(".svg"))
    return Path(file)
