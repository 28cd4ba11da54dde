"""``linkwork linkages`` lists the built-in linkages; ``linkwork show`` prints one (or a spec file) as TOML."""

from __future__ import annotations

from typing import Annotated

import typer

from linkwork.cli import options as opt
from linkwork.cli.common import friendly_errors, parse_assignments
from linkwork.outputs.staging import console


@friendly_errors
def linkages() -> None:
    """List the built-in linkages with their parameters (angles in degrees)."""
    from rich.table import Table

    from linkwork.linkages import REGISTRY

    table = Table(title="built-in linkages", title_justify="left")
    table.add_column("name", style="bold")
    table.add_column("parameters (defaults)")
    table.add_column("what it is")
    for name in sorted(REGISTRY):
        entry = REGISTRY[name]
        defaults = entry.file_defaults()
        params = "\n".join(
            f"{k} = {_default_text(defaults[k])}{' deg' if p.unit == 'deg' else ''}: {p.help}"
            for k, p in entry.params.items()
        )
        table.add_row(name, params or "-", entry.summary)
    console.print(table)
    console.print("use: linkwork trace NAME --set KEY=VALUE ...   or   linkwork show NAME > my.toml")


def _default_text(value: float | int | str) -> str:
    """A default as the table prints it: numbers with ``:g``, text quoted as in a TOML file."""
    return f'"{value}"' if isinstance(value, str) else f"{value:g}"


@friendly_errors
def show(
    spec: Annotated[str, typer.Argument(help="A built-in name or a TOML spec file.")],
    set_: opt.SetParams = None,
) -> None:
    """Print a linkage as a TOML spec file (its joints' axes at the start), ready to edit and trace."""
    from linkwork.io.spec import dump_spec, resolve_spec

    loaded = resolve_spec(spec, parse_assignments(set_, "--set"))
    typer.echo(dump_spec(loaded.mechanism), nl=False)
