"""The files of a parameter study: sweep.parquet and sweep.csv (one row per grid point), its plots, and with
robustness figures one folder per grid point."""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any

from linkwork.io.writer import json_text
from linkwork.names import COLUMN_PREFIX, csv_cell
from linkwork.outputs.staging import console, have_matplotlib, staged_output
from linkwork.studies.study_file import Study


def columns_of(rows: list[dict[str, Any]], study: Study) -> list[str]:
    """Column order: the grid parameters, then every other key in first-seen order, ``error`` last."""
    seen: list[str] = []
    for row in rows:
        for key in row:
            if key not in seen and key not in study.grid and key != "error":
                seen.append(key)

    def group(key: str) -> int:
        if key in ("mobility", "points"):
            return 0
        if key.endswith(("_min", "_max")) and key not in ("ratio_max", "first_order_max"):
            return 1
        return 2

    return [*study.grid, *sorted(seen, key=lambda k: (group(k), seen.index(k))), "error"]


def _value(value: Any) -> Any:
    """A cell as written: a computed number that is not finite (undefined at that grid point) is missing (an
    empty CSV cell, a Parquet null), never ``nan`` or ``inf``."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_table(rows: list[dict[str, Any]], cols: list[str], parquet: Path, csv_file: Path) -> None:
    """One row per grid point in both formats; missing values are empty (CSV) or null (Parquet)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    data = {c: [_value(row.get(c)) for row in rows] for c in cols}
    arrays = {}
    for c, values in data.items():
        try:
            arrays[c] = pa.array(values)
        except (pa.ArrowInvalid, pa.ArrowTypeError):
            arrays[c] = pa.array([None if v is None else str(v) for v in values])
    pq.write_table(pa.table(arrays), parquet)
    with csv_file.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(cols)
        for row in rows:
            writer.writerow(["" if _value(row.get(c)) is None else csv_cell(row.get(c)) for c in cols])


def write_sweep_outputs(
    study: Study, results: list[tuple[dict[str, Any], Any]], out: Path, plots: bool = True
) -> list[Path]:
    """Write sweep.parquet, sweep.csv, the plots and per-point robustness figures into ``out``, all or nothing.
    Returns the figures written."""
    rows = [row for row, _ in results]
    cols = columns_of(rows, study)
    figures: list[Path] = []
    with staged_output(out) as stage:
        write_table(rows, cols, stage / "sweep.parquet", stage / "sweep.csv")
        if plots and have_matplotlib():
            from linkwork.viz.sweep_plots import write_sweep_figures

            figures = write_sweep_figures(study, rows, stage)
            for i, (_, res) in enumerate(results):
                if res is None:
                    continue
                from linkwork.outputs.robustness import robustness_dict
                from linkwork.viz.robustness_plots import write_robustness_figures

                folder = stage / "points" / f"{i:04d}"
                folder.mkdir(parents=True)
                summary = robustness_dict(res, study.target)
                summary["parameters"] = {k: rows[i].get(k) for k in study.grid}
                (folder / "robustness.json").write_text(json_text(summary), encoding="utf-8")
                write_robustness_figures(res, summary, folder)
        elif plots:
            console.print("figures skipped: install the plotting extra, pip install 'linkwork[viz]'")
    return [Path(out) / f.name for f in figures]


def print_sweep_summary(study: Study, rows: list[dict[str, Any]]) -> None:
    """Print the study's table (at most 30 rows)."""
    from rich.table import Table

    cols = columns_of(rows, study)
    keep = [c for c in cols if c in study.grid or c in _HEADLINE]
    table = Table(title=f"{study.name}: {len(rows)} grid point(s)", title_justify="left")
    for c in keep:
        table.add_column(c, justify="right" if c != "error" else "left")
    for row in rows[:30]:
        table.add_row(*[_fmt(row.get(c)) for c in keep])
    console.print(table)
    if len(rows) > 30:
        console.print(f"... {len(rows) - 30} more rows in sweep.csv")
    prefixed = sorted({c[: -len("_min")] for c in cols if c.startswith(COLUMN_PREFIX) and c.endswith("_min")})
    if prefixed:
        console.print(
            "names changed for the file formats: sweep.csv: joints whose columns would clash with fixed ones are "
            "written " + ", ".join(f"{c}_min, {c}_max" for c in prefixed)
        )


_HEADLINE = (
    "mobility",
    "bifurcations",
    "ratio_max",
    "misfit_p50",
    "mobility_kept",
    "design",
    "e_max",
    "error",
)


def _fmt(value: Any) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)
