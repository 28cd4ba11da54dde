"""The README's workflow as a user runs it: `linkwork synth` then `linkwork mechanize OUT`, and a mechanization
that fails inside `synth` (exit 3, one line naming the closest design) keeping the chain it wrote."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import typer
from typer.testing import CliRunner

from linkwork.cli.mechanize import mechanize
from linkwork.cli.synth import synth

WING = Path(__file__).resolve().parents[2] / "examples" / "wing"


def _app(command: object) -> typer.Typer:
    app = typer.Typer()
    app.command()(command)  # type: ignore[arg-type]
    return app


def _wing_problem(tmp_path: Path, name: str = "mechanize.toml") -> Path:
    folder = tmp_path / "in"
    shutil.copytree(WING, folder)
    return folder / name


def test_failed_mechanization_keeps_the_chain_and_names_the_closest_design(tmp_path: Path) -> None:
    out = tmp_path / "out"
    # fixed pivots only in a small box at the nose: no design of the search passes
    args = [
        str(_wing_problem(tmp_path)),
        "-o",
        str(out),
        "--no-plots",
        "--ground-region",
        "0,-0.01,0.02,0.01",
    ]
    run = CliRunner().invoke(_app(synth), [*args, "--time-limit", "20", "--attempts", "2"])
    assert run.exit_code == 3, run.output
    message = run.output.strip().splitlines()[-1]
    assert message.startswith("error: mechanize: no design passes") and "closest: " in message
    chain = json.loads((out / "chain.json").read_text())
    assert chain["design"] == "MCMC"
    assert (out / "problem" / "problem.toml").is_file() and (out / "problem" / "cruise.dat").is_file()
    assert not (out / "mechanism.toml").exists() and not (out / "mechanization.json").exists()
    assert not list(tmp_path.glob(".linkwork-*"))  # no staging folder left behind


def test_mechanize_runs_on_the_folder_of_a_plain_synth(tmp_path: Path) -> None:
    out = tmp_path / "out"
    plain = _wing_problem(tmp_path).with_name("plain.toml")  # the MCMC wing without `mechanize = true`
    plain.write_text(plain.with_name("mechanize.toml").read_text().replace("mechanize = true\n", ""))
    run = CliRunner().invoke(_app(synth), [str(plain), "-o", str(out), "--no-plots"])
    assert run.exit_code == 0, run.output
    assert not (out / "mechanism.toml").exists()
    run = CliRunner().invoke(_app(mechanize), [str(out), "--no-plots", "--html", "--designs", "2"])
    assert run.exit_code == 0, run.output
    report = json.loads((out / "mechanization.json").read_text())
    assert report["dof"] == 1 and report["verification"]["passed"]
    assert 1 <= len(report["designs"]) <= 5
    quality = [d["quality"] for d in report["designs"]]
    assert quality == sorted(quality, reverse=True) and report["quality"]["quality"] == quality[0]
    page = (out / "mechanism.html").read_text()
    assert '"overlays":' in page and '"view":"fixed"' in page


def test_bad_mechanization_flag_of_synth_is_exit_2_before_any_work(tmp_path: Path) -> None:
    out = tmp_path / "out"
    run = CliRunner().invoke(_app(synth), [str(_wing_problem(tmp_path)), "-o", str(out), "--dof", "0"])
    assert run.exit_code == 2
    assert "--dof" in run.output
    assert not out.exists()
