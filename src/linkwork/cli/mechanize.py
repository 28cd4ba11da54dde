"""``linkwork mechanize DIR``: add binary links to a synthesised chain, verify by tracing, write the mechanism.

A thin layer over :func:`linkwork.mechanization.mechanize`. ``DIR`` is a ``linkwork synth`` output folder: its
``chain.json`` and the problem it came from (``DIR/problem/problem.toml``, which ``linkwork synth`` writes, or
``--problem``). The synthesis is run again from the problem (it is seeded, so it is the same) and checked
against ``chain.json`` before mechanizing. The problem file's mechanization keys are the defaults; the flags
override them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from linkwork.cli import mechanize_flags as mf
from linkwork.cli.common import check_range, friendly_errors, progress_bar
from linkwork.outputs.staging import check_output_folder, console, staged_output

MAX_DOF = 20
"""The most degrees of freedom ``--dof`` may ask for (each one more actuator and a search over more dyads)."""


@friendly_errors
@mf.with_mechanize_flags(after="out")
def mechanize(
    folder: Annotated[
        Path, typer.Argument(help="A `linkwork synth` output folder (chain.json).", show_default=False)
    ],
    problem: Annotated[
        Path | None, typer.Option(help="The problem file of the chain (default DIR/problem/problem.toml).")
    ] = None,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="Folder to write into (default: DIR).")
    ] = None,
    no_plots: Annotated[
        bool, typer.Option("--no-plots", help="Do not draw the figures and animation.")
    ] = False,
    html: Annotated[
        bool,
        typer.Option("--html", help="Also write mechanism.html: the mechanism over the target profiles."),
    ] = False,
    *,
    flags: dict[str, Any],
) -> None:
    """Add binary links (RR dyads, linear actuators) to a synthesised chain until it has DOF degrees of freedom,
    verify that it moves through every profile in order without circuit, branch or order defects, and write
    mechanism.toml (for `linkwork trace`), mechanization.json, figures and an animation."""
    from linkwork.outputs.mechanization import (
        mechanize_into,
        print_mechanization,
        resolve_options,
    )
    from linkwork.outputs.synthesis import rerun_synthesis, synthesis_problem

    check_output_folder(out or folder)
    if "dof" in flags:
        check_range("--dof", flags["dof"], 1, MAX_DOF, "a whole number of degrees of freedom")
    spec = synthesis_problem(folder, problem)
    options = resolve_options(spec, flags)  # a bad flag stops here, before the synthesis is run again
    result = rerun_synthesis(folder, spec)
    target = out or folder
    with (
        staged_output(target, part="mechanize") as stage,
        progress_bar("[bold]mechanizing[/]", None) as progress,
    ):
        found, written = mechanize_into(
            result, stage, options=options, plots=not no_plots, progress=progress, html=html
        )
    print_mechanization(found)
    console.print(f"wrote {len(written)} files to {target}/: " + ", ".join(p.name for p in written))
