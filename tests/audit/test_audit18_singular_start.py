"""A four-bar drawn at its change point: a parallelogram (crank 1, coupler 2, rocker 1, ground 2) laid flat, as
a new user draws one, against closed forms written here.

Reference: with the crank at angle A (from the ground line), B = (cos A, sin A); on the parallelogram branch the
coupler stays parallel to the ground (C = B + (2, 0), the coupler's turn relative to the crank, joint B, reads -A),
on the antiparallelogram branch C is the other intersection of the circles |C - B| = 2, |C - D| = 1. The flat
start A = 0 is the crossing of the two branches: the Jacobian loses one rank there, and the mechanism has
mobility 1 on each branch (a single loop of four hinges: Gruebler 3 (4 - 1) - 2 x 4 = 1).

Also a start at a fold of the drive: a slider-crank (crank 1, rod 3) at its top dead centre driven by its slider,
against the law of cosines.
"""

from __future__ import annotations

import numpy as np
import pytest
from audit_reference import Mech

import linkwork as lw


def parallelogram(a0: float) -> Mech:
    """The audit's own four-bar: A = (0, 0), B at angle ``a0`` (deg) on the unit circle, C = B + (2, 0), D = (2, 0);
    joint A reads ``a0`` at the start, the others 0 (as the built-in ``four-bar`` writes it: D's bodies are
    ``[ground, rocker]``)."""
    b = np.array([np.cos(np.radians(a0)), np.sin(np.radians(a0)), 0.0])
    points = {"A": np.zeros(3), "B": b, "C": b + np.array([2.0, 0.0, 0.0]), "D": np.array([2.0, 0.0, 0.0])}
    bodies = [["ground", "crank"], ["crank", "coupler"], ["coupler", "rocker"], ["ground", "rocker"]]
    joints = [
        dict(name=k, bodies=bb, point=list(points[k]), value=a0 if k == "A" else 0.0)
        for k, bb in zip("ABCD", bodies, strict=True)
    ]
    return Mech("parallelogram", joints, planar=True)


def worst_closure(tr: lw.Trace, a0: float) -> float:
    """The largest closure mismatch of the audit's four-bar at every row (displacements from the trace's start)."""
    ref = parallelogram(a0)
    start = np.array([a0, 0.0, 0.0, 0.0])
    rows = np.degrees(tr.angles - tr.angles[0]) + start
    return max(ref.poses(dict(zip("ABCD", row, strict=True)))[1] for row in rows)


def test_the_parallelogram_next_to_its_flat_point_traces_both_closed_forms() -> None:
    """Holds: started at A = 1 deg (built-in ``four-bar``, theta = 1), every row closes the circle equations to
    1e-12 and the path crosses the flat point on the parallelogram branch (B = -A to 1e-9 deg, wrapped)."""
    mech = lw.load("four-bar", ground=2.0, crank=1.0, coupler=2.0, rocker=1.0, theta=np.radians(1.0))
    tr = lw.trace(mech, drive="A", until=("A", np.radians(-30.0)), steps=31)
    assert worst_closure(tr, 1.0) < 1e-12
    a, b = np.degrees(tr.angles[:, 0]), np.degrees(tr.angles[:, 1])
    assert np.abs((b + a + 180.0) % 360.0 - 180.0).max() < 1e-9
    assert len(tr.bifurcations) == 1


def test_a_parallelogram_drawn_flat_is_traced_from_its_crossing() -> None:
    """``linkwork trace four-bar --set crank=1 --set coupler=2 --set rocker=1 --set theta=0`` (and the same four-bar
    written as a ``[mechanism]`` with its four points on a line). Got: 'four-bar: mobility 2 at the start (rank 2,
    4 unknowns); the tracer follows one-parameter paths: couple or fix joints', exit 2, from the API and the
    command line, in adaptive and paper mode, with or without --branches. Right: the flat start is a bifurcation
    point of a mechanism of mobility 1 (the rank drops there only); with branches it is located and both branches
    are traced (the parallelogram branch B = -A, and the antiparallelogram branch), and the advice to couple or fix
    joints (which would freeze a one-degree-of-freedom linkage) is not given. Suspected cause: the start's
    mobility is taken from the rank at the start (kinematics/tracer.py, _path_start / check before marching),
    with no test for a singular start of a path of lower mobility."""
    mech = lw.load("four-bar", ground=2.0, crank=1.0, coupler=2.0, rocker=1.0, theta=0.0)
    tr = lw.trace(mech, branches=True, max_steps=2000)
    assert worst_closure(tr, 0.0) < 1e-12
    a, b = np.degrees(tr.angles[:, 0]), np.degrees(tr.angles[:, 1])
    on_parallelogram = np.abs((b + a + 180.0) % 360.0 - 180.0) < 1e-9
    assert on_parallelogram.any() and (~on_parallelogram).any()


def crank_at(x: float, r: float = 1.0, rod: float = 3.0) -> float:
    """The crank angle (deg, in [0, 180]) of a slider-crank without offset whose slider pin is at ``x`` (law of
    cosines in the triangle crank pivot, crank pin, slider pin)."""
    return float(np.degrees(np.arccos((x * x + r * r - rod * rod) / (2 * x * r))))


def test_a_slider_started_at_its_dead_centre_reaches_a_target_adaptively() -> None:
    """Holds: the built-in slider-crank (crank 1, rod 3, no offset) at theta = 0, its slider D at the top dead
    centre x = 4, driven by D to 3: reached, the crank at arccos(1/6) = 80.4059 deg (1e-9)."""
    mech = lw.load("slider-crank", crank=1.0, rod=3.0, offset=0.0, theta=0.0)
    tr = lw.trace(mech, drive="D", until=("D", 3.0))
    assert tr.stats.unmet is None
    assert abs(abs(np.degrees(tr.angles[-1, 0])) - crank_at(3.0)) < 1e-9


@pytest.mark.parametrize("steps", [1, 10])
def test_a_slider_started_at_its_dead_centre_reaches_a_target_in_equal_steps(steps: int) -> None:
    """``linkwork trace slider-crank --set theta=0 --drive D --until D=3 --steps 10`` (or 1). Got: no step, 'drive
    turning point', exit 3: 'D never reaches 3 on this path (it turns back near 4): its range is [4, 4]' (the
    elliptic trammel started at X = 2, its extreme, the same), while the adaptive trace reaches D = 3. Right:
    equal steps of D from 4 to 3, every row's crank at the law of cosines' angle (1e-9 deg), the target reached:
    at a fold the drive can only move one way, towards the target, on either side of the start. Suspected cause:
    the start's tangent has no drive component there, so its orientation towards the target (kinematics/tracer.py:
    ``t_start`` from the sign of ``start.components[d_unknown]``) is arbitrary and the paper march's first step
    reads as the drive turning back."""
    mech = lw.load("slider-crank", crank=1.0, rod=3.0, offset=0.0, theta=0.0)
    tr = lw.trace(mech, drive="D", until=("D", 3.0), steps=steps)
    assert tr.stats.unmet is None
    np.testing.assert_allclose(tr.angles[:, 3], np.linspace(4.0, 3.0, steps + 1), rtol=0, atol=1e-12)
    for row in tr.angles:
        assert abs(abs(np.degrees(row[0])) - crank_at(row[3])) < 1e-9
