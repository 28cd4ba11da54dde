"""``path.csv``'s ``s`` (:func:`linkwork.io.results.file_arclength`) with a slider in long paper rows: the arclength
in file units (degrees for the revolute unknowns, the length unit for the slider), against the quadrature of the
slider-crank's closed form written here, whichever way the trace is computed (the closed form's rows or the
predictor-corrector's, in its own frame or not) and however many equal steps cover the same stretch of the path.

The slider-crank (crank ``c``, rod ``r``, offset ``e``; crank angle ``A``): the rod's angle ``phi`` has
``sin phi = (e - c sin A) / r``, the slider ``D = c cos A + r cos phi``, and the joints read ``B = phi - A``,
``C = -phi``. So ``s`` is the integral over ``A`` of ``|d(A, B, C in degrees, D)/dA|``.

A long paper row is taken in parts no longer than ``max_step`` of the drive (``kinematics/march.py``), and ``s``
sums their chords as ``Trace.arclength`` does: it is the arclength to the chords' accuracy at that spacing (relative
error ``~ (kappa h)^2 / 24``), which the tolerances below allow and which shrinks with ``max_step``. Before, each
row's increment was the internal arclength rescaled by the ratio of the row's chords, off by ``0.3`` on a quarter
turn in one row.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

import linkwork as lw
from linkwork.io.results import file_arclength
from linkwork.kinematics import tracer
from linkwork.kinematics.own_frame import own_frame

RAD = np.pi / 180.0
CRANK, ROD, OFFSET, START = 1.0, 3.0, 0.5, 30.0


def rod_angle(a: float, scale: float = 1.0) -> float:
    """``phi`` at crank angle ``a`` (radians) of the slider-crank with every length times ``scale``."""
    return float(np.arcsin((OFFSET - CRANK * np.sin(a)) / ROD))


def slider(a: float, scale: float = 1.0) -> float:
    """The slider's position ``D`` at crank angle ``a`` (radians), every length times ``scale``."""
    return scale * float(CRANK * np.cos(a) + ROD * np.cos(rod_angle(a)))


def file_speed(a: float, scale: float = 1.0) -> float:
    """``|d(A, B, C in degrees; D in length)/dA|`` at crank angle ``a`` (radians): the integrand of ``s``."""
    phi = rod_angle(a)
    dphi = -CRANK * np.cos(a) / (ROD * np.cos(phi))
    d_d = scale * (-CRANK * np.sin(a) - ROD * np.sin(phi) * dphi)
    k = np.degrees(1.0)
    return float(np.sqrt(k**2 + (k * (dphi - 1.0)) ** 2 + (k * dphi) ** 2 + d_d**2))


def reference_s(a_from: float, a_to: float, scale: float = 1.0) -> float:
    """The arclength in file units from crank angle ``a_from`` to ``a_to`` (degrees), by quadrature."""
    value, _ = quad(file_speed, a_from * RAD, a_to * RAD, args=(scale,), epsabs=1e-12, limit=200)
    return float(value)


def slider_crank(scale: float = 1.0) -> lw.Mechanism:
    """The built-in slider-crank with every length times ``scale`` (crank at 30 deg)."""
    return lw.load(
        "slider-crank", crank=CRANK * scale, rod=ROD * scale, offset=OFFSET * scale, theta=START * RAD
    )


@pytest.fixture(params=["closed form", "march"])
def way(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """Each trace twice: as the tracer picks (the planar closed form's rows), and with the closed form declined
    so that the predictor-corrector marches the same rows in its parts."""
    if request.param == "march":
        monkeypatch.setattr(tracer, "closed_form_rows", lambda *args, **kwargs: None)
    return str(request.param)


@pytest.mark.parametrize("steps", [1, 2, 7])
def test_s_of_a_slider_driven_trace_in_long_rows(way: str, steps: int) -> None:
    """The slider driven from 3.866 to D = 2.5 (A from 30 to 118.418 deg) in 1, 2 or 7 equal steps: the last ``s``
    is the quadrature's 131.2605 to 2e-3 (measured 1.2e-3 in one step: the chords of its 24 parts, the slider's
    part of max_step each, while the crank turns 3.7 deg a part; before, 131.570 in one step)."""
    mech = slider_crank()
    trace = lw.trace(mech, drive="D", until=("D", 2.5), steps=steps)
    assert trace.stats.unmet is None
    a_end = brentq(lambda a: slider(a * RAD) - 2.5, 90.0, 150.0, xtol=1e-13)
    assert trace.angles[-1, 0] == pytest.approx(a_end * RAD, abs=1e-9)
    s = file_arclength(trace)
    assert s[0] == 0.0 and np.all(np.diff(s) > 0.0)
    assert abs(s[-1] - reference_s(START, a_end)) < 2e-3


def test_s_of_a_slider_driven_row_converges_to_the_arclength(way: str) -> None:
    """The same single row with max_step a quarter of the default: its parts four times as many and the chords'
    error sixteen times smaller, within 1e-4 of the quadrature (what a rescaled chord of the row never reaches)."""
    trace = lw.trace(slider_crank(), drive="D", until=("D", 2.5), steps=1, max_step=0.5 * RAD)
    a_end = brentq(lambda a: slider(a * RAD) - 2.5, 90.0, 150.0, xtol=1e-13)
    assert abs(file_arclength(trace)[-1] - reference_s(START, a_end)) < 1e-4


@pytest.mark.parametrize("steps", [3, 7])
def test_s_of_a_full_crank_turn_in_long_rows(way: str, steps: int) -> None:
    """The crank turned once, from 30 to 390 deg, in 3 or 7 equal steps (rows of 120 and 51 deg): the last row is
    the start again, and its ``s`` is the whole turn's arclength 520.4684 by quadrature, to the chords' 5e-6 of
    it (measured 2.2e-6; before, 537.18 in 3 steps and 523.95 in 7)."""
    trace = lw.trace(slider_crank(), until=("A", 390 * RAD), steps=steps)
    assert trace.stats.unmet is None
    turned = trace.angles[-1] - trace.angles[0]  # A and B a whole turn on, C and D back where they were
    np.testing.assert_allclose(turned, [2 * np.pi, -2 * np.pi, 0.0, 0.0], atol=1e-9)
    s = file_arclength(trace)
    assert s[-1] == pytest.approx(reference_s(START, 390.0), rel=5e-6)


def test_s_of_a_closed_path_in_long_rows_two_turns() -> None:
    """Two turns of the crank in 6 equal steps: the path closes after the first (the predictor-corrector's
    closing row) and goes round again to the target; ``s`` at every row is the quadrature's from the start to
    that row's crank angle, to the chords' 5e-6 (measured 3.0e-6 at the first row)."""
    trace = lw.trace(slider_crank(), until=("A", 750 * RAD), steps=6)
    assert trace.stats.unmet is None
    s = file_arclength(trace)
    a = np.degrees(trace.angles[:, 0])
    expected = [reference_s(START, float(x)) for x in a]
    np.testing.assert_allclose(s, expected, rtol=5e-6)


def test_s_adaptive_with_a_slider_still_within_1e_3() -> None:
    """Adaptive, the crank from 30 to 120 deg and the slider to D = 2.5: ``s`` within 1e-3 of the quadrature
    (the rows' chords, no longer than max_step)."""
    mech = slider_crank()
    trace = lw.trace(mech, until=("A", 120 * RAD))
    assert abs(file_arclength(trace)[-1] - reference_s(START, 120.0)) < 1e-3
    driven = lw.trace(mech, drive="D", until=("D", 2.5))
    a_end = brentq(lambda a: slider(a * RAD) - 2.5, 90.0, 150.0, xtol=1e-13)
    assert abs(file_arclength(driven)[-1] - reference_s(START, a_end)) < 1e-3


@pytest.mark.parametrize("steps", [1, 3])
def test_s_in_its_own_frame_is_in_the_users_unit(steps: int) -> None:
    """The slider-crank in thousands (traced as its twin in its own frame, where a length is measured in the
    linkage's own): the slider's travel counts in the user's unit, ``s`` the quadrature's with ``D`` times 1000,
    to the chords' 1e-5 of it (before: the row's chord ratio, 1.5 % off in one step)."""
    mech = slider_crank(1e3)
    assert own_frame(mech).used
    trace = lw.trace(mech, until=("A", 120 * RAD), steps=steps)
    assert trace.stats.unmet is None
    assert file_arclength(trace)[-1] == pytest.approx(reference_s(START, 120.0, 1e3), rel=1e-5)


@pytest.mark.parametrize("steps", [None, 1, 3])
def test_s_without_a_slider_is_degrees_of_the_arclength(way: str, steps: int | None) -> None:
    """A four-bar (no prismatic unknown) in long rows, in short ones, adaptive: ``s`` is ``degrees(arclength)``
    bit for bit, and the trace carries no second arclength."""
    mech = lw.load("four-bar")
    trace = lw.trace(mech, until=("A", float(mech.offsets[0]) + 100 * RAD), steps=steps)
    assert trace.arclength_in_file_units is None
    np.testing.assert_array_equal(file_arclength(trace), np.degrees(trace.arclength))


@pytest.mark.parametrize("steps", [1, 3, None])
def test_s_of_a_row_landed_on_a_limit(steps: int | None) -> None:
    """The crank driven to 120 deg with ``limits={"D": (2.6, 5)}`` in 1 or 3 equal steps or adaptive: the branch
    ends on D = 2.6 (A = 111.661 deg, the closed form's root), landed on from the row before, and its ``s`` is the
    quadrature's 122.3057 to 1e-3 (measured 1.3e-4 in one step; before, the landing step's chord: 0.58 short in one
    step of 82 deg, 0.017 in three)."""
    trace = lw.trace(slider_crank(), until=("A", 120 * RAD), steps=steps, limits={"D": (2.6, 5.0)})
    assert trace.branches[0].end_kind == lw.StopReason.LIMIT
    a_end = brentq(lambda a: slider(a * RAD) - 2.6, 90.0, 120.0, xtol=1e-13)
    assert trace.angles[-1, 0] == pytest.approx(a_end * RAD, abs=1e-9)
    assert abs(file_arclength(trace)[-1] - reference_s(START, a_end)) < 1e-3


@pytest.mark.parametrize("steps", [45, 90])
def test_s_of_short_rows_with_a_slider(way: str, steps: int) -> None:
    """The crank from 30 to 120 deg in rows of 2 and 1 deg (no parts: each row one step of the sum): the last ``s``
    is the quadrature's 133.339 to 1e-3, as in long rows and adaptive."""
    trace = lw.trace(slider_crank(), until=("A", 120 * RAD), steps=steps)
    assert trace.stats.unmet is None
    assert abs(file_arclength(trace)[-1] - reference_s(START, 120.0)) < 1e-3
