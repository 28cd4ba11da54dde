"""Verification by tracing: DOF from the Jacobian rank, and designs that cross a singular configuration rejected."""

from __future__ import annotations

import math

import numpy as np

from linkwork.mechanization.assemble import BinaryLink, Design
from linkwork.mechanization.chain import ChainBody, ChainSegment, ShapeChain, apply, pose_matrix, pose_of
from linkwork.mechanization.verify import verify

from .conftest import COUPLER, GROUND_A, GROUND_D, coupler_pose


def _four_bar_design(poses: np.ndarray, ground_d: np.ndarray, coupler: float, links: int = 2) -> Design:
    """The coupler of a four-bar as a one-body chain guided by the four-bar's own crank and rocker."""
    disp = np.array([pose_of(pose_matrix(g) @ np.linalg.inv(pose_matrix(poses[0]))) for g in poses])
    line = apply(poses[0], np.column_stack([np.linspace(0.0, coupler, 5), np.zeros(5)]))
    targets = tuple(apply(d, line) for d in disp)
    body = ChainBody("s1", disp, line)
    segment = ChainSegment("M", "s1", "s1", line, 0.0, 0.0, np.full(len(poses), 4, dtype=np.int64))
    chain = ShapeChain("open", (body,), (), (segment,), targets, 4.0, np.zeros(len(poses)))
    crank = BinaryLink("D1", "RR", "ground", "s1", GROUND_A.copy(), line[0], via="D2")
    rocker = BinaryLink("D2", "RR", "ground", "s1", ground_d.copy(), line[-1], via="D1")
    return Design(chain, (crank, rocker)[:links], "D1a", 1, "four-bar")


def test_a_four_bar_through_three_of_its_positions_passes_exactly() -> None:
    poses = np.array([coupler_pose(p) for p in np.radians([40.0, 70.0, 110.0])])
    check = verify(_four_bar_design(poses, GROUND_D, COUPLER))
    assert check.passed, check.reason
    assert check.dof == 1
    drive = [s.drive_value for s in check.states]
    np.testing.assert_allclose(np.degrees(drive), [0.0, 30.0, 70.0], rtol=0, atol=1e-9)
    for state in check.states:
        assert state.deviation <= 1e-9  # the traced configuration is the profile's (radians)
        assert state.e_max <= 1e-9  # and the coupler is where the profile puts it (lengths of order 1)


def test_dof_is_counted_from_the_jacobian_rank() -> None:
    from dataclasses import replace

    from linkwork.mechanization.guidance import centre_point

    poses = np.array([coupler_pose(p) for p in np.radians([40.0, 70.0, 110.0])])
    design = _four_bar_design(poses, GROUND_D, COUPLER)
    # a third dyad, exact through the three positions: 4 bodies, 6 joints, 2 loops -> Jacobian rank 6, DOF 0
    m = apply(poses[0], np.array([1.0, 0.8]))
    disp = design.chain.bodies[0].displacements
    extra = BinaryLink("D3", "RR", "ground", "s1", centre_point(disp, m).centre_point, m, via="D1")
    check = verify(replace(design, links=(*design.links, extra)))
    assert not check.passed
    assert check.defect == "dof"
    assert (check.dof, check.rank) == (0, 6)


def test_a_design_crossing_a_singular_configuration_between_profiles_is_rejected() -> None:
    # a parallelogram four-bar (crank 1, coupler 2, rocker 1, ground 2): at crank 180 degrees all four pivots are
    # in line, where the parallelogram and anti-parallelogram branches cross; profiles at 60, 150, 240 degrees
    phis = np.radians([60.0, 150.0, 240.0])
    poses = np.array([[math.cos(p), math.sin(p), 0.0] for p in phis])
    check = verify(_four_bar_design(poses, np.array([2.0, 0.0]), 2.0))
    assert not check.passed
    assert check.defect == "branch"
    assert "singular" in check.reason
    assert "between profiles 2 and 3" in check.reason or "before profile 3" in check.reason


def test_a_drive_that_is_not_monotonic_over_the_profiles_is_an_order_defect() -> None:
    poses = np.array([coupler_pose(p) for p in np.radians([40.0, 110.0, 70.0])])
    check = verify(_four_bar_design(poses, GROUND_D, COUPLER))
    assert not check.passed
    assert check.defect == "order"


def test_the_mechanism_verified_in_memory_is_the_one_linkwork_trace_reads_from_the_file(tmp_path) -> None:
    from linkwork.io.spec import load_spec
    from linkwork.mechanization.assemble import spec_text
    from linkwork.mechanization.verify import loaded_mechanism

    poses = np.array([coupler_pose(p) for p in np.radians([40.0, 70.0, 110.0])])
    design = _four_bar_design(poses, GROUND_D, COUPLER)
    file = tmp_path / "mechanism.toml"
    file.write_text(spec_text(design), encoding="utf-8")
    read, memory = load_spec(file).mechanism, loaded_mechanism(design)
    assert read.joint_names == memory.joint_names and read.joint_types == memory.joint_types
    assert read.loops == memory.loops and read.bodies == memory.bodies
    # the spec file writes every coordinate to full precision: the same twists and offsets to rounding
    np.testing.assert_allclose(read.twists, memory.twists, rtol=0, atol=1e-15)
    np.testing.assert_allclose(read.offsets, memory.offsets, rtol=0, atol=1e-15)


def test_path_end_reads_every_stop_of_the_tracer() -> None:
    from types import SimpleNamespace

    from linkwork.kinematics.stops import StopReason
    from linkwork.mechanization.verify import path_end

    def kind(reason: StopReason, text: str = "whatever the words say") -> str:
        branch = SimpleNamespace(end_reason=text, end_kind=reason)
        return path_end(SimpleNamespace(branches=[branch])).kind  # type: ignore[arg-type]

    # every stop the march can report that verification acts on is told apart, from the enum alone
    assert {kind(r) for r in StopReason} >= {"target", "turning", "failed", "bifurcation", "budget", "closed"}
    assert (
        kind(StopReason.TURNING, "reached target") == "turning"
    )  # the structured end decides, not the words
    assert kind(StopReason.LIMIT) == "other" and kind(StopReason.NO_PROGRESS) == "other"


def test_path_end_of_a_real_trace_reads_its_branch() -> None:
    import linkwork as lw
    from linkwork.mechanization.verify import path_end

    mech = lw.load("four-bar")
    start = float(mech.offsets[0])
    assert path_end(lw.trace(mech, drive="A", until=("A", start + 0.5))).kind == "target"
    assert path_end(lw.trace(mech, drive="A", max_steps=3)).kind == "budget"
