"""Flags that name a joint: an unknown joint, paper mode without a target, a value that is not a number, each one
line naming the flag, exit 2, nothing written, on every built-in (the audit found the API's words instead:
"unknown joint 'E'" with no flag, "needs until=(joint, value)")."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

import linkwork as lw
from linkwork.cli import app
from linkwork.linkages import REGISTRY

runner = CliRunner()
ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")
BUILTINS = sorted(REGISTRY)


def error_line(args: list[str]) -> str:
    result = runner.invoke(app, args)
    text = ANSI.sub("", result.stderr).strip().splitlines()
    text = [line for line in text if not line.startswith("note:")]
    assert "Traceback" not in result.stdout + result.stderr
    assert result.exit_code == 2, (result.exit_code, text)
    assert len(text) == 1, text
    return text[0]


@pytest.mark.parametrize("name", BUILTINS)
@pytest.mark.parametrize("flag", ["--until", "--drive", "--deployed-at"])
def test_an_unknown_joint_names_the_flag_and_the_joints(tmp_path: Path, name: str, flag: str) -> None:
    joints = lw.load(name).joint_names
    value = "ZZ=10" if flag != "--drive" else "ZZ"
    out = tmp_path / "out"
    line = error_line(["trace", name, flag, value, "--no-plots", "-o", str(out)])
    assert line.startswith(f'error: {flag} "ZZ": unknown joint; expected one of ')
    assert line.endswith(", ".join(joints))
    assert not out.exists()


def test_steps_without_until_names_both_flags(tmp_path: Path) -> None:
    line = error_line(["trace", "four-bar", "--steps", "10", "--no-plots", "-o", str(tmp_path / "out")])
    assert "--steps 10" in line and "--until JOINT=VALUE" in line


def test_a_value_that_is_not_a_number_says_degrees_or_a_length(tmp_path: Path) -> None:
    line = error_line(
        ["trace", "slider-crank", "--until", "D=abc", "--no-plots", "-o", str(tmp_path / "out")]
    )
    assert "degrees (a length for a prismatic joint)" in line
