"""The files of a mechanized chain (mechanism.toml, mechanization.json, figures) and its printed summary."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from linkwork.outputs.staging import console, have_matplotlib

if TYPE_CHECKING:
    from linkwork.mechanization import Mechanization, MechanizeOptions
    from linkwork.mechanization.options import ProgressCallback
    from linkwork.synthesis.problem import Problem
    from linkwork.synthesis.result import SynthesisResult


def resolve_options(problem: Problem, flags: Mapping[str, Any] | None = None) -> MechanizeOptions:
    """The mechanization options of the problem file, overridden by the command line's ``flags`` (file units;
    ``None`` means not given).

    Raises
    ------
    SpecError
        Naming the problem file's key or the flag, and what was expected.
    """
    from linkwork.mechanization import options_from_values

    source = str(problem.source) if problem.source is not None else None
    options = options_from_values(problem.mechanize_options, source=source)
    return options_from_values(flags or {}, base=options, flags=True)


def mechanize_into(
    result: SynthesisResult,
    out_dir: Path,
    *,
    options: MechanizeOptions | None = None,
    plots: bool = True,
    progress: ProgressCallback | None = None,
    html: bool = False,
) -> tuple[Mechanization, list[Path]]:
    """Mechanize ``result`` and write ``mechanism.toml``, ``mechanization.json`` and the figures into ``out_dir``
    (and ``mechanism.html``, the viewer of the mechanism over the target profiles, with ``html`` and one DOF).

    ``options`` default to the problem file's (:func:`resolve_options`).

    Raises
    ------
    MechanizationError
        When no design passes (one line: the closest design and what it violated).
    """
    from linkwork.mechanization import mechanize

    found = mechanize(result, options or resolve_options(result.problem), progress=progress)
    return found, write_mechanization_outputs(found, out_dir, plots=plots, html=html)


def write_mechanization_outputs(
    found: Mechanization, out_dir: Path, *, plots: bool = True, html: bool = False
) -> list[Path]:
    """Write a mechanization's ``mechanism.toml``, ``mechanization.json`` and figures into ``out_dir`` (and
    ``mechanism.html`` with ``html`` and one DOF); returns their paths."""
    from linkwork.mechanization import write_mechanization

    out_dir = Path(out_dir)
    written = write_mechanization(found, out_dir)
    if plots and have_matplotlib():
        from linkwork.viz.mechanism_plots import write_mechanism_figures

        written += write_mechanism_figures(found, out_dir)
    if html and found.verification.paths:
        from linkwork.viz.mechanism_viewer import write_mechanism_viewer

        written.append(write_mechanism_viewer(found, out_dir / "mechanism.html"))
    return written


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
        "structural error",
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
            f"{link.structural_error:.3g}",
            f"{math.degrees(link.transmission):.1f}",
        )
    console.print(links)
    mech = design.mechanism()
    revolute = mech.joint_types[mech.index(design.drive)] == "R"
    states = Table(title=f"DOF {check.dof}, drive {design.drive}", title_justify="left", title_style="bold")
    for column in (
        "profile",
        "drive value" + (" (deg)" if revolute else ""),
        "E_max mechanism",
        "E_max joined chain",
    ):
        states.add_column(column, justify="right")
    for j, state in enumerate(check.states):
        value = math.degrees(state.drive_value) if revolute else state.drive_value
        states.add_row(
            str(j + 1), f"{value:.6f}", f"{state.e_max:.4f}", f"{design.chain.joined_errors[j]:.4f}"
        )
    console.print(states)
    if found.recut is not None:
        before = ", ".join(f"{e:.4f}" for e in found.recut.joined_before)
        console.print(
            f"the chain followed is re-cut so that every C-segment's piece count moves one way ("
            f"{found.recut.describe()}); the synthesised chain's E_max: {before}"
        )
    if found.options is not None:
        size = design.chain.size
        longest = found.options.link_limit(size)
        structural = max((link.structural_error for link in design.links), default=0.0)
        bound = found.options.max_structural_error
        console.print(
            f"longest link allowed {longest:.4g} ({longest / size:.3g} x the largest extent {size:.4g}); "
            f"largest structural error {structural:.3g}"
            + (f" (max_structural_error {bound:.4g})" if bound is not None else " (not bounded)")
        )
    if len(found.ranked) > 1:
        ranking = Table(title="Designs found, by quality factor", title_justify="left", title_style="bold")
        for column in ("rank", "quality", "min transmission (deg)", "link ratio", "stroke", "drive"):
            ranking.add_column(column, justify="right")
        for rank, r in enumerate(found.ranked, start=1):
            q = r.quality
            kind = next(s["type"] for s in r.design.joint_specs() if s["name"] == r.design.drive)
            stroke = f"{math.degrees(q.stroke):.1f} deg" if kind == "R" else f"{q.stroke:.4g}"
            ranking.add_row(
                str(rank),
                f"{q.factor:.4f}",
                f"{math.degrees(q.min_transmission):.1f}",
                f"{q.link_ratio:.2f}",
                stroke,
                r.design.drive,
            )
        console.print(ranking)
    stopped = f"; the search was stopped early: {found.stopped}" if found.stopped else ""
    if not check.traced:
        console.print(f"{check.reason} ({found.seconds:.1f} s{stopped})")
        return
    console.print(
        f"verified: no circuit, branch or order defect ({found.attempts} designs traced, {found.seconds:.1f} s"
        f"{stopped})"
    )
