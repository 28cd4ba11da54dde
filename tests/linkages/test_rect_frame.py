"""Guest-type rectangular frames: hinge lines against the faces and cut planes they are described by, Guest's
frame as one member (the same lines up to a rigid motion, the same motion), parameter checks."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import linkwork as lw
from linkwork.errors import SpecError
from linkwork.kinematics.closure import jacobian
from linkwork.kinematics.points import positions
from linkwork.kinematics.positions import poses_along
from linkwork.kinematics.rank import numerical_rank
from linkwork.linkages.guest import guest_frame
from linkwork.linkages.rect_frame import SITES, hinge_sites, rect_frame
from linkwork.linkages.registry import get

L, W, S = 2.0, 1.0, 0.1
H = S / np.sqrt(2.0)


def lines(mech: lw.Mechanism) -> tuple[np.ndarray, np.ndarray]:
    """Unit directions ``(n, 3)`` and moments ``(n, 3)`` (Pluecker coordinates) of the joint axes at the start."""
    w, v = mech.twists[:, :3], mech.twists[:, 3:]
    norm = np.linalg.norm(w, axis=1, keepdims=True)
    return w / norm, v / norm


def plane_distance(
    point: np.ndarray, direction: np.ndarray, normal: tuple[float, ...], offset: float
) -> float:
    """0 when the line lies in the plane ``normal . x = offset``."""
    n = np.asarray(normal, dtype=float)
    scale = np.linalg.norm(n)
    return max(abs(n @ direction) / scale, abs(n @ point - offset) / scale)


@pytest.mark.parametrize("cuts", ["EW", "NS", "E", "ENS", "NESW", ""])
def test_every_hinge_lies_on_its_face_and_its_mitre_or_cut_plane(cuts: str) -> None:
    """Each face choice: the line is on the rod's upward face (inward or outward) and on the mitre plane (a
    corner) or the cut plane (a midpoint), written out from the section |y - y0| + |z| <= h (docs/linkages.md)."""
    sites = hinge_sites(cuts)
    for faces in itertools.product("io", repeat=len(sites)):
        mech = rect_frame(L, W, S, cuts, "".join(faces))
        d, m = lines(mech)
        p = np.cross(d, m)  # the foot of the origin on each line
        for (name, sx, sy), face, pj, dj in zip(sites, faces, p, d, strict=True):
            s = -1.0 if face == "i" else 1.0  # inward: -n . (x - c) + z = h; outward: +n . (x - c) + z = h
            if sx and sy:
                # the long rod's upward face, and the vertical mitre plane through the corner along (sx, sy)
                assert plane_distance(pj, dj, (0.0, s * sy, 1.0), H + s * sy * sy * W / 2) < 1e-12
                assert plane_distance(pj, dj, (sy, -sx, 0.0), sy * sx * L / 2 - sx * sy * W / 2) < 1e-12
            elif sx:  # a short side cut by the plane y = 0
                assert plane_distance(pj, dj, (s * sx, 0.0, 1.0), H + s * L / 2) < 1e-12, name
                assert plane_distance(pj, dj, (0.0, 1.0, 0.0), 0.0) < 1e-12
            else:  # a long side cut by the plane x = 0
                assert plane_distance(pj, dj, (0.0, s * sy, 1.0), H + s * W / 2) < 1e-12, name
                assert plane_distance(pj, dj, (1.0, 0.0, 0.0), 0.0) < 1e-12


def test_default_member_is_guests_frame_with_the_same_motion() -> None:
    """rect-frame's defaults give guest-frame's hinge lines (1e-15), and the traced paths agree (1e-12)."""
    rect, guest = lw.load("rect-frame"), lw.load("guest-frame")
    np.testing.assert_allclose(rect.twists, guest.twists, rtol=0, atol=1e-15)
    until = ("A", np.radians(60.0))
    a, b = lw.trace(rect, until=until, steps=60), lw.trace(guest, until=until, steps=60)
    np.testing.assert_allclose(a.angles, b.angles, rtol=0, atol=1e-12)
    assert len(a.bifurcations) == len(b.bifurcations) == 1


def test_turned_member_is_guests_frame_turned_a_quarter() -> None:
    """A frame 1 x 2 cut on its N and S sides is Guest's 2 x 1 frame turned 90 deg about z: the same hinge lines
    up to that rigid motion (joints relabelled cyclically, F A B C D E), and the same motion."""
    turned = rect_frame(length=W, width=L, section=S, cuts="NS")
    guest = guest_frame(L, W, S)
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    order = [5, 0, 1, 2, 3, 4]  # rect-frame's NE, N, NW, SW, S, SE are guest's F, A, B, C, D, E turned
    gd, gm = lines(guest)
    td, tm = lines(turned)
    np.testing.assert_allclose(td, (gd @ turn.T)[order], rtol=0, atol=1e-15)
    np.testing.assert_allclose(tm, (gm @ turn.T)[order], rtol=0, atol=1e-15)
    until = ("B", np.radians(60.0))  # rect-frame's B is guest's A
    a = lw.trace(turned, until=until, steps=60)
    b = lw.trace(guest, until=("A", np.radians(60.0)), steps=60)
    np.testing.assert_allclose(a.angles, b.angles[:, order], rtol=0, atol=1e-12)


def test_named_points_ride_on_the_rods_they_are_on() -> None:
    """Two points on one rod keep their distance along the motion; every point's body exists."""
    mech = rect_frame()
    tr = lw.trace(mech, until=("A", np.radians(50.0)), steps=10)
    names = [p["name"] for p in mech.meta["points"]]
    _, named = positions(mech, tr.angles)
    # corner_NE (the rod after hinge B) and mid_N (uncut, on the same long rod): half the length apart
    ne, n = names.index("corner_NE"), names.index("mid_N")
    np.testing.assert_allclose(np.linalg.norm(named[:, ne] - named[:, n], axis=1), L / 2, rtol=0, atol=1e-12)
    poses = poses_along(mech, tr.angles)
    assert set(poses) >= {p["body"] for p in mech.meta["points"]}


def test_family_has_mobile_and_rigid_members() -> None:
    """Not every choice of faces moves: of Guest's cuts' 64 face choices, some are rigid at the flat start
    (rank 6) and 36 have mobility one (counted once by hand-written SVDs of the Jacobian)."""
    mobility = []
    for faces in itertools.product("io", repeat=6):
        mech = rect_frame(cuts="EW", faces="".join(faces))
        s = np.linalg.svd(jacobian(mech, np.zeros(6)), compute_uv=False)
        mobility.append(6 - numerical_rank(s))
    assert mobility.count(1) == 36 and mobility.count(0) == 24 and mobility.count(2) == 4


@pytest.mark.parametrize(
    ("given", "match"),
    [
        ({"cuts": "EE"}, "distinct letters"),
        ({"cuts": "X"}, "parameter cuts expected"),
        ({"faces": "ioi"}, "parameter faces expected"),
        ({"cuts": "E", "faces": "iiiiii"}, "5 letters"),
        ({"cuts": 3}, "parameter cuts expected"),
        ({"section": 1.5}, "section must lie"),
        ({"length": -1.0}, "length"),
    ],
)
def test_bad_parameters_are_refused_with_what_was_expected(given: dict[str, object], match: str) -> None:
    with pytest.raises(SpecError, match=match):
        get("rect-frame").make(**given)


def test_sites_go_anticlockwise() -> None:
    angles = [np.arctan2(sy, sx) % (2 * np.pi) for _, sx, sy in SITES]
    assert angles == sorted(angles)
