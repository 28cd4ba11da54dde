"""The built-in linkage library: every linkage closes, moves with mobility one, and meets its classical conditions.

Reference values come from outside the constructors: Bennett's closed form
``tan(t1/2) tan(t2/2) = sin((a2 + a1)/2) / sin((a2 - a1)/2)`` with ``t3 = -t1``, ``t4 = -t2`` (Bennett 1914);
the defining parameter conditions of each Bricard type (Baker 1980; Chen, You & Tarnai 2005); a DH product
written out here from elementary rotations and translations; central finite differences; the physical
description of Guest's frame (Gan & Pellegrino 2006, Sec. 6); and the paper's statement that the frame's rank
drops from 5 to 4 at an intermediate configuration. Every assertion states its tolerance.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize_scalar

from linkwork.kinematics.closure import body_poses, closure_residual, jacobian
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import numerical_rank
from linkwork.linkages import bennett as bennett_module
from linkwork.linkages import bricard as bricard_module
from linkwork.linkages import goldberg as goldberg_module
from linkwork.linkages import guest as guest_module
from linkwork.linkages import rect_frame as rect_frame_module
from linkwork.linkages import sarrus as sarrus_module
from linkwork.linkages.registry import REGISTRY

PROPERTY = settings(deadline=None, max_examples=40, derandomize=True)


# ------------------------------------------------------------------------------------------------------------
# references written out here
def rz(t: float) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], dtype=float)


def rx(t: float) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]], dtype=float)


def shift(x: float, z: float) -> np.ndarray:
    T = np.eye(4)
    T[0, 3], T[2, 3] = x, z
    return T


def dh_product(thetas: Sequence[float], links: Sequence[tuple[float, float, float]]) -> np.ndarray:
    """``prod Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)`` for links ``(d, a, alpha)`` (the spec file convention, docs/spec-format.md)."""
    g = np.eye(4)
    for t, (d, a, al) in zip(thetas, links, strict=True):
        g = g @ rz(t) @ shift(0.0, d) @ shift(a, 0.0) @ rx(al)
    return g


def closure_error(thetas: Sequence[float], links: Sequence[tuple[float, float, float]]) -> float:
    """Largest entry of ``prod T_i - I``."""
    return float(np.max(np.abs(dh_product(thetas, links) - np.eye(4))))


def meta_links(mech: Mechanism) -> list[tuple[float, float, float]]:
    """The DH links ``(d, a, alpha)`` recorded by ``from_dh`` in ``meta["params"]``."""
    return [(p.get("d", 0.0), p.get("a", 0.0), p.get("alpha", 0.0)) for p in mech.meta["params"]]


def bennett_theta2(theta1: float, alpha1: float, alpha2: float) -> float:
    """Bennett's closed form (Bennett 1914): ``tan(t2/2) = sin((a2 + a1)/2) / (sin((a2 - a1)/2) tan(t1/2))``."""
    k = np.sin((alpha2 + alpha1) / 2.0) / np.sin((alpha2 - alpha1) / 2.0)
    return float(2.0 * np.arctan(k / np.tan(theta1 / 2.0)))


def sigma(mech: Mechanism, q: np.ndarray | None = None) -> np.ndarray:
    q = np.zeros(mech.n_joints) if q is None else q
    return np.linalg.svd(jacobian(mech, q), compute_uv=False)


def step_along(mech: Mechanism, steps: int, size: float) -> list[np.ndarray]:
    """A plain predictor-corrector of this test's own: null-vector steps, Gauss-Newton back onto the loop."""
    q = np.zeros(mech.n_joints)
    tangent = np.linalg.svd(jacobian(mech, q))[2][-1]
    out = []
    for _ in range(steps):
        q = q + size * tangent
        for _ in range(30):
            r = closure_residual(mech, q)
            if np.linalg.norm(r) < 1e-13:
                break
            q = q - np.linalg.pinv(jacobian(mech, q), rcond=1e-10) @ r
        new = np.linalg.svd(jacobian(mech, q))[2][-1]
        tangent = new if new @ tangent > 0 else -new
        out.append(q.copy())
    return out


MOBILE_6R: dict[str, Callable[[], Mechanism]] = {
    "bricard-line": bricard_module.bricard_line,
    "bricard-plane": bricard_module.bricard_plane,
    "bricard-trihedral": bricard_module.bricard_trihedral,
    "bricard-threefold": bricard_module.bricard_threefold,
    "sarrus": sarrus_module.sarrus,
    "guest-frame": guest_module.guest_frame,
    "rect-frame": rect_frame_module.rect_frame,
}
ALL: dict[str, Callable[[], Mechanism]] = {
    "bennett": bennett_module.bennett,
    "goldberg": goldberg_module.goldberg,
    **MOBILE_6R,
}
DH_BUILT = ["bennett", "goldberg", "bricard-line", "bricard-plane", "bricard-trihedral", "bricard-threefold"]


# ------------------------------------------------------------------------------------------------------------
# every linkage
@pytest.mark.parametrize("name", sorted(ALL))
def test_registered_with_defaults_that_build(name: str) -> None:
    entry = REGISTRY[name]
    mech = entry.make()
    assert mech.meta["linkage"] == name
    for key, param in entry.params.items():
        assert mech.meta[key] == pytest.approx(param.default, abs=1e-15)
    assert mech.joint_names == tuple("ABCDEF"[: mech.n_joints])


@pytest.mark.parametrize("name", DH_BUILT)
def test_dh_start_closes(name: str) -> None:
    mech = ALL[name]()
    assert closure_error(mech.offsets, meta_links(mech)) < 1e-12


@pytest.mark.parametrize("name", sorted(ALL))
def test_start_is_a_regular_point_of_mobility_one(name: str) -> None:
    mech = ALL[name]()
    s = sigma(mech)
    assert numerical_rank(s) == mech.n_joints - 1
    assert s[-2] > 1e-2 * s[0]  # clearly regular, not near a bifurcation
    assert s[-1] < 1e-12 * s[0]


@pytest.mark.parametrize("name", sorted(ALL))
def test_moves_with_mobility_one(name: str) -> None:
    """A finite motion, not only a first-order one: 20 steps stay on the loop with the rank unchanged."""
    mech = ALL[name]()
    for q in step_along(mech, steps=20, size=0.02):
        assert np.linalg.norm(closure_residual(mech, q)) < 1e-12
        assert numerical_rank(sigma(mech, q)) == mech.n_joints - 1
    assert np.linalg.norm(q) > 0.3  # it really moved (20 steps of 0.02 along unit tangents)


@pytest.mark.parametrize("name", sorted(ALL))
def test_jacobian_matches_central_differences(name: str) -> None:
    mech = ALL[name]()
    qs = [np.zeros(mech.n_joints), step_along(mech, steps=5, size=0.05)[-1]]  # two closed configurations
    h = 1e-6
    for q in qs:
        fd = np.column_stack(
            [
                (closure_residual(mech, q + h * e) - closure_residual(mech, q - h * e)) / (2 * h)
                for e in np.eye(mech.n_joints)
            ]
        )
        J = jacobian(mech, q)
        assert np.linalg.norm(fd - J) <= 1e-6 * np.linalg.norm(J)


# ------------------------------------------------------------------------------------------------------------
# Bennett
@pytest.mark.parametrize("alphas", [(45.0, 75.0), (30.0, 120.0), (100.0, 20.0), (170.0, 10.0)])
def test_bennett_closed_form_closes_at_many_points(alphas: tuple[float, float]) -> None:
    a1, a2 = np.radians(alphas)
    links = [(0.0, np.sin(a1), a1), (0.0, np.sin(a2), a2)] * 2  # a_i = sin(alpha_i)
    for t1 in np.radians(np.linspace(-170.0, 170.0, 35)):
        if abs(t1) < 1e-9:
            continue
        t2 = bennett_theta2(t1, a1, a2)
        assert closure_error([t1, t2, -t1, -t2], links) < 1e-12


def test_bennett_constructor_follows_the_closed_form() -> None:
    for theta in np.radians([-150.0, -60.0, 10.0, 60.0, 135.0]):
        mech = bennett_module.bennett(np.radians(45.0), np.radians(75.0), 2.0, theta)
        t1, t2, t3, t4 = mech.offsets
        expected = bennett_theta2(theta, np.radians(45.0), np.radians(75.0))
        assert abs(t1 - theta) < 1e-12
        assert abs(np.angle(np.exp(1j * (t2 - expected)))) < 1e-12
        assert abs(t3 + t1) < 1e-12 and abs(t4 + t2) < 1e-12
        links = meta_links(mech)
        assert [link[1] / np.sin(link[2]) for link in links] == pytest.approx([2.0] * 4, abs=1e-12)
        assert closure_error(mech.offsets, links) < 1e-12


@PROPERTY
@given(
    a1=st.floats(5.0, 175.0),
    a2=st.floats(5.0, 175.0),
    theta=st.floats(-175.0, 175.0),
)
def test_random_bennett_closes_with_rank_three(a1: float, a2: float, theta: float) -> None:
    assume(abs(a1 - a2) > 1.0)
    mech = bennett_module.bennett(np.radians(a1), np.radians(a2), 1.0, np.radians(theta))
    assert closure_error(mech.offsets, meta_links(mech)) < 1e-10
    assert numerical_rank(sigma(mech)) == 3


# ------------------------------------------------------------------------------------------------------------
# Bricard
def test_bricard_line_conditions_and_angles() -> None:
    mech = bricard_module.bricard_line()
    links = meta_links(mech)
    for i in range(3):  # a, alpha and d repeat after three joints (Bricard 1927; Baker 1980)
        assert links[i + 3] == pytest.approx(links[i], abs=0.0)
    t = mech.offsets
    assert np.max(np.abs(np.angle(np.exp(1j * (t[3:] - t[:3]))))) < 1e-9  # theta_{i+3} = theta_i


def test_bricard_plane_conditions_and_angles() -> None:
    mech = bricard_module.bricard_plane()
    (d1, a1, al1), (d2, a2, al2), (d3, a3, al3), (d4, a4, al4), (d5, a5, al5), (d6, a6, al6) = meta_links(
        mech
    )
    assert (a6, a5, a4) == (a1, a2, a3)
    for x, y in ((al1, al6), (al2, al5), (al3, al4)):  # alpha + alpha' = 2 pi (mod 2 pi)
        assert abs(np.sin((x + y) / 2.0)) < 1e-15
    assert d1 == 0.0 and d4 == 0.0 and d6 == -d2 and d5 == -d3
    t = mech.offsets
    assert (
        abs(np.angle(np.exp(1j * (t[5] - t[1])))) < 1e-9 and abs(np.angle(np.exp(1j * (t[4] - t[2])))) < 1e-9
    )


def test_bricard_plane_is_mirror_symmetric() -> None:
    """The six joint axes at the start map to themselves under a reflection in a plane containing A and D."""
    mech = bricard_module.bricard_plane()
    w, v = mech.twists[:, :3], mech.twists[:, 3:]
    feet = np.cross(w, v)  # the point of each axis nearest the origin (unit directions)
    normal = np.cross(w[0], w[3]) if np.linalg.norm(np.cross(w[0], w[3])) > 1e-6 else None
    assert normal is not None
    # the plane contains both axes A and D: normal perpendicular to both, through a point of A
    normal = normal / np.linalg.norm(normal)
    assert abs(normal @ (feet[3] - feet[0])) < 1e-9
    mirror = np.eye(3) - 2.0 * np.outer(normal, normal)

    def reflect(i: int) -> tuple[np.ndarray, np.ndarray]:
        return mirror @ w[i], feet[0] + mirror @ (feet[i] - feet[0])

    for i, j in ((1, 5), (2, 4)):
        wi, pi = reflect(i)
        assert np.linalg.norm(np.cross(wi, w[j])) < 1e-9  # same direction up to sign
        assert np.linalg.norm(np.cross(pi - feet[j], w[j])) < 1e-9  # on the same line


def test_bricard_trihedral_conditions() -> None:
    mech = bricard_module.bricard_trihedral()
    links = meta_links(mech)
    assert all(d == 0.0 for d, _, _ in links)
    for i, (_, _, al) in enumerate(links):
        assert al == pytest.approx(np.pi / 2.0 if i % 2 == 0 else 1.5 * np.pi, abs=1e-15)
    odd = sum(links[i][1] ** 2 for i in (0, 2, 4))
    even = sum(links[i][1] ** 2 for i in (1, 3, 5))
    assert abs(odd - even) < 1e-12


def test_bricard_threefold_conditions_and_angles() -> None:
    mech = bricard_module.bricard_threefold()
    links = meta_links(mech)
    assert all(a == links[0][1] and d == 0.0 for d, a, _ in links)
    for i in range(6):
        expected = links[0][2] if i % 2 == 0 else 2.0 * np.pi - links[0][2]
        assert links[i][2] == pytest.approx(expected, abs=1e-15)
    t = mech.offsets
    assert np.ptp(t[0::2]) < 1e-9 and np.ptp(t[1::2]) < 1e-9
    # it is also a plane-symmetric Bricard loop (Chen, You & Tarnai 2005): a_6 = a_1, alpha_1 + alpha_6 = 2 pi, ...
    for i, j in ((0, 5), (1, 4), (2, 3)):
        assert links[i][1] == links[j][1] and abs(np.sin((links[i][2] + links[j][2]) / 2.0)) < 1e-15


def test_bricard_threefold_keeps_its_symmetry_along_the_motion() -> None:
    mech = bricard_module.bricard_threefold()
    for q in step_along(mech, steps=10, size=0.05):
        t = mech.angles_from_q(q)
        assert np.ptp(t[0::2]) < 1e-9 and np.ptp(t[1::2]) < 1e-9


def test_unassemblable_start_is_an_assembly_error() -> None:
    from linkwork.errors import AssemblyError

    # A generic 6R loop is rigid (isolated assemblies): with joint A at an arbitrary angle there is none.
    with pytest.raises(AssemblyError):
        bricard_module.solve_start(
            "rigid",
            [
                (0.0, 1.0, 0.3),
                (0.2, 5.0, 1.1),
                (0.0, 0.1, 2.0),
                (0.4, 0.7, 0.2),
                (0.1, 0.1, 0.9),
                (0.0, 0.3, 1.7),
            ],
            0.3,
            lambda t1, x: np.concatenate([[t1], x]),
            5,
            tries=20,
        )


# ------------------------------------------------------------------------------------------------------------
# Goldberg
@pytest.mark.parametrize(
    "twists", [(45.0, 75.0, -20.0), (45.0, 75.0, 30.0), (60.0, 100.0, 20.0), (30.0, 80.0, 120.0)]
)
def test_goldberg_closes_along_its_closed_form(twists: tuple[float, float, float]) -> None:
    al, be, ga = np.radians(twists)
    for theta in np.radians(np.linspace(-160.0, 160.0, 17)):
        mech = goldberg_module.goldberg(al, be, ga, 1.0, theta)
        links = meta_links(mech)
        assert closure_error(mech.offsets, links) < 1e-12
        assert all(a >= 0.0 and d == 0.0 for d, a, _ in links)
        assert numerical_rank(sigma(mech)) == 4


def test_goldberg_links_come_from_two_bennett_loops() -> None:
    al, be, ga = np.radians([45.0, 75.0, -20.0])
    links = goldberg_module.goldberg_links(al, be, ga)
    a, b, c = np.sin(al), np.sin(be), np.sin(ga)
    expected = [(a, al), (b, be), (a - c, al - ga), (b, be), (c, ga)]
    assert np.max(np.abs(np.array(links) - np.array(expected))) < 1e-15


# ------------------------------------------------------------------------------------------------------------
# Sarrus
def test_sarrus_top_plate_translates_along_the_common_perpendicular() -> None:
    mech = sarrus_module.sarrus()
    for q in step_along(mech, steps=10, size=0.05):
        poses = body_poses(mech, q=q)
        relative = np.linalg.inv(poses["link2"]) @ poses["link5"]  # top plate seen from the bottom plate
        assert np.max(np.abs(relative[:3, :3] - np.eye(3))) < 1e-12
        assert np.max(np.abs(relative[:2, 3])) < 1e-12
    tangent = np.linalg.svd(jacobian(mech, np.zeros(6)))[2][-1]
    tangent = tangent / tangent[0]
    assert tangent == pytest.approx([1.0, 2.0, 1.0, 1.0, 2.0, 1.0], abs=1e-12)


# ------------------------------------------------------------------------------------------------------------
# Guest's frame
L, W, S = 2.0, 1.0, 0.1
H = S / np.sqrt(2.0)


def axis_lines(mech: Mechanism) -> list[tuple[np.ndarray, np.ndarray]]:
    """(point, unit direction) of every joint axis at the start."""
    w, v = mech.twists[:, :3], mech.twists[:, 3:]
    return [(np.cross(wi, vi), wi) for wi, vi in zip(w, v, strict=True)]


def line_in_plane(point: np.ndarray, direction: np.ndarray, normal: Sequence[float], offset: float) -> float:
    """Distance measure of a line from the plane ``normal . x = offset``: 0 when it lies in it."""
    n = np.asarray(normal, dtype=float)
    n = n / np.linalg.norm(n)
    return max(abs(n @ direction), abs(n @ point - offset / np.linalg.norm(normal)))


def test_guest_hinges_lie_on_the_described_faces_and_cut_planes() -> None:
    lines = axis_lines(guest_module.guest_frame(L, W, S))
    corners = {1: (1, 1), 2: (-1, 1), 4: (-1, -1), 5: (1, -1)}
    for j, (sx, sy) in corners.items():
        p, u = lines[j]
        # upward-inward face of the long rod at y = sy W/2: -sy (y - sy W/2) + z = h
        assert line_in_plane(p, u, (0.0, -sy, 1.0), H - W / 2.0) < 1e-12
        # upward-inward face of the short rod at x = sx L/2: -sx (x - sx L/2) + z = h
        assert line_in_plane(p, u, (-sx, 0.0, 1.0), H - L / 2.0) < 1e-12
        # vertical mitre plane through the corner containing (sx, sy, 0)
        assert line_in_plane(p, u, (sy, -sx, 0.0), sy * sx * L / 2.0 - sx * sy * W / 2.0) < 1e-12
    for j, sx in ((0, 1), (3, -1)):
        p, u = lines[j]
        # upward-outward face of the short rod: sx (x - sx L/2) + z = h, and the cut plane y = 0
        assert line_in_plane(p, u, (sx, 0.0, 1.0), H + L / 2.0) < 1e-12
        assert line_in_plane(p, u, (0.0, 1.0, 0.0), 0.0) < 1e-12


def test_guest_frame_is_symmetric_about_both_mid_planes() -> None:
    lines = axis_lines(guest_module.guest_frame(L, W, S))
    for mirror in (np.diag([-1.0, 1.0, 1.0]), np.diag([1.0, -1.0, 1.0])):
        for p, u in lines:
            mp, mu = mirror @ p, mirror @ u
            matches = [
                np.linalg.norm(np.cross(mu, q_u)) < 1e-12 and np.linalg.norm(np.cross(mp - q_p, q_u)) < 1e-12
                for q_p, q_u in lines
            ]
            assert sum(matches) == 1


def test_guest_frame_folds_with_all_angles_positive() -> None:
    mech = guest_module.guest_frame()
    s = sigma(mech)
    assert numerical_rank(s) == 5
    tangent = np.linalg.svd(jacobian(mech, np.zeros(6)))[2][-1]
    tangent = tangent / tangent[0]
    assert np.all(tangent > 0.5)
    # first-order fold: A = D, B = C = E = F = sqrt(3/8) A (this frame, any proportions)
    assert tangent == pytest.approx(
        [1.0, *[np.sqrt(3.0 / 8.0)] * 2, 1.0, *[np.sqrt(3.0 / 8.0)] * 2], abs=1e-9
    )


def test_guest_frame_rank_drops_to_four_on_its_folding_path() -> None:
    """Gan & Pellegrino (2006, Sec. 6): the rank drops from 5 to 4 at an intermediate configuration."""
    mech = guest_module.guest_frame()

    def solve(theta_a: float, q: np.ndarray) -> np.ndarray:
        q = q.copy()
        q[0] = theta_a
        for _ in range(60):
            r = closure_residual(mech, q)
            if np.linalg.norm(r) < 1e-14:
                break
            q[1:] -= np.linalg.lstsq(jacobian(mech, q)[:, 1:], r, rcond=None)[0]
        return q

    q = np.zeros(6)
    path = []
    for theta_a in np.radians(np.arange(1.0, 50.0, 1.0)):
        q = solve(theta_a, q)
        assert np.linalg.norm(closure_residual(mech, q)) < 1e-12
        path.append((theta_a, q.copy(), sigma(mech, q)[4]))
    k = int(np.argmin([s5 for _, _, s5 in path]))
    start = path[k - 1][1]
    found = minimize_scalar(
        lambda t: sigma(mech, solve(t, start))[4],
        bounds=(path[k - 1][0], path[k + 1][0]),
        method="bounded",
        options={"xatol": 1e-12},
    )
    q_star = solve(found.x, start)
    s = sigma(mech, q_star)
    assert numerical_rank(s) == 4 and s[4] < 1e-6 * s[0]
    assert numerical_rank(sigma(mech, solve(found.x - 0.02, start))) == 5
    assert numerical_rank(sigma(mech, solve(found.x + 0.02, path[k + 1][1]))) == 5
    # the located point (regression value of this test's own continuation, default proportions)
    angles = np.degrees(q_star)
    assert angles == pytest.approx([38.9424, *[18.4630] * 2, 38.9424, *[18.4630] * 2], abs=1e-3)
