"""The two actuator paths of mechanization end to end: a prismatic (linear) actuator, and two DOF.

The problem is built here from outside the code under test: a known planar chain of two rigid bodies, ``s1`` (the
coupler of the four-bar of ``conftest``, moved by that four-bar's crank) and ``s2`` (hinged to the end of ``s1`` at
``J1``, turning relative to it by known angles), posed on three profiles. The target points are the chain's points
pushed off by known amounts, so the joined chain's error on every profile is known before anything runs.
"""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from linkwork.data import example
from linkwork.io.problem import load_problem
from linkwork.io.spec import load_spec
from linkwork.kinematics.closure import closure_residual, jacobian
from linkwork.kinematics.tracer import trace
from linkwork.mechanization import Mechanization, MechanizeOptions, mechanize, write_mechanization
from linkwork.mechanization.chain import (
    ChainBody,
    ChainJoint,
    ChainSegment,
    ShapeChain,
    apply,
    pose_matrix,
    pose_of,
)
from linkwork.synthesis import synthesize
from linkwork.synthesis.result import SynthesisResult

from .conftest import COUPLER, coupler_pose

CRANK_DEG = np.array([40.0, 70.0, 110.0])  # the four-bar's crank on the three profiles
HINGE_DEG = np.array(
    [10.0, 25.0, 45.0]
)  # s2 relative to s1 on the three profiles (profile 1's is the offset)
ARM = 2.0  # length of s2
OFFSETS = np.array([0.01, 0.02, 0.015])  # how far the targets are pushed off the chain, per profile


def _displacement(pose: np.ndarray, start: np.ndarray) -> np.ndarray:
    """The rigid motion carrying a frame from ``start`` to ``pose`` (world coordinates)."""
    return pose_of(pose_matrix(pose) @ np.linalg.inv(pose_matrix(start)))


def _known_chain() -> ShapeChain:
    """Two M-segment bodies joined by J1 on three profiles, targets off the chain by ``OFFSETS``."""
    frames1 = np.array([coupler_pose(math.radians(a)) for a in CRANK_DEG])
    # s2's frame: at C (the end of the coupler), turned by the hinge angle relative to s1
    frames2 = np.array(
        [
            pose_of(pose_matrix(f) @ pose_matrix([COUPLER, 0.0, math.radians(h)]))
            for f, h in zip(frames1, HINGE_DEG, strict=True)
        ]
    )
    local1 = np.column_stack([np.linspace(0.0, COUPLER, 5), 0.2 * np.sin(np.linspace(0.0, math.pi, 5))])
    local2 = np.column_stack([np.linspace(0.0, ARM, 5), -0.15 * np.sin(np.linspace(0.0, math.pi, 5))])
    line1, line2 = apply(frames1[0], local1), apply(frames2[0], local2)
    disp1 = np.array([_displacement(f, frames1[0]) for f in frames1])
    disp2 = np.array([_displacement(f, frames2[0]) for f in frames2])
    targets = []
    for j in range(3):
        pts = np.vstack([apply(disp1[j], line1), apply(disp2[j], line2)[1:]])
        # pushed off along a fixed direction by OFFSETS[j] at every second point: E_max of the chain = OFFSETS[j]
        push = np.zeros_like(pts)
        push[::2] = OFFSETS[j] * np.array([0.6, 0.8])
        targets.append(pts + push)
    four = np.full(3, 4, dtype=np.int64)
    joint = ChainJoint(
        "J1", "R", ("s1", "s2"), line1[-1].copy(), None, np.radians(HINGE_DEG - HINGE_DEG[0]), "joint"
    )
    return ShapeChain(
        kind="open",
        bodies=(ChainBody("s1", disp1, line1), ChainBody("s2", disp2, line2)),
        joints=(joint,),
        segments=(
            ChainSegment("M", "s1", "s1", line1, 0.0, 0.0, four),
            ChainSegment("M", "s2", "s2", line2, 0.0, 0.0, four),
        ),
        targets=tuple(targets),
        size=float(np.ptp(np.vstack(targets), axis=0).max()),
        joined_errors=OFFSETS.copy(),
    )


def _written(found: Mechanization, folder: Path) -> tuple[dict, dict]:
    write_mechanization(found, folder)
    report = json.loads((folder / "mechanization.json").read_text())
    spec = tomllib.loads((folder / "mechanism.toml").read_text())
    return report, spec


def _dof_from_rank(folder: Path) -> tuple[int, int]:
    """Unknowns minus the rank (numpy's SVD rank, not the core's) of the written spec's Jacobian at profile 1."""
    mech = load_spec(folder / "mechanism.toml").mechanism
    J = jacobian(mech, np.zeros(mech.n_joints))
    rank = int(np.linalg.matrix_rank(J, tol=1e-9 * np.linalg.norm(J, 2)))
    return mech.n_unknowns - rank, rank


def _grubler(spec: dict) -> int:
    """Planar mobility 3 (bodies - 1) - 2 joints (R and P joints each take two freedoms)."""
    joints = spec["mechanism"]["joints"]
    bodies = {b for j in joints for b in j["bodies"]}
    return 3 * (len(bodies) - 1) - 2 * len(joints)


@pytest.fixture(scope="module")
def prismatic(tmp_path_factory: pytest.TempPathFactory) -> tuple[Mechanization, dict, dict, Path]:
    found = mechanize(_known_chain(), MechanizeOptions(actuator="prismatic", designs=1, time_limit=120.0))
    folder = tmp_path_factory.mktemp("prismatic")
    return (found, *_written(found, folder), folder)


@pytest.fixture(scope="module")
def two_dof(tmp_path_factory: pytest.TempPathFactory) -> tuple[Mechanization, dict, dict, Path]:
    found = mechanize(_known_chain(), MechanizeOptions(dof=2, designs=1, time_limit=120.0))
    folder = tmp_path_factory.mktemp("two_dof")
    return (found, *_written(found, folder), folder)


def test_prismatic_actuator_is_a_p_joint_in_the_spec_and_drives_one_dof(prismatic: tuple) -> None:
    _found, report, spec, folder = prismatic
    joints = {j["name"]: j for j in spec["mechanism"]["joints"]}
    drive = report["drive"]
    assert joints[drive]["type"] == "P"
    assert report["drive_type"] == "P" and report["drive_unit"] == "length"
    assert any(d["type"] == "RPR" for d in report["dyads"])
    assert _dof_from_rank(folder)[0] == 1  # exact integer
    assert _grubler(spec) == 1  # generic geometry: Grubler's count agrees (exact integer)
    assert report["dof"] == 1 and report["verification"]["traced"] is True


def test_prismatic_drive_is_the_actuator_length_and_monotonic(prismatic: tuple) -> None:
    _, report, _, _ = prismatic
    actuator = next(d for d in report["dyads"] if d["type"] == "RPR")
    assert actuator["anchor"] == "ground"
    body = _known_chain().body(actuator["body"])
    fixed, moving = np.array(actuator["fixed_pivot"]), np.array(actuator["moving_pivot"])
    # the actuator's length on each profile, from the known motion of the body it pushes
    length = np.array([np.linalg.norm(apply(g, moving) - fixed) for g in body.displacements])
    drive = np.array([p["drive_value"] for p in report["profiles"]])
    np.testing.assert_allclose(drive, length - length[0], rtol=0, atol=1e-8)  # lengths of order 1
    steps = np.diff(drive)
    assert np.all(steps > 1e-6) or np.all(steps < -1e-6)  # strictly one way, by more than 1e-6


def test_tracing_the_p_joint_reproduces_every_profile(prismatic: tuple) -> None:
    _, report, _, folder = prismatic
    mech = load_spec(folder / "mechanism.toml").mechanism
    drive = report["drive"]
    d = mech.index(drive)
    kinds = dict(zip(mech.joint_names, mech.joint_types, strict=True))
    for j, profile in enumerate(report["profiles"][1:], start=1):
        path = trace(mech, drive=drive, until=(drive, profile["drive_value"]))
        assert path.branches[0].end_reason == "reached target"
        assert not path.bifurcations
        along = np.diff(path.angles[:, d])
        assert np.all(
            along * np.sign(profile["drive_value"]) >= -1e-12
        )  # the drive never turns back (length)
        last = path.angles[-1]
        got = {
            n: math.degrees(v) if kinds[n] == "R" else v for n, v in zip(mech.joint_names, last, strict=True)
        }
        for name, expected in profile["angles"].items():
            assert abs(got[name] - expected) <= 1e-8, name  # degrees, or lengths for P joints
        # and the chain's own joint is where the known chain puts it (degrees)
        assert abs(got["J1"] - (HINGE_DEG[j] - HINGE_DEG[0])) <= 1e-8
        assert float(np.linalg.norm(closure_residual(mech, last))) < 1e-12


def test_prismatic_design_keeps_the_joined_error(prismatic: tuple) -> None:
    _, report, _, _ = prismatic
    for j, profile in enumerate(report["profiles"]):
        assert abs(profile["e_max"] - OFFSETS[j]) <= 1e-9  # the known push-off (lengths of order 1)


def test_two_dof_has_rank_unknowns_minus_two(two_dof: tuple) -> None:
    found, report, spec, folder = two_dof
    dof, rank = _dof_from_rank(folder)
    mech = load_spec(folder / "mechanism.toml").mechanism
    assert (dof, rank) == (2, mech.n_unknowns - 2)  # exact integers
    assert _grubler(spec) == 2  # exact integer
    assert report["dof"] == 2 and report["rank"] == rank
    assert found.verification.dof == 2


def test_two_dof_profiles_close_the_loops_with_the_joined_error(two_dof: tuple) -> None:
    _, report, _, folder = two_dof
    mech = load_spec(folder / "mechanism.toml").mechanism
    kinds = dict(zip(mech.joint_names, mech.joint_types, strict=True))
    assert len(report["profiles"]) == 3
    for j, profile in enumerate(report["profiles"]):
        q = np.array(
            [
                math.radians(profile["angles"][n]) if kinds[n] == "R" else profile["angles"][n]
                for n in mech.joint_names
            ]
        )
        assert float(np.linalg.norm(closure_residual(mech, q))) < 1e-12
        assert abs(profile["e_max"] - OFFSETS[j]) <= 1e-9  # the joined chain's E_max (lengths of order 1)
        assert abs(profile["e_max"] - profile["joined_e_max"]) <= 1e-9
        assert abs(profile["angles"]["J1"] - (HINGE_DEG[j] - HINGE_DEG[0])) <= 1e-8  # degrees


def test_two_dof_says_it_was_not_traced(two_dof: tuple) -> None:
    found, report, _, _ = two_dof
    check = report["verification"]
    assert check["traced"] is False
    assert check["status"].startswith("not traced: dof 2")
    assert not any("circuit" in c or "order" in c for c in check["checks"])
    assert found.verification.paths == ()


EXAMPLES = example("wing").parents[1]  # the bundled example sets


@pytest.fixture(scope="module")
def wing() -> SynthesisResult:
    return synthesize(load_problem(EXAMPLES / "wing" / "mechanize.toml"))


def _joined_e_max(result: SynthesisResult) -> np.ndarray:
    """E_max of the joined (or compound) chain per profile, from the synthesis result itself."""
    compound = result.compound
    profiles = compound.profiles if compound is not None and compound.merged else result.joined
    return np.array([float(np.max(p.errors)) for p in profiles])


def test_wing_with_a_linear_actuator_traces_through_every_profile(
    wing: SynthesisResult, tmp_path: Path
) -> None:
    found = mechanize(wing, MechanizeOptions(actuator="prismatic", designs=1, time_limit=120.0))
    report, spec = _written(found, tmp_path)
    joints = {j["name"]: j for j in spec["mechanism"]["joints"]}
    drive = report["drive"]
    assert joints[drive]["type"] == "P"
    assert _dof_from_rank(tmp_path)[0] == 1  # exact integer
    values = np.array([p["drive_value"] for p in report["profiles"]])
    assert np.all(np.diff(values) > 1e-6) or np.all(np.diff(values) < -1e-6)  # monotonic (chord ~1)
    mech = load_spec(tmp_path / "mechanism.toml").mechanism
    kinds = dict(zip(mech.joint_names, mech.joint_types, strict=True))
    for profile in report["profiles"][1:]:
        path = trace(mech, drive=drive, until=(drive, profile["drive_value"]))
        assert path.branches[0].end_reason == "reached target"
        last = dict(zip(mech.joint_names, path.angles[-1], strict=True))
        for name, expected in profile["angles"].items():
            got = math.degrees(last[name]) if kinds[name] == "R" else last[name]
            assert abs(got - expected) <= 1e-8, name  # degrees, or lengths for P joints
    joined = _joined_e_max(wing)
    for j, profile in enumerate(report["profiles"]):
        assert abs(profile["e_max"] - joined[j]) <= 1e-9  # exact 3-position guidance (chord ~1)


def test_wing_with_two_actuators_closes_every_profile(wing: SynthesisResult, tmp_path: Path) -> None:
    found = mechanize(wing, MechanizeOptions(dof=2, designs=1, time_limit=120.0))
    report, _ = _written(found, tmp_path)
    mech = load_spec(tmp_path / "mechanism.toml").mechanism
    dof, rank = _dof_from_rank(tmp_path)
    assert (dof, rank) == (2, mech.n_unknowns - 2)  # exact integers
    kinds = dict(zip(mech.joint_names, mech.joint_types, strict=True))
    joined = _joined_e_max(wing)
    for j, profile in enumerate(report["profiles"]):
        q = np.array(
            [
                math.radians(profile["angles"][n]) if kinds[n] == "R" else profile["angles"][n]
                for n in mech.joint_names
            ]
        )
        assert float(np.linalg.norm(closure_residual(mech, q))) < 1e-12
        assert abs(profile["e_max"] - joined[j]) <= 1e-9  # chord ~1
    assert report["verification"]["status"].startswith("not traced: dof 2")
