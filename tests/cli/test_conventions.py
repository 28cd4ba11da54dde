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
