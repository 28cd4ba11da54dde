"""Command-line options that several commands share, declared once (``typer`` annotations).

Each is the same flag with the same help wherever it appears; an option whose meaning differs between commands
is declared by its command.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

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
    typer.Option(help="Dask scheduler tcp://HOST:PORT (default $LINKWORK_SCHEDULER, else local processes)."),
]
"""``--scheduler``: where a study's tasks run."""

Workers = Annotated[
    int | None,
    typer.Option(help="Local worker processes (default: one per core; 0 runs in this process)."),
]
"""``--workers``: the local processes of a study."""
