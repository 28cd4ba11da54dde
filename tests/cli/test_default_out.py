"""Without ``--out`` each run writes into its own folder, ``out/<what>-<command>/``, named after what it ran:
the README's commands (a trace of the hexagon, then of Guest's frame, then of a spec file) no longer overwrite each
other's results, and every command's ``--help`` states its default."""

from __future__ import annotations

import csv
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from linkwork.cli import app
from linkwork.cli.out_folder import problem_label, run_folder, safe_segment, spec_label

runner = CliRunner()
ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


def _trace(*args: str) -> None:
    result = runner.invoke(app, ["trace", *args, "--no-plots", "--max-steps", "30"])
    assert result.exit_code == 0, result.stderr


def _first_joint_values(folder: Path) -> list[str]:
    with open(folder / "path.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    return [row[3] for row in rows[1:4]]


def test_runs_of_different_linkages_and_parameters_get_different_folders(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    _trace("bennett")
    _trace("four-bar", "--drive", "A")
    _trace("hedgepeth-rods", "--set", "n=6")
    _trace("hedgepeth-rods", "--set", "n=8")
    folders = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert folders == [
        "bennett-trace",
        "four-bar-trace",
        "hedgepeth-rods-n=6-trace",
        "hedgepeth-rods-n=8-trace",
    ]
    # each folder holds its own run: the joints of path.csv are the linkage's own
    for name, joints in [
        ("bennett-trace", 4),
        ("hedgepeth-rods-n=6-trace", 6),
        ("hedgepeth-rods-n=8-trace", 8),
    ]:
        header = (tmp_path / "out" / name / "path.csv").read_text().splitlines()[0].split(",")
        assert len(header[3 : header.index("sigma_1")]) == joints
    assert _first_joint_values(tmp_path / "out" / "hedgepeth-rods-n=6-trace") != _first_joint_values(
        tmp_path / "out" / "hedgepeth-rods-n=8-trace"
    )


def test_a_spec_file_names_its_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, ["show", "bennett"])
    (tmp_path / "my bennett$1.toml").write_text(result.stdout)
    _trace("my bennett$1.toml")
    assert (tmp_path / "out" / "my_bennett_1-trace" / "path.csv").is_file()
    # a mechanism.toml that linkwork wrote is named after its folder
    _trace("out/my_bennett_1-trace/mechanism.toml")
    assert (tmp_path / "out" / "my_bennett_1-trace-trace" / "path.csv").is_file()


def test_names_are_one_plain_path_segment() -> None:
    assert spec_label("bennett") == "bennett"
    assert spec_label("Guest_Frame") == "guest-frame"
    assert spec_label("bennett", {"alpha1": 45.0, "alpha2": 75.5}) == "bennett-alpha1=45-alpha2=75.5"
    assert problem_label("wing") == "wing"
    assert problem_label("wing/mechanize.toml") == "wing-mechanize"
    assert problem_label("wing/problem.toml") == "wing"
    for hostile in ["../../etc", "a/b\\c", "\n\x1b[31m", "." * 5, "x" * 500, ""]:
        segment = safe_segment(hostile)
        assert segment and "/" not in segment and "\\" not in segment and not segment.startswith(".")
        assert len(segment) <= 80 and re.fullmatch(r"[A-Za-z0-9._=+-]+", segment)
        assert run_folder("trace", hostile).parent == Path("out")


@pytest.mark.parametrize(
    ("command", "example"),
    [
        ("trace", "hedgepeth-rods-n=6"),
        ("robustness", "hedgepeth-rods-n=6"),
        ("synth", "wing"),
        ("sweep", "bennett-twists"),
    ],
)
def test_every_help_states_its_default_folder(command: str, example: str) -> None:
    result = runner.invoke(app, [command, "--help"], env={"COLUMNS": "200"})
    text = " ".join(ANSI.sub("", result.stdout).split())
    assert f"default: out/NAME-{command}/" in text and f"out/{example}-{command}/" in text
