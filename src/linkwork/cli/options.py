"""Command-line options that several commands share, declared once (``typer`` annotations).

Each is the same flag with the same help wherever it appears; an option whose meaning differs between commands
is declared by its command.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from linkwork import limits

SpecName = Annotated[
    str, typer.Argument(help="A TOML spec file or a built-in name (see `linkwork linkages`).")
]
"""The linkage: a spec file or a built-in's name."""

SetParams = Annotated[
    list[str] | None,
    typer.Option(
        "--set", help="Built-in parameter KEY=VALUE (angles in degrees); repeatable.", show_default=False
    ),
]
"""``--set KEY=VALUE``: a built-in linkage's parameters."""

Fixed = Annotated[
    list[str] | None,
    typer.Option(help="Hold a joint at its start value; repeatable.", show_default=False),
]
"""``--fixed J``: joints held at their start values."""

OutFolder = Annotated[Path, typer.Option("--out", "-o", help="Output folder.")]
"""``--out``: the folder a study or a trace writes into."""

NoPlots = Annotated[bool, typer.Option("--no-plots", help="Do not draw figures.")]
"""``--no-plots``: write the data files only."""

Scheduler = Annotated[
    str | None,
    typer.Option(
        help="Dask scheduler tcp://HOST:PORT (default $LINKWORK_SCHEDULER, else local processes); one that does "
        "not answer within $LINKWORK_CONNECT_TIMEOUT seconds (default 30) is an error."
    ),
]
"""``--scheduler``: where a study's tasks run."""

Workers = Annotated[
    int | None,
    typer.Option(
        help="Local worker processes (default: one per core; 0 runs in this process; at most os.cpu_count())."
    ),
]
"""``--workers``: the local processes of a study."""


#: The bounds of every numeric flag of every command, by flag name (a flag means the same wherever it appears).
#: :func:`linkwork.cli.common.check_flags` attaches them to the parsed command line, so a value outside is refused
#: before any work starts, in one line naming the flag and the bounds. A test fails when a numeric flag has none.
FLAG_LIMITS: dict[str, limits.Limit] = {
    "--steps": limits.STEPS,
    "--max-steps": limits.STEPS,
    "--max-step": limits.Limit("a number of degrees", limits.SMALLEST_STEP_DEGREES, 90.0),
    "--closure-tol": limits.Limit("a closure misfit", 0.0, limits.MAX_MAGNITUDE, open_low=True),
    "--samples": limits.SAMPLES,
    "--seed": limits.SEED,
    "--hinge-position-tol": limits.POSITION_TOL,
    "--hinge-direction-tol": limits.DIRECTION_TOL,
    "--workers": limits.WORKERS,
    "--dof": limits.MECHANIZE["dof"],
    "--link-offset": limits.MECHANIZE["link_offset"],
    "--max-link": limits.MECHANIZE["max_link"],
    "--max-link-fraction": limits.MECHANIZE["max_link_fraction"],
    "--max-structural-error": limits.MECHANIZE["max_structural_error"],
    "--gallery": limits.Limit("a number of candidates", 0, 500, whole=True),
    "--min-transmission": limits.MECHANIZE["min_transmission"],
    "--attempts": limits.MECHANIZE["attempts"],
    "--designs": limits.MECHANIZE["designs"],
    "--time-limit": limits.MECHANIZE["time_limit"],
    "--branch": limits.Limit("a branch number (see report.json)", 0, 1_000_000, whole=True),
    "--point": limits.Limit(
        "a point number (negative counts from the end)",
        -limits.MAX_TRACE_STEPS,
        limits.MAX_TRACE_STEPS,
        whole=True,
    ),
    "--scale": limits.Limit("a positive factor", 0.0, 1e9, open_low=True),
}
