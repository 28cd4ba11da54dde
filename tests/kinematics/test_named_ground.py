"""A ground named in Python (``Mechanism.from_joints(..., ground="frame")``) is the ground everywhere: body poses,
the loops' common frame, the normalised Jacobian, drawings and exports. Reference: the same Watt II six-bar with
that body called ``ground`` (the name of a body changes nothing physical), and the poses chained by hand in numpy
(``exp_se3`` of each joint's twist along the tree from the named body).

Before, the name was used for the loops' spanning tree only; every other layer took the body called ``ground``,
else the first body: with the joints listed crank first, the crank was held still in the poses, the MJCF export's
world body and the DXF's ground layer, and the normalised Jacobians (read in the ground's frame) were those of the
mechanism held by its crank.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import linkwork as lw
from linkwork.errors import SpecError
from linkwork.export.mjcf import spanning_tree
from linkwork.geometry import exp_se3
from linkwork.kinematics.closure import body_poses
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.normalization import normalized_jacobians

POINTS = dict(A=(0, 0), B=(0.7, 0.6), C=(3.3, 2.4), D=(4.1, -0.1), E=(1.9, 3.6), F=(-1.2, 4.8), G=(-2.3, 0.4))
# Fixed (A, D, G), crank (A, B), coupler (B, C), rocker (C, D, E), link5 (E, F), link6 (F, G); the crank's
# joint listed first, so the first body is the crank.
BODIES = dict(
    A=("crank", "FIXED"),
    B=("crank", "coupler"),
    C=("coupler", "rocker"),
    D=("rocker", "FIXED"),
    E=("rocker", "link5"),
    F=("link5", "link6"),
    G=("link6", "FIXED"),
)


def watt(fixed: str, **kwargs: str) -> Mechanism:
    """The six-bar with its fixed body called ``fixed``."""
    joints = [
        {
            "name": n,
            "bodies": tuple(fixed if b == "FIXED" else b for b in BODIES[n]),
            "point": p,
            "direction": (0.0, 0.0, 1.0),
        }
        for n, p in POINTS.items()
    ]
    return Mechanism.from_joints("watt", joints, planar=True, **kwargs)


def test_the_named_ground_is_the_ground() -> None:
    named, reference = watt("frame", ground="frame"), watt("ground")
    assert named.bodies[0] == "crank"  # (the first body is not the ground)
    assert named.ground == "frame" and named.grounded
    assert reference.ground == "ground" and reference.grounded
    assert watt("frame").ground == "crank" and not watt("frame").grounded  # no ground named: the first body


def test_the_trace_and_the_poses_are_the_reference_ones() -> None:
    """Rows equal to 1e-12; the named ground's pose the identity at every row; every body's pose the one chained
    by hand from it (numpy), and equal to the reference's."""
    named, reference = watt("frame", ground="frame"), watt("ground")
    until = ("A", float(named.offsets[0]) + np.radians(40.0))
    a, b = lw.trace(named, until=until, steps=8), lw.trace(reference, until=until, steps=8)
    np.testing.assert_allclose(a.angles, b.angles, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(a.sigma, b.sigma, rtol=0.0, atol=1e-12)
    for row in a.angles:
        poses = body_poses(named, angles=row)
        ref = body_poses(reference, angles=row)
        np.testing.assert_allclose(poses["frame"], np.eye(4), atol=1e-15)
        q = named.q_from_angles(row)
        by_hand = {"frame": np.eye(4)}
        by_hand["crank"] = np.linalg.inv(exp_se3(named.twists[0] * q[0]))  # A: crank -> frame, walked back
        by_hand["coupler"] = by_hand["crank"] @ exp_se3(named.twists[1] * q[1])
        by_hand["rocker"] = np.linalg.inv(exp_se3(named.twists[3] * q[3]))  # D: rocker -> frame
        by_hand["link6"] = np.linalg.inv(exp_se3(named.twists[6] * q[6]))  # G: link6 -> frame
        by_hand["link5"] = by_hand["rocker"] @ exp_se3(named.twists[4] * q[4])
        for body, pose in by_hand.items():
            np.testing.assert_allclose(poses[body], pose, atol=1e-12)
            np.testing.assert_allclose(poses[body], ref["ground" if body == "frame" else body], atol=1e-12)


def test_the_normalised_jacobians_are_the_references() -> None:
    """Read in the ground's frame: equal to the reference's to 1e-12 (held by the crank they differ)."""
    named, reference = watt("frame", ground="frame"), watt("ground")
    rows = lw.trace(reference, until=("A", float(reference.offsets[0]) + np.radians(30.0)), steps=3).angles
    np.testing.assert_allclose(
        normalized_jacobians(named, rows), normalized_jacobians(reference, rows), rtol=0.0, atol=1e-12
    )
    by_crank = normalized_jacobians(watt("frame"), rows)
    assert np.abs(by_crank - normalized_jacobians(reference, rows)).max() > 1e-3  # (the test can tell)


def test_the_exports_hold_the_named_ground() -> None:
    """The MJCF tree's root and the drawing's ground are the named body."""
    named = watt("frame", ground="frame")
    assert spanning_tree(named)[0] == "frame"
    svg = named._repr_html_()
    grey = re.findall(r"stroke='#888'[^>]*><title>([^<]*)</title>", svg)
    assert grey == ["frame"]


@pytest.mark.parametrize(
    ("fixed", "ground", "expected"),
    [
        ("frame", "base", r"ground 'base' is not a body of any joint"),
        ("ground", "crank", r"ground 'crank': another body is called 'ground'"),
    ],
)
def test_a_ground_that_cannot_be_is_refused(fixed: str, ground: str, expected: str) -> None:
    with pytest.raises(SpecError, match=expected):
        watt(fixed, ground=ground)
