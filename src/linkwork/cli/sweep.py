"""``linkwork sweep``: a parameter study of a linkage family or a synthesis problem, one row per grid point."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.text import Text

from linkwork.cli import options as opt
from linkwork.cli.common import check_workers, friendly_errors, progress_bar
from linkwork.cli.out_folder import file_label, out_help, run_folder
from linkwork.outputs.staging import console


@friendly_errors
def sweep(
    study_file: Annotated[
        Path, typer.Argument(help="The study file (TOML): a linkage or problem and a \\[grid] table.")
    ],
    scheduler: opt.Scheduler = None,
    workers: opt.Workers = None,
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help=out_help("sweep", "bennett-twists"), show_default=False),
    ] = None,
    no_plots: opt.NoPlots = False,
) -> None:
    """Run every grid point of a study: sweep.parquet, sweep.csv and plots in --out (default out/NAME-sweep/,
    NAME the study file's name)."""

    from linkwork.errors import RequestNotMetError
    from linkwork.outputs.sweep import print_sweep_summary, write_sweep_outputs
    from linkwork.studies.study_file import load_study
    from linkwork.studies.sweep import prepare_study, run_sweep

    check_workers(workers)
    study = prepare_study(load_study(study_file))
    if out is None:
        out = run_folder("sweep", file_label(study_file))
    total = len(study.points())
    console.print(Text(study.name, style="bold"), f"{study.kind} study of {total} grid point(s)", sep=": ")
    with progress_bar("grid points", total) as report:
        results = run_sweep(
            study,
            scheduler=scheduler,
            workers=workers,
            progress=report,
        )
    figures = write_sweep_outputs(study, results, out, plots=not no_plots)
    rows = [row for row, _ in results]
    print_sweep_summary(study, rows)
    console.print(f"wrote {', '.join(['sweep.parquet', 'sweep.csv', *[f.name for f in figures]])} to {out}/")
    failed = sum(1 for row in rows if row.get("error"))
    if failed == len(rows):
        raise RequestNotMetError(f"every grid point failed; the first said: {rows[0]['error']}")
