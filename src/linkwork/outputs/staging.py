"""Safe output for the commands' summaries and folders: the console every summary is printed on, and the one
writer (:mod:`linkwork.io.writer`: staging, ownership through the manifest, no writing through links), re-exported
here for the output modules."""

from __future__ import annotations

import os
import re
import sys
from typing import Any

from rich.align import AlignMethod
from rich.console import Console, ConsoleDimensions
from rich.rule import Rule
from rich.style import Style
from rich.text import Text

from linkwork.io.writer import MANIFEST, check_output_file, check_output_folder, staged_output, write_file

__all__ = [
    "MANIFEST",
    "check_output_file",
    "check_output_folder",
    "console",
    "have_matplotlib",
    "staged_output",
    "write_file",
]

RULE_WIDTH = 120
"""The widest a section rule is drawn (characters)."""

FILE_WIDTH = 10_000
"""The width (characters) of the console when standard output is a file or a pipe and ``COLUMNS`` is not set."""


_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f\u0085\u2028\u2029]")


def _escaped(text: str) -> str:
    """``text`` with every control character but a line break and a tab written as an escape."""
    return _CONTROL.sub(lambda m: repr(m.group(0))[1:-1], text)


CLOSED_PIPE = 141
"""The exit code of a command whose standard output was closed by its reader (``128 + SIGPIPE``)."""


class _SummaryConsole(Console):
    """A console as wide as a terminal on a terminal, and :data:`FILE_WIDTH` wide on a file or a pipe (unless
    ``COLUMNS`` says otherwise), so a table saved to a file keeps its full headers and rows ("transmission", not
    "transmiss...") instead of being squeezed into 80 columns."""

    def __init__(self, **options: Any) -> None:
        super().__init__(**options)
        # rich fixes the width from ``COLUMNS`` once, when the console is made (at import); the summaries read it
        # when they print, so a caller (a test runner, a notebook) that sets or clears it later is obeyed.
        if "width" not in options:
            self._width = None
        if "height" not in options:
            self._height = None

    @property
    def size(self) -> ConsoleDimensions:
        size = super().size
        if self.is_terminal or self._width is not None or "COLUMNS" in os.environ:
            return size
        return ConsoleDimensions(max(size.width, FILE_WIDTH), size.height)

    @size.setter
    def size(self, new_size: tuple[int, int]) -> None:
        self._width, self._height = new_size

    def print(self, *objects: Any, **options: Any) -> None:
        """Print as rich does, with the control characters of every plain string escaped (``\\x1b``) but line
        breaks and tabs: a path or a name a user gave (``-o $'a\\x1b[31m'``) can never send escape sequences to
        the terminal or move the cursor (``\\r``) from a summary line.

        A line of text is never broken by the console (``soft_wrap``): with ``COLUMNS=10`` in the environment of
        a pipe, rich broke ``wrote ... to /tmp/a-long/folder/`` inside the path and the file names, so a script
        reading the line read another path; a terminal still wraps a long line for the eye. Tables keep the
        console's width."""
        if "soft_wrap" not in options and all(isinstance(o, str | Text) for o in objects):
            options["soft_wrap"] = True
        super().print(*(_escaped(o) if isinstance(o, str) else o for o in objects), **options)

    def on_broken_pipe(self) -> None:
        """The reader of the standard output closed it (``linkwork linkages | head``): quiet from here on, as
        rich is, and exit code 141 (``128 + SIGPIPE``, the shell's code for a writer whose pipe closed, like 130
        and 143 for Ctrl-C and SIGTERM), not rich's 1, which linkwork's exit codes do not have. Whatever the
        command wrote to files before is kept."""
        self.quiet = True
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        raise SystemExit(CLOSED_PIPE)

    def rule(
        self,
        title: str | Text = "",
        *,
        characters: str = "\u2500",
        style: str | Style = "rule.line",
        align: AlignMethod = "center",
    ) -> None:
        """A horizontal rule no wider than :data:`RULE_WIDTH` (on a file or a pipe the console is
        :data:`FILE_WIDTH` wide for tables, which a rule would fill)."""
        rule = Rule(title, characters=characters, style=style, align=align)
        self.print(rule, width=min(self.size.width, RULE_WIDTH))


console: Console = _SummaryConsole(markup=False)
"""The console every summary is printed on (standard output). Markup is off: names, files and notes a user wrote
are printed as text (``[/]`` in a joint name is two brackets and a slash); styled words are :class:`rich.text.Text`."""


def have_matplotlib() -> bool:
    """True when the optional plotting extra (``linkwork[viz]``) is installed."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True
