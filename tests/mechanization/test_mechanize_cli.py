"""`linkwork mechanize DIR` on a synth output folder of the wing (mechanize.toml variant)."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from linkwork.cli.mechanize import mechanize
from linkwork.data import example
from linkwork.io.problem import load_problem
from linkwork.outputs.synthesis import write_synthesis_outputs
from linkwork.synthesis import synthesize

from .geometry_checks import joint_positions

EXAMPLES = example("wing").parents[1]  # the bundled example sets


def _synth_folder(tmp_path: Path) -> Path:
    folder = tmp_path / "wing"
    problem = folder / "problem"
    shutil.copytree(EXAMPLES / "wing", problem)
    shutil.copy(problem / "mechanize.toml", problem / "problem.toml")
    write_synthesis_outputs(synthesize(load_problem(problem / "problem.toml")), folder, plots=False)
    return folder


def _app() -> typer.Typer:
    app = typer.Typer()
    app.command()(mechanize)
    return app


def test_mechanize_command_writes_the_mechanism_and_report(tmp_path: Path) -> None:
    folder = _synth_folder(tmp_path)
    run = CliRunner().invoke(_app(), [str(folder), "--no-plots", "--designs", "1"])
    assert run.exit_code == 0, run.output
    report = json.loads((folder / "mechanization.json").read_text())
    chain = json.loads((folder / "chain.json").read_text())
    assert report["dof"] == 1
    assert (folder / "mechanism.toml").is_file()
    for j, profile in enumerate(report["profiles"]):
        # exact three-position guidance: the wing's shape error is the joined chain's (chord ~1)
        assert abs(profile["e_max"] - max(chain["joined"]["error_matrix"][e][j] for e in range(4))) <= 1e-9
        assert profile["joined_e_max"] == max(chain["joined"]["error_matrix"][e][j] for e in range(4))
        # every link's two pivots in this profile's pose, against the joints of the written spec placed by the
        # kinematic core at this profile's joint values (1e-9 of a chord)
        at = joint_positions(folder, profile["angles"])
        assert set(profile["pivots"]) == {d["name"] for d in report["dyads"]}
        for dyad in report["dyads"]:
            anchor, moving = profile["pivots"][dyad["name"]]
            names = dyad["joints"]
            np.testing.assert_allclose(anchor, at[names[0]], rtol=0, atol=1e-9)
            np.testing.assert_allclose(moving, at[names[-1]], rtol=0, atol=1e-9)
            if dyad["type"] == "RR":
                assert abs(math.dist(anchor, moving) - dyad["length"]) <= 1e-9
    limits = report["limits"]
    assert limits["max_link"] == 1.5 * limits["largest_extent"]  # the default: 1.5 times the largest extent
    assert all(d["length"] <= limits["max_link"] for d in report["dyads"])
    assert "E_max mechanism" in run.output and "longest link allowed" in run.output


def test_bad_option_is_one_line_and_exit_code_2(tmp_path: Path) -> None:
    folder = _synth_folder(tmp_path)
    run = CliRunner().invoke(_app(), [str(folder), "--ground-region", "1,2,3"])
    assert run.exit_code == 2
    assert "--ground-region" in run.output
    assert not (folder / "mechanization.json").exists()


def test_bad_flags_stop_before_the_synthesis_is_run_again(tmp_path: Path, monkeypatch) -> None:
    import linkwork.synthesis as synthesis

    folder = _synth_folder(tmp_path)
    runs: list[object] = []
    monkeypatch.setattr(synthesis, "synthesize", lambda *a, **k: runs.append(a))
    for flag, value in (("--ground-region", "1,2,3"), ("--min-transmission", "120"), ("--max-link", "-1")):
        run = CliRunner().invoke(_app(), [str(folder), flag, value, "--no-plots"])
        assert run.exit_code == 2, (flag, run.output)
        assert flag.lstrip("-").replace("-", "_") in run.output or flag in run.output
    assert runs == []  # every mistake was found from the problem and the flags alone


@pytest.mark.parametrize(
    ("flag", "value", "named"),
    [
        ("--drive", "QQ", ["J1", "D<k>a", "A1s"]),
        ("--root", "QQ", ["s1", "s2a"]),
        ("--anchors", "QQ", ["'ground'", "'any'"]),
    ],
)
def test_an_unknown_drive_root_or_anchor_is_exit_2_naming_the_choices(
    tmp_path: Path, flag: str, value: str, named: list[str]
) -> None:
    folder = _synth_folder(tmp_path)
    run = CliRunner().invoke(_app(), [str(folder), flag, value, "--no-plots"])
    assert run.exit_code == 2, run.output
    assert flag in run.output.replace("\n", "") or flag.lstrip("-") in run.output
    for choice in named:
        assert choice.strip("'") in run.output, (choice, run.output)
    assert not (folder / "mechanization.json").exists()
