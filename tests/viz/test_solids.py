"""Solids for drawing: closed, outward-oriented meshes; bars between hinge axes; rigid posing; the bundle."""

from __future__ import annotations

import numpy as np
import pytest

from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.tracer import trace
from linkwork.linkages.registry import REGISTRY
from linkwork.viz.solids import (
    Mesh,
    bar_segments,
    body_meshes,
    common_normal,
    edge_counts,
    hinge_pins,
    joint_lines,
    posed_meshes,
)


def _builtin(name: str) -> Mechanism:
    entry = REGISTRY[name]
    return entry.build(**{k: p.default for k, p in entry.params.items()})


BUILTINS = sorted(REGISTRY)


def _planar_four_bar() -> Mechanism:
    """A planar 4R loop (every axis parallel to z): the parallel-axes case of the bars."""
    pts = [(0.0, 0.0), (0.3, 0.9), (1.4, 1.1), (1.6, 0.0)]
    joints = [
        {"name": n, "bodies": b, "point": p, "direction": (0.0, 0.0, 1.0)}
        for n, b, p in zip(
            "ABCD",
            [("ground", "crank"), ("crank", "coupler"), ("coupler", "rocker"), ("rocker", "ground")],
            pts,
            strict=True,
        )
    ]
    return Mechanism.from_joints("four-bar", joints, planar=True)


def _spherical_four_bar() -> Mechanism:
    """Four axes through one point: every common normal degenerates (the intersecting case)."""
    dirs = [(1.0, 0.0, 0.2), (0.3, 1.0, 0.1), (-1.0, 0.4, 0.3), (0.1, -1.0, 0.5)]
    joints = [
        {"name": n, "bodies": (f"b{i}", f"b{(i + 1) % 4}"), "point": (0.0, 0.0, 0.0), "direction": d}
        for i, (n, d) in enumerate(zip("ABCD", dirs, strict=True))
    ]
    return Mechanism.from_joints("spherical", joints, ground="b0")


def _check_closed(mesh: Mesh) -> None:
    bad_edges, bad_directed = edge_counts(mesh)
    assert bad_edges == 0  # every edge in exactly two faces (exact integer count)
    assert bad_directed == 0  # ... once in each direction: consistently oriented (exact)
    scale = float(np.ptp(mesh.vertices, axis=0).max())
    assert mesh.volume > 1e-9 * scale**3  # outward normals: positive divergence-theorem volume


@pytest.mark.parametrize("name", BUILTINS)
def test_every_builtin_mesh_is_closed_and_outward(name: str) -> None:
    mech = _builtin(name)
    bodies = body_meshes(mech)
    assert list(bodies) == list(mech.bodies)
    for mesh in [*bodies.values(), *hinge_pins(mech)]:
        _check_closed(mesh)


@pytest.mark.parametrize("make", [_planar_four_bar, _spherical_four_bar])
def test_degenerate_pairs_still_give_closed_bars(make) -> None:
    mech = make()
    for mesh in [*body_meshes(mech).values(), *hinge_pins(mech)]:
        _check_closed(mesh)


def test_styles_follow_the_linkage() -> None:
    assert {m.kind for m in body_meshes(_builtin("hedgepeth")).values()} == {"rod"}
    assert {m.kind for m in body_meshes(_builtin("guest-frame")).values()} == {"rod"}
    assert {m.kind for m in body_meshes(_builtin("bennett")).values()} == {"bar"}
    assert {m.kind for m in hinge_pins(_builtin("bennett"))} == {"pin"}


def test_guest_rods_have_the_square_section_volume() -> None:
    # Long rods: length L, section s^2 (the mitres add and remove equal wedges); half short sides: W/2 * s^2.
    mech = _builtin("guest-frame")
    L, W, s = (mech.meta[k] for k in ("length", "width", "section"))
    volumes = [m.volume for m in body_meshes(mech).values()]
    expected = [W / 2 * s**2, L * s**2, W / 2 * s**2, W / 2 * s**2, L * s**2, W / 2 * s**2]
    np.testing.assert_allclose(volumes, expected, rtol=1e-12)


@pytest.mark.parametrize("make", [lambda: _builtin("bennett"), lambda: _builtin("bricard-trihedral"),
                                  _planar_four_bar, _spherical_four_bar])  # fmt: skip
def test_bar_end_points_lie_on_the_two_hinge_axes(make) -> None:
    mech = make()
    points, directions = joint_lines(mech)
    body_joints = {b: [j for j, pair in enumerate(mech.joint_bodies) if b in pair] for b in mech.bodies}

    def distance(x: np.ndarray, j: int) -> float:
        r = x - points[j]
        return float(np.linalg.norm(r - (r @ directions[j]) * directions[j]))

    for body, bars in bar_segments(mech).items():
        for a, b in bars:
            # Each end on one of the body's joint axes, to 1e-12.
            assert min(distance(a, j) for j in body_joints[body]) < 1e-12
            assert min(distance(b, j) for j in body_joints[body]) < 1e-12


def test_common_normal_is_perpendicular_to_both_lines() -> None:
    rng = np.random.default_rng(5)
    for _ in range(20):
        p1, p2 = rng.normal(size=(2, 3))
        d1, d2 = (v / np.linalg.norm(v) for v in rng.normal(size=(2, 3)))
        f1, f2 = common_normal(p1, d1, p2, d2)
        seg = f2 - f1
        assert abs(seg @ d1) < 1e-12 and abs(seg @ d2) < 1e-12  # perpendicular to 1e-12


@pytest.mark.parametrize("name", ["hedgepeth", "guest-frame", "bennett"])
def test_posed_meshes_move_rigidly(name: str) -> None:
    mech = _builtin(name)
    path = trace(mech, max_steps=30)
    ref = [*body_meshes(mech).values(), *hinge_pins(mech)]
    for row in path.angles[[5, 17, 29]]:
        posed = posed_meshes(mech, row)
        assert len(posed) == len(ref)
        for a, b in zip(ref, posed, strict=True):
            da = np.linalg.norm(a.vertices[:, None] - a.vertices[None], axis=2)
            db = np.linalg.norm(b.vertices[:, None] - b.vertices[None], axis=2)
            assert np.max(np.abs(da - db)) < 1e-12  # pairwise distances preserved to 1e-12


def test_posed_at_the_reference_is_the_reference() -> None:
    mech = _builtin("guest-frame")
    for a, b in zip(body_meshes(mech).values(), posed_meshes(mech, mech.offsets, pins=False), strict=True):
        np.testing.assert_allclose(b.vertices, a.vertices, rtol=0, atol=1e-15)


def test_hedgepeth_bundle_rods_all_touch_the_central_axis() -> None:
    # n = 6 folded bundle: every rod's apex line lies on one line (the bundle's central axis), to 1e-9.
    mech = _builtin("hedgepeth")
    rods = posed_meshes(mech, np.zeros(mech.n_joints), pins=False)
    a, b = rods[0].vertices[0], rods[0].vertices[3]  # apex line ends of the first rod
    u = (b - a) / np.linalg.norm(b - a)

    def off_axis(x: np.ndarray) -> np.ndarray:
        r = x - a
        return np.linalg.norm(r - np.outer(r @ u, u), axis=1)

    for rod in rods:
        assert np.sum(off_axis(rod.vertices) < 1e-9) >= 2  # an apex edge (two vertices) on the axis, 1e-9
    # ... and the triangles tile the hexagon around it: the sections' apex angles add up to 360 degrees.
    total = 0.0
    for rod in rods:
        apex, p, q = rod.vertices[0], rod.vertices[1], rod.vertices[2]
        p, q = p - apex - ((p - apex) @ u) * u, q - apex - ((q - apex) @ u) * u
        total += np.degrees(np.arccos(p @ q / np.linalg.norm(p) / np.linalg.norm(q)))
    assert abs(total - 360.0) < 1e-9  # degrees


def test_hedgepeth_ends_are_cut_at_180_over_n_to_the_rod() -> None:
    # The paper (Sec. 3): rod ends cut at 180/n degrees to the rod's axis; here n = 6 -> 30 degrees.
    mech = _builtin("hedgepeth")
    rod = body_meshes(mech)[mech.bodies[0]]
    v = rod.vertices
    u = (v[3] - v[0]) / np.linalg.norm(v[3] - v[0])
    normal = np.cross(v[1] - v[0], v[2] - v[0])
    normal /= np.linalg.norm(normal)
    angle = 90.0 - np.degrees(np.arccos(abs(normal @ u)))
    assert abs(angle - 30.0) < 1e-9  # degrees
