"""The files of a robustness study (robustness.json, samples.parquet, figures) and its printed summary."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from linkwork.io.writer import json_text
from linkwork.outputs.staging import console, have_matplotlib, staged_output
from linkwork.progress import Progress
from linkwork.studies.robustness import (
    RobustnessResult,
    RobustnessSetup,
    run_study,
)


def _num(x: float) -> float | None:
    return float(x) if math.isfinite(float(x)) else None


def _list(values: np.ndarray) -> list[float | None]:
    return [_num(v) for v in np.asarray(values, dtype=float)]


def _pct(values: np.ndarray, q: float) -> float | None:
    return _num(float(np.percentile(values, q))) if values.size else None


def robustness_dict(result: RobustnessResult, source: str = "") -> dict[str, Any]:
    """The content of robustness.json (lengths in the linkage's units, angles in degrees)."""
    setup = result.setup
    mech = setup.mech
    model = setup.model
    drive = setup.drive
    revolute = mech.joint_types[mech.index(drive)] == "R"
    drive_values = np.degrees(setup.drive_values) if revolute else setup.drive_values
    fo = result.first_order_max
    ratio = np.divide(result.misfit_max, fo, out=np.full_like(fo, np.nan), where=fo > 0)
    ratio = ratio[np.isfinite(ratio)]
    return {
        "linkage": mech.name,
        "source": source,
        "drive": drive,
        "samples": int(result.samples),
        "samples_asked": int(result.samples_asked or result.samples),
        "complete": result.complete,
        **({"stopped": result.stopped} if result.stopped else {}),
        "seed": setup.seed,
        "tolerances": {
            "hinge_position": model.position_tol,
            "hinge_direction_deg": float(np.degrees(model.direction_tol)),
            "distribution": model.distribution,
            "meaning": model.meaning,
            "fraction_beyond": model.fraction_beyond,
            "errors": "spatial" if model.spatial or not mech.moves_in_plane else "in-plane",
        },
        "scale": {
            "length": setup.scale.length,
            "centre": [float(x) for x in setup.scale.centre],
            "misfit": "|(L * rotation, translation of the centre)| of the least closure residual, in the "
            "linkage's length units",
        },
        "misfit_max": {
            "p50": _pct(result.misfit_max, 50),
            "p95": _pct(result.misfit_max, 95),
            "max": _num(result.misfit_max.max()) if result.samples else None,
        },
        "first_order": {
            "p50": _pct(fo, 50),
            "p95": _pct(fo, 95),
            "max": _num(fo.max()) if fo.size else None,
            "misfit_over_first_order_p50": _pct(ratio, 50),
        },
        "mobility_kept": float(np.mean(result.mobility_kept)) if result.samples else None,
        "mobility_tolerance": setup.keep_tol,
        "bands": {
            "drive" + ("_deg" if revolute else ""): _list(drive_values),
            "p5": _list(result.band(0.05)),
            "p50": _list(result.band(0.50)),
            "p95": _list(result.band(0.95)),
            "max": _list(result.drive_max),
            "first_order_p50": _list(result.band(0.50, first_order=True)),
            "first_order_p95": _list(result.band(0.95, first_order=True)),
            "ratio": _list(result.ratio_paper),
            "ratio_normalised": _list(setup.ratio_normalised),
        },
    }


def run_and_write_robustness(
    setup: RobustnessSetup,
    samples: int,
    ratio_paper: np.ndarray,
    out: Path,
    *,
    source: str = "",
    plots: bool = True,
    engine: dict[str, Any] | None = None,
    progress: Progress | None = None,
) -> tuple[RobustnessResult, list[Path]]:
    """Run the study with its samples streamed to ``samples.parquet``, then write ``robustness.json`` and (if
    matplotlib is there) the figures, all into ``out`` or nothing."""
    from linkwork.studies.parquet import SampleWriter

    mech = setup.mech
    drive = mech.index(setup.drive)
    figures: list[Path] = []
    with staged_output(out) as stage:
        with SampleWriter(stage / "samples.parquet", setup.drive_values, mech.joint_types[drive] == "R") as w:
            result = run_study(setup, samples, ratio_paper, sink=w.write, progress=progress, **(engine or {}))
        summary = robustness_dict(result, source)
        (stage / "robustness.json").write_text(json_text(summary), encoding="utf-8")
        if plots and result.samples > 0:
            if have_matplotlib():
                from linkwork.viz.robustness_plots import write_robustness_figures

                figures = write_robustness_figures(result, summary, stage)
            else:
                console.print("figures skipped: install the plotting extra, pip install 'linkwork[viz]'")
    return result, [Path(out) / f.name for f in figures]


def print_robustness_summary(summary: dict[str, Any]) -> None:
    """Print the headline numbers of a robustness study."""
    from rich.table import Table

    def fmt(x: float | None) -> str:
        return "-" if x is None else f"{x:.4g}"

    tol = summary["tolerances"]
    table = Table(title=f"{summary['linkage']}: {summary['samples']} imperfect samples", title_justify="left")
    table.add_column("largest misfit along the path")
    table.add_column("p50", justify="right")
    table.add_column("p95", justify="right")
    table.add_column("max", justify="right")
    for label, key in (("Monte Carlo", "misfit_max"), ("first order", "first_order")):
        row = summary[key]
        table.add_row(label, fmt(row["p50"]), fmt(row["p95"]), fmt(row["max"]))
    console.print(table)
    console.print(
        f"hinge tolerances {tol['hinge_position']:g} (position), {tol['hinge_direction_deg']:g} deg (direction), "
        f"{tol['distribution']}, {tol['errors']} errors; misfit in length units, L = {summary['scale']['length']:.4g}"
    )
    console.print(f"mobility kept by {100.0 * (summary['mobility_kept'] or 0.0):.1f} % of the samples")
    b = summary["bands"]
    key = "drive_deg" if "drive_deg" in b else "drive"
    unit = " deg" if key == "drive_deg" else ""
    median = np.array([np.nan if v is None else v for v in b["p50"]], dtype=float)
    ratio = np.array([np.nan if v is None else v for v in b["ratio"]], dtype=float)
    if np.any(np.isfinite(median)) and np.nanmax(median) > 0:
        k = int(np.nanargmax(median))
        console.print(
            f"median misfit largest at {summary['drive']} = {b[key][k]:.5g}{unit} (point {k}): {median[k]:.4g}"
        )
    if np.any(np.isfinite(ratio)):
        k = int(np.nanargmax(ratio))
        normalised = np.array(
            [np.nan if v is None else v for v in b.get("ratio_normalised", [])], dtype=float
        )
        # The paper's ratio is the raw Jacobian's: it grows with the distance from the file's origin and with the
        # unit; the normalised one (moments about the hinge centre, lengths in L) does not.
        own = (
            f"; normalised (moments about the hinge centre, lengths in L) {np.nanmax(normalised):.4g}"
            if normalised.size and np.any(np.isfinite(normalised))
            else ""
        )
        console.print(
            f"Sec. 5 ratio largest at {summary['drive']} = {b[key][k]:.5g}{unit} (point {k}): {ratio[k]:.4g}{own}"
        )
