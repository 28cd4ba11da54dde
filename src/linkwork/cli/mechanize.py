"""``linkwork mechanize DIR``: add binary links to a synthesised chain, verify by tracing, write the mechanism.

A thin layer over :func:`linkwork.mechanization.mechanize`. ``DIR`` is a ``linkwork synth`` output folder: its
``chain.json`` and the problem it came from (``DIR/problem/problem.toml``, as ``linkwork demo`` writes it, or
``--problem``). The synthesis is run again from the problem (it is seeded, so it is the same) and checked
against ``chain.json`` before mechanizing. :func:`mechanize_into` is what ``linkwork synth`` calls for a problem
with ``mechanize = true``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from linkwork.cli.common import check_range, friendly_errors
from linkwork.errors import SpecError
from linkwork.io.toml_reader import show
from linkwork.outputs.staging import check_output_folder, console, staged_output


def _region(text: str | None) -> tuple[float, float, float, float] | None:
    if text is None:
        return None
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if (
        len(values) != 4
        or not all(math.isfinite(v) for v in values)
        or values[0] >= values[2]
        or values[1] >= values[3]
    ):
        raise SpecError(
            f"--ground-region {show(text)}: expected XMIN,YMIN,XMAX,YMAX (finite numbers) with XMIN < XMAX and "
            "YMIN < YMAX"
        )
    return values


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
    dof: Annotated[int, typer.Option(help="Degrees of freedom (number of actuators).")] = 1,
    drive: Annotated[str | None, typer.Option(help="The driven joint (default: chosen).")] = None,
    root: Annotated[
        str | None, typer.Option(help="The chain body guided first (default: tried in turn).")
    ] = None,
    anchors: Annotated[
        str, typer.Option(help="Dyads to 'ground', between links too ('any'), or 'auto'.")
    ] = "auto",
    actuator: Annotated[
        str, typer.Option(help="'revolute' (a crank) or 'prismatic' (a linear actuator).")
    ] = "revolute",
    ground_region: Annotated[
        str | None, typer.Option(help="Fixed pivots only in XMIN,YMIN,XMAX,YMAX (profile units).")
    ] = None,
    min_transmission: Annotated[float, typer.Option(help="Smallest transmission angle (degrees).")] = 15.0,
    no_plots: Annotated[
        bool, typer.Option("--no-plots", help="Do not draw the figures and animation.")
    ] = False,
) -> None:
    """Add binary links (RR dyads, a linear actuator) to a synthesised chain until it has DOF degrees of freedom,
    verify that it moves through every profile in order without circuit, branch or order defects, and write
    mechanism.toml (for `linkwork trace`), mechanization.json, figures and an animation."""
    from linkwork.mechanization import MechanizeOptions

    check_output_folder(out or folder)
    check_range("--dof", dof, 1, 20, "a whole number of degrees of freedom")
    check_range("--min-transmission", min_transmission, 0.0, 90.0, "an angle in degrees", open_low=False)
    options = MechanizeOptions(
        dof=dof,
        drive=drive,
        root=root,
        anchors=anchors,
        actuator=actuator,
        ground_region=_region(ground_region),
        min_transmission=math.radians(min_transmission),
    )
    from linkwork.outputs.mechanization import mechanize_into, print_mechanization
    from linkwork.outputs.synthesis import load_synthesis

    result = load_synthesis(folder, problem)
    target = out or folder
    with staged_output(target) as stage:
        found, written = mechanize_into(result, stage, options=options, plots=not no_plots)
    print_mechanization(found)
    console.print(f"wrote {len(written)} files to {target}/: " + ", ".join(p.name for p in written))
