"""Shared machinery of the fuzz suite: the hypothesis settings (fixed seed, a small budget in CI) and the one
checker of the command line's promises.

Run longer locally with ``LINKWORK_FUZZ_EXAMPLES=2000 python -m pytest tests/fuzz`` (see docs/testing.md).
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, settings
from typer.testing import CliRunner

from linkwork.cli import app

#: Examples per property: a couple of minutes for the whole suite in CI; raise it to search longer.
EXAMPLES = int(os.environ.get("LINKWORK_FUZZ_EXAMPLES", "20"))

#: The settings of every property: derandomized (the same examples on every run, so CI is reproducible and a
#: failure can be rerun), no per-example deadline (the machine may be loaded), no example database.
FUZZ = settings(
    max_examples=EXAMPLES,
    derandomize=True,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)

ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")

#: Hostile strings: rich markup, HTML that would run, comment and script terminators, line and paragraph
#: separators, control characters, quotes, a long name.
HOSTILE_TEXT = [
    "[/]",
    "[/italic]",
    "[bold]x",
    "<u>x</u>",
    '"><img src=x onerror=window.__pwned=1>',
    "<!--",
    "</script><script>window.__pwned=1</script>",
    "a\nb",
    "a\u2028b\u2029c",
    "tab\there",
    "\x1b[31mred",
    "'quote\"",
    "A" * 5000,
    "ümlaut ∑",
    "..",
    "a/b",
]


@dataclass(frozen=True)
class Run:
    """One command run: exit code, standard output and standard error (ANSI codes removed)."""

    code: int
    stdout: str
    stderr: str


def tree(folder: Path) -> dict[str, bytes | None]:
    """Every entry under ``folder`` with a file's bytes (``None`` for a folder)."""
    if not folder.exists():
        return {}
    return {
        str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else None)
        for p in sorted(folder.rglob("*"))
    }


def run_cli(args: list[str], *, out: Path | None = None, home: Path | None = None) -> Run:
    """Run ``linkwork ARGS`` in-process and check the promises of every command.

    Exit code 0, 2 or 3; no traceback; for 2 and 3 exactly one ``error:`` line on stderr (no warning next to
    it; a ``note:`` line such as the one-time kernel compilation notice may precede it); for 2, ``out``
    unchanged; nothing under ``home`` touched except inside ``out``.
    """
    before_out = tree(out) if out is not None else {}
    before_home = _outside(home, out)
    result = CliRunner().invoke(app, args)
    run = Run(result.exit_code, ANSI.sub("", result.stdout), ANSI.sub("", result.stderr))
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        raise AssertionError(f"linkwork {args!r:.300} raised {result.exception!r:.300}") from result.exception
    assert run.code in (0, 2, 3), (args, run)
    assert "Traceback" not in run.stdout + run.stderr
    if run.code in (2, 3):
        # "note:" lines (the one-time "compiling kernels" announcement) are not part of the error
        lines = [line for line in run.stderr.strip("\n").split("\n") if not line.startswith("note: ")]
        assert len(lines) == 1 and lines[0].startswith("error: "), (args, run.stderr[:2000])
        assert "Warning" not in run.stderr
    if run.code == 2 and out is not None:
        assert tree(out) == before_out, f"--out changed on exit 2: {args!r:.300}"
    assert _outside(home, out) == before_home, f"something outside --out changed: {args!r:.300}"
    return run


def _outside(home: Path | None, out: Path | None) -> dict[str, bytes | None]:
    if home is None:
        return {}
    everything = tree(home)
    if out is None:
        return everything
    try:
        inside = str(out.resolve().relative_to(home.resolve()))
    except ValueError:
        return everything
    return {k: v for k, v in everything.items() if not (k == inside or k.startswith(inside + os.sep))}


def one_line_error(call: Callable[[], object], kinds: tuple[type[BaseException], ...]) -> str | None:
    """Call; ``None`` when it returns, the message when it raises one of ``kinds`` (checked to be one line)."""
    try:
        call()
    except kinds as exc:
        message = str(exc)
        assert "\n" not in message and "\r" not in message, message[:500]
        assert "\u2028" not in message and "\u2029" not in message
        return message
    return None


def finite(points: np.ndarray) -> bool:
    """True when every coordinate is finite."""
    return bool(np.all(np.isfinite(points)))
