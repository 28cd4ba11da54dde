"""The audit's linkages, none of them a built-in, traced through the Python API and checked against the audit's own
numpy references (``audit_reference``: closed forms, forward kinematics, closure Jacobians and their SVD).

* every row's joint values against the closed form at that row's drive value (four-bars of every Grashof class, an
  offset slider-crank driven by its slider, a Stephenson III six-bar, a spherical 4R, a Bennett loop);
* every row's singular values against numpy's SVD of the closure Jacobian built from that row's angles;
* a closed path's last row is its first; folds where the law of cosines puts the drive's extremes, and
  ``Trace.folds[k].value`` a joint value; targets at a drive's extremes reached;
* paper-mode steps landing exactly on a parallelogram's crossing report the bifurcation;
* the step sequence is the same with the linkage scaled by 1000, moved and turned.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from audit_reference import (
    Bennett,
    FourBar,
    Mech,
    SliderCrank,
    Spherical4R,
    Stephenson3,
    dh,
    nearest,
    rot,
    wrap_deg,
)

import linkwork as lw

RAD = np.pi / 180.0


def load(tmp_path: Path, name: str, text: str) -> lw.Mechanism:
    spec = tmp_path / f"{name}.toml"
    spec.write_text(text)
    return lw.load(str(spec))


def rows_deg(case: Mech, trace: lw.Trace) -> np.ndarray:
    """The trace's rows in file units: degrees for revolute joints, lengths for prismatic ones."""
    ang = np.asarray(trace.angles).copy()
    for k, j in enumerate(case.joints):
        if j["type"] == "R":
            ang[:, k] = np.degrees(ang[:, k])
    return ang


def check_planar(case, trace: lw.Trace, drive: str) -> tuple[float, float]:
    """Worst joint error (deg; the closed form from the drive, or from the other input near the drive's folds) and
    worst singular-value error relative to sigma_1."""
    mech = case.mech
    names = mech.names
    pris = {j["name"] for j in mech.joints if j["type"] == "P"}
    worst_angle = worst_sigma = 0.0
    sig = np.asarray(trace.sigma)
    rows = rows_deg(mech, trace)
    for i in sorted({*range(0, len(rows), 2), len(rows) - 1}):  # every other row and the last (time)
        row = dict(zip(names, rows[i], strict=True))
        err = min(
            nearest(case.solve(x, row[x]), row, names, pris)[0] for x in getattr(case, "inputs", (drive,))
        )
        worst_angle = max(worst_angle, err)
        s_ref = np.linalg.svd(mech.jacobian(row), compute_uv=False)
        worst_sigma = max(worst_sigma, float(np.max(np.abs(sig[i] - s_ref[: sig.shape[1]])) / s_ref[0]))
    return worst_angle, worst_sigma


FOUR_BARS = {
    "crank-rocker": (4.0, 1.3, 3.7, 2.9, 35.0),
    "double-crank": (1.0, 2.5, 3.0, 2.8, 70.0),
    "triple-rocker": (4.0, 2.0, 3.5, 2.4, 20.0),
    "change-point": (4.0, 1.5, 3.0, 2.5, 60.0),
    "parallelogram": (3.0, 1.0, 3.0, 1.0, 30.0),
    "deltoid": (1.0, 1.0, 2.5, 2.5, 50.0),
}


@pytest.mark.parametrize("name", sorted(FOUR_BARS))
def test_four_bar_whole_loop(tmp_path: Path, name: str) -> None:
    """Adaptive trace round the whole loop: rows on the closed form (to the closure tolerance's conditioning near
    the singular points), singular values numpy's, the last row the first."""
    case = FourBar(name, *FOUR_BARS[name])
    trace = lw.trace(load(tmp_path, name, case.mech.toml()))
    angle, sigma = check_planar(case, trace, "A")
    assert angle < 3e-9  # degrees: 5e-11 rad, near bifurcations where a 1e-12 residual allows that much
    assert sigma < 1e-12
    assert trace.branches[0].end_kind == lw.StopReason.CLOSED
    a = rows_deg(case.mech, trace)
    assert np.max(np.abs(wrap_deg(a[-1] - a[0]))) < 1e-9
    assert np.max(np.abs(np.asarray(trace.sigma)[-1] - np.asarray(trace.sigma)[0])) < 1e-12


def test_four_bar_folds_are_the_law_of_cosines_extremes(tmp_path: Path) -> None:
    """A triple rocker's input folds where coupler and rocker are in line; a crank-rocker's rocker where crank
    and coupler are; Trace.folds[k].value is the joint value there (radians)."""
    for name, drive in (("triple-rocker", "A"), ("crank-rocker", "D")):
        case = FourBar(name, *FOUR_BARS[name])
        trace = lw.trace(load(tmp_path, name, case.mech.toml()), drive=drive)
        refs = case.fold_refs(drive)
        assert len(trace.folds) == 2
        for f in trace.folds:
            assert min(abs(float(wrap_deg(np.degrees(f.value) - x))) for x in refs) < 1e-9


def test_triple_rocker_targets_at_its_extremes(tmp_path: Path) -> None:
    """--until at the input's extreme (law of cosines) and just inside it is reached exactly."""
    case = FourBar("triple-rocker", *FOUR_BARS["triple-rocker"])
    mech = load(tmp_path, "triple-rocker", case.mech.toml())
    top = max(case.fold_refs("A"))
    for target in (top, top - 1e-9, top - 1e-6, -top + 1e-9):
        trace = lw.trace(mech, until=("A", target * RAD))
        assert trace.stats.unmet is None
        assert abs(float(np.degrees(trace.angles[-1, 0])) - target) < 1e-11


def test_slider_crank_driven_by_its_slider(tmp_path: Path) -> None:
    """Offset slider-crank, the slider as drive: rows on the closed form, folds at x = sqrt((l +- r)^2 - e^2)."""
    case = SliderCrank("offset-slider-crank", 1.0, 3.0, 0.4, 40.0)
    trace = lw.trace(load(tmp_path, "sc", case.mech.toml()), drive="D")
    angle, sigma = check_planar(case, trace, "D")
    assert angle < 1e-10
    assert sigma < 1e-12
    refs = case.fold_refs("D")
    assert sorted(float(f.value) for f in trace.folds) == pytest.approx(sorted(refs), abs=1e-11)


def test_stephenson_six_bar(tmp_path: Path) -> None:
    """Stephenson III (ternary ground and coupler not joined): two loops, closed form by two dyads."""
    case = Stephenson3(
        "stephenson-audit",
        dict(A=(0, 0), B=(0.7, 0.6), C=(3.3, 2.4), D=(4.1, -0.1), E=(1.9, 3.6), F=(-1.2, 4.8), G=(-2.3, 0.4)),
        40.6,
    )
    mech = load(tmp_path, "stephenson", case.mech.toml())
    for kwargs in ({}, dict(until=("A", 100.6 * RAD), steps=30)):
        angle, sigma = check_planar(case, lw.trace(mech, **kwargs), "A")
        assert angle < 1e-10
        assert sigma < 1e-12


def test_spherical_four_bar(tmp_path: Path) -> None:
    """Spherical 4R from its hinge lines: the input-output equation A cos psi + B sin psi = K."""
    case = Spherical4R("spherical-4r", 70, 25, 60, 50, 30)
    trace = lw.trace(load(tmp_path, "sph", case.toml()))
    sig = np.asarray(trace.sigma)
    for i, r in enumerate(np.degrees(np.asarray(trace.angles))):
        assert case.check(r)["angle"] < 1e-10
        s_ref = np.linalg.svd(case.jacobian(r), compute_uv=False)
        assert np.max(np.abs(sig[i] - s_ref[: sig.shape[1]])) < 1e-12 * s_ref[0]


def test_bennett_own_dimensions(tmp_path: Path) -> None:
    """Bennett 30/110 deg: tan(t1/2) tan(t2/2) = sin((a2+a1)/2) / sin((a2-a1)/2), t3 = -t1, t4 = -t2; the
    singular values those of the DH loop's Jacobian (frame 0 held still)."""
    case = Bennett("bennett-audit", 0.8, 30.0, 110.0, 70.0)
    mech = load(tmp_path, "bennett", case.toml())
    for kwargs in ({}, dict(until=("A", 250 * RAD), steps=90), dict(until=("A", 430 * RAD))):
        trace = lw.trace(mech, **kwargs)
        sig = np.asarray(trace.sigma)
        for i, r in enumerate(np.degrees(np.asarray(trace.angles))):
            err = case.check(r)
            assert err["angle"] < 1e-9 and err["closure"] < 1e-12
            s_ref = np.linalg.svd(case.jacobian(r), compute_uv=False)
            assert np.max(np.abs(sig[i] - s_ref[: sig.shape[1]])) < 1e-12 * s_ref[0]
        assert trace.stats.unmet is None


def test_parallelogram_paper_steps_on_the_crossing(tmp_path: Path) -> None:
    """1-degree steps from 30 to 200 deg land exactly on the crossing at 180 deg: the bifurcation is reported."""
    case = FourBar("parallelogram", *FOUR_BARS["parallelogram"])
    trace = lw.trace(load(tmp_path, "pg", case.mech.toml()), until=("A", 200 * RAD), steps=170)
    assert [np.degrees(b.angles[0]) for b in trace.bifurcations] == [pytest.approx(180.0, abs=1e-8)]


def _bennett_lines(b: Bennett, scale: float, g: np.ndarray) -> str:
    """Bennett's hinge lines (from the audit's DH product at the start), scaled, then moved by ``g``."""
    m, joints, bodies = np.eye(4), [], ["L3", "L0", "L1", "L2", "L3"]
    for i, (n, (d, a, al), t) in enumerate(zip(b.names, b.links, b.theta0, strict=True)):
        joints.append(
            dict(name=n, bodies=bodies[i : i + 2], point=list(m[:3, 3]), direction=list(m[:3, 2]), value=t)
        )
        m = m @ dh(np.radians(t), d, a, np.radians(al))
    return Mech("bennett-lines", joints, planar=False, root="L3").toml(scale=scale, motion=g)


def test_steps_do_not_depend_on_unit_or_placement(tmp_path: Path) -> None:
    """The same Bennett loop, as written and x1000, moved and turned: the same adaptive steps."""
    b = Bennett("bennett-audit", 0.8, 30.0, 110.0, 70.0)
    g = np.eye(4)
    g[:3, :3] = rot([0.3, -1.0, 0.5], 2.1)
    g[:3, 3] = [12.0, -40.0, 7.0]
    t0 = lw.trace(load(tmp_path, "b0", _bennett_lines(b, 1.0, np.eye(4))))
    t1 = lw.trace(load(tmp_path, "b1", _bennett_lines(b, 1000.0, g)))
    assert t0.angles.shape == t1.angles.shape
    assert np.max(np.abs(np.asarray(t0.arclength) - np.asarray(t1.arclength))) < 1e-9
    assert np.max(np.abs(wrap_deg(np.degrees(np.asarray(t0.angles) - np.asarray(t1.angles))))) < 1e-9


@pytest.mark.parametrize(("name", "crossings"), [("change-point", [180.0]), ("parallelogram", [0.0, 180.0])])
def test_located_crossings_are_within_their_stated_accuracy(
    tmp_path: Path, name: str, crossings: list[float]
) -> None:
    """A four-bar whose links can all lie on the ground line crosses itself there (the crank at 180 deg, and
    0 deg too for the parallelogram): each located crossing is within the accuracy it states (report.json's
    `accuracy`, `Bifurcation.bracket`, radians over the unknowns) of the closed form, and that is below 1e-8.

    Was: the change-point four-bar's crossing 4.2e-9 deg off, stated accurate to 2.3e-15 (the distance between
    the two fitted branches, not their fit's error)."""
    case = FourBar(name, *FOUR_BARS[name])
    trace = lw.trace(load(tmp_path, name, case.mech.toml()))
    assert len(trace.bifurcations) == len(crossings)
    names = case.mech.names
    for bif in trace.bifurcations:
        row = dict(zip(names, np.degrees(np.asarray(bif.angles)), strict=True))
        a = min(crossings, key=lambda c: abs(wrap_deg(row["A"] - c)))
        err_deg, _ = nearest(case.solve("A", a), row, names, set())
        assert err_deg * RAD <= bif.bracket < 1e-8, (
            f"off by {err_deg * RAD:.2e} rad, stated {bif.bracket:.2e}"
        )


@pytest.mark.parametrize("scale", [1e-5, 1e-3, 1.0, 1e3])
def test_accuracy_does_not_depend_on_the_length_unit(tmp_path: Path, scale: float) -> None:
    """A crank-rocker of 4 units and the same written 1000 times larger or up to 100,000 times smaller (a
    millimetre mechanism in metres, a MEMS one): every row on the closed form to the same round-off.

    Was: the corrector stopped at a residual of 1e-12 in the length unit, a billionth of a 1-mm loop: 1.2e-8 deg
    off the closed form at 1e-3, 8.4e-7 deg at 1e-5 (1.1e-13 at 1)."""
    case = FourBar("crank-rocker", *(x * scale for x in FOUR_BARS["crank-rocker"][:4]), 35.0)
    trace = lw.trace(load(tmp_path, "cr", case.mech.toml()))
    angle, sigma = check_planar(case, trace, "A")
    assert angle < 1e-12  # degrees
    assert sigma < 1e-13
    assert trace.branches[0].end_kind == lw.StopReason.CLOSED


@pytest.mark.parametrize("scale", [1e-5, 1e-3, 1.0, 1e3])
def test_a_slider_crank_driven_by_its_slider_folds_at_its_extremes_in_any_unit(
    tmp_path: Path, scale: float
) -> None:
    """The offset slider-crank driven by its slider turns back at the slider's extremes,
    sqrt((l +- r)^2 - e^2): both folds found, to 2e-13 of the slider's travel, whatever the length unit.

    Was: x1000, one fold, 2e-5 off (the tangent oriented in the plain metric flipped beyond the slider's
    extreme while the fold was bisected); x0.001, both folds, 6.7e-10 off."""
    r, l, e = 1.0 * scale, 3.0 * scale, 0.4 * scale
    case = SliderCrank("offset-slider-crank", r, l, e, 40.0)
    trace = lw.trace(load(tmp_path, "sc", case.mech.toml()), drive="D")
    assert trace.branches[0].end_kind == lw.StopReason.CLOSED
    extremes = sorted([np.sqrt((l + r) ** 2 - e**2), np.sqrt((l - r) ** 2 - e**2)])
    found = sorted(f.value for f in trace.folds)
    np.testing.assert_allclose(found, extremes, rtol=0.0, atol=2e-13 * 2 * r)
