"""A wing morphing NACA 2412 -> 3412 -> 4412 (chords 1.0, 1.05, 1.1, open outlines) mechanized with
``ground_region = "inside"``: every pivot of every link, fixed and moving, inside every airfoil outline in that
profile's pose, and every link inside (checked with matplotlib's point-in-polygon on the outlines as written, from
``mechanization.json``'s ``profiles[k].pivots``), no link longer than the cruise chord (1.0), and the written
mechanism, traced, passes through every profile."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from linkwork.io.problem import load_problem
from linkwork.io.spec import load_spec
from linkwork.kinematics.tracer import trace
from linkwork.mechanization import MechanizeOptions, mechanize, write_mechanization
from linkwork.mechanization.inside import traced_leaving
from linkwork.mechanization.verify import SHAPE_ALLOWANCE
from linkwork.synthesis import synthesize

from .geometry_checks import joint_positions, triangle_angle
from .test_many_profiles import naca4

CHORD = 1.0  # the cruise profile's chord, the shortest of the three
SECTIONS = {"cruise": ("2412", 1.0), "climb": ("3412", 1.05), "landing": ("4412", 1.1)}


@pytest.fixture(scope="module")
def inside(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, object, tuple]:
    profiles = tmp_path_factory.mktemp("wing-inside")
    for name, (code, chord) in SECTIONS.items():
        np.savetxt(
            profiles / f"{name}.csv", naca4(code, chord)[:-1], delimiter=",", header="x,y", comments=""
        )
    (profiles / "problem.toml").write_text(
        'type = "open"\nprofiles = ["cruise.csv", "climb.csv", "landing.csv"]\npiece_length = 0.02\n'
        'design = "MCMC"\nmechanize = true\n'
    )
    result = synthesize(load_problem(profiles / "problem.toml"))
    options = MechanizeOptions(ground_region="inside", max_link=CHORD, designs=1, time_limit=120.0)
    calls: list[tuple[int, int | None]] = []
    found = mechanize(result, options, progress=lambda done, total: calls.append((done, total)))
    write_mechanization(found, profiles)
    return profiles, result, (calls, found.attempts, found)


def _outline(folder: Path, name: str) -> np.ndarray:
    return np.loadtxt(folder / name, delimiter=",", skiprows=1)


def test_every_pivot_and_link_is_inside_every_airfoil_in_its_pose(inside: tuple) -> None:
    mpath = pytest.importorskip("matplotlib.path")
    folder, _, _ = inside
    report = json.loads((folder / "mechanization.json").read_text())
    pivots = [d["ground_pivot"] for d in report["dyads"] if d["ground_pivot"] is not None]
    assert pivots, "at least the root's links are pivoted on the ground"
    for name in SECTIONS:
        assert np.all(mpath.Path(_outline(folder, f"{name}.csv")).contains_points(pivots)), name
    for profile, name in zip(report["profiles"], SECTIONS, strict=True):
        shape = mpath.Path(_outline(folder, f"{name}.csv"))  # closed from its last point to its first
        for link, (anchor, moving) in profile["pivots"].items():
            along = np.linspace(0.0, 1.0, 201)[:, None]
            points = np.array(anchor) + along * (np.array(moving) - np.array(anchor))
            assert np.all(shape.contains_points(points)), (link, name)
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
        # links inside a slender shape need not be exact: the shape error is within the joined chain's plus the
        # documented allowance of five times the largest structural error
        joined = float(np.max(result.joined[j].errors))
        assert profile["joined_e_max"] == joined
        assert profile["e_max"] <= joined + SHAPE_ALLOWANCE * report["max_structural_error"] + 1e-9
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
    # how near the profiles: 1 within 1 % of the size of the joined chain's error, else their ratio
    slack = 0.01 * report["limits"]["largest_extent"]
    shape = min(min(1.0, (p["joined_e_max"] + slack) / p["e_max"]) for p in report["profiles"])
    assert report["quality"]["shape_factor"] == pytest.approx(shape, abs=1e-12)
    expected = math.sin(math.radians(mu)) * min(lengths) / max(lengths) * min(1.0, 180.0 / sweep) * shape
    assert abs(report["quality"]["quality"] - expected) <= 1e-12
    assert report["designs"][0]["quality"] == report["quality"]["quality"]


def test_the_search_reports_progress_after_every_design(inside: tuple) -> None:
    _, _, (calls, attempts, _) = inside
    assert [done for done, _ in calls] == list(range(1, attempts + 1))  # one call per design traced
    assert all(total is not None and done <= total for done, total in calls)


def test_a_pivot_that_leaves_on_the_traced_poses_is_named_with_how_far(inside: tuple) -> None:
    """The check on the traced poses: nothing leaves the airfoils as they are; with every airfoil moved up by
    0.05 (of a 0.12-thick section) pivots leave, and the worst is the largest distance outside found here, from
    ``mechanization.json``'s pivots with matplotlib's point-in-polygon and the distance to the moved outlines."""
    mpath = pytest.importorskip("matplotlib.path")
    folder, _, (_, _, found) = inside
    assert traced_leaving(found.design, found.verification) is None
    chain = found.design.chain
    moved = tuple(t + np.array([0.0, 0.05]) for t in chain.targets)
    worst = traced_leaving(replace(found.design, chain=replace(chain, targets=moved)), found.verification)
    assert worst is not None
    report = json.loads((folder / "mechanization.json").read_text())
    deepest = 0.0
    for j, profile in enumerate(report["profiles"]):
        a, b = moved[j], np.roll(moved[j], -1, axis=0)
        for link, pair in profile["pivots"].items():
            if next(d for d in report["dyads"] if d["name"] == link)["type"] != "RR":
                continue
            for point in np.array(pair):
                if mpath.Path(moved[j]).contains_points([point])[0]:
                    continue
                t = np.clip(np.sum((point - a) * (b - a), axis=1) / np.sum((b - a) ** 2, axis=1), 0.0, 1.0)
                deepest = max(
                    deepest, float(np.min(np.linalg.norm(a + t[:, None] * (b - a) - point, axis=1)))
                )
    assert deepest > 0.0
    assert worst[1].by == pytest.approx(deepest, abs=1e-9)
