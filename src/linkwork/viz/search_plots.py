"""The figure of a deployable-structure search (``candidates.png``): every traced candidate's membrane stretch
against its bundle ratio, the passing ones marked, with the criteria's limits. matplotlib is imported inside the
functions."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from linkwork.viz.labels import plain

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def _column(rows: list[dict[str, Any]], key: str) -> np.ndarray:
    """A numeric column of the candidates' rows, NaN where a candidate has no value (it failed to trace)."""
    values = [row.get(key) for row in rows]
    return np.array([np.nan if v is None or v == "" else float(v) for v in values], dtype=float)


def candidates_figure(
    name: str,
    rows: list[dict[str, Any]],
    max_membrane_stretch: float | None = None,
    max_bundle_ratio: float | None = None,
) -> Figure:
    """Membrane stretch (percent) against bundle ratio of every candidate that traced: passing candidates in
    colour, the others grey, the criteria's limits as dashed lines (when the study sets them)."""
    from matplotlib.figure import Figure

    stretch = 100.0 * _column(rows, "membrane_stretch")
    bundle = _column(rows, "bundle_ratio")
    passes = np.array([row.get("passes") in (True, "True", "true") for row in rows], dtype=bool)
    traced = np.isfinite(stretch) & np.isfinite(bundle)
    fig = Figure(figsize=(6.4, 4.8), layout="constrained")
    ax = fig.subplots()
    failing = traced & ~passes
    ax.plot(bundle[failing], stretch[failing], "o", ms=4, color="0.65", label=f"fails ({int(failing.sum())})")
    ok = traced & passes
    ax.plot(bundle[ok], stretch[ok], "o", ms=5, color="tab:blue", label=f"passes ({int(ok.sum())})")
    if max_bundle_ratio is not None:
        ax.axvline(max_bundle_ratio, color="tab:red", lw=0.9, ls="--", label="criteria limits")
    if max_membrane_stretch is not None:
        ax.axhline(
            100.0 * max_membrane_stretch,
            color="tab:red",
            lw=0.9,
            ls="--",
            label=None if max_bundle_ratio is not None else "criteria limits",
        )
    ax.set_xlabel("bundle ratio: folded size / deployed size (ratio)")
    ax.set_ylabel("largest membrane stretch (%)")
    ax.grid(alpha=0.3)
    untraced = int((~traced).sum())
    note = f"; {untraced} did not trace" if untraced else ""
    ax.set_title(f"{plain(name)}: {len(rows)} candidates{note}", fontsize=10)
    # Below the axes, never over the points.
    fig.legend(fontsize=8, loc="outside lower center", ncol=3)
    return fig


def plot_candidates(
    name: str,
    rows: list[dict[str, Any]],
    file: Path,
    max_membrane_stretch: float | None = None,
    max_bundle_ratio: float | None = None,
) -> Path:
    """Write :func:`candidates_figure` to ``file`` (PNG); returns ``file``."""
    fig = candidates_figure(name, rows, max_membrane_stretch, max_bundle_ratio)
    fig.savefig(file, dpi=120)
    return file
