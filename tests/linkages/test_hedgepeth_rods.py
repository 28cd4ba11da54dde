"""Hedgepeth's hoop built from its rods, against geometry built independently of the hinge construction.

The references are: a mitred picture frame built directly as a flat regular n-gon (not from the hinges), the
paper's Eqs. (7), (9), (10) and (13), its printed n = 4 model, and the rods' meshes.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from linkwork.errors import SpecError
from linkwork.kinematics.closure import body_poses, jacobian
from linkwork.kinematics.rank import numerical_rank
from linkwork.kinematics.tracer import trace
from linkwork.linkages import hedgepeth, hedgepeth_rods
from linkwork.linkages.hedgepeth import deployed_angle, hedgepeth_angles
from linkwork.linkages.hedgepeth_rods import deployed_angles, hinge_angle_to_apex_line, rod_frame
from linkwork.viz.solids import body_meshes, hinge_pins, place


def picture_frame(n: int) -> list[np.ndarray]:
    """Rod frames of the flat regular n-gon of unit side, built directly: rod i along side i, apex up, base
    direction pointing out of the polygon (the rods' frames as :func:`rod_frame` defines them)."""
    radius = 0.5 / np.sin(np.pi / n)
    corners = [
        radius * np.array([np.cos(2 * np.pi * k / n), np.sin(2 * np.pi * k / n), 0.0]) for k in range(n + 1)
    ]
    frames = []
    for i in range(n):
        x = corners[i + 1] - corners[i]
        z = np.array([0.0, 0.0, -1.0])  # from the apex line down to the base
        F = np.eye(4)
        F[:3, 0], F[:3, 1], F[:3, 2], F[:3, 3] = x, np.cross(z, x), z, corners[i]
        frames.append(F)
    return frames


def traced_frames(n: int, angles: np.ndarray) -> list[np.ndarray]:
    mech = hedgepeth_rods(n)
    poses = body_poses(mech, angles=angles)
    return [poses[f"link{i}"] @ rod_frame(n, i) for i in range(n)]


def relative(frames: list[np.ndarray]) -> list[np.ndarray]:
    n = len(frames)
    return [np.linalg.inv(frames[i]) @ frames[(i + 1) % n] for i in range(n)]


@pytest.mark.parametrize("n", [4, 6, 8, 10, 12])
def test_traced_from_the_bundle_it_lands_on_the_flat_mitred_n_gon(n: int) -> None:
    mech = hedgepeth_rods(n)
    inner, outer = deployed_angles(n)
    path = trace(mech, until=("A", inner), max_steps=4000)
    assert path.branches[0].end_reason == "reached target"
    end = path.angles[-1]
    np.testing.assert_allclose(end[0::2], inner, atol=1e-12)
    np.testing.assert_allclose(end[1::2], outer, atol=1e-9)
    # Same shape as the picture frame: every rod's pose relative to the next agrees (frame-independent).
    for got, want in zip(relative(traced_frames(n, end)), relative(picture_frame(n)), strict=True):
        np.testing.assert_allclose(got, want, atol=1e-9)
    assert np.all(path.residual < 1e-11)


def test_the_hexagon_deploys_symmetrically_with_mobility_one_and_monotonic_hinges() -> None:
    mech = hedgepeth_rods(6)  # no symmetry imposed
    path = trace(mech, until=("A", deployed_angles(6)[0]), steps=200)
    A, B, C, D, E, F = path.angles.T
    np.testing.assert_allclose(
        C, A, atol=1e-10
    )  # Sec. 5: theta_A = theta_C = theta_E, theta_B = theta_D = ...
    np.testing.assert_allclose(E, A, atol=1e-10)
    np.testing.assert_allclose(D, B, atol=1e-10)
    np.testing.assert_allclose(F, B, atol=1e-10)
    assert np.all(np.diff(A) > 0) and np.all(np.diff(B) > 0)  # "increase monotonically during deployment"
    assert set(path.rank.tolist()) == {5}


def test_deployed_angle_closed_form_and_the_bound_that_rules_out_equation_10_for_n_6_and_more() -> None:
    for n in range(4, 52, 2):
        inner, outer = deployed_angles(n)
        alpha1 = 2 * np.pi / n
        assert np.cos(inner) == pytest.approx(-(1 + np.cos(alpha1) ** 2) / 2, abs=1e-14)
        assert inner + outer == pytest.approx(2 * np.pi, abs=1e-14)
        # A hinge turning by theta turns a rod's direction by at most theta; consecutive rods go from antiparallel
        # (bundle) to the polygon's exterior angle 360/n: every hinge must turn by at least 180 - 360/n.
        assert min(inner, 2 * np.pi - outer) >= np.pi - alpha1 - 1e-12
    assert np.degrees(deployed_angles(4)[0]) == pytest.approx(
        np.degrees(deployed_angle(4)), abs=1e-12
    )  # Eq. (10)
    for n in (6, 8, 10):
        assert deployed_angle(n) < np.pi - 2 * np.pi / n  # Eq. (10) as printed is below that bound


def test_the_square_is_the_printed_model_mirrored_and_follows_equation_13() -> None:
    rods = trace(hedgepeth_rods(4), until=("A", np.radians(120)), steps=200)
    printed = trace(hedgepeth(4), until=("A", np.radians(-120)), steps=200)
    np.testing.assert_allclose(rods.angles, -printed.angles, atol=1e-10)
    A, B = rods.angles[1:, 0], rods.angles[1:, 1]
    c, s, r3 = np.cos(-A), np.sin(-A), np.sqrt(3.0)
    eq13 = np.arctan(
        (2 * r3 * c**2 - 3 * s * c + 3 * s - 4 * r3 * c + 2 * r3)
        / (-(c**2) - 2 * r3 * s * c + 2 * r3 * s - c + 2)
    )
    wrapped = np.angle(np.exp(2j * (-B - eq13))) / 2  # Eq. (13) is an arctan: theta_B modulo 180 deg
    np.testing.assert_allclose(wrapped, 0.0, atol=1e-9)


@pytest.mark.parametrize("n", [4, 6, 10])
def test_end_sections_are_the_isosceles_triangles_of_equation_9_cut_at_180_over_n(n: int) -> None:
    rod = body_meshes(hedgepeth_rods(n))["link0"]
    F = rod_frame(n, 0)
    axis = F[:3, 0]
    start, end = rod.vertices[:3], rod.vertices[3:]
    alpha3 = hedgepeth_angles(n)["alpha3"]  # Eq. (9)
    for tri in (start, end):
        apex, b1, b2 = tri
        normal = np.cross(b1 - apex, b2 - apex)
        normal /= np.linalg.norm(normal)
        assert np.degrees(np.arccos(abs(normal @ axis))) == pytest.approx(180 / n, abs=1e-9)  # the cut
        for p, q in ((b1, b2), (b2, b1)):  # base angles
            u, v = (apex - p) / np.linalg.norm(apex - p), (q - p) / np.linalg.norm(q - p)
            assert np.arccos(u @ v) == pytest.approx(alpha3, abs=1e-12)
    # The apex angle of the section (Eq. (7)) and the rod length along its apex line.
    e1, e2 = start[1] - start[0], start[2] - start[0]
    e1, e2 = e1 - (e1 @ axis) * axis, e2 - (e2 @ axis) * axis
    assert np.arccos(e1 @ e2 / np.linalg.norm(e1) / np.linalg.norm(e2)) == pytest.approx(
        2 * np.pi / n, abs=1e-12
    )
    assert np.linalg.norm(end[0] - start[0]) == pytest.approx(1.0, abs=1e-14)


@pytest.mark.parametrize("n", [4, 6, 8])
def test_each_hinge_is_an_edge_of_both_rods_it_joins(n: int) -> None:
    mech = hedgepeth_rods(n)
    rods, pins = body_meshes(mech), hinge_pins(mech)
    for j, pin in enumerate(pins):
        axis = mech.twists[j, :3]
        p0 = np.cross(axis, mech.twists[j, 3:])  # the foot of the origin on the hinge axis
        for body in mech.joint_bodies[j]:  # both rods have an edge (two vertices) on the axis ...
            on_line = [v for v in rods[body].vertices if np.linalg.norm(np.cross(v - p0, axis)) < 1e-12]
            assert len(on_line) == 2
        # ... and so does the pin drawn along it.
        assert np.all(np.linalg.norm(np.cross(pin.vertices.mean(axis=0) - p0, axis)) < 1e-12)
        # The hinge makes the angle gamma with the apex line of the rods (the bundle's z-axis).
        assert np.arccos(abs(axis[2])) == pytest.approx(hinge_angle_to_apex_line(n), abs=1e-12)


def test_the_rods_never_pass_through_each_other() -> None:
    n = 6
    mech = hedgepeth_rods(n)
    path = trace(mech, until=("A", deployed_angles(n)[0]), steps=60)
    rods = body_meshes(mech)
    grid = np.linspace(0.0, 1.0, 8)
    st = [(s, t) for s, t in itertools.product(grid, grid) if s + t <= 1.0]
    deepest = -np.inf
    for angles in path.angles:
        meshes = place(mech, rods, [], angles)
        for a, b in itertools.permutations(range(n), 2):
            tri = meshes[a].triangles
            points = np.concatenate(
                [tri[:, 0] + s * (tri[:, 1] - tri[:, 0]) + t * (tri[:, 2] - tri[:, 0]) for s, t in st]
            )
            centre = meshes[b].vertices.mean(axis=0)
            shrunk = centre + 0.97 * (meshes[b].triangles - centre)  # touching faces are not overlaps
            normals = np.cross(shrunk[:, 1] - shrunk[:, 0], shrunk[:, 2] - shrunk[:, 0])
            normals /= np.linalg.norm(normals, axis=1)[:, None]
            offsets = np.einsum("ij,ij->i", normals, shrunk[:, 0])
            depth = np.min(offsets[None, :] - points @ normals.T, axis=1)  # > 0 inside rod b
            deepest = max(deepest, float(depth.max()))
    assert deepest < 0.0


def test_large_hoops_get_the_papers_symmetry_and_mobility_one() -> None:
    free = hedgepeth_rods(8, couple=False)
    s = np.linalg.svd(jacobian(free, np.zeros(8)), compute_uv=False)
    assert 8 - numerical_rank(s) == 3  # n - 5 at the bundle, as for the printed hoops
    coupled = hedgepeth_rods(8)
    assert coupled.n_unknowns == 2
    s = np.linalg.svd(jacobian(coupled, np.zeros(8)) @ coupled.coupling_matrix(), compute_uv=False)
    assert 2 - numerical_rank(s) == 1


@pytest.mark.parametrize("n", [3, 5, 2, 0])
def test_odd_or_small_n_is_refused(n: int) -> None:
    with pytest.raises(SpecError, match="even"):
        hedgepeth_rods(n)
