"""The ``linkwork`` command line: a thin typer layer that parses, calls the API, prints and writes files.

Each command lives in its own module and imports the heavy parts of linkwork lazily, so ``linkwork --help``
stays fast.
"""

from __future__ import annotations

import typer

from linkwork.cli import demo, export, linkages, mechanize, robustness, sweep, synth, trace

app = typer.Typer(
    name="linkwork",
    help="Kinematics of shape-changing mechanisms: trace closed-loop linkages, synthesise shape-changing chains.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
app.command("trace")(trace.trace)
app.command("linkages")(linkages.linkages)
app.command("show")(linkages.show)
app.command("synth")(synth.synth)
app.command("mechanize")(mechanize.mechanize)
app.command("demo")(demo.demo)
app.command("robustness")(robustness.robustness)
app.command("sweep")(sweep.sweep)
app.add_typer(export.app, name="export")


def main() -> None:
    """Entry point of the ``linkwork`` script."""
    app()
