"""``linkwork robustness``: imperfection sensitivity of a linkage by Monte Carlo, with its first-order prediction."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.text import Text

from linkwork.cli import options as opt
from linkwork.cli.common import (
    check_word,
    check_workers,
    fail,
    friendly_errors,
    parse_assignments,
    parse_couple,
    parse_until,
    progress_bar,
    until_in_api_units,
)
from linkwork.cli.out_folder import out_help, run_folder, spec_label
from linkwork.outputs.staging import console
from linkwork.studies.imperfections import DISTRIBUTIONS

if TYPE_CHECKING:
    from linkwork.kinematics.mechanism import Mechanism
    from linkwork.kinematics.trace_result import Trace


@friendly_errors
def robustness(
    spec: opt.SpecName,
    samples: Annotated[int, typer.Option(help="Number of imperfect samples.")],
    hinge_position_tol: Annotated[
        float,
        typer.Option(
            help="Hinge position tolerance normal to the line (length units): with --distribution normal the "
            "standard deviation of each of the two shift components (61 % of hinges shift by more); with uniform "
            "a hard bound (the shift is uniform in a disc of this radius)."
        ),
    ],
    hinge_direction_tol: Annotated[
        float,
        typer.Option(
            help="Hinge direction tolerance (deg), a tilt about the hinge itself: with --distribution normal the "
            "standard deviation of each of the two tilt components (61 % of hinges tilt by more); with uniform a "
            "hard bound (the tilt is uniform in a cone of this half-angle)."
        ),
    ],
    set_: opt.SetParams = None,
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
    fixed: opt.Fixed = None,
    distribution: Annotated[
        str,
        typer.Option(
            help="normal: each tolerance is the standard deviation of each error component (the default; 61 % of "
            "hinges exceed it); uniform: each tolerance is a hard bound (errors uniform in a disc or cone)."
        ),
    ] = "normal",
    seed: Annotated[int, typer.Option(help="Seed of the study; sample i gets its own seed from it.")] = 0,
    scheduler: opt.Scheduler = None,
    workers: opt.Workers = None,
    spatial_errors: Annotated[
        bool,
        typer.Option(
            "--spatial-errors", help="Planar mechanisms: tilt and shift hinges out of the plane too."
        ),
    ] = False,
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help=out_help("robustness", "hedgepeth-rods-n=6"), show_default=False),
    ] = None,
    no_plots: opt.NoPlots = False,
) -> None:
    """Imperfection sensitivity: robustness.json, samples.parquet and figures in --out (default
    out/NAME-robustness/, NAME the linkage's name with its --set values or the spec file's name)."""
    import numpy as np

    from linkwork.limits import MAX_PATH_POINTS
    from linkwork.studies.engine import RunStatus, scheduler_address
    from linkwork.studies.imperfections import ImperfectionModel
    from linkwork.studies.robustness import nominal_ratio, prepare

    _check_counts(samples, seed, workers)
    scheduler_address(scheduler)  # a malformed address is bad input, found before any work
    if steps is not None and until is None:
        raise fail("--steps needs --until JOINT=VALUE")
    if steps is not None and steps + 1 > MAX_PATH_POINTS:
        raise fail(
            f"--steps {steps}: expected at most {MAX_PATH_POINTS - 1} for a robustness study (the nominal path's "
            "points each keep per-point histograms in memory)"
        )
    check_word("--distribution", distribution, DISTRIBUTIONS)
    target = parse_until(until)
    if out is None:
        out = run_folder("robustness", spec_label(spec, parse_assignments(set_, "--set")))
    mech = _mechanism(spec, set_, couple, fixed)
    model = ImperfectionModel(
        position_tol=hinge_position_tol,
        direction_tol=float(np.radians(hinge_direction_tol)),
        distribution=distribution,
        spatial=spatial_errors or not mech.moves_in_plane,
    )
    nominal = _nominal_path(mech, until_in_api_units(mech, target), steps, max_steps)
    setup = prepare(mech, nominal, model, seed)
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

    status = RunStatus()
    with progress_bar("samples", samples, fraction=True) as report:
        result, figures = run_and_write_robustness(
            setup,
            samples,
            nominal_ratio(nominal),
            out,
            source=spec,
            plots=not no_plots,
            engine={"scheduler": scheduler, "workers": workers, "status": status},
            progress=report,
        )
    print_robustness_summary(robustness_dict(result, spec))
    written = ["robustness.json", "samples.parquet", *[f.name for f in figures]]
    console.print(f"wrote {', '.join(written)} to {out}/")
    if not status.complete:
        raise fail(
            f"{status.stopped}; {result.samples} of {samples} samples computed and written (robustness.json says "
            '"complete": false)',
            code=status.code,
        )
    if target is not None:
        _check_reached(mech, nominal, float(setup.drive_values[-1]), target)


def _check_counts(samples: int, seed: int, workers: int | None) -> None:
    """Refuse a study of no samples, a negative seed or a number of workers the machine does not have (the
    flags are checked as they are parsed, see cli/options.py; this repeats it for a direct call)."""
    from linkwork.limits import SAMPLES, SEED

    for flag, value, limit in (("--samples", samples, SAMPLES), ("--seed", seed, SEED)):
        if limit.broken(value):
            raise fail(f"{flag} {value}: expected {limit.expected(flag)}")
    check_workers(workers)


def _mechanism(
    spec: str, set_: list[str] | None, couple: list[str] | None, fixed: list[str] | None
) -> Mechanism:
    """The linkage of the study, with its couplings and fixed joints."""
    from linkwork.io.spec import resolve_spec

    mech = resolve_spec(spec, parse_assignments(set_, "--set")).mechanism
    if couple or fixed:
        mech = mech.with_couplings(parse_couple(couple), fixed or [])
    return mech


def _nominal_path(
    mech: Mechanism, until: tuple[str, float] | None, steps: int | None, max_steps: int
) -> Trace:
    """The perfect linkage's path, along which every sample is measured (at least two points)."""
    from linkwork.errors import SpecError
    from linkwork.kinematics.tracer import trace as run_trace

    nominal = run_trace(mech, until=until, steps=steps, max_steps=max_steps)
    if nominal.angles.shape[0] < 2:
        raise SpecError("the nominal path has a single point; give --until or a longer budget")
    return nominal


def _check_reached(mech: Mechanism, trace: Trace, last: float, target: tuple[str, float]) -> None:
    """Exit 3 (after everything is written) when the nominal path stopped short of ``--until``; ``last`` is the
    drive's value (radians or a length) where it stopped."""
    import numpy as np

    from linkwork.errors import RequestNotMetError

    end = trace.branches[0].end_reason if trace.branches else ""
    if end == "reached target":
        return
    reached = float(np.degrees(last)) if mech.joint_types[mech.index(target[0])] == "R" else last
    raise RequestNotMetError(
        f"the nominal path stopped before {target[0]} = {target[1]:g} ({end}, at {reached:.6g}); "
        "the study covers the path up to there"
    )
