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
        ("--drive", "QQ", ["J1", "D1 ... D7", "suffix a, m"]),
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


@pytest.mark.parametrize(
    ("flags", "named"),
    [
        (["--drive", "D99a"], ["D1 ... D", "J1"]),  # of the right form, but no design has 99 links
        (["--drive", "D1s"], ["suffix a, m"]),  # a slider's joint, but only RR links are asked for
        (["--drive", "A1s"], ["D1 ... D"]),  # the actuator's joint without `--actuator prismatic`
        (["--root", "s9b"], ["s1", "s2a"]),  # a body's form, not a body of this chain
    ],
)
def test_a_name_of_the_right_form_that_no_design_has_is_exit_2_before_any_search(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, flags: list[str], named: list[str]
) -> None:
    import sys

    mechanize_module = sys.modules["linkwork.mechanization.mechanize"]
    folder = _synth_folder(tmp_path)
    searched: list[object] = []
    monkeypatch.setattr(mechanize_module, "_search", lambda *a, **k: searched.append(a))
    run = CliRunner().invoke(_app(), [str(folder), *flags, "--no-plots"])
    assert run.exit_code == 2, run.output
    for choice in named:
        assert choice in run.output.replace("\n", " "), (choice, run.output)
    assert searched == [] and not (folder / "mechanization.json").exists()


def test_every_link_joint_name_offered_is_one_a_design_can_have(tmp_path: Path) -> None:
    # the names check_names accepts are exactly the joints the designs of this chain get (the found design's
    # link joints are among them, and the count of links is the chain's mobility less one)
    from linkwork.mechanization import MechanizeOptions
    from linkwork.mechanization import mechanize as run_mechanize
    from linkwork.mechanization.chain import build_chain
    from linkwork.mechanization.mechanize import link_joints

    result = synthesize(load_problem(_synth_folder(tmp_path) / "problem" / "problem.toml"))
    chain = build_chain(result)
    found = run_mechanize(result, MechanizeOptions(designs=1))
    offered = set(link_joints(chain, MechanizeOptions()))
    made = {n for link in found.design.links for n in link.joint_names()}
    assert made <= offered
    assert len(found.design.links) == chain.mobility() - 1 == len(offered) // 2
