"""Sarrus's linkage crossing its folded configuration, against the audit's own hinge lines (built from
docs/linkages.md, "Sarrus (6R)") and closed form.

Link 1, height 1.3, beta 90 deg. On the motion path the top plate translates along z; the joints read
q = A (1, 2, 1, 1, 2, 1) (the ratio 1 : 2 : 1 on each limb), and the plates meet (height 2 sin(b - A) = 0) at
A = b = arcsin(1.3 / 2) = 40.5416 deg. There each limb is folded flat with its top and bottom hinges on one line, so
either limb can swing about that line with the plates held: the path crosses a two-dimensional component (a torus
of the two swings) at that point, and goes on to the other side (plates passing through each other). linkwork's
adaptive trace records that point once (kind ``component``, dimension 2) and goes on to its target.
"""

from __future__ import annotations

import numpy as np
import pytest
from audit_reference import about_line

import linkwork as lw

LINK, HEIGHT = 1.0, 1.3
B = float(np.arcsin(HEIGHT / (2 * LINK)))
RATIO = np.array([1.0, 2.0, 1.0, 1.0, 2.0, 1.0])


def hinge_lines(beta: float = np.pi / 2) -> list[tuple[np.ndarray, np.ndarray]]:
    """``(point, direction)`` of A..F from docs/linkages.md: limb k in the vertical plane along n_k = z x u_k, top
    hinge r n_k + height z, knee (r + e) n_k + height/2 z, bottom r n_k; directions +u1, -u1, +u1, -u2, +u2, -u2."""
    z = np.array([0.0, 0.0, 1.0])
    u1, u2 = np.array([1.0, 0.0, 0.0]), np.array([np.cos(beta), np.sin(beta), 0.0])
    r, e = LINK / 2, np.sqrt(LINK**2 - (HEIGHT / 2) ** 2)
    out = []
    for u, signs in ((u1, (1, -1, 1)), (u2, (-1, 1, -1))):
        n = np.cross(z, u)
        top, knee, bottom = r * n + HEIGHT * z, (r + e) * n + HEIGHT / 2 * z, r * n
        points = (top, knee, bottom) if signs[0] > 0 else (bottom, knee, top)
        out += [(p, s * u) for p, s in zip(points, signs, strict=True)]
    return out


def closure(q: np.ndarray) -> float:
    """Largest entry of exp(xi_A q_A) ... exp(xi_F q_F) - I (the audit's product of exponentials)."""
    g = np.eye(4)
    for (p, d), x in zip(hinge_lines(), q, strict=True):
        g = g @ about_line(p, d, x)
    return float(np.abs(g - np.eye(4)).max())


def test_the_reference_holds_on_the_path_and_on_the_component() -> None:
    """The audit's lines close on q = A (1, 2, 1, 1, 2, 1) for any A (1e-14), and at A = b limb 1 can swing with
    limb 2 and the plates held (A, B, C = b + s, 2b, b - s for any s: the two-dimensional component)."""
    for a in np.radians([0.0, 17.0, 40.5416, 63.0, 81.0]):
        assert closure(a * RATIO) < 1e-14
    for s in (0.3, 1.1, np.pi):
        assert closure(np.array([B + s, 2 * B, B - s, B, 2 * B, B])) < 1e-14


def test_an_adaptive_trace_crosses_the_fold_to_its_target() -> None:
    """Holds: from the built-in (its lines equal the audit's: every row closes the audit's product to 1e-12) to A =
    2b: reached, the rows on the closed form (1e-9 rad), the crossing recorded once at A = b (1e-8 deg) as a
    component of dimension 2."""
    mech = lw.load("sarrus", link=LINK, height=HEIGHT)
    tr = lw.trace(mech, drive="A", until=("A", 2 * B))
    assert tr.stats.unmet is None
    assert max(closure(q) for q in tr.angles) < 1e-12
    assert np.abs(tr.angles - np.outer(tr.angles[:, 0], RATIO)).max() < 1e-9
    (point,) = tr.bifurcations
    assert abs(np.degrees(point.angles[0] - B)) < 1e-8 and point.kind == "component"


@pytest.mark.parametrize(("steps", "target"), [(1, B), (2, 2 * B), (200, 2 * B)])
def test_paper_steps_landing_on_the_fold_go_on_to_the_target(steps: int, target: float) -> None:
    """Equal steps of A of which one lands exactly on A = b. Got: the branch ends there, 'entered a 2-dimensional
    component (mobility 2) at point 0', and 'A did not reach 81.08 deg' (with one step to b itself, whose last row
    is b: 'A did not reach 40.54 deg' although it is there). The path does not enter the component, it crosses
    it (the adaptive trace, and paper steps that do not land on it, go on). Right: the target reached, the rows on
    the closed form q = A (1, 2, 1, 1, 2, 1) (1e-9), the point recorded once. Suspected cause: the component test
    (mobility >= 2 over ``component_points`` points) counts the landing row, the located point and the row after
    as three points of the component (kinematics/marcher.py / march.py, the paper march's singular landing)."""
    mech = lw.load("sarrus", link=LINK, height=HEIGHT)
    tr = lw.trace(mech, drive="A", until=("A", target), steps=steps)
    assert tr.stats.unmet is None
    assert np.abs(tr.angles - np.outer(tr.angles[:, 0], RATIO)).max() < 1e-9


@pytest.mark.parametrize("steps", [5, 7])
def test_paper_steps_straddling_the_fold_record_it(steps: int) -> None:
    """5 or 7 equal steps to A = 2b straddle A = b. Got: the target reached with no point recorded
    (``bifurcations == ()``), where the adaptive trace and 3 steps to b + 0.3 rad record the component at b. Right:
    the crossing recorded (at A = b, 1e-8 deg) whatever the step."""
    mech = lw.load("sarrus", link=LINK, height=HEIGHT)
    tr = lw.trace(mech, drive="A", until=("A", 2 * B), steps=steps)
    assert tr.stats.unmet is None
    assert len(tr.bifurcations) == 1 and abs(np.degrees(tr.bifurcations[0].angles[0] - B)) < 1e-8
