"""``linkwork synth``: synthesise a shape-changing chain from a problem file, write files, print a summary.

A thin layer over :func:`linkwork.io.problem.load_problem` and :func:`linkwork.synthesis.synthesize`. The
command writes into a staging folder and moves the files into ``--out`` only when all of them were written, so
a failure never leaves half an output. :func:`run_synthesis_example` runs a bundled example for
``linkwork demo``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from linkwork.cli import mechanize_flags as mf
from linkwork.cli.common import check_word, fail, friendly_errors, progress_bar
from linkwork.cli.out_folder import out_help, problem_label, run_folder
from linkwork.errors import RequestNotMetError
from linkwork.interrupts import exit_code, held_signals
from linkwork.outputs.staging import check_output_folder, console, have_matplotlib, staged_output


@friendly_errors
@mf.with_mechanize_flags(after="mechanize")
def synth(
    problem: Annotated[
        Path,
        typer.Argument(
            help="Problem file (TOML): type, profiles, piece_length, min_pieces, design, starts, merge_below "
            "(degrees), seed; or a bundled example by name (wing, closed, fixed-end, seat). See docs/synthesis.md.",
            show_default=False,
        ),
    ],
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help=out_help("synth", "wing"), show_default=False)
    ] = None,
    no_plots: Annotated[bool, typer.Option("--no-plots", help="Do not draw the figures.")] = False,
    html: Annotated[bool, typer.Option("--html", help="Also write an interactive HTML viewer.")] = False,
    search: Annotated[
        str,
        typer.Option(
            help="'paper': the adjustment rules of Sec. 4; 'refined': then move segmentation points one piece "
            "at a time while the error matrix improves (never worse than 'paper').",
        ),
    ] = "paper",
    mechanize: Annotated[
        bool | None,
        typer.Option(
            "--mechanize/--no-mechanize",
            rich_help_panel=mf.PANEL,
            help="Also mechanize the chain (default: the problem's `mechanize` key, or any mechanization flag).",
        ),
    ] = None,
    exhaustive: Annotated[
        bool,
        typer.Option(
            "--exhaustive",
            help="Join every design vector of design = 'auto' (no pruning by the lower bound on E_max; the "
            "chosen design is the same, only slower).",
        ),
    ] = False,
    *,
    flags: dict[str, Any],
) -> None:
    """Synthesise a chain of rigid segments, revolute and prismatic joints, that approximates every profile.

    Writes chain.json, target_profiles.csv, outline.svg, outline.dxf and the figures (PNG and SVG) into --out
    (default out/NAME-synth/, NAME the bundled example's or the problem file's name), and prints a summary: the profiles, the design vector, the segment and error matrices, E_max and E_mean
    before and after joining, and the joints merged into compound segments. A copy of the problem and its
    profiles goes to --out/problem/ (for `linkwork mechanize OUT`). With mechanization (the problem's
    `mechanize = true`, --mechanize or any mechanization flag) the chain's files are written first; if no
    mechanism passes they stay and the command exits with code 3 naming the closest design.

    Ctrl-C or SIGTERM (exit 130 / 143) during the design search stops it after the design vector in hand: the
    best chain joined so far is written (chain.json says "complete": false and why it "stopped") and not
    mechanized; during the mechanization, the chain stays and the best mechanism that passed so far is written
    (mechanization.json says "complete": false), or none when none had passed. A second signal stops at once,
    writing nothing more.
    """
    from linkwork.io.problem import load_problem
    from linkwork.outputs.problem_copy import copy_problem
    from linkwork.outputs.synthesis import print_synthesis_summary, write_synthesis_outputs
    from linkwork.synthesis import synthesize

    if out is None:
        out = run_folder("synth", problem_label(problem))
    check_output_folder(out, ["chain.json", "target_profiles.csv", "outline.svg", "outline.dxf"])
    check_word("--search", search, ("paper", "refined"))
    from linkwork.data import problem_file

    problem = problem_file(problem)
    spec = load_problem(problem)
    from linkwork.outputs.mechanization import resolve_options

    options = resolve_options(spec, flags)  # a bad flag or key stops here, before the synthesis
    mechanizing = (spec.mechanize or bool(flags)) if mechanize is None else mechanize
    if mechanizing:  # a drive or root no chain can have: refused before anything is synthesised
        from linkwork.mechanization.mechanize import check_name_forms

        check_name_forms(options)
    with held_signals() as hold, progress_bar("[bold]synthesising[/]", None) as progress:
        try:
            result = synthesize(spec, progress=progress, search=search, prune=not exhaustive)  # type: ignore[arg-type]
        except RequestNotMetError:
            if not hold.signum:
                raise
            raise fail(
                f"{hold.stopped}: no design vector had been joined yet; nothing is written to {out}/",
                code=exit_code(hold.signum),
            ) from None

    plots = not no_plots
    if plots and not have_matplotlib():
        console.print("note: matplotlib is not installed (pip install 'linkwork[viz]'): no figures drawn")
        plots = False
    with staged_output(out) as stage:
        written = write_synthesis_outputs(result, stage, plots=plots)
        written += copy_problem(problem, stage / "problem")
        if html:
            from linkwork.viz.viewer import write_synthesis_viewer

            written.append(write_synthesis_viewer(result, stage / "viewer.html"))
    print_synthesis_summary(result)
    console.print(f"wrote {len(written)} files to {out}/: " + ", ".join(path.name for path in written))
    if hold.signum:
        stats = result.stats
        what = (
            f"the best chain found so far (design {result.design}, joined E_max {result.joined_e_max:.4g}; "
            f"{stats.designs_tried} of {stats.designs_tried + stats.not_searched} design vectors searched) is "
            f'written to {out}/ (chain.json says "complete": false)'
            if stats.stopped
            else f"the search had ended; its chain is written to {out}/"
        )
        raise fail(
            f"{hold.stopped}: {what}" + ("; not mechanized" if mechanizing else ""),
            code=exit_code(hold.signum),
        )
    if mechanizing:
        # the chain is on disk already: a mechanization that fails (exit 3) loses nothing of it
        from linkwork.cli.mechanize import mechanize_and_write

        mechanize_and_write(result, out, options, plots=plots, html=html)
