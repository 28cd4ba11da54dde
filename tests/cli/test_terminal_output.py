"""What a user sees when a command's output is not a terminal (a file, a pipe, a notebook's captured cell):
tables keep their full headers and cells; and a mistyped built-in name gets the closest name suggested."""

from __future__ import annotations

import io
import re
from contextlib import redirect_stdout
from pathlib import Path

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


HOSTILE_OUT = "a\x1b[31mred\rX"
"""An output name with an escape sequence (red text) and a carriage return (the cursor back to the line's start)."""


@pytest.mark.parametrize(
    "command",
    [
        ["trace", "bennett", "--no-plots", "--max-steps", "10", "-o", "{dir}"],
        ["export", "stl", "{trace}", "-o", "{dir}.stl"],
        ["export", "mjcf", "{trace}", "-o", "{dir}.xml"],
        ["export", "dxf", "{trace}", "-o", "{dir}.dxf"],
        ["sweep", "{study}", "--workers", "0", "--no-plots", "-o", "{dir}"],
    ],
    ids=lambda c: " ".join(c[:2]),
)
def test_a_users_path_in_a_summary_line_sends_no_control_characters(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, command: list[str]
) -> None:
    """``wrote ... to OUT/`` printed the --out a user gave as it was: ``-o $'a\\x1b[31m...'`` turned the terminal
    red and ``\\r`` moved the cursor. Every summary goes through the one console, which escapes them."""
    monkeypatch.chdir(tmp_path)
    trace = tmp_path / "t"
    assert (
        runner.invoke(
            app, ["trace", "four-bar", "--no-plots", "--max-steps", "10", "-o", str(trace)]
        ).exit_code
        == 0
    )
    study = tmp_path / "study.toml"
    study.write_text('linkage = "bennett"\n[trace]\nuntil = "A=90"\nsteps = 5\n[grid]\nalpha1 = [30]\n')
    args = [a.format(dir=HOSTILE_OUT, trace=trace, study=study) for a in command]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.stderr
    assert "\x1b" not in result.stdout and "\r" not in result.stdout
    assert "a\\x1b[31mred\\rX" in result.stdout


def test_a_closed_standard_output_ends_the_command_with_141_quietly() -> None:
    """``linkwork linkages | head``: the reader closes the pipe before linkwork writes its table; the command
    ends with exit code 141 (``128 + SIGPIPE``, as the README's exit codes say) and nothing on stderr (rich's own
    handling exits 1, a code linkwork does not have; Python's would print a BrokenPipeError traceback)."""
    import subprocess
    import sys

    from linkwork.outputs.staging import CLOSED_PIPE

    with subprocess.Popen(
        [sys.executable, "-c", "from linkwork.cli import app; app()", "linkages"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    ) as proc:
        assert proc.stdout is not None and proc.stderr is not None
        proc.stdout.close()  # before the table is written: importing linkwork takes far longer than this
        err = proc.stderr.read()
        assert proc.wait(timeout=120) == CLOSED_PIPE == 141
    assert err == b""
