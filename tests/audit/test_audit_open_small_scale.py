"""Open (strict xfail): the located singular points of a linkage depend on its length unit and placement.

Goldberg's built-in has no singular point on its path (the smallest non-zero singular value of the closure Jacobian
stays above 6e-2 of the largest, the audit's own check in changes/audit.md). Written in thousandths and moved 42 units
away and turned, it reports five points (two "bifurcations" with an accuracy of inf, two "folds"), and its steps
differ from row 100 on: the rank decisions (``Tolerances.local_min``, ``loose``) are taken on the raw
``sigma_r / sigma_1``, which falls there to 1e-7 (moments about a far origin in a small unit), while the normalised
ratio (``Trace.max_condition``, ``kinematics.normalization``) stays 11.74. See changes/audit.md, "Open".
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from audit_reference import rot

import linkwork as lw


@pytest.mark.xfail(
    strict=True, reason="rank decisions on the raw Jacobian depend on unit and placement (open)"
)
def test_goldberg_in_thousandths_moved_far_has_no_singular_point() -> None:
    mech = lw.load("goldberg")
    r, d, scale = rot([0.3, -1.0, 0.5], 2.1), np.array([12.0, -40.0, 7.0]), 0.001
    w, v = mech.twists[:, :3] @ r.T, scale * mech.twists[:, 3:] @ r.T
    far = replace(mech, twists=np.concatenate([w, v + np.cross(d, w)], axis=1), hinge_points=np.zeros((0, 3)))
    assert len(lw.trace(far).bifurcations) == 0
