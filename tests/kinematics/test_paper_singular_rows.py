"""Paper mode (equal drive steps) at the drive's and the Jacobian's singular rows, against closed forms written here.

* A slider-crank (crank r, rod l, no offset) started at a dead centre of its slider, driven by the slider: the
  slider pin's position is ``x(A) = r cos A + sqrt(l^2 - r^2 sin^2 A)`` at crank angle A; the start is a fold of
  the drive (x is extreme there), and equal steps of x towards the inside of ``[l - r, l + r]`` reach any target
  there (issue 18, audit18 item 9).
* A four-bar (ground 2) whose crank swings between extremes, traced in equal crank steps past its largest one:
  the fold is where coupler and rocker line up (law of cosines, ``|BD| = coupler + rocker``), and it lies after
  the branch's last row, the step ``Fold.step`` names (audit18 item 4).
* Sarrus's linkage (link a, height h): the path ``q = A (1, 2, 1, 1, 2, 1)`` crosses a two-dimensional component at
  ``A = b = arcsin(h / 2a)`` (plates meeting); equal steps landing on b or straddling it go through to 2b and record
  the point once (audit18 item 10).
"""

from __future__ import annotations

import numpy as np
import pytest

import linkwork as lw

RNG = np.random.default_rng(18)
SLIDERS = [
    (float(r), float(r * k), dead, int(steps))
    for (r, k), dead, steps in zip(
        RNG.uniform([0.3, 1.3], [3.0, 4.0], size=(8, 2)),
        [0, 1] * 4,
        [1, 3, 10, 37, 2, 7, 25, 200],
        strict=True,
    )
]


def slider_at(a: np.ndarray, r: float, rod: float) -> np.ndarray:
    """The slider pin's distance from the crank pivot at crank angle ``a`` (rad): law of cosines."""
    return np.asarray(r * np.cos(a) + np.sqrt(rod**2 - (r * np.sin(a)) ** 2))


@pytest.mark.parametrize(("r", "rod", "dead", "steps"), SLIDERS)
def test_equal_slider_steps_leave_a_dead_centre(r: float, rod: float, dead: int, steps: int) -> None:
    """From the top (theta = 0, x = l + r) or bottom (theta = pi, x = l - r) dead centre, equal steps of the slider
    to a target a third of the stroke inside: every row on the law of cosines (1e-9 of the stroke), the slider's
    values equally spaced, the target reached, no fold at the start."""
    start = rod + r if dead == 0 else rod - r
    target = start - (2 * r / 3) * (1 if dead == 0 else -1)
    mech = lw.load("slider-crank", crank=r, rod=rod, offset=0.0, theta=np.pi * dead)
    tr = lw.trace(mech, drive="D", until=("D", target), steps=steps)
    assert tr.stats.unmet is None
    np.testing.assert_allclose(
        tr.angles[:, 3], np.linspace(start, target, steps + 1), rtol=0, atol=1e-12 * rod
    )
    assert np.abs(slider_at(tr.angles[:, 0], r, rod) - tr.angles[:, 3]).max() < 1e-9 * r
    assert tr.folds == ()


@pytest.mark.parametrize(("r", "rod", "dead", "steps"), SLIDERS[:4])
def test_a_target_beyond_the_dead_centre_is_a_turning_point(
    r: float, rod: float, dead: int, steps: int
) -> None:
    """From a dead centre towards a target outside the stroke: the slider moves away from it either way, so no
    row is taken and the target is refused (the drive turns back at the start)."""
    start = rod + r if dead == 0 else rod - r
    mech = lw.load("slider-crank", crank=r, rod=rod, offset=0.0, theta=np.pi * dead)
    tr = lw.trace(mech, drive="D", until=("D", start + (0.5 if dead == 0 else -0.5) * r), steps=steps)
    assert tr.stats.unmet is not None
    assert len(tr.angles) == 1


def crank_rockers(n: int) -> list[tuple[float, float, float, float]]:
    """Random four-bars (ground 2) assembled at a crank angle ``theta`` whose crank turns back at an extreme
    ``A_max`` above ``theta`` (coupler and rocker in line): ``(crank, coupler, rocker, theta)``."""
    out: list[tuple[float, float, float, float]] = []
    rng = np.random.default_rng(4)
    while len(out) < n:
        crank, coupler, rocker = rng.uniform(0.5, 3.0, size=3)
        c = (crank**2 + 4.0 - (coupler + rocker) ** 2) / (4.0 * crank)
        if not -0.95 < c < 0.95:
            continue
        theta = np.arccos(c) - np.radians(40.0)
        bd = np.sqrt(crank**2 + 4.0 - 4.0 * crank * np.cos(theta))
        if theta > 0.1 and abs(coupler - rocker) + 0.05 < bd < coupler + rocker - 0.05:
            out.append((float(crank), float(coupler), float(rocker), float(theta)))
    return out


@pytest.mark.parametrize(("crank", "coupler", "rocker", "theta"), crank_rockers(6))
@pytest.mark.parametrize("steps", [3, 10, 45, 200])
def test_a_paper_fold_is_after_the_last_row(
    crank: float, coupler: float, rocker: float, theta: float, steps: int
) -> None:
    """Equal crank steps towards theta + 90 deg, past the crank's extreme: the branch turns back there, the fold's
    value is the law of cosines' extreme (1e-7 deg) and its step is the branch's last row."""
    mech = lw.load("four-bar", ground=2.0, crank=crank, coupler=coupler, rocker=rocker, theta=theta)
    tr = lw.trace(mech, drive="A", until=("A", theta + np.pi / 2), steps=steps)
    extreme = np.arccos((crank**2 + 4.0 - (coupler + rocker) ** 2) / (4.0 * crank))
    (fold,) = tr.folds
    assert abs(np.degrees(fold.value - extreme)) < 1e-7
    (branch,) = tr.branches
    assert fold.step == branch.steps == len(tr.angles) - 1


RATIO = np.array([1.0, 2.0, 1.0, 1.0, 2.0, 1.0])


@pytest.mark.parametrize(
    ("link", "height"), [(1.0, 0.7), (2.0, 3.1), (0.01, 0.015), (1.0, 1.9), (30.0, 11.0)]
)
@pytest.mark.parametrize(
    ("steps", "times"),
    [(1, 1.0), (2, 2.0), (4, 2.0), (200, 2.0), (5, 2.0), (7, 2.0), (9, 2.0), (5, 1.5)],
)
def test_paper_steps_cross_sarrus_fold(link: float, height: float, steps: int, times: float) -> None:
    """Equal steps of A to ``times`` b, landing on b (1, 2, 4, 200 steps) or straddling it (5, 7, 9 steps; 5 to 1.5 b): reached, the rows
    on ``q = A (1, 2, 1, 1, 2, 1)`` (1e-9 rad), the crossing recorded once, at b (1e-8 deg), as a component.
    (Open: rows so coarse that the ratio sigma_5 / sigma_1 has no local minimum at a row next to b, 3 steps of 48
    deg at height 1.9, do not record it.)"""
    b = float(np.arcsin(height / (2 * link)))
    mech = lw.load("sarrus", link=link, height=height)
    tr = lw.trace(mech, drive="A", until=("A", times * b), steps=steps)
    assert tr.stats.unmet is None
    assert np.abs(tr.angles - np.outer(tr.angles[:, 0], RATIO)).max() < 1e-9
    (point,) = tr.bifurcations
    assert point.kind == "component" and abs(np.degrees(point.angles[0] - b)) < 1e-8
