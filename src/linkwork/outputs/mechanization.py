"""The files of a mechanized chain (mechanism.toml, mechanization.json, figures) and its printed summary."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

from linkwork.outputs.staging import console, have_matplotlib

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
