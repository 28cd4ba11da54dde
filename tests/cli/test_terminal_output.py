"""What a user sees when a command's output is not a terminal (a file, a pipe, a notebook's captured cell):
tables keep their full headers and cells; and a mistyped built-in name gets the closest name suggested."""

from __future__ import annotations

import io
import re
from contextlib import redirect_stdout

import pytest
from rich.table import Table
from typer.testing import CliRunner

from linkwork.cli import app
from linkwork.linkages import REGISTRY

runner = CliRunner()
ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


def test_a_wide_table_printed_to_a_pipe_keeps_every_header(monkeypatch: pytest.MonkeyPatch) -> None:
    """Twelve long headers need about 180 characters; rich squeezed them into 80 ("transmiss…") before."""
    from linkwork.outputs.staging import console

    monkeypatch.delenv("COLUMNS", raising=False)
    headers = [f"transmission angle {k} (deg)" for k in range(12)]
    table = Table(title="wide")
    for h in headers:
        table.add_column(h)
    table.add_row(*[f"{k}.123456" for k in range(12)])
    buffer = io.StringIO()
    with redirect_stdout(buffer):
        assert not console.is_terminal
        console.print(table)
    text = buffer.getvalue()
    assert "…" not in text
    for h in headers:
        assert h in text


def test_linkages_listed_to_a_pipe_are_whole(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("COLUMNS", raising=False)
    result = runner.invoke(app, ["linkages"])
    assert result.exit_code == 0
    text = ANSI.sub("", result.stdout)
    assert "…" not in text
    for name, entry in REGISTRY.items():
        assert name in text and entry.summary in text  # one row per built-in, each summary on one line


@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_a_mistyped_built_in_gets_a_did_you_mean(name: str) -> None:
    """Every built-in's name with one letter dropped or two letters swapped suggests that built-in."""
    middle = len(name) // 2
    for typo in (
        name[:middle] + name[middle + 1 :],
        name[:middle] + name[middle + 1] + name[middle] + name[middle + 2 :],
    ):
        result = runner.invoke(app, ["trace", typo])
        assert result.exit_code == 2
        assert f"did you mean '{name}'?" in result.stderr, (typo, result.stderr)


def test_a_name_far_from_every_built_in_gets_no_suggestion() -> None:
    result = runner.invoke(app, ["trace", "zzqqxx"])
    assert result.exit_code == 2
    assert "did you mean" not in result.stderr and "built-ins are bennett" in result.stderr


def test_a_section_rule_printed_to_a_pipe_stays_a_line_wide(monkeypatch: pytest.MonkeyPatch) -> None:
    """The console is 10,000 characters wide on a pipe (for tables); a rule (the demo's section titles) must not
    fill that: at most RULE_WIDTH characters, title included."""
    from rich.text import Text

    from linkwork.outputs.staging import RULE_WIDTH, console

    monkeypatch.delenv("COLUMNS", raising=False)
    buffer = io.StringIO()
    with redirect_stdout(buffer):
        console.file = buffer
        try:
            console.rule(Text("1. Tracing", style="bold"))
        finally:
            console.file = None  # type: ignore[assignment]
    lines = [ANSI.sub("", line) for line in buffer.getvalue().splitlines() if line.strip()]
    assert len(lines) == 1 and "1. Tracing" in lines[0] and 40 <= len(lines[0]) <= RULE_WIDTH
