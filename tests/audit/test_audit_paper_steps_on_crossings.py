"""Paper-mode steps that land exactly on a four-bar's crossing (Grashof's change point), checked against the audit's
closed form (``audit_reference.FourBar``: circle intersections from the drive's value) and the paper mode's promise
of equal drive steps.

Got, before the fixes (compiled kernels; `linkwork trace` of the same spec with `--until A=340 --steps 3`):

* the row at the crossing (A = 180 deg) 3.8e-5 deg off the closed form: the corrector holding the drive stops at a
  closure residual of 1e-12, which on a double point leaves the other joints only as close as its square root,
  while the crossing located beside it was right to 5e-12 rad (now the row is put on the located point);
* the next row at A = 260.00000001092 deg instead of 260, its other joints 1e-7 deg off: the corrector's
  truncated-SVD fallback (taken next to the crossing, where the Cholesky step is refused) moved the held drive by
  the round-off in its zero column times a large correction (now the held unknown is never moved).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from audit_reference import FourBar, nearest

import linkwork as lw

RAD = np.pi / 180.0


@pytest.mark.parametrize(
    ("dims", "target", "steps"),
    [
        ((3.0, 1.0, 2.5, 1.5, 100.0, 1), 340.0, 3),  # crank 1: a crank-rocker at its change point
        (
            (2.0, 3.0, 1.5, 3.5, 100.0, 0),
            260.0,
            2,
        ),  # coupler 1.5 shortest: a double rocker at its change point
    ],
)
def test_equal_steps_through_a_crossing_stay_on_the_closed_form(
    tmp_path: Path, dims: tuple[float, ...], target: float, steps: int
) -> None:
    """Every row on the closed form to 1e-9 deg and at its equal drive step to 1e-9 deg; the crossing reported."""
    case = FourBar("change-point", *dims[:5], side=int(dims[5]))
    spec = tmp_path / "cp.toml"
    spec.write_text(case.mech.toml())
    trace = lw.trace(lw.load(str(spec)), until=("A", target * RAD), steps=steps)
    rows = np.degrees(np.asarray(trace.angles))
    np.testing.assert_allclose(rows[:, 0], np.linspace(dims[4], target, steps + 1), rtol=0.0, atol=1e-9)
    for r in rows:
        row = dict(zip("ABCD", r, strict=True))
        err = min(nearest(case.solve(x, row[x]), row, list("ABCD"), set())[0] for x in "AD")
        assert err < 1e-9, f"row at A = {r[0]!r} is {err:.2e} deg off the closed form"
    assert [round(float(np.degrees(b.angles[0])), 6) for b in trace.bifurcations] == [180.0]
