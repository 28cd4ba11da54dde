"""``linkwork mechanize DIR``: add binary links to a synthesised chain, verify by tracing, write the mechanism.

A thin layer over :func:`linkwork.mechanization.mechanize`. ``DIR`` is a ``linkwork synth`` output folder: its
``chain.json`` and the problem it came from (``DIR/problem/problem.toml``, which ``linkwork synth`` writes, or
``--problem``). The synthesis is run again from the problem (it is seeded, so it is the same) and checked
against ``chain.json`` before mechanizing. The problem file's mechanization keys are the defaults; the flags
override them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from linkwork.cli import mechanize_flags as mf
from linkwork.cli.common import check_range, friendly_errors
from linkwork.outputs.staging import check_output_folder, console, staged_output

MAX_DOF = 20
"""The most degrees of freedom ``--dof`` may ask for (each one more actuator and a search over more dyads)."""


@friendly_errors
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
    dof: mf.Dof = None,
    drive: mf.Drive = None,
    root: mf.Root = None,
    anchors: mf.Anchors = None,
    actuator: mf.Actuator = None,
    binary_links: mf.BinaryLinks = None,
    ground_region: mf.GroundRegion = None,
    link_offset: mf.LinkOffset = None,
    max_link: mf.MaxLink = None,
    min_transmission: mf.MinTransmission = None,
    attempts: mf.Attempts = None,
    designs: mf.Designs = None,
    time_limit: mf.TimeLimit = None,
    no_plots: Annotated[
        bool, typer.Option("--no-plots", help="Do not draw the figures and animation.")
    ] = False,
    html: Annotated[
        bool,
        typer.Option("--html", help="Also write mechanism.html: the mechanism over the target profiles."),
    ] = False,
) -> None:
    """Add binary links (RR dyads, linear actuators) to a synthesised chain until it has DOF degrees of freedom,
    verify that it moves through every profile in order without circuit, branch or order defects, and write
    mechanism.toml (for `linkwork trace`), mechanization.json, figures and an animation."""
    from linkwork.outputs.mechanization import (
        mechanize_into,
        print_mechanization,
        progress_bar,
        resolve_options,
    )
    from linkwork.outputs.synthesis import load_synthesis

    flags = mf.flag_values(
        dof=dof,
        drive=drive,
        root=root,
        anchors=anchors,
        actuator=actuator,
        binary_links=binary_links,
        ground_region=ground_region,
        link_offset=link_offset,
        max_link=max_link,
        min_transmission=min_transmission,
        attempts=attempts,
        designs=designs,
        time_limit=time_limit,
    )
    check_output_folder(out or folder)
    if dof is not None:
        check_range("--dof", dof, 1, MAX_DOF, "a whole number of degrees of freedom")
    result = load_synthesis(folder, problem)
    options = resolve_options(result.problem, flags)
    target = out or folder
    with staged_output(target) as stage, progress_bar() as progress:
        found, written = mechanize_into(
            result, stage, options=options, plots=not no_plots, progress=progress, html=html
        )
    print_mechanization(found)
    console.print(f"wrote {len(written)} files to {target}/: " + ", ".join(p.name for p in written))
