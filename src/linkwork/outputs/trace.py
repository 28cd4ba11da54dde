"""The files of a traced linkage (path.csv, report.json, points.csv, mechanism.toml, figures, sequence, animation, viewer) and its printed
summary."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from linkwork.deprecation import trace_keyword
from linkwork.outputs.staging import console, have_matplotlib, staged_output

if TYPE_CHECKING:
    import numpy as np
    from rich.table import Table

    from linkwork.kinematics.chains import Assembly
    from linkwork.kinematics.deployment import Deployment
    from linkwork.kinematics.mechanism import Mechanism
    from linkwork.kinematics.trace_result import Trace


@trace_keyword
def write_trace_outputs(
    trace: Trace,
    out: Path,
    assembly: Assembly | None = None,
    plots: bool = True,
    html: bool = False,
    animate: bool = False,
    deployment: Deployment | None = None,
    *,
    deployment_unmet: str | None = None,
) -> list[Path]:
    """Write path.csv, report.json, (if matplotlib is there) the figures and the deployment sequence of the
    first branch (``sequence.png``, like Figs. 11, 13, 16), with ``animate`` an animation of every branch
    (``motion.gif``, and ``motion.mp4`` when an ffmpeg is found), and with ``html`` the interactive viewer
    ``viewer.html`` into ``out``, all or nothing; ``deployment`` (default ``trace.deployment()``) goes into
    report.json and ``stretch.png``; ``deployment_unmet`` says why the deployed configuration asked for is not on
    the path (report.json's ``deployment`` is then ``null`` and ``stretch.png`` is left out). A trace stopped
    early (``trace.stats.stopped``: a signal) is written the same way: what was traced. Returns the figures,
    animation and viewer written."""
    from linkwork.io.readback import path_columns, points_columns
    from linkwork.io.results import write_path_csv, write_points_csv, write_report_json
    from linkwork.kinematics.points import points_columns as position_names
    from linkwork.names import describe

    figures: list[Path] = []
    renamed = describe(
        path_columns(trace.mechanism.joint_names), points_columns(position_names(trace.mechanism))
    )
    if renamed:
        console.print(renamed)
    with staged_output(out) as stage:
        write_path_csv(trace, stage / "path.csv")
        write_report_json(
            trace, stage / "report.json", assembly, deployment, deployment_unmet=deployment_unmet
        )
        write_points_csv(trace, stage / "points.csv")
        write_trace_mechanism(trace.mechanism, stage)
        if plots:
            if have_matplotlib():
                from linkwork.viz.deployment_plots import plot_stretch
                from linkwork.viz.snapshots import deployment_sequence
                from linkwork.viz.trace_plots import write_trace_figures

                figures = write_trace_figures(trace, stage)
                figures.append(deployment_sequence(trace, stage / "sequence.png"))
                if deployment_unmet is None:
                    figures.append(plot_stretch(trace, stage / "stretch.png", deployment))
                if animate:
                    from linkwork.viz.animate import animate_path

                    motion = animate_path(trace, stage / "motion.gif")
                    figures += [f for f in (motion.gif, motion.mp4) if f is not None]
            else:
                console.print("figures skipped: install the plotting extra, pip install 'linkwork[viz]'")
        if html:
            from linkwork.viz.viewer import write_trace_viewer

            figures.append(write_trace_viewer(trace, stage / "viewer.html"))
    return [Path(out) / f.name for f in figures]


def write_trace_mechanism(mech: Mechanism, folder: Path) -> None:
    """Write what rebuilds the traced mechanism next to its path: ``mechanism.toml`` (a spec file, read back by
    ``linkwork trace`` and ``linkwork export``) and ``drawing.json`` (the constructor's parameters, which choose
    how its solids are drawn: Hedgepeth's and Guest's rods)."""
    from linkwork.io.spec import dump_spec
    from linkwork.io.writer import json_text

    (folder / "mechanism.toml").write_text(dump_spec(mech))
    (folder / "drawing.json").write_text(json_text(dict(mech.meta), indent=1), encoding="utf-8")


@trace_keyword
def print_trace_summary(trace: Trace) -> None:
    """Print the summary tables of a traced path: branches, rank and mobility, bifurcation points."""
    from linkwork.io.results import report_dict

    rep = report_dict(trace)
    console.print(_branch_table(trace))
    mob = rep["mobility_along_path"]
    console.print(
        f"rank {rep['rank']} / mobility {rep['mobility']} at the start; mobility along the path "
        f"{mob['min']}..{mob['max']} (away from bifurcation points); max closure residual "
        f"{rep['max_residual']:.2e}; max condition (sigma_1 / smallest non-zero) {rep['max_condition']:.4g}; "
        f"{rep['points']} points in {rep['seconds']:.3f} s"
    )
    if rep["closure_tol"] > 1e-12:
        console.print(
            f"closure accepted within {rep['closure_tol']:.2e} (--closure-tol); largest misfit met "
            f"{rep['max_misfit']:.2e}"
        )
    for fold in rep["folds"]:
        console.print(
            f"fold of the drive on branch {fold['branch']} (after step {fold['step']}): "
            f"{fold['drive']} turns back at {fold['value']:.4f}"
        )
    if trace.bifurcations:
        console.print(_bifurcation_table(trace))


def _joints_text(mech: Mechanism, values: np.ndarray) -> str:
    """``A=12.3456  B=...``: joint values in file units (degrees, or lengths for a prismatic joint)."""
    import numpy as np

    return "  ".join(
        f"{name}={np.degrees(v):.4f}" if kind == "R" else f"{name}={v:.6f}"
        for name, v, kind in zip(mech.joint_names, values, mech.joint_types, strict=True)
    )


def _branch_table(trace: Trace) -> Table:
    """One row per branch: where it starts, its steps, its mobility, why it ended and its joints at the end."""
    from rich.table import Table

    table = Table(title="branches", title_justify="left")
    table.add_column("branch", justify="right")
    table.add_column("from")
    table.add_column("steps", justify="right")
    table.add_column("mob.", justify="right")
    table.add_column("end")
    table.add_column("joints at the end (deg)", overflow="fold")
    for br in trace.branches:
        mask = trace.of_branch(br.id)
        origin = "start" if br.parent is None else f"bif {br.bifurcation} on {br.parent}"
        table.add_row(
            str(br.id),
            origin,
            str(br.steps),
            str(br.mobility),
            br.end_reason,
            _joints_text(trace.mechanism, trace.angles[mask][-1]),
        )
    return table


def _bifurcation_table(trace: Trace) -> Table:
    """One row per bifurcation point: where, the rank there, sigma_r / sigma_1 and the branches leaving it."""
    from rich.table import Table

    bt = Table(title="bifurcation points", title_justify="left")
    bt.add_column("id", justify="right")
    bt.add_column("branch", justify="right")
    bt.add_column("step", justify="right")
    bt.add_column("rank", justify="right")
    bt.add_column("σ_r/σ_1", justify="right")
    bt.add_column("branches")
    bt.add_column("joints (deg)", overflow="fold")
    for b in trace.bifurcations:
        zero = b.sigma[b.rank] / b.sigma[0] if b.rank < len(b.sigma) else 0.0
        what = f"{len(b.tangents)} ({b.method})"
        if b.kind == "component":
            what = f"none: meets a {b.dimension}-dimensional component"
        bt.add_row(
            str(b.id), str(b.branch), str(b.step), str(b.rank), f"{zero:.1e}", what,
            _joints_text(trace.mechanism, b.angles),
        )  # fmt: skip
    return bt
