"""The mechanization flags shared by ``linkwork mechanize`` and ``linkwork synth`` (each is also a problem-file
key of the same name; a flag overrides the key).

The flags are declared once, in :data:`FLAGS`; :func:`with_mechanize_flags` adds them to a command's parameters
and hands the command the ones given, as problem-file values.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from functools import wraps
from typing import Annotated, Any

import typer

PANEL = "Mechanization (each also a problem-file key)"

Dof = Annotated[
    int | None, typer.Option(rich_help_panel=PANEL, help="Degrees of freedom (number of actuators); key dof.")
]
Drive = Annotated[
    str | None, typer.Option(rich_help_panel=PANEL, help="The driven joint (default: chosen); key drive.")
]
Root = Annotated[
    str | None,
    typer.Option(rich_help_panel=PANEL, help="The chain body guided first (default: tried in turn)."),
]
Anchors = Annotated[
    str | None,
    typer.Option(
        rich_help_panel=PANEL, help="Dyads to 'ground', between bodies too ('any'), or 'auto'; key anchors."
    ),
]
Actuator = Annotated[
    str | None,
    typer.Option(
        rich_help_panel=PANEL, help="'revolute' (a crank) or 'prismatic' (a linear actuator); key actuator."
    ),
]
BinaryLinks = Annotated[
    str | None,
    typer.Option(
        help="'revolute' (RR dyads), 'prismatic' (PR sliders on guides) or 'both'; key binary_links."
    ),
]
GroundRegion = Annotated[
    str | None,
    typer.Option(
        help="Fixed pivots only in XMIN,YMIN,XMAX,YMAX, in a polygon X1,Y1;X2,Y2;X3,Y3;... (profile units), or "
        "'inside': every pivot, fixed and moving, and every link inside every profile; key ground_region."
    ),
]
LinkOffset = Annotated[
    float | None,
    typer.Option(
        rich_help_panel=PANEL,
        help="Moving pivots up to this many body lengths off the chain; key link_offset.",
    ),
]
MaxLink = Annotated[
    float | None,
    typer.Option(
        rich_help_panel=PANEL,
        help="Longest link, a length in the profiles' units (default 1.5 times their largest extent); key "
        "max_link.",
    ),
]
MaxLinkFraction = Annotated[
    float | None,
    typer.Option(
        rich_help_panel=PANEL,
        help="Longest link as a multiple of the profiles' largest extent (instead of --max-link); key "
        "max_link_fraction.",
    ),
]
MaxStructuralError = Annotated[
    float | None,
    typer.Option(
        rich_help_panel=PANEL,
        help="Largest structural error of a least-squares link (more than five profiles): the spread of the "
        "length it would need across the profiles, profile units; key max_structural_error.",
    ),
]
MinTransmission = Annotated[
    float | None,
    typer.Option(rich_help_panel=PANEL, help="Smallest transmission angle (degrees); key min_transmission."),
]
Attempts = Annotated[
    int | None, typer.Option(rich_help_panel=PANEL, help="Designs traced at most per root and anchor choice.")
]
Designs = Annotated[
    int | None,
    typer.Option(
        rich_help_panel=PANEL,
        help="Passing designs to find and rank by quality factor (1: the first); key designs.",
    ),
]
TimeLimit = Annotated[
    float | None,
    typer.Option(rich_help_panel=PANEL, help="Seconds after which the search stops; key time_limit."),
]


FLAGS: dict[str, Any] = {
    "dof": Dof,
    "drive": Drive,
    "root": Root,
    "anchors": Anchors,
    "actuator": Actuator,
    "binary_links": BinaryLinks,
    "ground_region": GroundRegion,
    "link_offset": LinkOffset,
    "max_link": MaxLink,
    "max_link_fraction": MaxLinkFraction,
    "max_structural_error": MaxStructuralError,
    "min_transmission": MinTransmission,
    "attempts": Attempts,
    "designs": Designs,
    "time_limit": TimeLimit,
}
"""Each mechanization flag's parameter name and its typer annotation, in the order ``--help`` lists them."""


def with_mechanize_flags(after: str) -> Callable[[Callable[..., None]], Callable[..., None]]:
    """Add the mechanization flags of :data:`FLAGS` to a command, after its parameter ``after``.

    The decorated command declares a keyword parameter ``flags`` instead of the flags; it receives the
    flags given on the command line as problem-file values (see :func:`flag_values`).
    """

    def decorate(command: Callable[..., None]) -> Callable[..., None]:
        signature = inspect.signature(command, eval_str=True)
        own = [p for p in signature.parameters.values() if p.name != "flags"]
        at = [p.name for p in own].index(after) + 1
        added = [
            inspect.Parameter(
                name, inspect.Parameter.POSITIONAL_OR_KEYWORD, default=None, annotation=annotation
            )
            for name, annotation in FLAGS.items()
        ]

        @wraps(command)
        def run(*args: Any, **kwargs: Any) -> None:
            given = {name: kwargs.pop(name, None) for name in FLAGS}
            command(*args, flags=flag_values(**given), **kwargs)

        parameters = own[:at] + added + own[at:]
        run.__signature__ = signature.replace(parameters=parameters)  # type: ignore[attr-defined]
        run.__annotations__ = {p.name: p.annotation for p in parameters} | {"return": None}
        return run

    return decorate


def flag_values(**flags: Any) -> dict[str, Any]:
    """The flags given (not ``None``) as problem-file values; ``ground_region`` parsed from its text."""
    from linkwork.mechanization.options import parse_region_flag

    values = {key: value for key, value in flags.items() if value is not None}
    if "ground_region" in values:
        values["ground_region"] = parse_region_flag(values["ground_region"])
    return values
