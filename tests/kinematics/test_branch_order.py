"""Which direction of a new branch is traced first does not depend on the sign an SVD gave its tangent."""

from __future__ import annotations

import numpy as np

import linkwork as lw
from linkwork.kinematics.marcher import leading_sign
from linkwork.kinematics.tracer import trace


def test_leading_sign_is_that_of_the_drive_or_of_the_first_moving_unknown() -> None:
    rng = np.random.default_rng(7)
    for _ in range(50):
        t = rng.normal(size=6)
        t /= np.linalg.norm(t)
        drive = int(rng.integers(6))
        assert leading_sign(t, drive) * t[drive] > 0.0
        np.testing.assert_array_equal(leading_sign(t, drive) * t, leading_sign(-t, drive) * -t)
    still = np.array([1e-12, 0.0, -0.6, 0.8])  # the drive (unknown 0) stays put: the first unknown that moves
    assert leading_sign(still, 0) == -1 and leading_sign(-still, 0) == 1


def test_a_parallelograms_new_branch_is_traced_first_with_the_drive_increasing() -> None:
    """The parallelogram four-bar (ground 2, crank 1) branches where it folds flat (crank at 180 deg): the
    branch queued there first leaves with the crank angle increasing, its twin with it decreasing."""
    mech = lw.load("four-bar", ground=2, crank=1, coupler=2, rocker=1, theta=np.radians(60))
    tr = trace(mech, branches=True)
    queued = [br for br in tr.branches if br.parent is not None]
    assert len(queued) == 2 and queued[0].bifurcation == queued[1].bifurcation
    drive = mech.index(tr.drive)
    moves = []
    for br in queued:
        rows = np.flatnonzero(tr.branch == br.id)
        moves.append(tr.angles[rows[1], drive] - tr.angles[rows[0], drive])
    assert moves[0] > 0.0 > moves[1]
