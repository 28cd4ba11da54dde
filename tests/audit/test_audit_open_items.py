"""The two open items of the session-16 audit, closed in session 17 (they were strict expected failures), with
properties over generated inputs of each kind, checked against closed forms.

* One paper row over two crossings reported neither: the test function changes sign twice inside the row, and the
  march compared its sign row to row (the rows themselves were right). Now the sign is compared part by part
  within a row, and each part over which it changed is located (``march.MAX_CROSSINGS``).
* Paper steps of about 80 deg or more failed on a Goldberg 5R whose drive nearly stops (other joints move up to 435
  times as fast as the drive A there): one equal step to A + 60 deg was reached, to A + 80 deg it ended 'corrector
  failed at a fixed drive step' after the start (every retake up to 1,311 equal parts failed: a part of 0.06 deg of
  A moves the other joints up to 26 deg there), though an adaptive trace reaches every value of A. Now a step that
  fails in every number of parts follows the path adaptively to the row's drive value and lands on it
  (``BranchMarcher._follow_row``).

References (no linkwork): a four-bar's singular configurations are those with its four pivots in line, the crank
along the ground line (``FourBar.solve`` gives the rows); Goldberg's 5R from Bennett's relation
``tan(t1/2) tan(t2/2) = sin((beta + alpha)/2) / sin((beta - alpha)/2)`` of its two Bennett loops (Goldberg 1943;
the angles of ``linkages.goldberg``'s module docstring, written out again here).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from audit_reference import FourBar, nearest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

import linkwork as lw
from linkwork.linkages.goldberg import goldberg

RAD = np.pi / 180.0

GOLDBERG = """name = "g"
[loop]
convention = "hinge-lines"
[[loop.joints]]
name = "A"
point = [0.6763723584498789, -0.4083216409094894, 0.0]
direction = [-0.3798152453144945, -0.6291523826079277, -0.6781649201230171]
theta = -162.4472241382195
[[loop.joints]]
name = "B"
point = [-0.004764705654008994, -0.018998834356259764, 0.02029428143576991]
direction = [0.02585874022680818, -0.006867488864354649, 0.999642017499555]
theta = 179.7034014234257
[[loop.joints]]
name = "C"
point = [0.7848132297926311, 7.979727989493313e-17, -2.42861286636753e-17]
direction = [-3.4070806119431744e-17, -0.7300226084902118, -0.6834229957304241]
theta = 54.852880171675565
[[loop.joints]]
name = "D"
point = [-0.273924344582003, -0.1245151796200486, 0.1330053228977243]
direction = [0.16947385422244718, -0.6457198323366622, 0.7445297246330072]
theta = -95.57632739886338
[[loop.joints]]
name = "E"
point = [-0.970504512147737, -0.4606958749202211, 0.0]
direction = [-0.4285330465425569, 0.9027501176258373, -0.03743865846276526]
theta = -23.418881198948867
"""


def test_one_paper_row_over_two_crossings_reports_both(tmp_path: Path) -> None:
    """A parallelogram (ground = coupler 3, crank = rocker 1) from 30 to 370 deg in one equal step passes its
    crossings at A = 180 and 360 deg: both are bifurcation points of the closed form."""
    spec = tmp_path / "pg.toml"
    spec.write_text(FourBar("parallelogram", 3.0, 1.0, 3.0, 1.0, 30.0).mech.toml())
    trace = lw.trace(lw.load(str(spec)), until=("A", 370.0 * RAD), steps=1)
    assert trace.stats.unmet is None
    crossings = sorted(float(np.degrees(b.angles[0])) % 360.0 for b in trace.bifurcations)
    assert len(crossings) == 2


def test_a_long_paper_step_of_a_goldberg_linkage_is_taken(tmp_path: Path) -> None:
    """The Goldberg 5R above, one equal step from A = -162.447 to -82.447 deg: the adaptive trace reaches that
    value, so the paper step must too."""
    spec = tmp_path / "g.toml"
    spec.write_text(GOLDBERG)
    mech = lw.load(str(spec))
    target = float(mech.offsets[mech.index("A")]) + 80.0 * RAD
    assert lw.trace(mech, until=("A", target)).stats.unmet is None  # adaptive: reached
    assert lw.trace(mech, until=("A", target), steps=1).stats.unmet is None


# ---- properties: one paper row over both crossings of a parallelogram or a deltoid

PROPERTY = settings(deadline=None, max_examples=10, derandomize=True)


def four_pivots_in_line(case: FourBar, reading: float) -> float:
    """The distance (deg) from a crank reading to the nearest reading with the crank along the ground line, where
    a four-bar's singular configurations are (its four pivots in line)."""
    return float(min(abs((reading - x + 180.0) % 360.0 - 180.0) for x in (0.0, 180.0)))


@PROPERTY
@given(
    kind=st.sampled_from(["parallelogram", "deltoid"]),
    ground=st.floats(1.5, 4.0),
    ratio=st.floats(0.15, 0.8),
    start=st.floats(15.0, 165.0),
    end=st.floats(365.0, 535.0),
    side=st.sampled_from([0, 1]),
)
@example(kind="parallelogram", ground=2.0, ratio=0.5, start=15.0, end=472.6875, side=1)  # a part 0.0007 deg short
def test_one_paper_row_over_both_crossings_reports_both(
    tmp_path_factory: object, kind: str, ground: float, ratio: float, start: float, end: float, side: int
) -> None:
    """A parallelogram (ground = coupler, crank = rocker) or a deltoid (crank = coupler, ground = rocker) meets its
    two singular configurations, the crank along the ground line at 0 and 180 deg, once a turn. One equal step over
    both (and no third) reports both, each a bifurcation on the closed form, and the row is on the closed form, on
    the branch the start is on: a parallelogram's coupler keeps its direction (readings A + B constant) on the
    parallelogram branch only; a deltoid's rocker stays put (D constant, the coupler folded back onto the crank, C
    on A) on its folded branch only. (A part of the row a hair from a crossing had gone on along the other branch:
    the parallelogram 2 x 1 from 15 to 472.69 deg, a part 0.0007 deg short of 360 deg.)"""
    g, a = ground, ratio * ground
    if kind == "parallelogram":
        case = FourBar(kind, g, a, g, a, start, side=side)
        pts = case.pts
        special = bool(np.linalg.norm((pts["C"] - pts["B"]) - (pts["D"] - pts["A"])) < 1e-9)
    else:
        case = FourBar(kind, g, a, a, g, start, side=side)
        special = bool(np.linalg.norm(case.pts["C"] - case.pts["A"]) < 1e-9)
    spec = tmp_path_factory.mktemp("pg") / "pg.toml"  # type: ignore[attr-defined]
    spec.write_text(case.mech.toml())
    trace = lw.trace(lw.load(str(spec)), until=("A", end * RAD), steps=1)
    assert trace.stats.unmet is None
    rows = np.degrees(np.asarray(trace.angles))
    np.testing.assert_allclose(rows[:, 0], [start, end], rtol=0.0, atol=1e-9)
    for r in rows:  # the rows, as before
        row = dict(zip("ABCD", r, strict=True))
        assert nearest(case.solve("A", row["A"]), row, list("ABCD"), set())[0] < 1e-9
    invariant = rows[:, 0] + rows[:, 1] - start if kind == "parallelogram" else rows[:, 3]
    on_special = abs((float(invariant[-1]) + 180.0) % 360.0 - 180.0) < 1e-6
    assert on_special == special, "the row went on along the other branch through a crossing"
    points = [np.degrees(b.angles) for b in trace.bifurcations]
    assert sorted(round(float(p[0]) % 360.0 / 180.0) % 2 for p in points) == [0, 1]  # one at 0, one at 180 deg
    for p in points:
        assert four_pivots_in_line(case, float(p[0])) < 1e-7
        # the other joints against the closed form at the crossing's own reading, to the square root of round-off:
        # at a double point the circle intersection's discriminant is zero, and its round-off (and the located
        # reading's 1e-10 rad) moves the joints as its square root, 1e-6 deg
        row = dict(zip("ABCD", p, strict=True))
        exact = float(p[0]) - ((float(p[0]) + 90.0) % 180.0 - 90.0)
        assert nearest(case.solve("A", exact), row, list("BCD"), set())[0] < 1e-4
    assert {b.kind for b in trace.bifurcations} == {"bifurcation"}
