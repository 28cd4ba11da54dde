"""Command-line conventions shared by every command: ``--version``; ``-o`` for ``--out``; help pages without
``<bool>`` or ``<list[...]>`` placeholders; bundled examples by name; the exit codes documented in ``--help`` and
in the README; kernel announcements on stderr."""

from __future__ import annotations

import json
import re
from importlib.metadata import version
from pathlib import Path

import pytest
import typer.main
from typer.testing import CliRunner

import linkwork
from linkwork.cli import app

runner = CliRunner()
COMMANDS = sorted(typer.main.get_command(app).commands)  # type: ignore[attr-defined]
README = Path(__file__).resolve().parents[2] / "README.md"


def test_version_is_the_installed_distributions() -> None:
    result = runner.invoke(app, ["--version"])
    assert result.exit_code == 0
    assert result.stdout.strip() == f"linkwork {linkwork.__version__}"
    assert linkwork.__version__ == version("linkwork")


@pytest.mark.parametrize("command", [None, *COMMANDS])
def test_help_has_no_python_type_placeholders(command: str | None) -> None:
    result = runner.invoke(app, [*([command] if command else []), "--help"])
    assert result.exit_code == 0, result.stderr
    assert "<bool>" not in result.stdout
    assert "<list" not in result.stdout
    assert "Show this message and exit." in result.stdout


@pytest.mark.parametrize("command", COMMANDS)
def test_every_out_option_has_the_short_form(command: str) -> None:
    cli = typer.main.get_command(app).commands[command]  # type: ignore[attr-defined]
    subcommands = getattr(cli, "commands", None)  # a group (export): every subcommand writes a file
    for sub in subcommands.values() if subcommands else [cli]:
        for param in sub.params:
            if "--out" in param.opts:
                assert "-o" in param.opts, f"{command} --out has no -o"
        assert command in ("linkages", "show", "compile") or any("--out" in p.opts for p in sub.params)


def test_short_out_writes_where_asked(tmp_path: Path) -> None:
    result = runner.invoke(
        app, ["trace", "bennett", "--until", "A=80", "--no-plots", "-o", str(tmp_path / "t")]
    )
    assert result.exit_code == 0, result.stderr
    report = json.loads((tmp_path / "t" / "report.json").read_text())
    assert report["branches"][0]["end_reason"] == "reached target"


def test_synth_finds_a_bundled_example_by_name(tmp_path: Path) -> None:
    result = runner.invoke(app, ["synth", "closed", "--no-plots", "-o", str(tmp_path / "s")])
    assert result.exit_code == 0, result.stderr
    chain = json.loads((tmp_path / "s" / "chain.json").read_text())
    assert chain["kind"] == "closed" and len(chain["profiles"]) == 3


def test_synth_names_the_examples_when_nothing_matches(tmp_path: Path) -> None:
    result = runner.invoke(app, ["synth", "wingg", "-o", str(tmp_path / "s")])
    assert result.exit_code == 2
    assert len(result.stderr.strip().splitlines()) == 1
    assert "wing, closed, fixed-end, seat" in result.stderr
    assert not (tmp_path / "s").exists()


def test_exit_codes_are_documented_in_help_and_readme() -> None:
    text = " ".join(runner.invoke(app, ["--help"]).stdout.split())
    readme = " ".join(README.read_text(encoding="utf-8").split())
    for doc in (text, readme):
        assert re.search(r"\b`?0`? done as asked", doc)
        assert re.search(r"\b`?2`? bad input", doc)
        assert re.search(r"\b`?3`? the request could not be met", doc)


def test_a_cold_kernel_cache_is_announced_on_stderr(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from linkwork.kernel_cache import CACHE
    from linkwork.kinematics import jit, tracer

    monkeypatch.setenv("LINKWORK_JIT", "compiled")
    monkeypatch.setattr(CACHE, "ready", lambda group: False)
    monkeypatch.setattr(CACHE, "mark_ready", lambda groups: None)
    monkeypatch.setitem(jit._state, "loaded", False)
    monkeypatch.setattr(tracer, "warm_up", lambda: None)  # the kernels are compiled in this process already
    result = runner.invoke(
        app, ["trace", "bennett", "--until", "A=70", "--no-plots", "-o", str(tmp_path / "t")]
    )
    assert result.exit_code == 0, result.stderr
    assert "note: compiling kernels, first run only" in result.stderr
    assert "compiling" not in result.stdout


def test_compile_fills_the_cache_and_marks_every_group(monkeypatch: pytest.MonkeyPatch) -> None:
    from linkwork.cli import kernels
    from linkwork.kernel_cache import CACHE, GROUPS

    warmed: list[str] = []
    for group in GROUPS:  # stand-ins: the real warm-ups compile for minutes on a cold cache
        monkeypatch.setitem(kernels.WARM_UPS, group, lambda group=group: warmed.append(group))
    marked: list[str] = []
    monkeypatch.setattr(CACHE, "mark_ready", lambda groups: marked.extend(groups))
    monkeypatch.setattr(CACHE, "remove_stale", lambda: [])
    result = runner.invoke(app, ["compile"])
    assert result.exit_code == 0, result.stderr
    assert warmed == marked == list(GROUPS)
    assert f"kernels-{CACHE.key}" in result.stdout and "tracing: ready" in result.stdout


def _callbacks(command: object, path: str = "") -> list[tuple[str, object]]:
    """``(command path, callback)`` of every (sub)command of the built app."""
    subs = getattr(command, "commands", None)
    if subs is None:
        return [(path, getattr(command, "callback", None))]
    return [item for name, sub in subs.items() for item in _callbacks(sub, f"{path} {name}".strip())]


@pytest.mark.parametrize(("name", "callback"), _callbacks(typer.main.get_command(app)))
def test_every_command_runs_inside_friendly_errors(name: str, callback: object) -> None:
    """The one-line errors, the exit codes of OSErrors and the warnings as notes live in ``friendly_errors``:
    every command gets them only by being decorated with it (typer wraps the callback once more)."""
    from linkwork.cli.common import friendly_errors

    wrapper_code = friendly_errors(lambda: None).__code__
    codes, func = [], callback
    while func is not None:
        codes.append(getattr(func, "__code__", None))
        func = getattr(func, "__wrapped__", None)
    assert wrapper_code in codes, name


@pytest.mark.parametrize(
    "message", ["constrained_layout not applied", "two\nlines [red]markup[/red]", "x" * 5000]
)
def test_a_warning_while_a_command_runs_is_one_note_line(
    message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """A warning (matplotlib's layout warning, drawn for long profile names) was printed by Python as two lines,
    the second the source line of linkwork that drew the figure; now one ``note:`` line, markup as text."""
    import warnings

    from linkwork.cli.common import MAX_MESSAGE_CHARS, friendly_errors

    @friendly_errors
    def command() -> int:
        warnings.warn(message, UserWarning, stacklevel=1)
        return 0

    with warnings.catch_warnings():
        warnings.simplefilter("always")  # the test run turns warnings into errors; a user's run shows them
        assert command() == 0
    lines = capsys.readouterr().err.strip("\n").split("\n")
    assert len(lines) == 1 and lines[0].startswith("note: "), lines
    assert "warnings.warn" not in lines[0] and len(lines[0]) <= MAX_MESSAGE_CHARS + len("note: ")
    assert message.split("\n")[0][:50] in lines[0]


def test_a_joint_coupled_to_itself_is_refused(tmp_path: Path) -> None:
    """``--couple A=A`` couples nothing: it was traced as if absent (exit 0); a slip is bad input."""
    result = runner.invoke(
        app, ["trace", "bennett", "--couple", "A=B=A", "--no-plots", "-o", str(tmp_path / "t")]
    )
    assert result.exit_code == 2
    assert result.stderr.strip().splitlines() == [
        'error: --couple "A=B=A": names a joint twice; expected distinct joints, e.g. A=C=E'
    ]
    assert not (tmp_path / "t").exists()


def test_an_animation_without_figures_is_refused(tmp_path: Path) -> None:
    """``--animate --no-plots`` wrote no animation and said nothing (exit 0): the animation is one of the
    figures, so the pair contradicts itself; one line, exit 2, nothing written."""
    result = runner.invoke(app, ["trace", "four-bar", "--animate", "--no-plots", "-o", str(tmp_path / "t")])
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: --animate") and "--no-plots" in lines[0]
    assert not (tmp_path / "t").exists()


@pytest.mark.parametrize("kind", ["a file", "a name too long"])
def test_a_cache_folder_that_cannot_be_written_stops_compile_at_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, kind: str
) -> None:
    """``LINKWORK_CACHE_DIR`` naming a file (or a name too long): ``linkwork compile`` compiled for minutes and
    then failed, and every cold run started a background compile that could never be kept; now one line naming
    the folder (exit 2), and the background process stops before compiling anything."""
    from linkwork.cli import kernels
    from linkwork.kernel_cache import CACHE
    from linkwork.kinematics import jit

    bad = tmp_path / "cache"
    if kind == "a file":
        bad.write_text("the user's file\n", encoding="utf-8")
    else:
        bad = tmp_path / ("c" * 300)
    monkeypatch.setitem(CACHE.__dict__, "parent", bad)  # the cached property, as LINKWORK_CACHE_DIR sets it

    def never() -> None:
        raise AssertionError("compiled into a cache folder that cannot be written")

    monkeypatch.setattr(kernels, "compile_all", never)
    monkeypatch.setattr(jit, "hold_lock", never)
    result = runner.invoke(app, ["compile"])
    assert result.exit_code == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and "LINKWORK_CACHE_DIR" in lines[0]
    assert str(bad)[:60] in lines[0]
    kernels.compile_in_background()  # returns at once
    if kind == "a file":
        assert bad.read_text(encoding="utf-8") == "the user's file\n"


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full (Linux)")
@pytest.mark.parametrize("command", [None, *COMMANDS])
def test_help_into_a_full_standard_output_is_one_line(command: str | None) -> None:
    """``linkwork --help > /dev/full`` was a 60-line traceback from rich's buffer: the help is printed outside
    every command's ``friendly_errors``; now one line, exit 3 (the request could not be met)."""
    import subprocess
    import sys

    with open("/dev/full", "w", encoding="utf-8") as full:
        done = subprocess.run(
            [
                sys.executable,
                "-c",
                "from linkwork.cli import app; app()",
                *([command] if command else []),
                "--help",
            ],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            timeout=120,
        )
    assert done.returncode == 3, done.stderr
    assert done.stderr.strip().splitlines() == [
        "error: cannot write to the standard output (No space left on device)"
    ]
