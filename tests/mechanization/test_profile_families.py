"""Families of six to eight smoothly morphing profiles, built here from the NACA 4-digit formulas and a generated
bending strip, mechanized to one DOF; each written mechanism is traced again by the kinematic core through every
profile, in order.

Checked against what the search does not compute itself: the written ``mechanism.toml`` read back and traced to
every profile's drive value (the joint values reproduced to 1e-6 degrees, the drive values in order, no
bifurcation on the way); every least-squares link's structural error against the spread of the distance between
its pivots in the chain's own poses; every profile's shape error within the documented allowance.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from linkwork.io.problem import load_problem
from linkwork.io.spec import load_spec
from linkwork.kinematics.tracer import trace
from linkwork.mechanization import MechanizationError, MechanizeOptions, mechanize, write_mechanization
from linkwork.mechanization.chain import track
from linkwork.mechanization.verify import SHAPE_ALLOWANCE
from linkwork.synthesis import synthesize

from .test_many_profiles import naca4


def _outline(code: str, chord: float) -> np.ndarray:
    """The open NACA outline (upper trailing edge, nose, lower trailing edge) of the 4-digit formulas."""
    return naca4(code, chord)[:-1]


def _arch(k: int) -> np.ndarray:
    """Half an ellipse growing wider (semi-axis 1 + 0.04 k) and taller (0.3 + 0.04 k), left to right."""
    t = np.linspace(math.pi, 0.0, 121)
    return np.column_stack([(1.0 + 0.04 * k) * np.cos(t), (0.3 + 0.04 * k) * np.sin(t)])


def _bending_strip(k: int, count: int) -> np.ndarray:
    """A strip of length 1 + 0.04 k bending into an arc of growing turn (0 to 60 degrees) and sagging."""
    length = 1.0 + 0.04 * k
    turn = math.radians(60.0) * k / (count - 1)
    s = np.linspace(0.0, length, 121)
    heading = turn * (s / length) ** 1.5 - 0.1 * k / count
    ds = np.diff(s)
    x = np.concatenate([[0.0], np.cumsum(np.cos(heading[:-1]) * ds)])
    y = np.concatenate([[0.0], np.cumsum(np.sin(heading[:-1]) * ds)])
    return np.column_stack([x, y])


def _camber_line(code: str, chord: float, n: int = 61) -> np.ndarray:
    """The mean camber line of NACA ``code`` (4 digits), cosine-spaced, leading edge to trailing edge (Abbott &
    von Doenhoff Sec. 6.4), as an open profile."""
    m, p = int(code[0]) / 100.0, int(code[1]) / 10.0
    x = (1.0 - np.cos(np.linspace(0.0, math.pi, n))) / 2.0
    y = np.where(x < p, m / p**2 * (2 * p * x - x**2), m / (1 - p) ** 2 * ((1 - 2 * p) + 2 * p * x - x**2))
    return np.column_stack([x, y]) * chord


FAMILIES = {
    # the issue's set: camber 2..7 % with the chord growing 1.0 -> 1.25
    "camber-2-to-7": [_outline(f"{k}412", 1.0 + 0.05 * (k - 2)) for k in range(2, 8)],
    # eight profiles: camber 0..7 % with the chord growing 1.0 -> 1.28
    "eight-cambers": [_outline(f"{k}412", 1.0 + 0.04 * k) for k in range(8)],
    # seven profiles: the camber's position moving aft, 20 % -> 80 % of the chord
    "camber-moving-aft": [_outline(f"4{p}12", 1.0 + 0.03 * (p - 2)) for p in range(2, 9)],
    # a generated smooth morph: an arch growing wider and taller
    "growing-arch": [_arch(k) for k in range(6)],
    # seven camber lines, NACA 1412 ... 7412 at chords 1.0 ... 1.3 (exit 3 before the re-cut)
    "seven-camber-lines": [_camber_line(f"{k}412", 1.0 + 0.05 * (k - 1)) for k in range(1, 8)],
}


def _problem(folder: Path, profiles: list[np.ndarray], extra: str = "") -> Path:
    names = []
    for k, points in enumerate(profiles, start=1):
        np.savetxt(folder / f"p{k}.csv", points, delimiter=",", header="x,y", comments="")
        names.append(f'"p{k}.csv"')
    (folder / "problem.toml").write_text(
        f'type = "open"\nprofiles = [{", ".join(names)}]\npiece_length = 0.02\ndesign = "MCMC"\n'
        f"mechanize = true\n{extra}"
    )
    return folder / "problem.toml"


def assert_traced_through_every_profile_in_order(folder: Path, report: dict[str, Any]) -> None:
    """The written mechanism traced again by the kinematic core from profile 1 to each later profile: the
    drive's values run one way, each target is reached without a bifurcation or a change of rank, and every
    joint lands on the profile's joint values to 1e-6 (degrees or lengths)."""
    mech = load_spec(folder / "mechanism.toml").mechanism
    drive, revolute = report["drive"], report["drive_type"] == "R"
    values = [p["drive_value"] for p in report["profiles"]]
    assert np.all(np.diff(values) > 0) or np.all(np.diff(values) < 0)  # the profiles in order along the drive
    for profile in report["profiles"][1:]:
        target = math.radians(profile["drive_value"]) if revolute else profile["drive_value"]
        path = trace(mech, drive=drive, until=(drive, target))
        assert path.branches[0].end_reason == "reached target"
        assert not path.bifurcations and np.all(path.rank == path.rank[0])
        end = dict(zip(mech.joint_names, path.angles[-1], strict=True))
        for name, kind in zip(mech.joint_names, mech.joint_types, strict=True):
            got = math.degrees(end[name]) if kind == "R" else end[name]
            assert abs(got - profile["angles"][name]) <= 1e-6, (name, profile["profile"])


@pytest.mark.slow
@pytest.mark.parametrize("family", sorted(FAMILIES))
def test_a_family_of_morphing_profiles_is_mechanized_and_traced_through_every_profile(
    tmp_path: Path, family: str
) -> None:
    result = synthesize(load_problem(_problem(tmp_path, FAMILIES[family])))
    found = mechanize(result, MechanizeOptions(designs=1, time_limit=120.0))
    write_mechanization(found, tmp_path)
    report = json.loads((tmp_path / "mechanization.json").read_text())
    assert report["dof"] == 1 and len(report["profiles"]) == len(FAMILIES[family])
    assert_traced_through_every_profile_in_order(tmp_path, report)
    structural = report["max_structural_error"]
    for profile in report["profiles"]:
        assert profile["e_max"] <= profile["joined_e_max"] + SHAPE_ALLOWANCE * structural + 1e-9
    # every link's structural error: the spread of the distance between its pivots in the chain's own poses
    chain = found.design.chain
    for link in found.design.links:
        if link.kind != "RR":
            continue
        anchor = track(chain.motion(link.anchor), link.centre)
        moving = track(chain.motion(link.body), link.circle)
        spread = np.ptp(np.linalg.norm(moving - anchor, axis=1))
        assert abs(spread - link.structural_error) <= 1e-9, link.name


@pytest.mark.slow
def test_max_structural_error_bounds_every_link_and_says_so_when_none_fits(tmp_path: Path) -> None:
    result = synthesize(load_problem(_problem(tmp_path, FAMILIES["camber-moving-aft"])))
    found = mechanize(result, MechanizeOptions(designs=1, max_structural_error=0.02, time_limit=120.0))
    assert found.design.links and all(link.structural_error <= 0.02 + 1e-9 for link in found.design.links)
    # no link of some body fits within 0.002 (the smallest found is above it): exit 3 saying which limit
    with pytest.raises(MechanizationError, match=r"with a structural error at most 0\.002"):
        mechanize(result, MechanizeOptions(designs=1, max_structural_error=0.002, time_limit=120.0))


@pytest.mark.slow
def test_a_strip_bending_by_60_degrees_is_mechanized_near_the_chain_on_every_profile(tmp_path: Path) -> None:
    """The synthesis cuts the strip's C-segments 10, 14, 21, 20, 14, 15 and 9, 7, 2, 5, 13, 14 pieces (its arc
    slides zigzag): no design followed it in the search's time. Re-cut with monotonic counts it joins as well,
    and a design (its pivots fitted jointly) follows every profile within a quarter of a percent of the strip's
    length of the synthesised chain's error there."""
    result = synthesize(load_problem(_problem(tmp_path, [_bending_strip(k, 6) for k in range(6)])))
    chain_errors = np.array([float(np.max(p.errors)) for p in result.joined])
    found = mechanize(result, MechanizeOptions(designs=1, time_limit=120.0))
    e_max = np.array([state.e_max for state in found.verification.states])
    assert found.recut is not None and len(e_max) == 6
    assert np.all(e_max <= chain_errors + 0.0025), (e_max, chain_errors)
    assert np.all(e_max <= 1.5 * chain_errors.max()), (e_max, chain_errors)


def test_a_family_no_design_follows_names_the_closest_designs_and_what_each_violated(tmp_path: Path) -> None:
    # the bending strip with the ground region far away: no link of the root can reach it, on either cut (one
    # root and one anchor choice: each plan costs seconds, the names of what was violated are the point)
    result = synthesize(load_problem(_problem(tmp_path, [_bending_strip(k, 6) for k in range(6)])))
    far = MechanizeOptions(
        root="s1", anchors="ground", ground_region=(50.0, 50.0, 51.0, 51.0), time_limit=300.0
    )
    with pytest.raises(MechanizationError) as info:
        mechanize(result, far)
    message = str(info.value)
    assert "\n" not in message and message.startswith("mechanize: no design passes")
    # the chain as synthesised and the chain re-cut with monotonic piece counts, each with its closest plans
    parts = message.split("; and on ")
    assert len(parts) == 2 and "re-cut chain (segment 2: 10, 14, 21, 20, 14, 15 -> " in message, message
    for part in parts:
        closest = re.findall(r"\((\d)\) (root \S+, anchors \w+[^|]*?)(?= \| \(\d\) |$)", part)
        assert [k for k, _ in closest] == ["1"], part
        for _, line in closest:
            # each: what it violated, with the limits as numbers
            assert re.search(r"no (four-bar|dyad)", line), line
            assert re.search(r"transmission angles? (above|below) 15 deg", line), line
            assert re.search(r"max_link \d", line) and re.search(r"structural error at most \d", line), line


#: The issue's case: the camber lines of NACA 2412 ... 7412 at chords 1.0 ... 1.25.
CAMBER_LINES = [_camber_line(f"{k}412", 1.0 + 0.05 * (k - 2)) for k in range(2, 8)]


@pytest.mark.slow
def test_the_issues_camber_lines_mechanize_within_the_chains_error_and_retrace_in_order(
    tmp_path: Path,
) -> None:
    """The synthesis cuts the first C-segment 10, 11, 12, 18, 11, 13 pieces: mechanized as cut, profile 4 was
    missed by 0.13 (the chain: 0.0008). Re-cut with monotonic piece counts, every profile is within a quarter of
    a percent of a chord of the synthesised chain's error there, and within 1.5 times the chain's E_max."""
    result = synthesize(load_problem(_problem(tmp_path, CAMBER_LINES)))
    chain_errors = np.array([float(np.max(p.errors)) for p in result.joined])
    found = mechanize(result, MechanizeOptions(designs=1, time_limit=120.0))
    write_mechanization(found, tmp_path)
    report = json.loads((tmp_path / "mechanization.json").read_text())
    assert report["recut"] is not None and report["recut"]["synthesised_joined_e_max"] == pytest.approx(
        chain_errors, abs=1e-15
    )
    for row in report["recut"]["segment_matrix"]:  # each segment's piece count moves one way
        assert np.all(np.diff(row) >= 0) or np.all(np.diff(row) <= 0)
    e_max = np.array([p["e_max"] for p in report["profiles"]])
    assert np.all(e_max <= chain_errors + 0.0025), (e_max, chain_errors)  # 0.25 % of the smallest chord
    assert np.all(e_max <= 1.5 * chain_errors.max()), (e_max, chain_errors)
    # the written mechanism traced again by the kinematic core, profile by profile, in order
    assert_traced_through_every_profile_in_order(tmp_path, report)


def test_a_recut_keeps_every_profiles_total_and_the_m_segments_and_moves_each_c_segment_one_way() -> None:
    from linkwork.mechanization.recut import monotonic, recut_matrix

    cut = np.array([[13] * 6, [10, 11, 12, 18, 11, 13], [17] * 6, [10, 12, 13, 10, 20, 20]])
    new = recut_matrix("MCMC", cut, 4)
    assert new is not None
    np.testing.assert_array_equal(new.sum(axis=0), cut.sum(axis=0))  # every profile's pieces
    np.testing.assert_array_equal(new[[0, 2]], cut[[0, 2]])  # the M-segments as cut
    np.testing.assert_array_equal(new[:, [0, -1]], cut[:, [0, -1]])  # first and last profile as cut
    assert monotonic(new[1]) and monotonic(new[3])
    assert recut_matrix("MCMC", new, 4) is None  # already monotonic: nothing to re-cut
    # the C-segments' totals going up and down: no cut by this rule moves each one way
    assert recut_matrix("MCMC", np.array([[5] * 3, [6, 9, 6], [5] * 3, [6, 9, 6]]), 4) is None


@pytest.mark.slow
def test_an_unseen_like_family_camber_moving_aft_with_thickness_and_a_shrinking_chord(tmp_path: Path) -> None:
    """NACA 1312, 2313, 3414, 4415, 5516, 6517 outlines at chords 1.2 down to 0.95 (camber 1-6 % moving aft from
    30 % to 50 %, thickness 12-17 %, the chord shrinking: a family of none of the kinds above). The synthesis
    cuts its C-segments 43, 31, 30, 36, 31, 30 and 51, 59, 55, 44, 45, 41 pieces; the re-cut joins better
    (E_max 0.041 against 0.055, but 0.041 against 0.032 on profile 1), and the mechanism follows every profile
    within 1.2 % of the largest chord of the synthesised chain's error there (measured: 0.009 above it on
    profile 1, below it on the others)."""
    codes = [f"{k}{2 + (k + 1) // 2}{11 + k}" for k in range(1, 7)]
    profiles = [_outline(code, 1.2 - 0.05 * (k - 1)) for k, code in enumerate(codes, start=1)]
    result = synthesize(load_problem(_problem(tmp_path, profiles)))
    chain_errors = np.array([float(np.max(p.errors)) for p in result.joined])
    found = mechanize(result, MechanizeOptions(designs=1, time_limit=120.0))
    e_max = np.array([state.e_max for state in found.verification.states])
    assert len(e_max) == 6 and np.all(e_max <= chain_errors + 0.012), (e_max, chain_errors)
