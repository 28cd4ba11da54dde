"""The misfit means what an engineer reads: its definitions (docs/robustness.md) tested as invariances.

* The same imperfect structure has the same misfit whichever link is the ground (the loop relabelled so that
  another body is held still; the hinge errors follow their joints): equal to second order in the tolerances.
* A direction error tilts a hinge about the hinge itself (the point written for it, or the joint point linkwork
  draws), not about its line's point nearest the centre: a spherical 4R binds under direction errors alone.
* Concurrent hinge lines (a spherical linkage) have a length scale from their hinges, so the misfit is
  proportional to the linkage's size.
* A linkage whose hinge axes are all parallel is planar however it is written (a ``dh`` loop with zero twists,
  hinge lines along x): in-plane errors leave it mobile, as a planar four-bar must be.
"""

from __future__ import annotations

import numpy as np
import pytest

import linkwork as lw
from linkwork.kinematics.chains import from_dh
from linkwork.kinematics.mechanism import Mechanism
from linkwork.studies.imperfections import (
    HingeLines,
    ImperfectionModel,
    hinge_errors,
    perturbed_twists,
    sample_seeds,
)
from linkwork.studies.misfit import misfit_batch
from linkwork.studies.robustness import prepare, robustness
from linkwork.studies.scale import misfit_scale

DEG = np.pi / 180.0


def relabelled(mech: Mechanism, shift: int) -> Mechanism:
    """The same loop with the body before joint ``shift`` as its ground (joints rolled, twists unchanged)."""
    return Mechanism.single_loop(
        mech.name,
        np.roll(np.array(mech.joint_names), -shift).tolist(),
        np.roll(mech.twists, -shift, axis=0),
        np.roll(mech.offsets, -shift),
    )


@pytest.mark.parametrize(
    ("name", "params"), [("bennett", {}), ("hedgepeth-rods", {"n": 6}), ("bricard-line", {})]
)
def test_the_misfit_does_not_depend_on_the_link_held_as_ground(name: str, params: dict[str, int]) -> None:
    """Tolerances 1e-6: the misfits agree to 1e-4 relative (the weight's centre follows the nominal linkage, the
    loop's cut the imperfect one: they differ at second order, 1e-6 relative here; it was 0.84-1.22x)."""
    mech = lw.load(name, **params)
    drive, target = mech.joint_names[0], float(mech.offsets[0] + 60 * DEG)
    model = ImperfectionModel(1e-6, 5e-5 * DEG)
    setup = prepare(mech, lw.trace(mech, until=(drive, target), steps=30), model, seed=3)
    errors = hinge_errors(sample_seeds(3, 0, 40), setup.mech, model, setup.lines)
    imperfect = perturbed_twists(errors, setup.lines)
    base = misfit_batch(imperfect, *setup.kernel_args(), 30)
    assert base.max() > 1e-8  # over-constrained loops: they bind
    for shift in (1, 2, 3):
        other = relabelled(mech, shift)
        path = lw.trace(other, drive=drive, until=(drive, target), steps=30)
        moved = misfit_batch(
            np.roll(imperfect, -shift, axis=1).copy(), *prepare(other, path, model).kernel_args(), 30
        )
        np.testing.assert_allclose(moved.max(axis=1), base.max(axis=1), rtol=1e-4)


def spherical(radius: float) -> Mechanism:
    """A spherical 4R (arcs 70, 20, 70, 70 deg, crank at 40 deg), each hinge written at ``radius`` from the
    centre along its axis (the lines themselves do not depend on ``radius``)."""
    a = np.array([0.0, 0.0, 1.0])
    d = np.array([np.sin(70 * DEG), 0.0, np.cos(70 * DEG)])
    b = np.array([np.sin(20 * DEG) * np.cos(40 * DEG), np.sin(20 * DEG) * np.sin(40 * DEG), np.cos(20 * DEG)])
    c0 = np.linalg.lstsq(np.array([b, d]), np.cos([70 * DEG, 70 * DEG]), rcond=None)[0]
    n = np.cross(b, d) / np.linalg.norm(np.cross(b, d))
    c = c0 + np.sqrt(1.0 - c0 @ c0) * n
    bodies = [("ground", "crank"), ("crank", "coupler"), ("coupler", "rocker"), ("rocker", "ground")]
    joints = [
        {"name": name, "bodies": pair, "direction": axis, "point": radius * axis}
        for name, pair, axis in zip("ABCD", bodies, (a, b, c, d), strict=True)
    ]
    return Mechanism.from_joints("spherical 4R", joints)


def test_direction_errors_tilt_a_hinge_about_the_hinge_itself() -> None:
    """The tilted line passes through the written hinge point (no position error): distance below 1e-12."""
    mech = spherical(2.0)
    lines = HingeLines.of(mech, misfit_scale(mech).centre)
    np.testing.assert_allclose(lines.points, mech.hinge_points, atol=1e-12)
    model = ImperfectionModel(0.0, 0.5 * DEG)
    twists = perturbed_twists(hinge_errors(sample_seeds(1, 0, 20), mech, model, lines), lines)
    w, v = twists[..., :3], twists[..., 3:]
    # distance from a point p to the line (w, v = x0 x w): |p x w - v|
    gap = np.linalg.norm(np.cross(mech.hinge_points[None], w) - v, axis=-1)
    assert gap.max() < 1e-12


def test_a_spherical_4r_binds_under_direction_errors_in_proportion_to_its_size() -> None:
    path = lw.trace(spherical(1.0), until=("A", 80 * DEG), steps=20)
    model = ImperfectionModel(0.0, 0.05 * DEG)
    small = robustness(spherical(1.0), path, model, 60, seed=2, workers=0)
    large = robustness(spherical(10.0), path, model, 60, seed=2, workers=0)
    # tilts of 1e-3 rad about hinges 1 from the centre leave lines ~1e-3 off it: the loop binds at that order
    assert np.median(small.misfit_max) > 1e-5 and not small.mobility_kept.any()
    assert small.setup.scale.length == pytest.approx(1.0, rel=1e-12)
    assert large.setup.scale.length == pytest.approx(10.0, rel=1e-12)
    np.testing.assert_allclose(large.misfit_max, 10.0 * small.misfit_max, rtol=1e-6)
    np.testing.assert_allclose(small.first_order_max, small.misfit_max, rtol=0.05)


def dh_four_bar() -> Mechanism:
    """A planar four-bar (ground 2, crank 1, coupler 2.5, rocker 2, crank at 60 deg) written as a ``dh`` loop with
    zero twists and offsets: T_i = Rz(theta_i) Tx(a_i) around the polygon O2, A, B, O4."""
    O2, O4 = np.array([0.0, 0.0]), np.array([2.0, 0.0])
    A = np.array([np.cos(60 * DEG), np.sin(60 * DEG)])
    d = np.linalg.norm(O4 - A)
    x = (2.5**2 - 2.0**2 + d * d) / (2 * d)
    e = (O4 - A) / d
    B = A + x * e + np.sqrt(2.5**2 - x * x) * np.array([-e[1], e[0]])
    vertices = [O2, A, B, O4]
    edges = [vertices[(i + 1) % 4] - vertices[i] for i in range(4)]
    heading = [np.arctan2(y, x_) for x_, y in edges]
    params = [
        {"theta": float(heading[i] - heading[i - 1]), "a": float(np.linalg.norm(edges[i])), "alpha": 0.0}
        for i in range(4)
    ]
    return from_dh("four-bar (dh)", params)[0]


def along_x(mech: Mechanism) -> Mechanism:
    """The same loop turned so that its hinge axes point along x (hinge lines written in 3-D)."""
    R = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    twists = np.concatenate([mech.twists[:, :3] @ R.T, mech.twists[:, 3:] @ R.T], axis=1)
    return Mechanism.single_loop(mech.name, mech.joint_names, twists, mech.offsets)


@pytest.mark.parametrize("turn", [False, True], ids=["dh-zero-twists", "axes-along-x"])
def test_a_four_bar_with_parallel_axes_is_planar_however_written(turn: bool) -> None:
    mech = along_x(dh_four_bar()) if turn else dh_four_bar()
    assert not mech.planar and mech.moves_in_plane
    normal = mech.plane_normal()
    assert normal is not None and abs(abs(normal[0 if turn else 2]) - 1.0) < 1e-12
    path = lw.trace(mech, until=("A", float(mech.offsets[0] + 40 * DEG)), steps=20)
    in_plane = ImperfectionModel(1e-2, 0.5 * DEG, spatial=not mech.moves_in_plane)
    res = robustness(mech, path, in_plane, 100, seed=4, workers=0)
    assert res.misfit_max.max() < 1e-10 and res.mobility_kept.all()  # a four-bar stays a four-bar
    spatial = robustness(mech, path, ImperfectionModel(1e-3, 0.05 * DEG, spatial=True), 40, seed=4, workers=0)
    assert (spatial.misfit_max > 1e-6).all()  # tilted out of the plane it binds: the test can fail


@pytest.mark.parametrize("turn", [False, True], ids=["dh-zero-twists", "axes-along-x"])
def test_the_python_default_errors_are_the_command_lines(turn: bool) -> None:
    """``ImperfectionModel``'s default decides by the mechanism as ``linkwork robustness`` does: a planar four-bar
    (however written) gets in-plane errors and stays a four-bar, the same samples as ``spatial=False``; a Bennett
    loop gets spatial errors, the same samples as ``spatial=True``. (The default was ``spatial=True``: every
    planar linkage studied from Python bound.)"""
    mech = along_x(dh_four_bar()) if turn else dh_four_bar()
    path = lw.trace(mech, until=("A", float(mech.offsets[0] + 40 * DEG)), steps=20)
    default = robustness(mech, path, ImperfectionModel(1e-2, 0.5 * DEG), 30, seed=4, workers=0)
    in_plane = robustness(
        mech, path, ImperfectionModel(1e-2, 0.5 * DEG, spatial=False), 30, seed=4, workers=0
    )
    np.testing.assert_array_equal(default.misfit_max, in_plane.misfit_max)
    assert default.misfit_max.max() < 1e-10 and default.mobility_kept.all()
    bennett = lw.load("bennett")
    path = lw.trace(bennett, until=("A", float(bennett.offsets[0]) + 60 * DEG), steps=10)
    default = robustness(bennett, path, ImperfectionModel(1e-3, 0.05 * DEG), 20, seed=4, workers=0)
    spatial = robustness(
        bennett, path, ImperfectionModel(1e-3, 0.05 * DEG, spatial=True), 20, seed=4, workers=0
    )
    np.testing.assert_array_equal(default.misfit_max, spatial.misfit_max)
    assert (default.misfit_max > 1e-6).all()


def test_a_spatial_loop_is_not_planar() -> None:
    assert lw.load("bennett").plane_normal() is None
    assert lw.load("four-bar").plane_normal() is not None


@pytest.mark.parametrize("distribution", ["normal", "uniform"])
def test_what_a_tolerance_means_is_stated_and_true(distribution: str) -> None:
    """Normal: the tolerance is each component's standard deviation, so a hinge's shift exceeds it with the
    Rayleigh probability exp(-1/2) = 0.607 (20,000 hinges: 4 standard errors is 0.014); uniform: a hard bound.
    robustness.json states which, and the fraction."""
    from linkwork.outputs.robustness import robustness_dict

    mech = lw.load("bennett")
    model = ImperfectionModel(1e-3, 0.05 * DEG, distribution=distribution)
    lines = HingeLines.of(mech, misfit_scale(mech).centre)
    errors = hinge_errors(sample_seeds(9, 0, 5000), mech, model, lines)
    beyond = np.mean(np.linalg.norm(errors[..., 2:], axis=-1) > model.position_tol)
    tilted = np.mean(np.linalg.norm(errors[..., :2], axis=-1) > model.direction_tol)
    expected = np.exp(-0.5) if distribution == "normal" else 0.0
    assert abs(beyond - expected) < 0.014 and abs(tilted - expected) < 0.014
    assert model.fraction_beyond == pytest.approx(expected, abs=1e-15)
    path = lw.trace(mech, until=("A", 90 * DEG), steps=10)
    summary = robustness_dict(robustness(mech, path, model, 20, seed=1, workers=0))
    tolerances = summary["tolerances"]
    assert tolerances["distribution"] == distribution
    assert tolerances["fraction_beyond"] == pytest.approx(expected, abs=1e-15)
    assert ("standard deviation" if distribution == "normal" else "hard bound") in tolerances["meaning"]


def test_robustness_command_gives_a_dh_four_bar_in_plane_errors(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """`linkwork robustness` on a spec file of a four-bar written as a `dh` loop with zero twists: in-plane errors
    by default (robustness.json says so), every sample keeps its mobility."""
    import json

    from typer.testing import CliRunner

    from linkwork.cli import app

    mech = dh_four_bar()
    lines = ['name = "four-bar as dh"', 'angles = "deg"', "", "[loop]", 'convention = "dh"']
    for p in mech.meta["params"]:
        lines += [
            "",
            "[[loop.joints]]",
            f"theta = {float(np.degrees(p['theta']))!r}",
            f"a = {float(p['a'])!r}",
            "alpha = 0.0",
        ]
    spec = tmp_path / "four-bar-dh.toml"
    spec.write_text("\n".join(lines) + "\n")
    out = tmp_path / "rb"
    result = CliRunner().invoke(
        app,
        ["robustness", str(spec), "--samples", "30", "--hinge-position-tol", "1e-2", "--hinge-direction-tol",
         "0.5", "--until", f"A={float(np.degrees(mech.offsets[0])) + 30.0!r}", "--steps", "10", "--workers", "0",
         "--no-plots", "-o", str(out)],
    )  # fmt: skip
    assert result.exit_code == 0, result.stdout + result.stderr
    summary = json.loads((out / "robustness.json").read_text())
    assert summary["tolerances"]["errors"] == "in-plane"
    assert summary["mobility_kept"] == 1.0
