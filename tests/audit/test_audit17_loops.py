"""Bookkeeping properties on loops the tracer's own tests and the first audit do not use, each against the audit's
own numpy references (``audit_reference``: circle intersections, the law of cosines, spherical trigonometry
solved by ``scipy.optimize.brentq``, Bennett's relation, the closure Jacobian from the hinge screws and numpy's SVD):

* a planar four-bar written as a ``dh`` loop with zero twists traces as the same four-bar written as a planar
  ``[mechanism]``, folds at the law of cosines' extremes, is called planar and is drawn from above (it was called
  "spatial", drawn in an isometric view and had no ``points.png``), and keeps its mobility under in-plane hinge
  errors sample by sample as the ``[mechanism]`` one does;
* the inversions of a four-bar and of an offset slider-crank (each body held as the ground) trace the same rows,
  with the singular values of their own Jacobian (held still at that body);
* a non-Grashof spherical 4R folds where its coupler and output arcs line up, and its steps do not depend on where
  it stands;
* Bennett loops of obtuse and negative twists keep Bennett's relation, close on their first row;
* targets at exactly one turn, just below it, at and next to a rocker's extremes are reached;
* ``path.csv`` and ``report.json`` hold the values of the Python API (a slider's folds as lengths).
"""

from __future__ import annotations

import csv
import itertools
import json
from pathlib import Path

import numpy as np
import pytest
from audit_reference import Bennett, DHLoop, FourBar, Mech, SliderCrank, Spherical4R, rot, wrap_deg
from scipy.optimize import brentq
from typer.testing import CliRunner

import linkwork as lw
from linkwork.cli import app
from linkwork.studies.imperfections import ImperfectionModel
from linkwork.studies.robustness import robustness

RAD = np.pi / 180.0
FOUR_BARS = {"crank-rocker": (4.0, 1.3, 3.7, 2.9, 35.0), "triple-rocker": (4.0, 2.0, 3.5, 2.4, 20.0)}


def load(tmp_path: Path, name: str, text: str) -> lw.Mechanism:
    spec = tmp_path / f"{name}.toml"
    spec.write_text(text)
    return lw.load(str(spec))


def dh_four_bar(case: FourBar) -> DHLoop:
    """The four-bar's loop A-B-C-D as ``dh`` links of zero twist: ``a`` the link lengths, ``theta`` the turn from
    one link's direction to the next (numpy, from the closed-form assembly's points)."""
    pts = [case.pts[k] for k in "ABCD"]
    heading = [np.arctan2(*(pts[(i + 1) % 4] - pts[i])[1::-1]) for i in range(4)]
    lengths = [float(np.linalg.norm(pts[(i + 1) % 4] - pts[i])) for i in range(4)]
    theta = [float(wrap_deg(np.degrees(heading[i] - heading[i - 1]))) for i in range(4)]
    return DHLoop("dh-four-bar", [(0.0, a, 0.0) for a in lengths], theta)


@pytest.mark.parametrize("name", sorted(FOUR_BARS))
def test_a_dh_four_bar_of_zero_twists_is_the_planar_four_bar(tmp_path: Path, name: str) -> None:
    case = FourBar(name, *FOUR_BARS[name])
    loop = dh_four_bar(case)
    as_dh = load(tmp_path, "dh", loop.toml())
    as_mechanism = load(tmp_path, "planar", case.mech.toml())
    assert "planar" in repr(as_dh) and as_dh.moves_in_xy  # was "spatial"
    a, b = lw.trace(as_dh), lw.trace(as_mechanism)
    assert a.branches[0].end_kind == b.branches[0].end_kind == lw.StopReason.CLOSED
    assert a.angles.shape == b.angles.shape
    np.testing.assert_allclose(a.angles - a.angles[0], b.angles - b.angles[0], rtol=0.0, atol=1e-12)
    rows = np.degrees(a.angles)
    for i in range(0, len(rows), 3):
        reference = np.linalg.svd(loop.jacobian(rows[i]), compute_uv=False)
        np.testing.assert_allclose(a.sigma[i], reference[:4], rtol=0.0, atol=1e-13 * reference[0])
        assert loop.closure(rows[i]) < 1e-12
    refs = [x - case.mech.joints[0]["value"] for x in case.fold_refs("A")]  # displacements of A
    found = [np.degrees(f.value) - rows[0, 0] for f in a.folds]
    assert len(found) == len(refs)
    for x in found:
        assert min(abs(float(wrap_deg(x - r))) for r in refs) < 1e-9


def test_a_dh_four_bar_keeps_its_mobility_under_in_plane_errors_sample_by_sample(tmp_path: Path) -> None:
    """In-plane hinge errors cannot bind a single planar loop of four hinges: every sample of both forms keeps
    its mobility, with a misfit at round-off, and the first order predicts zero."""
    case = FourBar("crank-rocker", *FOUR_BARS["crank-rocker"])
    for text in (dh_four_bar(case).toml(), case.mech.toml()):
        mech = load(tmp_path, "m", text)
        trace = lw.trace(mech, until=("A", float(mech.offsets[0]) + 90 * RAD), steps=15)
        model = ImperfectionModel(
            1e-3, 0.05 * RAD, spatial=False
        )  # the command line's default for a planar one
        res = robustness(mech, trace, model, 16, seed=2, workers=0)
        assert np.all(res.mobility_kept)
        assert np.max(res.misfit_max) < 1e-13 and np.max(res.first_order_max) < 1e-13


def inversion(case: FourBar | SliderCrank, body: str) -> Mech:
    """The same joints with ``body`` and the ground swapped: ``body`` is held still."""
    swap = {body: "ground", "ground": body}
    joints = [
        {
            **j,
            "bodies": [swap.get(b, b) for b in j["bodies"]],
            "point": list(j["point"]),
            "direction": list(j["direction"]),
        }
        for j in case.mech.joints
    ]
    return Mech(f"inversion-{body}", joints, planar=True)


@pytest.mark.parametrize(
    "case",
    [
        FourBar("crank-rocker", *FOUR_BARS["crank-rocker"]),
        SliderCrank("offset-slider-crank", 1.0, 3.0, 0.4, 40.0),
    ],
)
def test_every_inversion_traces_the_same_rows_with_its_own_singular_values(
    tmp_path: Path, case: FourBar | SliderCrank
) -> None:
    base = None
    for body in case.mech.bodies:
        ref = inversion(case, body)
        trace = lw.trace(load(tmp_path, body, ref.toml()), drive="D")
        if base is None:
            base = trace
        assert trace.angles.shape == base.angles.shape
        np.testing.assert_allclose(trace.angles, base.angles, rtol=0.0, atol=1e-12)
        assert [f.value for f in trace.folds] == pytest.approx([f.value for f in base.folds], abs=1e-12)
        for i in range(0, len(trace.angles), 5):
            row = {
                j["name"]: float(np.degrees(v)) if j["type"] == "R" else float(v)
                for j, v in zip(ref.joints, trace.angles[i], strict=True)
            }
            reference = np.linalg.svd(ref.jacobian(row), compute_uv=False)
            np.testing.assert_allclose(trace.sigma[i], reference[:3], rtol=0.0, atol=1e-13 * reference[0])


def test_a_spherical_rocker_folds_where_its_arcs_line_up(tmp_path: Path) -> None:
    """Spherical 4R, ground 80, input 50, coupler 45, output 60 deg (non-Grashof: the input rocks). The input
    turns back where the input's far hinge is b + c or |b - c| from the output's fixed one (spherical
    trigonometry, solved by brentq); the same steps turned and moved in space."""
    g, a, b, c, theta0 = 80.0, 50.0, 45.0, 60.0, 10.0
    case = Spherical4R("spherical-rocker", g, a, b, c, theta0)
    trace = lw.trace(load(tmp_path, "s", case.toml()))
    u_a, u_b, u_d = case.u["A"], case.u["B"], case.u["D"]

    def arc(theta: float, target: float) -> float:
        turned = rot(u_a, np.radians(theta - theta0)) @ u_b
        return float(np.degrees(np.arccos(np.clip(turned @ u_d, -1.0, 1.0)))) - target

    grid = np.linspace(theta0 - 180.0, theta0 + 180.0, 721)
    extremes = [
        brentq(arc, x0, x1, args=(target,), xtol=1e-13)
        for target in (b + c, abs(b - c))
        for x0, x1 in itertools.pairwise(grid)
        if np.sign(arc(x0, target)) != np.sign(arc(x1, target))
    ]
    assert trace.branches[0].end_kind == lw.StopReason.CLOSED and len(extremes) == 2
    found = np.degrees([f.value for f in trace.folds])
    assert len(found) == 2
    for x in found:
        assert min(abs(float(wrap_deg(x - e))) for e in extremes) < 1e-9
    rows = np.degrees(trace.angles)
    assert np.max(np.abs(wrap_deg(rows[-1] - rows[0]))) < 1e-9
    g_move = np.eye(4)
    g_move[:3, :3] = rot(np.array([0.3, -1.0, 0.5]), 2.1)
    g_move[:3, 3] = [12.0, -40.0, 7.0]
    moved = lw.trace(load(tmp_path, "s1", case.toml(motion=g_move)))
    assert moved.angles.shape == trace.angles.shape
    np.testing.assert_allclose(moved.angles, trace.angles, rtol=0.0, atol=1e-10)


@pytest.mark.parametrize(("alpha1", "alpha2"), [(113.0, -157.5), (-83.6, 35.4), (-167.6, -109.1)])
def test_bennett_loops_of_obtuse_and_negative_twists(tmp_path: Path, alpha1: float, alpha2: float) -> None:
    case = Bennett("bennett", 1.3, alpha1, alpha2, -40.0)
    mech = load(tmp_path, "b", case.toml())
    trace = lw.trace(mech)
    assert trace.branches[0].end_kind == lw.StopReason.CLOSED
    rows = np.degrees(trace.angles)
    for i, row in enumerate(rows):
        assert case.check(row)["angle"] < 1e-9
        reference = np.linalg.svd(case.jacobian(row), compute_uv=False)
        np.testing.assert_allclose(trace.sigma[i], reference[:4], rtol=0.0, atol=1e-13 * reference[0])
    assert np.max(np.abs(wrap_deg(rows[-1] - rows[0]))) < 1e-9
    start = float(mech.offsets[0])
    for target in (start + 2 * np.pi, start + 2 * np.pi - 1e-9, start - 2 * np.pi + 0.5 * RAD):
        for steps in (None, 9):
            reached = lw.trace(mech, until=("A", target), steps=steps)
            assert reached.stats.unmet is None
            assert abs(reached.angles[-1, 0] - target) < 1e-12 * abs(target)
            assert case.check(np.degrees(reached.angles[-1]))["angle"] < 1e-9


def test_a_dh_triple_rocker_reaches_its_extremes(tmp_path: Path) -> None:
    """Targets at the input's extremes (law of cosines) and 1e-9 deg inside them, adaptive and in equal steps."""
    case = FourBar("triple-rocker", *FOUR_BARS["triple-rocker"])
    mech = load(tmp_path, "tr", dh_four_bar(case).toml())
    shift = float(np.degrees(mech.offsets[0])) - case.mech.joints[0]["value"]
    for ref in case.fold_refs("A"):
        for inside in (0.0, -1e-9 * np.sign(ref)):
            target = (ref + inside + shift) * RAD
            for steps in (None, 11):
                reached = lw.trace(mech, until=("A", target), steps=steps)
                assert reached.stats.unmet is None
                assert abs(reached.angles[-1, 0] - target) < 1e-12 * max(1.0, abs(target))


def test_path_csv_and_report_json_hold_the_api_values(tmp_path: Path) -> None:
    """An offset slider-crank driven by its slider: path.csv's columns are the API's angles in degrees and the
    slider in lengths, its singular values and residuals the API's; report.json's folds are the API's, at
    sqrt((l +- r)^2 - e^2) (closed form)."""
    case = SliderCrank("offset-slider-crank", 1.0, 3.0, 0.4, 40.0)
    spec = tmp_path / "sc.toml"
    spec.write_text(case.mech.toml())
    trace = lw.trace(lw.load(str(spec)), drive="D")
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["trace", str(spec), "--drive", "D", "--no-plots", "-o", str(out)])
    assert result.exit_code == 0, result.stderr
    with (out / "path.csv").open() as f:
        table = list(csv.DictReader(f))
    assert len(table) == len(trace.angles)
    got = np.array([[float(r[k]) for k in "ABCD"] for r in table])
    expected = np.column_stack([np.degrees(trace.angles[:, :3]), trace.angles[:, 3]])
    np.testing.assert_allclose(got, expected, rtol=1e-15, atol=1e-12)
    sigma = np.array([[float(r[f"sigma_{k}"]) for k in (1, 2, 3)] for r in table])
    np.testing.assert_allclose(sigma, trace.sigma, rtol=1e-14, atol=0.0)  # the command marches in chunks
    np.testing.assert_allclose([float(r["residual"]) for r in table], trace.residual, rtol=0.0, atol=1e-14)
    report = json.loads((out / "report.json").read_text())
    folds = sorted(f["value"] for f in report["folds"])
    assert folds == pytest.approx(sorted(f.value for f in trace.folds), rel=1e-15)
    assert folds == pytest.approx(sorted(case.fold_refs("D")), abs=1e-12)
