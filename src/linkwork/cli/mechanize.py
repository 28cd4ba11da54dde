"""``linkwork mechanize DIR``: add binary links to a synthesised chain, verify by tracing, write the mechanism.

A thin layer over :func:`linkwork.mechanization.mechanize`. ``DIR`` is a ``linkwork synth`` output folder: its
``chain.json`` and the problem it came from (``DIR/problem/problem.toml``, as ``linkwork demo`` writes it, or
``--problem``). The synthesis is run again from the problem (it is seeded, so it is the same) and checked
against ``chain.json`` before mechanizing. :func:`mechanize_into` is what ``linkwork synth`` calls for a problem
with ``mechanize = true``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from linkwork.cli.common import console, friendly_errors, have_matplotlib, staged_output
from linkwork.errors import SpecError

if TYPE_CHECKING:
    from linkwork.mechanization import Mechanization, MechanizeOptions
    from linkwork.synthesis.result import SynthesisResult


def mechanize_into(
    result: SynthesisResult,
    out_dir: Path,
    *,
    options: MechanizeOptions | None = None,
    plots: bool = True,
) -> tuple[Mechanization, list[Path]]:
    """Mechanize ``result`` and write ``mechanism.toml``, ``mechanization.json`` and the figures into ``out_dir``.

    Raises
    ------
    MechanizationError
        When no design passes (one line: why).
    """
    from linkwork.mechanization import mechanize, write_mechanization

    found = mechanize(result, options)
    out_dir = Path(out_dir)
    written = write_mechanization(found, out_dir)
    if plots and have_matplotlib():
        from linkwork.viz.mechanism_plots import write_mechanism_figures

        written += write_mechanism_figures(found, out_dir)
    return found, written


def _region(text: str | None) -> tuple[float, float, float, float] | None:
    if text is None:
        return None
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 4 or values[0] >= values[2] or values[1] >= values[3]:
        raise SpecError(
            f"--ground-region {text!r}: expected XMIN,YMIN,XMAX,YMAX with XMIN < XMAX and YMIN < YMAX"
        )
    return values


def load_synthesis(folder: Path, problem: Path | None = None) -> SynthesisResult:
    """The synthesis result of a ``linkwork synth`` output folder, checked against its ``chain.json``.

    Raises
    ------
    SpecError
        When ``chain.json`` or the problem file is missing, or the problem no longer gives the same chain.
    """
    from linkwork.io.problem import load_problem
    from linkwork.synthesis import synthesize

    chain_file = folder / "chain.json"
    if not chain_file.is_file():
        raise SpecError(f"{folder}: no chain.json; expected a `linkwork synth` output folder")
    problem = problem or folder / "problem" / "problem.toml"
    if not problem.is_file():
        raise SpecError(
            f"{folder}: no problem file at {problem}; pass the problem the chain came from with --problem"
        )
    saved = json.loads(chain_file.read_text(encoding="utf-8"))
    result = synthesize(load_problem(problem))
    same = saved.get("design") == result.design and math.isclose(
        float(saved.get("joined", {}).get("e_max", math.nan)),
        result.joined_e_max,
        rel_tol=1e-9,
        abs_tol=1e-12,
    )
    if not same:
        raise SpecError(
            f"{chain_file}: the chain (design {saved.get('design')}) is not what {problem} gives now "
            f"(design {result.design}); run `linkwork synth` again"
        )
    return result


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

    options = MechanizeOptions(
        dof=dof,
        drive=drive,
        root=root,
        anchors=anchors,
        actuator=actuator,
        ground_region=_region(ground_region),
        min_transmission=math.radians(min_transmission),
    )
    result = load_synthesis(folder, problem)
    target = out or folder
    with staged_output(target) as stage:
        found, written = mechanize_into(result, stage, options=options, plots=not no_plots)
    print_mechanization(found)
    console.print(f"wrote {len(written)} files to {target}/: " + ", ".join(p.name for p in written))


def print_mechanization(found: Mechanization) -> None:
    """Print the links, DOF, drive and the state on every profile."""
    from rich.table import Table

    design, check = found.design, found.verification
    links = Table(title="Binary links", title_justify="left", title_style="bold")
    for column in (
        "link",
        "type",
        "anchor",
        "body",
        "fixed pivot",
        "moving pivot",
        "length",
        "transmission (deg)",
    ):
        links.add_column(column)
    for link in design.links:
        links.add_row(
            link.name,
            link.kind,
            link.anchor,
            link.body,
            f"({link.centre[0]:.4g}, {link.centre[1]:.4g})",
            f"({link.circle[0]:.4g}, {link.circle[1]:.4g})",
            f"{link.length:.4g}",
            f"{math.degrees(link.transmission):.1f}",
        )
    console.print(links)
    mech = design.mechanism()
    revolute = mech.joint_types[mech.index(design.drive)] == "R"
    states = Table(title=f"DOF {check.dof}, drive {design.drive}", title_justify="left", title_style="bold")
    for column in ("profile", "drive value" + (" (deg)" if revolute else ""), "E_max", "E_max joined"):
        states.add_column(column, justify="right")
    for j, state in enumerate(check.states):
        value = math.degrees(state.drive_value) if revolute else state.drive_value
        states.add_row(
            str(j + 1), f"{value:.6f}", f"{state.e_max:.4f}", f"{design.chain.joined_errors[j]:.4f}"
        )
    console.print(states)
    if not check.traced:
        console.print(f"{check.reason} ({found.seconds:.1f} s)")
        return
    console.print(
        f"verified: no circuit, branch or order defect ({found.attempts} designs traced, {found.seconds:.1f} s)"
    )
