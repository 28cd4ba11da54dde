"""The ``linkwork`` command line: a thin typer layer that parses, calls the API, prints and writes files.

Each command lives in its own module and imports the heavy parts of linkwork lazily, so ``linkwork --help``
stays fast.
"""

from __future__ import annotations

import logging
import sys
from collections.abc import Sequence
from typing import Annotated, Any

import typer

from linkwork.cli import (
    demo,
    export,
    help,
    kernels,
    linkages,
    mechanize,
    robustness,
    search,
    sweep,
    synth,
    trace,
)
from linkwork.cli.common import check_flags, environment_misuse, fail, option_misuse
from linkwork.interrupts import Interrupted, exit_code, install_safe_interrupt

try:  # typer >= 0.20 carries its own copy of click, whose exceptions are these
    from typer._click import exceptions as click_exceptions
except ImportError:  # pragma: no cover - older typer uses click itself
    from click import exceptions as click_exceptions  # type: ignore[no-redef]

EXIT_CODES = (
    "Exit codes: 0 done as asked; 2 bad input (one line on stderr names the file, key or flag and what was "
    "expected); 3 the request could not be met (target not reached, no design or mechanism passes): one line "
    "says why, and everything computed so far is written; 130 / 143 interrupted (Ctrl-C / SIGTERM; trace, "
    "robustness, sweep and search write what they computed, synth the best chain and mechanize the best mechanism "
    "found so far, marked incomplete); 141 the standard output closed by its reader (| head)."
)


class OneLineErrors(help.Group):
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
        check_flags(self)  # every numeric flag's bounds (cli/options.py), checked before any work starts
        given = list(sys.argv[1:] if args is None else args)
        misuse = option_misuse(self, given) or environment_misuse()
        if misuse is not None:
            if not standalone_mode:
                raise click_exceptions.UsageError(misuse)
            fail(misuse, code=2)
            sys.exit(2)
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
        except Interrupted as exc:  # SIGTERM before or after a command's own work (its own is caught there)
            fail(f"interrupted ({exc})", code=exit_code(exc.signum))
            sys.exit(exit_code(exc.signum))
        except (
            OSError
        ) as exc:  # printing the help or a usage line failed: the standard output is full or gone
            where = f"{exc.filename}" if exc.filename else "the standard output"
            fail(f"cannot write to {where} ({exc.strerror or exc})", code=3)
            sys.exit(3)
        sys.exit(code if isinstance(code, int) else 0)


app = typer.Typer(
    name="linkwork",
    help="Kinematics of shape-changing mechanisms: trace closed-loop linkages, synthesise shape-changing chains.",
    epilog=EXIT_CODES,
    cls=OneLineErrors,
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
app.command("trace", cls=help.Command)(trace.trace)
app.command("linkages", cls=help.Command)(linkages.linkages)
app.command("show", cls=help.Command)(linkages.show)
app.command("synth", cls=help.Command)(synth.synth)
app.command("mechanize", cls=help.Command)(mechanize.mechanize)
app.command("demo", cls=help.Command)(demo.demo)
app.command("robustness", cls=help.Command)(robustness.robustness)
app.command("sweep", cls=help.Command)(sweep.sweep)
app.command("search", cls=help.Command)(search.search)
app.command("compile", cls=help.Command)(kernels.compile_kernels)
app.add_typer(export.app, name="export")


def _print_version(value: bool) -> None:
    if value:
        from linkwork.version import __version__

        typer.echo(f"linkwork {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option(
            "--version", callback=_print_version, is_eager=True, help="Print linkwork's version and exit."
        ),
    ] = False,
) -> None:
    """Kinematics of shape-changing mechanisms: trace closed-loop linkages, synthesise shape-changing chains."""
    _announce_kernels()


def _announce_kernels() -> None:
    """Print the kernel announcements (``compiling kernels, first run only``) on stderr, once."""
    log = logging.getLogger("linkwork.jit")
    if not any(isinstance(h, _StderrNote) for h in log.handlers):
        log.addHandler(_StderrNote())
        log.setLevel(logging.INFO)


class _StderrNote(logging.Handler):
    """A logging handler that prints a record as one ``note:`` line on stderr."""

    def emit(self, record: logging.LogRecord) -> None:
        from linkwork.cli.common import err_console

        err_console.print(f"note: {record.getMessage()}", highlight=False, soft_wrap=True)


def main() -> None:
    """Entry point of the ``linkwork`` script: a cold run traces with the plain-Python kernels and compiles every
    kernel for the next run in a detached process (only the script does this; library calls, and the command
    group called from Python, compile in the foreground)."""
    misuse = environment_misuse()  # before numba is imported: it reads NUMBA_NUM_THREADS as it loads
    if misuse is not None:
        fail(misuse, code=2)
        sys.exit(2)
    from linkwork.kinematics import jit

    install_safe_interrupt()
    jit.enable_background_compile([sys.executable, "-c", kernels.BACKGROUND_COMMAND])
    app()
