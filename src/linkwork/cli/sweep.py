"""``linkwork sweep``: a parameter study of a linkage family or a synthesis problem, one row per grid point."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.text import Text

from linkwork.cli import options as opt
from linkwork.cli.common import check_workers, fail, friendly_errors, progress_bar
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
    NAME the study file's name).

    Every key of the study file is checked before any point runs. A point that fails keeps its row with the
    reason in `error`. Interrupted (Ctrl-C, SIGTERM: exit 130, 143) or with its Dask cluster lost (exit 3), the
    rows computed so far are written and the others say `not run: ...` in `error`."""

    from linkwork.errors import RequestNotMetError
    from linkwork.outputs.sweep import print_sweep_summary, write_sweep_outputs
    from linkwork.studies.engine import RunStatus, scheduler_address
    from linkwork.studies.sweep import read_study, run_sweep

    check_workers(workers)
    scheduler_address(scheduler)  # a malformed address is bad input, found before any work
    study = read_study(study_file)
    if out is None:
        out = run_folder("sweep", file_label(study_file))
    total = study.count()
    console.print(Text(study.name, style="bold"), f"{study.kind} study of {total} grid point(s)", sep=": ")
    status = RunStatus()
    with progress_bar("grid points", total) as report:
        results = run_sweep(study, scheduler=scheduler, workers=workers, progress=report, status=status)
    computed = len(results)
    if not status.complete:
        reason = f"not run: {status.stopped}"
        results += [({**study.point(i), "error": reason}, None) for i in range(computed, total)]
    figures = write_sweep_outputs(study, results, out, plots=not no_plots)
    rows = [row for row, _ in results]
    print_sweep_summary(study, rows)
    console.print(f"wrote {', '.join(['sweep.parquet', 'sweep.csv', *[f.name for f in figures]])} to {out}/")
    if not status.complete:
        raise fail(
            f"{status.stopped}; {computed} of {total} grid point(s) computed and written, the others are marked "
            "'not run' in sweep.csv",
            code=status.code,
        )
    failed = sum(1 for row in rows if row.get("error"))
    if failed == len(rows):
        raise RequestNotMetError(f"every grid point failed; the first said: {rows[0]['error']}")
