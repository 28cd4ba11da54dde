"""``linkwork robustness``: imperfection sensitivity of a linkage by Monte Carlo, with its first-order prediction."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.text import Text

from linkwork.cli.common import (
    fail,
    friendly_errors,
    parse_assignments,
    parse_couple,
    parse_until,
    progress_bar,
)
from linkwork.outputs.staging import console


@friendly_errors
def robustness(
    spec: Annotated[
        str, typer.Argument(help="A TOML spec file or a built-in name (see `linkwork linkages`).")
    ],
    samples: Annotated[int, typer.Option(help="Number of imperfect samples.")],
    hinge_position_tol: Annotated[
        float, typer.Option(help="Hinge position tolerance, normal to the line (length units).")
    ],
    hinge_direction_tol: Annotated[
        float, typer.Option(help="Hinge direction tolerance: cone half-angle (deg).")
    ],
    set_: Annotated[
        list[str] | None,
        typer.Option(
            "--set", help="Built-in parameter KEY=VALUE (angles in degrees); repeatable.", show_default=False
        ),
    ] = None,
    until: Annotated[
        str | None, typer.Option(help="Nominal path: trace until JOINT reaches VALUE (degrees), e.g. A=120.")
    ] = None,
    steps: Annotated[int | None, typer.Option(help="N equal steps of the drive up to --until.")] = None,
    max_steps: Annotated[int, typer.Option(help="Step budget of the nominal trace.")] = 5000,
    couple: Annotated[
        list[str] | None,
        typer.Option(
            help="Force joints equal, e.g. A=C=E (kept in every sample); repeatable.", show_default=False
        ),
    ] = None,
    fixed: Annotated[
        list[str] | None,
        typer.Option(help="Hold a joint at its start value; repeatable.", show_default=False),
    ] = None,
    distribution: Annotated[
        str, typer.Option(help="normal (tolerance = standard deviation) or uniform (within the tolerance).")
    ] = "normal",
    seed: Annotated[int, typer.Option(help="Seed of the study; sample i gets its own seed from it.")] = 0,
    scheduler: Annotated[
        str | None,
        typer.Option(
            help="Dask scheduler tcp://HOST:PORT (default $LINKWORK_SCHEDULER, else local processes)."
        ),
    ] = None,
    workers: Annotated[
        int | None,
        typer.Option(help="Local worker processes (default: one per core; 0 runs in this process)."),
    ] = None,
    spatial_errors: Annotated[
        bool,
        typer.Option(
            "--spatial-errors", help="Planar mechanisms: tilt and shift hinges out of the plane too."
        ),
    ] = False,
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder.")] = Path("out"),
    no_plots: Annotated[bool, typer.Option("--no-plots", help="Do not draw figures.")] = False,
) -> None:
    """Imperfection sensitivity: robustness.json, samples.parquet and figures in --out."""
    import numpy as np

    from linkwork.errors import SpecError
    from linkwork.io.spec import resolve_spec
    from linkwork.kinematics.tracer import trace as run_trace
    from linkwork.studies.imperfections import ImperfectionModel
    from linkwork.studies.robustness import nominal_ratio, prepare

    if samples < 1:
        raise fail(f"--samples {samples}: expected at least 1")
    if seed < 0:
        raise fail(f"--seed {seed}: expected a non-negative whole number")
    if workers is not None and workers < 0:
        raise fail(f"--workers {workers}: expected 0 or more")
    if steps is not None and until is None:
        raise fail("--steps needs --until JOINT=VALUE")
    params = parse_assignments(set_, "--set")
    target = parse_until(until)
    loaded = resolve_spec(spec, params)
    mech = loaded.mechanism
    if couple or fixed:
        mech = mech.with_couplings(parse_couple(couple), fixed or [])
    model = ImperfectionModel(
        position_tol=hinge_position_tol,
        direction_tol=float(np.radians(hinge_direction_tol)),
        distribution=distribution,
        spatial=spatial_errors or not mech.planar,
    )
    until_api = None
    if target is not None:
        j = mech.index(target[0])
        until_api = (target[0], float(np.radians(target[1]) if mech.joint_types[j] == "R" else target[1]))
    path = run_trace(mech, until=until_api, steps=steps, max_steps=max_steps)
    if path.angles.shape[0] < 2:
        raise SpecError("the nominal path has a single point; give --until or a longer budget")
    setup = prepare(mech, path, model, seed)
    console.print(
        Text(mech.name, style="bold"),
        f"nominal path of {setup.u_path.shape[0]} points; {samples} samples "
        f"(misfit length scale L = {setup.scale.length:.4g})",
        sep=": ",
    )
    from linkwork.outputs.robustness import (
        print_robustness_summary,
        robustness_dict,
        run_and_write_robustness,
    )

    with progress_bar("samples", samples, fraction=True) as report:
        result, figures = run_and_write_robustness(
            setup,
            samples,
            nominal_ratio(path),
            out,
            source=spec,
            plots=not no_plots,
            engine={"scheduler": scheduler, "workers": workers},
            progress=report,
        )
    print_robustness_summary(robustness_dict(result, spec))
    written = ["robustness.json", "samples.parquet", *[f.name for f in figures]]
    console.print(f"wrote {', '.join(written)} to {out}/")
    end = path.branches[0].end_reason if path.branches else ""
    if target is not None and end != "reached target":
        from linkwork.errors import RequestNotMetError

        last = float(setup.drive_values[-1])
        reached = float(np.degrees(last)) if mech.joint_types[mech.index(target[0])] == "R" else last
        raise RequestNotMetError(
            f"the nominal path stopped before {target[0]} = {target[1]:g} ({end}, at {reached:.6g}); "
            "the study covers the path up to there"
        )
