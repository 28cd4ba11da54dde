"""``linkwork trace``: trace a linkage's motion, locate its bifurcations, write path.csv, report.json, figures."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from linkwork.cli.common import (
    console,
    fail,
    friendly_errors,
    have_matplotlib,
    parse_assignments,
    staged_output,
)


def _parse_until(text: str | None) -> tuple[str, float] | None:
    if text is None:
        return None
    name, sep, raw = text.partition("=")
    try:
        value = float(raw)
    except ValueError:
        value = float("nan")
    if not sep or not name.strip() or not math.isfinite(value):
        raise fail(f"--until {text!r}: expected JOINT=VALUE with VALUE in degrees, e.g. A=87.0067")
    return name.strip(), value


def _parse_couple(items: list[str] | None) -> list[list[str]]:
    groups = []
    for item in items or []:
        names = [x.strip() for x in item.split("=")]
        if len(names) < 2 or not all(names):
            raise fail(f"--couple {item!r}: expected joints joined by '=', e.g. A=C=E")
        groups.append(names)
    return groups


@friendly_errors
def trace(
    spec: Annotated[
        str, typer.Argument(help="A TOML spec file or a built-in name (see `linkwork linkages`).")
    ],
    set_: Annotated[
        list[str] | None,
        typer.Option(
            "--set", help="Built-in parameter KEY=VALUE (angles in degrees); repeatable.", show_default=False
        ),
    ] = None,
    drive: Annotated[str | None, typer.Option(help="Joint that orients and counts the steps.")] = None,
    until: Annotated[
        str | None, typer.Option(help="Stop exactly when JOINT reaches VALUE (degrees), e.g. A=87.0067.")
    ] = None,
    steps: Annotated[
        int | None,
        typer.Option(help="Paper mode: N equal steps of the drive up to --until (the paper uses 200)."),
    ] = None,
    max_step: Annotated[
        float, typer.Option(help="Largest adaptive step (degrees, arclength in the joints).")
    ] = 2.0,
    max_steps: Annotated[int, typer.Option(help="Step budget over all branches.")] = 5000,
    couple: Annotated[
        list[str] | None, typer.Option(help="Force joints equal, e.g. A=C=E; repeatable.", show_default=False)
    ] = None,
    fixed: Annotated[
        list[str] | None,
        typer.Option(help="Hold a joint at its start value; repeatable.", show_default=False),
    ] = None,
    branches: Annotated[
        bool, typer.Option("--branches", help="Follow every branch at every bifurcation.")
    ] = False,
    out: Annotated[Path, typer.Option(help="Output folder.")] = Path("out"),
    no_plots: Annotated[bool, typer.Option("--no-plots", help="Do not draw figures.")] = False,
    animate: Annotated[
        bool,
        typer.Option(
            "--animate",
            help="Also write motion.gif and motion.mp4 (with ffmpeg), an animation of every branch.",
        ),
    ] = False,
    html: Annotated[
        bool,
        typer.Option(
            "--html", help="Also write viewer.html: the interactive 3-D viewer (one self-contained file)."
        ),
    ] = False,
) -> None:
    """Trace a closed-loop linkage: path.csv, report.json and figures in --out."""
    import numpy as np

    from linkwork.io.spec import resolve_spec
    from linkwork.kinematics.tracer import trace as run_trace

    params = parse_assignments(set_, "--set")
    target = _parse_until(until)
    loaded = resolve_spec(spec, params)
    mech = loaded.mechanism
    if couple or fixed:
        mech = mech.with_couplings(_parse_couple(couple), fixed or [])
    if max_step <= 0:
        raise fail(f"--max-step {max_step}: expected a positive number of degrees")
    until_rad = None
    if target is not None:
        j = mech.index(target[0])
        value = np.radians(target[1]) if mech.joint_types[j] == "R" else target[1]
        until_rad = (target[0], float(value))

    console.print(
        f"[bold]{mech.name}[/]: {mech.n_joints} joints, {len(mech.loops)} loop(s), {mech.n_unknowns} unknowns"
    )
    if loaded.assembly is not None and loaded.assembly.residual_before > 1e-12:
        worst = float(np.degrees(np.max(np.abs(loaded.assembly.correction))))
        console.print(
            f"start corrected onto the loop: residual {loaded.assembly.residual_before:.2e} -> "
            f"{loaded.assembly.residual_after:.2e}, joints moved by up to {worst:.3g} deg"
        )
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    total = steps if steps is not None else max_steps
    with Progress(
        TextColumn("tracing"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.description}"),
        TimeElapsedColumn(),
        console=console,
        transient=True,
        disable=not console.is_terminal,
    ) as progress:
        task = progress.add_task("", total=total)

        def report(done: float, what: str) -> None:
            progress.update(task, advance=done, description=what)

        path = run_trace(
            mech,
            drive=drive,
            until=until_rad,
            steps=steps,
            max_step=float(np.radians(max_step)),
            max_steps=max_steps,
            branches=branches,
            progress=report,
        )
    figures = write_trace_outputs(path, out, loaded.assembly, plots=not no_plots, html=html, animate=animate)
    _summary(path)
    written = ["path.csv", "report.json", *[f.name for f in figures]]
    console.print(f"wrote {', '.join(written)} to {out}/")


def summary(path) -> None:
    """Print the summary tables of a traced path (used by ``linkwork demo`` too)."""
    _summary(path)


def write_trace_outputs(
    path, out: Path, assembly=None, plots: bool = True, html: bool = False, animate: bool = False
) -> list[Path]:
    """Write path.csv, report.json, (if matplotlib is there) the figures and the deployment sequence of the
    first branch (``sequence.png``, like Figs. 11, 13, 16), with ``animate`` an animation of every branch
    (``motion.gif``, and ``motion.mp4`` when an ffmpeg is found), and with ``html`` the interactive viewer
    ``viewer.html`` into ``out``, all or nothing. Returns the figures, animation and viewer written."""
    from linkwork.io.results import write_path_csv, write_report_json

    figures: list[Path] = []
    with staged_output(out) as stage:
        write_path_csv(path, stage / "path.csv")
        write_report_json(path, stage / "report.json", assembly)
        if plots:
            if have_matplotlib():
                from linkwork.viz.snapshots import deployment_sequence
                from linkwork.viz.trace_plots import write_trace_figures

                figures = write_trace_figures(path, stage)
                figures.append(deployment_sequence(path, stage / "sequence.png"))
                if animate:
                    from linkwork.viz.animate import animate_path

                    motion = animate_path(path, stage / "motion.gif")
                    figures += [f for f in (motion.gif, motion.mp4) if f is not None]
            else:
                console.print("figures skipped: install the plotting extra, pip install 'linkwork\\[viz]'")
        if html:
            from linkwork.viz.viewer import write_trace_viewer

            figures.append(write_trace_viewer(path, stage / "viewer.html"))
    return [Path(out) / f.name for f in figures]


def _summary(path) -> None:
    """Print the rich summary tables of a traced path."""
    import numpy as np
    from rich.table import Table

    from linkwork.io.results import report_dict

    rep = report_dict(path)
    mech = path.mechanism
    revolute = [t == "R" for t in mech.joint_types]

    def show(values: np.ndarray) -> list[str]:
        return [f"{np.degrees(v):.4f}" if r else f"{v:.6f}" for v, r in zip(values, revolute, strict=True)]

    def angles_text(values: np.ndarray) -> str:
        return "  ".join(f"{n}={v}" for n, v in zip(mech.joint_names, show(values), strict=True))

    table = Table(title="branches", title_justify="left")
    table.add_column("branch", justify="right")
    table.add_column("from")
    table.add_column("steps", justify="right")
    table.add_column("end")
    table.add_column("joints at the end (deg)", overflow="fold")
    for br in path.branches:
        mask = path.of_branch(br.id)
        origin = "start" if br.parent is None else f"bif {br.bifurcation} on {br.parent}"
        table.add_row(str(br.id), origin, str(br.steps), br.end_reason, angles_text(path.angles[mask][-1]))
    console.print(table)
    mob = rep["mobility_along_path"]
    console.print(
        f"rank {rep['rank']} / mobility {rep['mobility']} at the start; mobility along the path "
        f"{mob['min']}..{mob['max']} (away from bifurcation points); max closure residual "
        f"{rep['max_residual']:.2e}; max condition (sigma_1 / smallest non-zero) {rep['max_condition']:.4g}; "
        f"{rep['points']} points in {rep['seconds']:.3f} s"
    )
    if path.bifurcations:
        bt = Table(title="bifurcation points", title_justify="left")
        bt.add_column("id", justify="right")
        bt.add_column("branch", justify="right")
        bt.add_column("step", justify="right")
        bt.add_column("rank", justify="right")
        bt.add_column("σ_r/σ_1", justify="right")
        bt.add_column("branches")
        bt.add_column("joints (deg)", overflow="fold")
        for b in path.bifurcations:
            zero = b.sigma[b.rank] / b.sigma[0] if b.rank < len(b.sigma) else 0.0
            bt.add_row(
                str(b.id), str(b.branch), str(b.step), str(b.rank), f"{zero:.1e}",
                f"{len(b.tangents)} ({b.method})", angles_text(b.angles),
            )  # fmt: skip
        console.print(bt)
