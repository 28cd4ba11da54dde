"""The seat mechanized as the paper's Fig. 14: prismatic sliders between the segments and the frame, a slider
drives, and any of the sliders can; mechanization.json's transmission angles and quality factor checked against
triangle geometry of the traced mechanism's joints and the documented definition."""

from __future__ import annotations

import json
import math
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from linkwork.io.spec import load_spec
from linkwork.kinematics.closure import body_poses
from linkwork.mechanization import mechanize, options_from_values


@pytest.fixture(scope="module")
def seat(seat_mechanized: tuple) -> tuple[object, object, Path]:
    return seat_mechanized  # the problem file's options: binary_links = "both"


def _report(folder: Path) -> dict:
    return json.loads((folder / "mechanization.json").read_text())


def test_sliders_on_the_frame_and_a_slider_drives(seat: tuple) -> None:
    _, _, folder = seat
    report = _report(folder)
    sliders = [d for d in report["dyads"] if d["type"] == "PR"]
    assert any(d["anchor"] == "ground" and d["ground_pivot"] is not None for d in sliders)
    assert report["drive"] in {f"{d['name']}s" for d in sliders}
    assert report["drive_type"] == "P"
    drive = [p["drive_value"] for p in report["profiles"]]
    assert np.all(np.diff(drive) > 0)  # a slider moves one way along its guide through the profiles


@pytest.mark.slow
def test_the_designer_chooses_which_slider_drives(seat: tuple) -> None:
    result, found, _ = seat
    sliders = [f"{link.name}s" for link in found.design.links if link.kind == "PR"]
    assert len(sliders) >= 2
    base = options_from_values(result.problem.mechanize_options)
    joined = [float(np.max(p.errors)) for p in result.compound.profiles]
    for drive in sliders[1:2]:  # the first slider drives by default; choose another
        chosen = mechanize(result, replace(base, drive=drive, attempts=2))
        assert chosen.design.drive == drive and chosen.verification.passed
        assert next(link for link in chosen.design.links if f"{link.name}s" == drive).kind == "PR"
        for state, e in zip(chosen.verification.states, joined, strict=True):
            assert abs(state.e_max - e) <= 1e-9  # exact guidance for three profiles


def _joint_positions(folder: Path, values_deg: dict[str, float]) -> dict[str, np.ndarray]:
    """World positions of every joint, from the spec file's joint points and the kinematic core's body poses."""
    mech = load_spec(folder / "mechanism.toml").mechanism
    spec = tomllib.loads((folder / "mechanism.toml").read_text())["mechanism"]["joints"]
    q = np.array(
        [
            math.radians(values_deg[n]) if t == "R" else values_deg[n]
            for n, t in zip(mech.joint_names, mech.joint_types, strict=True)
        ]
    )
    poses = body_poses(mech, q)
    out = {}
    for joint in spec:
        x, y = joint["point"][:2]
        out[joint["name"]] = (poses[joint["bodies"][1]] @ np.array([x, y, 0.0, 1.0]))[:2]
    return out


def test_transmission_angles_are_the_triangle_angles_at_the_moving_pivots(seat: tuple) -> None:
    _, _, folder = seat
    report = _report(folder)
    names = {d["name"] for d in report["dyads"]}
    angles: dict[str, list[float]] = {}
    for profile in report["profiles"]:
        at = _joint_positions(folder, profile["angles"])
        for d in report["dyads"]:
            if d["type"] != "RR":
                continue
            via = d.get("via")
            other = f"{via}m" if via in names else via
            c, m, p = at[f"{d['name']}a"], at[f"{d['name']}m"], at[other]
            # law of cosines in the triangle fixed pivot - moving pivot - the joint that places the body
            a, b, opposite = math.dist(m, c), math.dist(m, p), math.dist(c, p)
            angle = math.degrees(
                math.acos(max(-1.0, min(1.0, (a * a + b * b - opposite * opposite) / (2 * a * b))))
            )
            angles.setdefault(d["name"], []).append(min(angle, 180.0 - angle))
    assert angles
    for d in report["dyads"]:
        if d["name"] in angles:
            assert abs(d["transmission_deg"] - min(angles[d["name"]])) <= 1e-6, d["name"]  # degrees


def test_quality_factor_is_the_documented_product(seat: tuple) -> None:
    _, _, folder = seat
    report = _report(folder)
    for design in report["designs"]:
        mu = min(d["transmission_deg"] for d in design["dyads"])
        lengths = [d["length"] for d in design["dyads"] if d["type"] == "RR"]
        ratio = max(lengths) / min(lengths)
        assert abs(design["min_transmission_deg"] - mu) <= 1e-9
        assert abs(design["link_ratio"] - ratio) <= 1e-9 * ratio
        expected = math.sin(math.radians(mu)) / ratio * design["stroke_factor"]
        assert abs(design["quality"] - expected) <= 1e-12
