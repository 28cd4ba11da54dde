"""The bundled seat mechanized to one DOF: the written mechanism.toml, traced as `linkwork trace` traces it,
reproduces every profile's reported configuration at its drive value, and the chain sits on every profile."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from linkwork.io.spec import load_spec
from linkwork.kinematics.tracer import trace
from linkwork.mechanization import MechanizationError, MechanizeOptions, mechanize

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def seat(seat_mechanized: tuple) -> tuple[object, object, Path]:
    return seat_mechanized


def test_seat_is_mechanized_to_one_dof_with_the_joined_error(seat: tuple) -> None:
    result, _found, folder = seat
    report = json.loads((folder / "mechanization.json").read_text())
    assert report["dof"] == 1
    assert report["drive"] in report["profiles"][0]["angles"]
    assert len(report["dyads"]) >= 1
    joined = result.compound.profiles
    for j, profile in enumerate(report["profiles"]):
        # exact guidance for three positions: the mechanism's shape error is the joined chain's (lengths ~50 in)
        assert abs(profile["e_max"] - float(np.max(joined[j].errors))) <= 1e-9
    drive = [p["drive_value"] for p in report["profiles"]]
    assert drive[0] == 0.0
    assert np.all(np.diff(drive) > 0) or np.all(np.diff(drive) < 0)


def test_trace_of_the_spec_reproduces_every_profile(seat: tuple) -> None:
    _, _, folder = seat
    report = json.loads((folder / "mechanization.json").read_text())
    mech = load_spec(folder / "mechanism.toml").mechanism
    drive = report["drive"]
    revolute = np.array([t == "R" for t in mech.joint_types])
    for profile in report["profiles"][1:]:
        value = profile["drive_value"]
        value = math.radians(value) if report["drive_type"] == "R" else value
        path = trace(mech, drive=drive, until=(drive, value))
        assert path.branches[0].end_reason == "reached target"
        shown = np.where(revolute, np.degrees(path.angles[-1]), path.angles[-1])
        got = dict(zip(mech.joint_names, shown, strict=True))
        for name, expected in profile["angles"].items():
            assert abs(got[name] - expected) <= 1e-8, name  # degrees, or lengths (~50 in) for sliders


def test_cli_trace_reproduces_a_profile(seat: tuple, tmp_path: Path) -> None:
    from linkwork.cli.trace import trace as trace_command

    _, _, folder = seat
    report = json.loads((folder / "mechanization.json").read_text())
    drive, last = report["drive"], report["profiles"][-1]
    app = typer.Typer()
    app.command()(trace_command)
    out = tmp_path / "trace"
    args = [str(folder / "mechanism.toml"), "--drive", drive, "--until", f"{drive}={last['drive_value']!r}"]
    run = CliRunner().invoke(app, [*args, "--out", str(out), "--no-plots"])
    assert run.exit_code == 0, run.output
    with open(out / "path.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    for name, expected in last["angles"].items():
        assert abs(float(rows[-1][name]) - expected) <= 1e-8, name  # degrees (lengths for sliders)


def test_no_design_passing_is_one_clear_error(seat: tuple) -> None:
    result, _, _ = seat
    # a ground region far from the seat leaves no fixed pivot anywhere
    options = MechanizeOptions(ground_region=(1000.0, 1000.0, 1001.0, 1001.0), time_limit=10.0)
    with pytest.raises(MechanizationError, match="no design passes") as info:
        mechanize(result, options)
    assert "\n" not in str(info.value)
