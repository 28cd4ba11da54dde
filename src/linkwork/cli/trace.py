"""``linkwork trace``: trace a linkage's motion, locate its bifurcations, write path.csv, report.json, figures."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.text import Text

from linkwork.cli import options as opt
from linkwork.cli.common import (
    check_range,
    fail,
    friendly_errors,
    joint_named,
    parse_assignments,
    parse_couple,
    parse_joint_value,
    parse_until,
    progress_bar,
    until_in_api_units,
)
from linkwork.cli.out_folder import out_help, run_folder, spec_label
from linkwork.errors import RequestNotMetError
from linkwork.interrupts import exit_code, held_signals
from linkwork.limits import plain_number
from linkwork.messages import show
from linkwork.outputs.staging import check_output_folder, console

MAX_STEP_DEG = 90.0
"""The largest ``--max-step`` (degrees)."""

MAX_TRACE_STEPS = 1_000_000
"""The largest step budget ``--max-steps`` (and ``--steps``): a bound on time and memory."""

if TYPE_CHECKING:
    from collections.abc import Callable

    from linkwork.io.spec import LoadedSpec
    from linkwork.kinematics.deployment import Deployment
    from linkwork.kinematics.mechanism import Mechanism
    from linkwork.kinematics.trace_result import Trace


def _parse_limits(items: list[str] | None) -> dict[str, tuple[float, float]]:
    """``--limit J=LO:HI`` items as ``{joint: (lo, hi)}`` in file units (degrees, or lengths)."""
    out: dict[str, tuple[float, float]] = {}
    for item in items or []:
        name, sep, span = item.partition("=")
        lo_text, colon, hi_text = span.partition(":")
        lo_number, hi_number = (
            plain_number(lo_text),
            plain_number(hi_text),
        )  # ASCII digits (limits.PLAIN_NUMBER)
        lo = float("nan") if lo_number is None else lo_number
        hi = float("nan") if hi_number is None else hi_number
        if (
            not sep
            or not colon
            or not name.strip()
            or not (math.isfinite(lo) and math.isfinite(hi))
            or lo >= hi
        ):
            raise fail(
                f"--limit {show(item)}: expected JOINT=LO:HI with LO < HI (degrees, or lengths), e.g. D=-140:-100"
            )
        if name.strip() in out:  # two ranges for one joint: which one was meant?
            raise fail(
                f"--limit {show(item)}: {show(name.strip())} is limited twice; expected one range a joint"
            )
        out[name.strip()] = (lo, hi)
    return out


@friendly_errors
def trace(
    spec: opt.SpecName,
    set_: opt.SetParams = None,
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
    fixed: opt.Fixed = None,
    branches: Annotated[
        bool, typer.Option("--branches", help="Follow every branch at every bifurcation.")
    ] = False,
    limit: Annotated[
        list[str] | None,
        typer.Option(
            help="Joint limit JOINT=LO:HI (degrees, or lengths for a prismatic joint); a branch passing it ends "
            "with the reason 'limit JOINT'. Repeatable.",
            show_default=False,
        ),
    ] = None,
    closure_tol: Annotated[
        float | None,
        typer.Option(
            help="Accept a least-squares closure within this misfit (play in the hinges), for a loop whose "
            "link parameters are slightly inconsistent; report.json states it and the largest misfit met. "
            "Default: 1e-12 of the file's unit, no play (what lw.trace does without closure_tol).",
            show_default=False,
        ),
    ] = None,
    deployed_at: Annotated[
        str | None,
        typer.Option(
            help="The deployed configuration for the deployment measures in report.json: where JOINT first "
            "reaches VALUE (degrees) on branch 0, e.g. A=128.6822 (default: the last point of branch 0).",
            show_default=False,
        ),
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help=out_help("trace", "hedgepeth-rods-n=6"), show_default=False),
    ] = None,
    no_plots: opt.NoPlots = False,
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
    """Trace a closed-loop linkage: path.csv, report.json and figures in --out (default out/NAME-trace/, NAME the
    linkage's name with its --set values or the spec file's name).

    Exit codes: 0 done as asked; 2 bad input (one line saying which file, key or flag and what was expected);
    3 the request could not be met (the --until target is never reached on the path, or would need more steps
    than --max-steps; the --deployed-at value is not reached on branch 0: the range is printed), after
    path.csv, report.json and the figures of what was traced are written; 130 / 143 interrupted by Ctrl-C /
    SIGTERM while tracing: the path traced so far is written (report.json's "stopped" and the branch's end say
    so); a second signal stops at once, writing nothing.
    """
    import numpy as np

    from linkwork.kinematics.tracer import trace as run_trace

    params = parse_assignments(set_, "--set")
    if out is None:
        out = run_folder("trace", spec_label(spec, params))
    check_output_folder(out, ["path.csv", "report.json"])
    check_range("--max-step", max_step, 0.0, MAX_STEP_DEG, "a number of degrees", open_low=True)
    check_range("--max-steps", max_steps, 1, MAX_TRACE_STEPS, "a whole number of steps")
    if steps is not None:
        check_range("--steps", steps, 1, MAX_TRACE_STEPS, "a whole number of steps")
    if animate and no_plots:  # the animation is one of the figures: asking for it and for none contradicts
        raise fail(
            "--animate: the animation is a figure and --no-plots leaves the figures out; expected one of the two"
        )
    target = parse_until(until)
    limits_file = _parse_limits(limit)
    if closure_tol is not None and not (math.isfinite(closure_tol) and closure_tol > 0):
        raise fail(f"--closure-tol {closure_tol}: expected a positive number")
    # Without --closure-tol the spec is assembled at the default closure and traced as lw.trace traces it
    # without closure_tol: no play (given, the play is a length in the file's unit, also in the own frame).
    loaded = _load(spec, params, closure_tol)
    mech = loaded.mechanism
    if couple or fixed:
        mech = mech.with_couplings(parse_couple(couple), fixed or [])
    limits = _limits_in_api_units(mech, limits_file)
    if drive is not None:
        joint_named(mech, drive, "--drive")
    if steps is not None and target is None:
        raise fail(
            f"--steps {steps}: paper mode's equal steps go to a target; expected --until JOINT=VALUE too"
        )
    until_rad = until_in_api_units(mech, target)
    deployed_rad = until_in_api_units(mech, _parse_deployed_at(deployed_at), "--deployed-at")

    console.print(
        Text(mech.name, style="bold"),
        f"{mech.n_joints} joints, {len(mech.loops)} loop(s), {mech.n_unknowns} unknowns",
        sep=": ",
    )
    if loaded.assembly is not None and loaded.assembly.residual_before > 1e-12:
        worst = float(np.degrees(np.max(np.abs(loaded.assembly.correction))))
        console.print(
            f"start corrected onto the loop: residual {loaded.assembly.residual_before:.2e} -> "
            f"{loaded.assembly.residual_after:.2e}, joints moved by up to {worst:.3g} deg"
        )
    # Ctrl-C or SIGTERM while tracing ends the trace at its next chunk of steps, keeping what was traced.
    with held_signals() as hold:
        traced = _run_with_progress(
            run_trace, mech, total=steps if steps is not None else max_steps, drive=drive, until=until_rad,
            steps=steps, max_step=float(np.radians(max_step)), max_steps=max_steps, branches=branches,
            limits=limits, closure_tol=closure_tol,
        )  # fmt: skip
    from linkwork.outputs.trace import print_trace_summary, write_trace_outputs

    deployment, deployment_unmet = _deployment(traced, deployed_rad)
    figures = write_trace_outputs(
        traced, out, loaded.assembly, plots=not no_plots, html=html, animate=animate, deployment=deployment,
        deployment_unmet=deployment_unmet,
    )  # fmt: skip
    print_trace_summary(traced)
    written = ["path.csv", "report.json", "points.csv", "mechanism.toml", *[f.name for f in figures]]
    console.print(f"wrote {', '.join(written)} to {out}/")
    if hold.signum:  # the signal wins over a target not reached: the trace was cut short on purpose
        raise fail(
            f"{hold.stopped}: the {len(traced.branch)} points traced so far are written to {out}/ "
            "(report.json says where each branch stopped)",
            code=exit_code(hold.signum),
        )
    if traced.stats.unmet is not None:
        raise RequestNotMetError(traced.stats.unmet)
    if deployment_unmet is not None:
        raise RequestNotMetError(deployment_unmet)


def _deployment(traced: Trace, deployed_at: tuple[str, float] | None) -> tuple[Deployment | None, str | None]:
    """The deployment measures at ``--deployed-at`` (default: the last point of branch 0), or ``(None, why)``
    when branch 0 never reaches that value (the trace is written all the same, then the command exits 3)."""
    if deployed_at is None:
        return None, None
    try:
        return traced.deployment(deployed_at), None
    except RequestNotMetError as exc:
        return None, str(exc)


def _parse_deployed_at(text: str | None) -> tuple[str, float] | None:
    """``--deployed-at JOINT=VALUE`` (degrees, or a length), or None without the flag."""
    return parse_joint_value(text, "--deployed-at", "A=128.6822")


def _load(spec: str, params: dict[str, Any], closure_tol: float | None) -> LoadedSpec:
    """The spec, assembled accepting a closure misfit within ``closure_tol`` (play in the hinges; ``None``:
    :func:`~linkwork.io.spec.resolve_spec`'s default closure)."""
    from linkwork.io.spec import resolve_spec

    if closure_tol is None:
        return resolve_spec(spec, params)
    return resolve_spec(spec, params, closure_tol=closure_tol)


def _limits_in_api_units(
    mech: Mechanism, limits_file: dict[str, tuple[float, float]]
) -> dict[str, tuple[float, float]]:
    """``--limit`` values (degrees, or lengths) in the API's units (radians), each checked against the start."""
    import numpy as np

    limits = {}
    for name, (lo, hi) in limits_file.items():
        j = mech.index(name)
        scale = np.radians(1.0) if mech.joint_types[j] == "R" else 1.0
        start = float(mech.offsets[j] / scale)
        if not lo <= start <= hi:
            raise fail(f"--limit {name}={lo:g}:{hi:g}: the start value {start:.6g} of {name} is outside it")
        limits[name] = (float(lo * scale), float(hi * scale))
    return limits


def _run_with_progress(run: Callable[..., Trace], mech: Mechanism, total: int, **options: Any) -> Trace:
    """``run(mech, **options, progress=...)`` with a progress bar of the steps on a terminal (none otherwise)."""
    with progress_bar("tracing", total) as report:  # steps so far, against the paper steps or the budget
        return run(mech, **options, progress=report)
