"""Figures of a parameter study: each result against each parameter (one line per parameter), and a heat map
when the grid has exactly two parameters. matplotlib is imported inside the functions."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from linkwork.viz.labels import plain

if TYPE_CHECKING:  # a type only: viz sits below studies
    from linkwork.studies.study_file import Study

#: Results plotted, when present, with their axis labels.
METRICS = {
    "ratio_max": "largest Sec. 5 ratio along the path",
    "bifurcations": "bifurcations found",
    "mobility": "mobility at the start",
    "misfit_p50": "median largest misfit",
    "mobility_kept": "fraction keeping mobility",
    "e_max": "e_max (largest shape error)",
    "e_mean": "e_mean",
}


#: The unit of each result, for its axis label.
METRIC_UNITS = {
    "ratio_max": "-",
    "bifurcations": "count",
    "mobility": "degrees of freedom",
    "misfit_p50": "length unit",
    "mobility_kept": "-",
    "e_max": "profile unit",
    "e_mean": "profile unit",
}

#: The unit of a synthesis study's grid settings (problem keys).
SETTING_UNITS = {
    "piece_length": "profile unit",
    "merge_below": "deg",
    "segments": "count",
    "min_pieces": "count",
    "starts": "count",
}

#: Built-in parameter units (``Param.unit``) as axis units.
PARAM_UNITS = {"deg": "deg", "length": "length unit", "int": "count"}


def metric_label(metric: str) -> str:
    """A result's axis label with its unit, e.g. ``bifurcations found (count)``."""
    return f"{METRICS[metric]} ({METRIC_UNITS.get(metric, '-')})"


def parameter_label(study: Study, name: str) -> str:
    """A grid parameter's axis label with its unit: a built-in's parameter unit (degrees for angles, as in the
    study file), a synthesis setting's, or ``-``."""
    unit = None
    if study.kind == "linkage":
        from linkwork.linkages import REGISTRY

        entry = REGISTRY.get(str(study.target).replace("_", "-").lower())
        param = entry.params.get(name) if entry is not None else None
        unit = PARAM_UNITS.get(param.unit) if param is not None else None
    else:
        unit = SETTING_UNITS.get(name)
    return f"{plain(name)} ({unit or '-'})"


def _numeric(rows: list[dict[str, Any]], key: str) -> np.ndarray:
    out = []
    for row in rows:
        v = row.get(key)
        out.append(float(v) if isinstance(v, int | float) and not isinstance(v, bool) else np.nan)
    return np.array(out)


def plot_lines(study: Study, rows: list[dict[str, Any]], metric: str, file: Path) -> Path:
    """``metric`` against every numeric parameter (one panel each); other parameters as separate lines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    params = [p for p in study.grid if np.isfinite(_numeric(rows, p)).all()]
    fig, axes = plt.subplots(
        1, len(params), figsize=(4.5 * len(params), 3.8), layout="constrained", squeeze=False
    )
    y = _numeric(rows, metric)
    for ax, p in zip(axes[0], params, strict=True):
        x = _numeric(rows, p)
        others = [q for q in study.grid if q != p]
        keys = [tuple(row.get(q) for q in others) for row in rows]
        for key in dict.fromkeys(keys):
            mask = np.array([k == key for k in keys])
            order = np.argsort(x[mask])
            label = ", ".join(
                f"{plain(q)}={v:g}" if isinstance(v, int | float) else f"{plain(q)}={plain(str(v))}"
                for q, v in zip(others, key, strict=True)
            )
            ax.plot(x[mask][order], y[mask][order], "o-", ms=3, label=label or None)
        ax.set_xlabel(parameter_label(study, p))
        ax.set_ylabel(metric_label(metric))
        if others and len(set(keys)) <= 8:
            ax.legend(fontsize=7)
    fig.suptitle(f"{plain(study.name)}: {METRICS[metric]}", fontsize=10)
    fig.savefig(file, dpi=110)
    plt.close(fig)
    return file


def plot_heatmap(study: Study, rows: list[dict[str, Any]], metric: str, file: Path) -> Path:
    """``metric`` over a two-parameter grid as a heat map (grid values as ticks)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    p, q = list(study.grid)
    xs, ys = study.grid[q], study.grid[p]
    Z = _numeric(rows, metric).reshape(len(ys), len(xs))
    fig, ax = plt.subplots(figsize=(6.5, 5.0), layout="constrained")
    im = ax.imshow(Z, origin="lower", aspect="auto", cmap="viridis")
    ax.set_xticks(range(len(xs)), [f"{v:g}" if isinstance(v, int | float) else str(v) for v in xs])
    ax.set_yticks(range(len(ys)), [f"{v:g}" if isinstance(v, int | float) else str(v) for v in ys])
    ax.set_xlabel(parameter_label(study, q))
    ax.set_ylabel(parameter_label(study, p))
    fig.colorbar(im, ax=ax, label=metric_label(metric))
    ax.set_title(f"{plain(study.name)}: {METRICS[metric]}", fontsize=10)
    fig.savefig(file, dpi=110)
    plt.close(fig)
    return file


def write_sweep_figures(study: Study, rows: list[dict[str, Any]], folder: Path) -> list[Path]:
    """``sweep_<metric>.png`` line plots, and ``heatmap_<metric>.png`` for a two-parameter grid."""
    figures: list[Path] = []
    if not study.grid:
        return figures
    numeric_params = [p for p in study.grid if np.isfinite(_numeric(rows, p)).all()]
    for metric in METRICS:
        values = _numeric(rows, metric)
        finite = values[np.isfinite(values)]
        if finite.size == 0 or (len(rows) > 1 and np.all(finite == finite[0])):
            continue  # nothing to see: absent, or the same at every grid point
        if numeric_params:
            figures.append(plot_lines(study, rows, metric, Path(folder) / f"sweep_{metric}.png"))
        if len(study.grid) == 2 and len(rows) == np.prod([len(v) for v in study.grid.values()]):
            figures.append(plot_heatmap(study, rows, metric, Path(folder) / f"heatmap_{metric}.png"))
    return figures
