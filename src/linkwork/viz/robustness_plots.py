"""Figures of a robustness study: the misfit band along the path with its first-order prediction and the Sec. 5
singular-value ratio, and the histogram of every sample's largest misfit. matplotlib is imported inside."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from linkwork.viz.labels import plain, plain_log_ticks

if TYPE_CHECKING:  # a type only: viz sits below studies
    from linkwork.studies.robustness import RobustnessResult


def _positive(values: list[float | None]) -> np.ndarray:
    a = np.array([np.nan if v is None else v for v in values], dtype=float)
    return np.where(a > 0, a, np.nan)


#: A misfit below this many of the linkage's length L is round-off (the corrector's closure tolerance is 1e-12):
#: the bands draw it on this floor, so that noise of a structure that keeps its mobility is not drawn as decades
#: of spikes on the log axis.
ROUNDOFF = 1e-12


def _misfit(values: list[float | None], floor: float) -> np.ndarray:
    """A misfit band with round-off drawn on ``floor``; zero (the start, where the imperfect structure is
    assembled) and missing values stay gaps."""
    a = np.array([np.nan if v is None else v for v in values], dtype=float)
    return np.where(a > 0, np.maximum(a, floor), np.nan)


def plot_bands(summary: dict[str, Any], file: Path) -> Path:
    """Misfit percentiles (5-95 % band, median, largest) against the drive, the first-order median and 95 %
    curves, and on a second axis the paper's ratio of largest to smallest non-zero singular value."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    b = summary["bands"]
    key = "drive_deg" if "drive_deg" in b else "drive"
    drive = np.array(b[key], dtype=float)
    steps = np.diff(drive)
    monotonic = bool(np.all(steps > 0) or np.all(steps < 0))
    # A path on which the drive turns back (a closed path, a fold) is drawn against the point number instead.
    x = drive if monotonic else np.arange(drive.size, dtype=float)
    fig, ax = plt.subplots(figsize=(8.0, 5.0), layout="constrained")
    floor = ROUNDOFF * float(summary["scale"]["length"])
    ax.fill_between(
        x, _misfit(b["p5"], floor), _misfit(b["p95"], floor), color="tab:blue", alpha=0.25, label="5-95 %"
    )
    ax.plot(x, _misfit(b["p50"], floor), color="tab:blue", label="median (Monte Carlo)")
    ax.plot(x, _misfit(b["max"], floor), ":", color="tab:blue", label="largest sample")
    ax.plot(x, _misfit(b["first_order_p50"], floor), "--", color="tab:orange", label="median (first order)")
    ax.plot(x, _misfit(b["first_order_p95"], floor), "-.", color="tab:orange", label="95 % (first order)")
    largest = _misfit(b["max"], floor)
    if np.any(np.isfinite(largest)):
        top = float(np.nanmax(largest))
        ax.set_yscale("log")
        # The start (where the imperfect structure is assembled) has no misfit: show five decades below the top,
        # down to the round-off floor at most.
        bottom = max(10.0 ** (np.floor(np.log10(top)) - 4.0), 0.5 * floor)
        ax.set_ylim(bottom=bottom, top=max(top * 2.0, 10.0 * floor))
    unit = "deg" if key == "drive_deg" else "length unit"
    if monotonic:
        ax.set_xlabel(f"drive {plain(str(summary['drive']))} ({unit})")
    else:
        ax.set_xlabel(
            f"point along the nominal path (count), drive {plain(str(summary['drive']))} between {drive.min():.4g} and "
            f"{drive.max():.4g} {unit}"
        )
    ax.set_ylabel(f"closure misfit (length units, L = {summary['scale']['length']:.3g})")
    ratio = _positive(b["ratio"])
    twin = ax.twinx()
    twin.plot(x, ratio, color="tab:gray", lw=1.0, label="Sec. 5 ratio (paper)")
    twin.plot(
        x, _positive(b["ratio_normalised"]), color="tab:green", lw=1.0, label="ratio (normalised Jacobian)"
    )
    if np.any(np.isfinite(ratio)):
        twin.set_yscale("log")
        plain_log_ticks(twin.yaxis)
    if ax.get_yscale() == "log":
        plain_log_ticks(ax.yaxis)
    twin.set_ylabel("largest / smallest non-zero singular value (-)")
    lines = ax.get_legend_handles_labels()
    more = twin.get_legend_handles_labels()
    # Below the axes, never over the curves.
    fig.legend(lines[0] + more[0], lines[1] + more[1], fontsize=8, loc="outside lower center", ncol=4)
    tol = summary["tolerances"]
    ax.set_title(
        f"{plain(str(summary['linkage']))}: {summary['samples']} samples, hinges within {tol['hinge_position']:g} and "
        f"{tol['hinge_direction_deg']:g} deg ({tol['distribution']}, {tol['errors']})",
        fontsize=10,
    )
    fig.savefig(file, dpi=120)
    plt.close(fig)
    return file


def plot_histogram(result: RobustnessResult, summary: dict[str, Any], file: Path) -> Path:
    """Histogram of every sample's largest misfit along the path, with the first-order predictions."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 4.5), layout="constrained")
    mc = result.misfit_max
    fo = result.first_order_max
    both = np.concatenate([mc, fo])
    both = both[both > 0]
    if both.size and both.max() > both.min() * 1.0001:
        from matplotlib.ticker import NullFormatter

        edges = np.geomspace(both.min(), both.max(), 50)
        ax.set_xscale("log")
        plain_log_ticks(ax.xaxis)
        if both.max() > 100.0 * both.min():  # two decades or more: the decades alone are labelled
            ax.xaxis.set_minor_formatter(NullFormatter())
    else:
        edges = np.linspace(
            float(mc.min()) if mc.size else 0.0, float(mc.max()) + 1e-300 if mc.size else 1.0, 50
        )
    ax.hist(mc, bins=list(edges), alpha=0.6, label="Monte Carlo")
    ax.hist(fo, bins=list(edges), histtype="step", lw=1.5, label="first order")
    ax.set_xlabel("largest misfit along the path (length units)")
    ax.set_ylabel("samples (count)")
    kept = summary["mobility_kept"]
    ax.set_title(
        f"{plain(str(summary['linkage']))}: mobility kept by {100.0 * (kept or 0.0):.1f} % of samples",
        fontsize=10,
    )
    ax.legend(fontsize=8)
    fig.savefig(file, dpi=120)
    plt.close(fig)
    return file


def write_robustness_figures(result: RobustnessResult, summary: dict[str, Any], folder: Path) -> list[Path]:
    """``misfit_bands.png`` and ``misfit_histogram.png`` in ``folder``."""
    return [
        plot_bands(summary, Path(folder) / "misfit_bands.png"),
        plot_histogram(result, summary, Path(folder) / "misfit_histogram.png"),
    ]
