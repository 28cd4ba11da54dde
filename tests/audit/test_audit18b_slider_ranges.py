"""The slider's range on an offset slider-crank (crank r = 1, rod l = 3, offset e = 0.7), its crank driven one
full turn, against the closed form: the pin's extremes where crank and rod lie in line, ``x = sqrt((l +- r)^2 -
e^2)``, at crank angles ``atan2(e, x)`` (extended) and ``atan2(-e, -x)`` (folded). In metres-like and
millimetres-like sizes (x 1e-3, x 1, x 1e3), moved 5.4 sizes away and turned; adaptive and in 2-deg paper steps;
started generically or 0.3 deg past an extreme (in the step that closes the turn).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from audit_reference import SliderCrank, rot

import linkwork as lw
from linkwork.kinematics.extremes import joint_ranges

R, L, E = 1.0, 3.0, 0.7


def extremes() -> tuple[float, float]:
    return float(np.sqrt((L - R) ** 2 - E**2)), float(np.sqrt((L + R) ** 2 - E**2))


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e3])
@pytest.mark.parametrize("steps", [None, 180])
@pytest.mark.parametrize("start", ["generic", "past-extended", "past-folded"])
def test_the_sliders_range_is_its_stroke(tmp_path: Path, scale: float, steps: int | None, start: str) -> None:
    """D's range is the closed form's stroke ends times ``scale`` to 1e-9 of the crank (measured 5e-16 .. 1.2e-11),
    never narrower than the rows. Before this branch's fixes in kinematics/extremes.py every x 1e3 case read the
    rows' stroke (3.1e-5 of the crank short at the folded end: `_tangent` oriented both ends' tangents by the
    chord in the plain metric, where the slider's length outweighs the angles, so the slider's turn was never
    seen), and the ``past-*`` starts at the other sizes missed the extreme in the closing step."""
    lo_ref, hi_ref = extremes()
    theta0 = {
        "generic": 40.0,
        "past-extended": float(np.degrees(np.arctan2(E, hi_ref))) + 0.3,
        "past-folded": float(np.degrees(np.arctan2(-E, -lo_ref))) % 360.0 + 0.3,
    }[start]
    case = SliderCrank("offset-slider-crank", R, L, E, theta0)
    motion = np.eye(4)
    motion[:3, :3] = rot([0.0, 0.0, 1.0], 0.9)
    motion[:3, 3] = [5.0 * scale, -2.0 * scale, 0.0]
    spec = tmp_path / "sc.toml"
    spec.write_text(case.mech.toml(scale=scale, motion=motion))
    mech = lw.load(str(spec))
    until = None if steps is None else ("A", np.radians(theta0 + 360.0))
    trace = lw.trace(mech, drive="A", until=until, steps=steps)
    lo, hi = joint_ranges(trace, 0)["D"]
    assert abs(lo - lo_ref * scale) < 1e-9 * R * scale
    assert abs(hi - hi_ref * scale) < 1e-9 * R * scale
    rows = trace.angles[:, list(mech.joint_names).index("D")]
    assert lo <= rows.min() and hi >= rows.max()


@pytest.mark.parametrize("far", [100.0, 1e4])
def test_a_large_slider_crank_far_from_the_origin(tmp_path: Path, far: float) -> None:
    """The same slider-crank x 1e3 (a 1000 mm crank) moved ``far`` sizes from the origin (1e5 and 1e7 mm),
    2-deg paper steps: the stroke's ends to 1e-9 of the crank, as at the origin (measured 8.4e-13 and 1.1e-12).
    Was: off by 7.7e-8 of the crank (far 100) and the rows' stroke (far 1e4: 3.1e-5 and 1.3e-6 of the crank
    short, no turning point located). Cause: the tracer traced the linkage as its twin in its own frame
    (kinematics/own_frame.py) but kinematics/extremes.py located the turning points on the user's linkage, whose
    closure Jacobian at 1e5 mm from the origin has singular values 1.9e5 .. 3.6e-3: the corrector stalled at
    7e-10 mm and that left the point 7.7e-5 mm off the path along the slider (at 1e7 mm nothing was corrected).
    Fixed there: the points are located on the twin, with the twin's tolerances."""
    lo_ref, hi_ref = extremes()
    case = SliderCrank("offset-slider-crank", R, L, E, 40.0)
    motion = np.eye(4)
    motion[:3, :3] = rot([0.0, 0.0, 1.0], 0.9)
    motion[:3, 3] = [far * 1e3, -0.4 * far * 1e3, 0.0]
    spec = tmp_path / "sc.toml"
    spec.write_text(case.mech.toml(scale=1e3, motion=motion))
    mech = lw.load(str(spec))
    trace = lw.trace(mech, drive="A", until=("A", np.radians(400.0)), steps=180)
    lo, hi = joint_ranges(trace, 0)["D"]
    assert abs(lo - lo_ref * 1e3) < 1e-9 * 1e3
    assert abs(hi - hi_ref * 1e3) < 1e-9 * 1e3
