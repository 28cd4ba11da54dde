"""``linkwork mechanize DIR``: add binary links to a synthesised chain, verify by tracing, write the mechanism.

A thin layer over :func:`linkwork.mechanization.mechanize`. ``DIR`` is a ``linkwork synth`` output folder: its
``chain.json`` and the problem it came from (``DIR/problem/problem.toml``, which ``linkwork synth`` writes, or
``--problem``). The synthesis is run again from the problem (it is seeded, so it is the same) and checked
against ``chain.json`` before mechanizing. The problem file's mechanization keys are the defaults; the flags
override them.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from linkwork.cli import mechanize_flags as mf
from linkwork.cli.common import check_range, fail, friendly_errors, progress_bar
from linkwork.interrupts import exit_code, held_signals
from linkwork.outputs.staging import check_output_folder, console, staged_output

if TYPE_CHECKING:
    from linkwork.mechanization import MechanizeOptions
    from linkwork.synthesis.result import SynthesisResult

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
    mechanism.toml (for `linkwork trace`), mechanization.json, figures and an animation.

    Exit codes: 0 done; 2 bad input; 3 no design passes (the closest is named); 130 / 143 interrupted by Ctrl-C /
    SIGTERM during the search: the best design that passed so far is written (mechanization.json says
    "complete": false and why it "stopped"), or nothing when none had passed; a second signal stops at once,
    writing nothing.
    """
    from linkwork.outputs.mechanization import resolve_options
    from linkwork.outputs.synthesis import rerun_synthesis, synthesis_problem

    check_output_folder(out or folder)
    if "dof" in flags:
        check_range("--dof", flags["dof"], 1, MAX_DOF, "a whole number of degrees of freedom")
    spec = synthesis_problem(folder, problem)
    options = resolve_options(spec, flags)  # a bad flag stops here, before the synthesis is run again
    result = rerun_synthesis(folder, spec)
    mechanize_and_write(result, out or folder, options, plots=not no_plots, html=html)


def mechanize_and_write(
    result: SynthesisResult, target: Path, options: MechanizeOptions, *, plots: bool, html: bool
) -> None:
    """Mechanize ``result``, write the mechanization into ``target`` (its part ``mechanize``, all or nothing) and
    print it: the step ``linkwork mechanize`` and ``linkwork synth --mechanize`` share.

    While the search runs, the first SIGINT or SIGTERM is held (:func:`linkwork.interrupts.held_signals`): the
    search stops after the design it is tracing, the best design passed so far is written as a whole
    (mechanization.json ``"complete": false``, ``"stopped"``), and the command ends with one line saying so and
    exit code 130 / 143; when none had passed, nothing is written (one line, 130 / 143).
    """
    from linkwork.mechanization import mechanize
    from linkwork.mechanization.search import MechanizationError
    from linkwork.outputs.mechanization import print_mechanization, write_mechanization_outputs

    with held_signals() as hold, progress_bar("[bold]mechanizing[/]", None) as progress:
        try:
            found = mechanize(result, options, progress=progress)
        except MechanizationError:
            if not hold.signum:
                raise
            raise fail(
                f"{hold.stopped}: no design had passed verification yet; nothing of the mechanization is written "
                f"to {target}/",
                code=exit_code(hold.signum),
            ) from None
    with staged_output(target, part="mechanize") as stage:
        written = write_mechanization_outputs(found, stage, plots=plots, html=html)
    print_mechanization(found)
    console.print(f"wrote {len(written)} files to {target}/: " + ", ".join(p.name for p in written))
    if hold.signum:
        what = (
            f"the best of the {len(found.ranked)} design(s) that passed verification so far ({found.attempts} "
            f'traced) is written to {target}/ (mechanization.json says "complete": false)'
            if found.stopped
            else f"the search had ended; its design is written to {target}/"
        )
        raise fail(f"{hold.stopped}: {what}", code=exit_code(hold.signum))
