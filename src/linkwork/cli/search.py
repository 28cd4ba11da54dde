"""``linkwork search``: screen a linkage family for deployable structures (membrane, bundle, flatness, mobility)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.text import Text

from linkwork.cli import options as opt
from linkwork.cli.common import check_range, check_workers, fail, friendly_errors, progress_bar
from linkwork.cli.out_folder import file_label, out_help, run_folder
from linkwork.outputs.staging import check_output_folder, console

MAX_GALLERY = 500
"""The most candidates drawn in gallery.html (each gets a viewer page)."""


@friendly_errors
def search(
    study_file: Annotated[
        Path,
        typer.Argument(
            help="The study file (TOML): a linkage, \\[trace], a \\[grid] and the \\[criteria] to meet."
        ),
    ],
    scheduler: opt.Scheduler = None,
    workers: opt.Workers = None,
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help=out_help("search", "rect-frame-search"), show_default=False),
    ] = None,
    gallery: Annotated[
        int,
        typer.Option(help="How many of the best candidates gallery.html draws (each with a viewer page)."),
    ] = 12,
) -> None:
    """Trace every candidate of a study and judge it: candidates.csv/.parquet, ranked.csv, gallery.html in --out
    (default out/NAME-search/, NAME the study file's name).

    The default --out is out/NAME-search/, NAME the study file's name. Re-running on the same --out continues an interrupted search (its records are in --out/.linkwork-search/).

    Exit codes: 0 some candidate passes; 2 bad input; 3 none passes (the closest is printed, outputs written);
    130 / 143 interrupted by Ctrl-C / SIGTERM (or 3, its Dask cluster lost): the candidates evaluated so far are
    written (candidates.csv, ranked.csv, search.json saying "complete": false; no gallery), and the same command
    continues the search; a second signal stops at once.
    """
    from linkwork.errors import RequestNotMetError
    from linkwork.outputs.search import (
        OUTPUT_NAMES,
        SearchRecords,
        print_search_summary,
        write_search_outputs,
    )
    from linkwork.studies.engine import RunStatus
    from linkwork.studies.search import closest, load_search, run_search

    check_workers(workers)
    check_range("--gallery", gallery, 0, MAX_GALLERY, "a number of candidates")
    search_study = load_search(study_file)
    if out is None:
        out = run_folder("search", file_label(study_file))
    check_output_folder(out, OUTPUT_NAMES)
    total = search_study.total
    console.print(Text(search_study.study.name, style="bold"), f"search of {total} candidate(s)", sep=": ")
    with SearchRecords(out, search_study) as records:
        if records.restarted:
            console.print("the study changed since the records in --out were written: starting afresh")
        elif records.rows:
            console.print(f"resuming: {len(records.rows)} of {total} candidate(s) already done")
        # SIGINT / SIGTERM are held while the candidates run (the engine's hold): the run ends after the batches
        # in hand, whose rows are recorded whole, and what was evaluated is written below
        status = RunStatus()
        with progress_bar("candidates", total) as report:
            report(len(records.rows), total)
            for rows in run_search(
                search_study,
                skip=set(records.rows),
                scheduler=scheduler,
                workers=workers,
                progress=report,
                status=status,
            ):
                records.add(rows)
        rows = list(records.rows.values())
    stopped = None if status.complete else status.stopped
    summary = write_search_outputs(search_study, rows, out, gallery=gallery, stopped=stopped)
    print_search_summary(search_study, rows)
    written = [n for n in OUTPUT_NAMES if stopped is None or n not in ("gallery.html", "viewers")]
    console.print(f"wrote {', '.join(written)} to {out}/")
    if stopped is not None:
        raise fail(
            f"{stopped}: {len(rows)} of {total} candidate(s) evaluated are written to {out}/ (search.json says "
            '"complete": false; no gallery); run the same command again to continue',
            code=status.code,
        )
    if summary["passing"] == 0:
        near = closest(rows)
        if near is None:
            raise RequestNotMetError("the study has no candidates")
        params = ", ".join(f"{k}={near[k]}" for k in search_study.study.grid) or "the only candidate"
        raise RequestNotMetError(
            f"no candidate meets the criteria; the closest is {params}: {near['reason']}"
        )
