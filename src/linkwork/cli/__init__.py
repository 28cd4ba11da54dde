"""The ``linkwork`` command line: a thin typer layer that parses, calls the API, prints and writes files.

Each command lives in its own module and imports the heavy parts of linkwork lazily, so ``linkwork --help``
stays fast.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from typing import Any

import typer
from typer.core import TyperGroup

from linkwork.cli import demo, linkages, mechanize, synth, trace
from linkwork.cli.common import fail

try:  # typer >= 0.20 carries its own copy of click, whose exceptions are these
    from typer._click import exceptions as click_exceptions
except ImportError:  # pragma: no cover - older typer uses click itself
    from click import exceptions as click_exceptions  # type: ignore[no-redef]


class OneLineErrors(TyperGroup):
    """The command group, with click's usage errors (an unknown flag, a value of the wrong type) printed as the
    one ``error:`` line and exit code 2 that every other bad input gets, instead of click's framed usage box."""

    def main(
        self,
        args: Sequence[str] | None = None,
        prog_name: str | None = None,
        complete_var: str | None = None,
        standalone_mode: bool = True,
        windows_expand_args: bool = True,
        **extra: Any,
    ) -> Any:
        if not standalone_mode:
            return super().main(args, prog_name, complete_var, False, windows_expand_args, **extra)
        try:
            code = super().main(args, prog_name, complete_var, False, windows_expand_args, **extra)
        except click_exceptions.NoArgsIsHelpError as exc:
            exc.show()  # no command or argument at all: the help is the answer
            sys.exit(exc.exit_code)
        except click_exceptions.ClickException as exc:
            fail(exc.format_message(), code=2)
            sys.exit(2)
        except typer.Abort:
            fail("aborted", code=1)
            sys.exit(1)
        sys.exit(code if isinstance(code, int) else 0)


app = typer.Typer(
    cls=OneLineErrors,
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


def main() -> None:
    """Entry point of the ``linkwork`` script."""
    app()
