"""Deployment measures: checked against distances recomputed from points.csv, closed forms and invariances."""

from __future__ import annotations

import csv
import itertools
import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import linkwork as lw
from linkwork.cli import app
from linkwork.errors import RequestNotMetError
from linkwork.kinematics.closure import closure_residual
from linkwork.kinematics.deployment import flatness_of, pair_extremes

HEX_DEPLOYED_DEG = 128.6822  # hedgepeth-rods n = 6: arccos(sin^2(60 deg) / 2 - 1), docs/linkages.md


def _read_points(file: Path, names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """Branch ids and ``(N, m, 3)`` positions from points.csv, read with the csv module."""
    with file.open() as fh:
        rows = list(csv.DictReader(fh))
    branch = np.array([int(r["branch"]) for r in rows])
    xyz = np.array([[[float(r[f"{n}_{c}"]) for c in "xyz"] for n in names] for r in rows])
    return branch, xyz


def test_hexagon_membrane_must_stretch_as_recomputed_from_points_csv(tmp_path: Path) -> None:
    """G&P Sec. 7: a membrane on the deployable hexagon would have to stretch. The report's value is checked
    against a plain double loop over every traced point and pair of points.csv."""
    out = tmp_path / "hex"
    result = CliRunner().invoke(
        app,
        ["trace", "hedgepeth-rods", "--until", f"A={HEX_DEPLOYED_DEG}", "--no-plots", "--out", str(out)],
    )
    assert result.exit_code == 0, result.output
    report = json.loads((out / "report.json").read_text())
    dep = report["deployment"]
    names = dep["attachment"]
    branch, xyz = _read_points(out / "points.csv", names)
    xyz = xyz[branch == 0]
    deployed = xyz[-1]
    worst, worst_pair, worst_row = -np.inf, ("", ""), -1
    sizes = []
    for k, config in enumerate(xyz):
        size = 0.0
        for i, j in itertools.combinations(range(len(names)), 2):
            d = float(np.sqrt(np.sum((config[i] - config[j]) ** 2)))
            d0 = float(np.sqrt(np.sum((deployed[i] - deployed[j]) ** 2)))
            size = max(size, d)
            if d / d0 - 1.0 > worst:
                worst, worst_pair, worst_row = d / d0 - 1.0, (names[i], names[j]), k
        sizes.append(size)
    assert worst > 0.1  # it must stretch, by a significant amount (21.7 % between opposite hinges)
    assert dep["membrane_stretch"]["value"] == pytest.approx(worst, rel=1e-12, abs=1e-12)
    # the reported pair and point reach the largest stretch (A-C, C-E and E-A tie by the three-fold symmetry)
    i, j = (names.index(n) for n in dep["membrane_stretch"]["pair"])
    at = xyz[dep["membrane_stretch"]["step"]]  # branch 0's step counts its rows
    reported = np.linalg.norm(at[i] - at[j]) / np.linalg.norm(deployed[i] - deployed[j]) - 1.0
    assert reported == pytest.approx(worst, rel=1e-12)
    assert set(worst_pair) <= {"A", "C", "E"} and dep["membrane_stretch"]["step"] == worst_row
    assert dep["bundle_ratio"]["value"] == pytest.approx(min(sizes) / sizes[-1], rel=1e-12)
    assert dep["deployed"]["angles"]["A"] == pytest.approx(HEX_DEPLOYED_DEG, abs=1e-9)


def test_four_bar_stretch_matches_the_law_of_cosines() -> None:
    """A planar four-bar: the only pairs whose distance changes are the diagonals; |AC|^2 = a^2 + b^2 -
    2ab cos(angle at B) on the triangle A-B-C (rigid links AB, BC)."""
    pts = [(0.0, 0.0), (0.3, 0.9), (1.4, 1.1), (1.6, 0.0)]
    bodies = [("ground", "crank"), ("crank", "coupler"), ("coupler", "rocker"), ("rocker", "ground")]
    joints = [
        {"name": n, "bodies": b, "point": p, "direction": (0.0, 0.0, 1.0)}
        for n, b, p in zip("ABCD", bodies, pts, strict=True)
    ]
    mech = lw.Mechanism.from_joints("four-bar", joints, planar=True)  # no named points: the joints attach
    tr = lw.trace(mech, max_steps=400)
    dep = tr.deployment()
    pts = tr.positions()[dep.path]
    a = np.linalg.norm(pts[0, 1] - pts[0, 0])
    b = np.linalg.norm(pts[0, 2] - pts[0, 1])
    u, v = pts[:, 0] - pts[:, 1], pts[:, 2] - pts[:, 1]
    cos_b = np.einsum("ij,ij->i", u, v) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
    ac = np.sqrt(a * a + b * b - 2 * a * b * cos_b)
    ac_ratio = ac / ac[-1] - 1.0
    assert np.all(dep.stretch_along >= ac_ratio - 1e-12)  # the largest pair is at least the diagonal AC
    assert dep.flatness < 1e-12  # a planar mechanism deploys flat


def test_measures_are_invariant_under_scale() -> None:
    """Stretch, bundle ratio and flatness are ratios: unchanged when the frame is scaled (same drive steps)."""
    until = ("A", np.radians(60.0))
    small = lw.trace(lw.load("guest-frame"), until=until, steps=60).deployment()
    scaled = lw.load("guest-frame", length=20.0, width=10.0, section=1.0)
    large = lw.trace(scaled, until=until, steps=60).deployment()
    assert small.membrane_stretch > 0.01
    assert large.membrane_stretch == pytest.approx(small.membrane_stretch, rel=1e-9)
    assert large.bundle_ratio == pytest.approx(small.bundle_ratio, rel=1e-9)
    assert large.flatness == pytest.approx(small.flatness, rel=1e-9, abs=1e-12)
    assert large.deployed_size == pytest.approx(10 * small.deployed_size, rel=1e-12)


def test_pair_extremes_in_blocks_equals_one_block(monkeypatch: pytest.MonkeyPatch) -> None:
    """Memory is bounded by blocks of points; the blocks give the same result as one pass."""
    rng = np.random.default_rng(7)
    pts = rng.normal(size=(50, 9, 3))
    whole = pair_extremes(pts, pts[-1])
    import linkwork.kinematics.deployment as dm

    monkeypatch.setattr(dm, "PAIR_BLOCK", 40)  # one point per block
    parts = pair_extremes(pts, pts[-1])
    for x, y in zip(whole, parts, strict=True):
        np.testing.assert_array_equal(x, y)


def test_flatness_is_the_ratio_of_the_spreads() -> None:
    """Points on a plane have flatness 0; a box of half-sides 1, 1, 0.1 has 0.1."""
    rng = np.random.default_rng(3)
    plane = np.c_[rng.normal(size=(20, 2)), np.zeros(20)] @ np.linalg.qr(rng.normal(size=(3, 3)))[0]
    assert flatness_of(plane) < 1e-14
    box = np.array(list(itertools.product([-1.0, 1.0], [-1.0, 1.0], [-0.1, 0.1])))
    assert flatness_of(box) == pytest.approx(0.1, rel=1e-12)


def test_deployed_at_between_points_closes_the_loop_at_the_value() -> None:
    """``deployed_at`` between two traced points is solved onto the loop (closure 1e-12) with the joint at the
    value, and agrees with a trace that stops there (--until) to 1e-8 rad."""
    mech = lw.load("hedgepeth-rods")
    value = np.radians(100.0)
    dep = lw.trace(mech).deployment(("A", value))
    assert dep.deployed_angles[0] == pytest.approx(value, abs=1e-13)
    q = mech.q_from_angles(dep.deployed_angles[None, :])[0]
    assert np.linalg.norm(closure_residual(mech, q)) < 1e-12
    stopped = lw.trace(mech, until=("A", value))
    np.testing.assert_allclose(dep.deployed_angles, stopped.angles[-1], atol=1e-8)


def test_deployed_at_off_the_path_says_the_range() -> None:
    tr = lw.trace(lw.load("hedgepeth-rods"))
    with pytest.raises(RequestNotMetError, match=r"A goes from 0 to 360 deg"):
        tr.deployment(("A", np.radians(400.0)))


def test_guest_frame_bifurcation_is_on_the_path_and_raises_the_mobility() -> None:
    """G&P Sec. 6: the rank drops from 5 to 4 at the symmetry-breaking point: mobility 2 there."""
    dep = lw.trace(lw.load("guest-frame"), max_steps=400).deployment()
    assert dep.bifurcations_on_path >= 1
    assert dep.mobility_on_path == 2


def test_cli_deployed_at_refusals(tmp_path: Path) -> None:
    runner = CliRunner()
    out = tmp_path / "o"
    bad = runner.invoke(app, ["trace", "hedgepeth-rods", "--deployed-at", "A", "--no-plots", "-o", str(out)])
    assert bad.exit_code == 2 and "--deployed-at" in bad.output
    assert not out.exists()  # bad input: nothing written
    off = runner.invoke(
        app, ["trace", "hedgepeth-rods", "--deployed-at", "A=400", "--no-plots", "-o", str(out)]
    )
    assert off.exit_code == 3 and "goes from 0 to 360" in off.output
    report = json.loads((out / "report.json").read_text())  # the trace is kept, the deployment not measured
    assert report["deployment"] is None and "goes from 0 to 360" in report["deployment_unmet"]


def test_a_frame_traced_from_its_flat_start_is_deployed_there() -> None:
    """rect-frame starts flat: ``deployed_at = ("A", 0)`` picks the first point (exactly), whose named points are
    the rectangle's corners and mid-sides in z = 0 (flatness 0, size the diagonal)."""
    mech = lw.load("rect-frame")
    tr = lw.trace(mech, max_steps=200)
    dep = tr.deployment(("A", 0.0))
    np.testing.assert_array_equal(dep.deployed_angles, tr.angles[0])
    assert dep.flatness < 1e-15
    assert dep.deployed_size == pytest.approx(np.hypot(2.0, 1.0), rel=1e-14)
    assert dep.membrane_stretch > 0.0 and dep.bundle_ratio < 1.0
