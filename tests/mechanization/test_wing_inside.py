"""The bundled wing mechanized with ``ground_region = "inside"``: every fixed pivot inside every airfoil outline
(checked with matplotlib's point-in-polygon on the Selig files as written), every binary link no longer than the
cruise chord (1.0), and the written mechanism, traced, passes through every profile."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from linkwork.data import example
from linkwork.io.problem import load_problem
from linkwork.io.spec import load_spec
from linkwork.kinematics.tracer import trace
from linkwork.mechanization import MechanizeOptions, mechanize, write_mechanization
from linkwork.synthesis import synthesize

from .geometry_checks import joint_positions, triangle_angle

WING = example("wing").parent
CHORD = 1.0  # the cruise profile's chord, the shortest of the three


@pytest.fixture(scope="module")
def inside(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, object, tuple]:
    result = synthesize(load_problem(WING / "mechanize.toml"))
    options = MechanizeOptions(ground_region="inside", max_link=CHORD, designs=1, time_limit=60.0)
    calls: list[tuple[int, int | None]] = []
    found = mechanize(result, options, progress=lambda done, total: calls.append((done, total)))
    folder = tmp_path_factory.mktemp("wing-inside")
    write_mechanization(found, folder)
    return folder, result, (calls, found.attempts)


def _outline(name: str) -> np.ndarray:
    return np.loadtxt(WING / name, skiprows=1)


def test_every_ground_pivot_is_inside_every_airfoil(inside: tuple) -> None:
    mpath = pytest.importorskip("matplotlib.path")
    folder, _, _ = inside
    report = json.loads((folder / "mechanization.json").read_text())
    pivots = [d["ground_pivot"] for d in report["dyads"] if d["ground_pivot"] is not None]
    assert pivots, "at least the root's links are pivoted on the ground"
    for name in ("cruise.dat", "climb.dat", "landing.dat"):
        assert np.all(mpath.Path(_outline(name)).contains_points(pivots)), name
    for dyad in report["dyads"]:
        assert (dyad["ground_pivot"] is None) == (dyad["anchor"] != "ground")
        if dyad["type"] == "RR":
            assert dyad["length"] <= CHORD + 1e-12
            # the length is the distance between the pivots as written
            assert abs(math.dist(dyad["fixed_pivot"], dyad["moving_pivot"]) - dyad["length"]) <= 1e-12


def test_the_written_mechanism_traces_through_every_profile(inside: tuple) -> None:
    folder, result, _ = inside
    report = json.loads((folder / "mechanization.json").read_text())
    mech = load_spec(folder / "mechanism.toml").mechanism
    drive = report["drive"]
    for j, profile in enumerate(report["profiles"]):
        # exact three-position guidance: the shape error on every profile is the joined chain's
        assert abs(profile["e_max"] - float(np.max(result.joined[j].errors))) <= 1e-9
        if j == 0:
            continue
        value = (
            math.radians(profile["drive_value"]) if report["drive_type"] == "R" else profile["drive_value"]
        )
        path = trace(mech, drive=drive, until=(drive, value))
        assert path.branches[0].end_reason == "reached target"
        assert not path.bifurcations


def test_transmission_angles_are_the_triangle_angles_at_the_moving_pivots(inside: tuple) -> None:
    folder, _, _ = inside
    report = json.loads((folder / "mechanization.json").read_text())
    names = {d["name"] for d in report["dyads"]}
    at = [joint_positions(folder, p["angles"]) for p in report["profiles"]]
    checked = 0
    for d in report["dyads"]:
        if d["type"] != "RR" or d["via"] is None:
            continue
        other = f"{d['via']}m" if d["via"] in names else d["via"]
        # the triangle fixed pivot - moving pivot - the joint that places the body with this link
        angles = [triangle_angle(a[f"{d['name']}a"], a[f"{d['name']}m"], a[other]) for a in at]
        assert abs(d["transmission_deg"] - min(angles)) <= 1e-6, d["name"]  # degrees
        checked += 1
    assert checked >= 5


def test_quality_factor_is_the_documented_product(inside: tuple) -> None:
    folder, _, _ = inside
    report = json.loads((folder / "mechanization.json").read_text())
    sweep = abs(
        report["profiles"][-1]["drive_value"] - report["profiles"][0]["drive_value"]
    )  # the crank, deg
    lengths = [d["length"] for d in report["dyads"] if d["type"] == "RR"]
    mu = min(d["transmission_deg"] for d in report["dyads"])
    expected = math.sin(math.radians(mu)) * min(lengths) / max(lengths) * min(1.0, 180.0 / sweep)
    assert abs(report["quality"]["quality"] - expected) <= 1e-12
    assert report["designs"][0]["quality"] == report["quality"]["quality"]


def test_the_search_reports_progress_after_every_design(inside: tuple) -> None:
    _, _, (calls, attempts) = inside
    assert [done for done, _ in calls] == list(range(1, attempts + 1))  # one call per design traced
    assert all(total is not None and done <= total for done, total in calls)
