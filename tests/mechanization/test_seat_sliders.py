"""The seat mechanized as the paper's Fig. 14: prismatic sliders between the segments and the frame, a slider
drives, and any of the sliders can; mechanization.json's transmission angles and quality factor checked against
triangle geometry of the traced mechanism's joints and the documented definition."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from linkwork.mechanization import mechanize, options_from_values, verify

from .geometry_checks import joint_positions


@pytest.fixture(scope="module")
def seat(seat_mechanized: tuple) -> tuple[object, object, Path]:
    return seat_mechanized  # the problem file's options: binary_links = "prismatic"


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


def test_every_slider_on_the_frame_can_drive_the_design(seat: tuple) -> None:
    _, found, _ = seat
    on_frame = [
        f"{link.name}s" for link in found.design.links if link.kind == "PR" and link.anchor == "ground"
    ]
    assert len(on_frame) >= 2
    joined = found.design.chain.joined_errors
    for drive in on_frame:  # the paper: "actuated via any one of the ... prismatic joints"
        check = verify(replace(found.design, drive=drive))
        assert check.passed, (drive, check.reason)
        for state, e in zip(check.states, joined, strict=True):
            assert abs(state.e_max - e) <= 1e-9  # exact guidance for three profiles


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


def _acute(u: np.ndarray, v: np.ndarray) -> float:
    """The acute angle between two lines, degrees."""
    cosine = abs(float(u @ v)) / (float(np.linalg.norm(u)) * float(np.linalg.norm(v)))
    return math.degrees(math.acos(min(1.0, cosine)))


def test_slider_transmission_is_the_angle_between_its_guide_and_the_joint_line(seat: tuple) -> None:
    _, _, folder = seat
    report = _report(folder)
    names = {d["name"] for d in report["dyads"]}
    at = [joint_positions(folder, p["angles"]) for p in report["profiles"]]
    checked = 0
    for d in report["dyads"]:
        if d["type"] != "PR" or d["anchor"] != "ground":
            continue
        via = f"{d['via']}m" if d["via"] in names else d["via"]
        pivot = np.array([a[f"{d['name']}m"] for a in at])
        guide = pivot[-1] - pivot[0]  # a slider on the frame: its pivot's positions lie on the fixed guide
        # the guide pushes along its normal; the pivot is free to move normal to the line to the joint: the
        # transmission angle is 90 degrees minus the angle between the guide and that line
        mu = [90.0 - _acute(guide, pivot[j] - a[via]) for j, a in enumerate(at)]
        assert abs(d["transmission_deg"] - min(mu)) <= 1e-6, d["name"]  # degrees
        checked += 1
    assert checked >= 2


def test_quality_factor_is_the_documented_product(seat: tuple) -> None:
    _, _, folder = seat
    report = _report(folder)
    for design in report["designs"]:
        mu = min(d["transmission_deg"] for d in design["dyads"])
        lengths = [d["length"] for d in design["dyads"] if d["type"] == "RR"]
        ratio = max(lengths) / min(lengths) if lengths else 1.0  # sliders have no length
        assert design["stroke_factor"] == 1.0  # a slider drives: its guide is as long as it must be
        assert abs(design["min_transmission_deg"] - mu) <= 1e-9
        assert abs(design["link_ratio"] - ratio) <= 1e-9 * ratio
        assert design["shape_factor"] == 1.0  # exact three-profile guidance: on the joined chain's error
        expected = math.sin(math.radians(mu)) / ratio * design["stroke_factor"] * design["shape_factor"]
        assert abs(design["quality"] - expected) <= 1e-12
