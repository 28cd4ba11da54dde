"""Pivot placement inside the shape (``linkwork.mechanization.placement``), checked by independent code:
matplotlib's point-in-polygon on the profiles as given, rigid motions and distances written here, and closed
forms (a translating rectangle's admissible region)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from linkwork.mechanization.placement import admissible, inside_links, segments_inside

from .test_many_profiles import naca4

mpath = pytest.importorskip("matplotlib.path")


def _pose(g: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Points of a body moved by the rigid motion ``g = (x, y, angle)``: rotate, then translate."""
    c, s = math.cos(g[2]), math.sin(g[2])
    return pts @ np.array([[c, s], [-s, c]]) + g[:2]


def _relative(ga: np.ndarray, gb: np.ndarray) -> np.ndarray:
    """``ga^-1 gb`` for poses ``(x, y, angle)``, written out."""
    c, s = math.cos(ga[2]), math.sin(ga[2])
    d = gb[:2] - ga[:2]
    return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1], gb[2] - ga[2]])


def test_admissible_pivots_of_a_translating_body_are_the_intersection_of_the_shifted_rectangles() -> None:
    # three profiles the same rectangle [0, 1] x [0, 0.2]; the body slides by 0, 0.1, 0.3 along x: a point of it
    # stays inside every profile exactly when 0 <= x and x + 0.3 <= 1
    rect = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.2], [0.0, 0.2]])
    poses = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.3, 0.0, 0.0]])
    found = admissible((rect, rect, rect), poses, 1.0)
    pts = found.points
    assert len(pts) > 100
    assert np.all(pts[:, 0] > 0.0) and np.all(pts[:, 0] < 0.7)
    # every grid point farther than the clearance and a spacing from the region's edge is kept
    side = found.spacing
    assert pts[:, 0].min() <= 2 * side and pts[:, 0].max() >= 0.7 - 2 * side
    assert pts[:, 1].min() <= 2 * side and pts[:, 1].max() >= 0.2 - 2 * side


def test_admissible_pivots_of_a_turning_body_lie_inside_every_airfoil_in_its_pose() -> None:
    targets = (naca4("2412", 1.0), naca4("3412", 1.05), naca4("4412", 1.1))
    poses = np.array([[0.0, 0.0, 0.0], [0.02, 0.01, -0.03], [0.05, 0.03, -0.07]])
    found = admissible(targets, poses, 1.1)
    assert len(found.points) > 200
    for target, g in zip(targets, poses, strict=True):
        assert np.all(mpath.Path(target).contains_points(_pose(g, found.points)))
    # nothing admissible is missed: random points inside every pulled-back profile, a spacing from every outline,
    # have an admissible sample within a spacing
    rng = np.random.default_rng(3)
    trial = rng.uniform([0.0, -0.1], [1.1, 0.2], (4000, 2))
    inside = np.ones(len(trial), dtype=bool)
    for target, g in zip(targets, poses, strict=True):
        shape = mpath.Path(target)
        inside &= shape.contains_points(_pose(g, trial), radius=-2 * found.spacing)  # shrunk by 2 spacings
        inside &= shape.contains_points(_pose(g, trial))
    assert inside.sum() > 100
    nearest = np.min(np.linalg.norm(trial[inside][:, None] - found.points[None], axis=2), axis=1)
    assert np.all(nearest <= found.spacing)


def test_segments_inside_agrees_with_201_points_along_each_segment() -> None:
    u_shape = np.array(
        [[0.0, 0.0], [3.0, 0.0], [3.0, 3.0], [2.0, 3.0], [2.0, 1.0], [1.0, 1.0], [1.0, 3.0], [0.0, 3.0]]
    )
    rng = np.random.default_rng(11)
    p, q = rng.uniform(-0.5, 3.5, (3000, 2)), rng.uniform(-0.5, 3.5, (3000, 2))
    got = segments_inside(u_shape, p, q)
    along = np.linspace(0.0, 1.0, 201)
    shape = mpath.Path(np.vstack([u_shape, u_shape[:1]]), closed=True)
    sampled = np.array(
        [np.all(shape.contains_points(a + along[:, None] * (b - a))) for a, b in zip(p, q, strict=True)]
    )
    assert got.sum() > 200 and (~got).sum() > 200  # both kinds are tried
    # inside by the crossing test is inside at 201 points; a segment out at a sample is out by the test
    assert np.array_equal(got, sampled)


def _about(pole: list[float], angles: list[float], drift: list[list[float]]) -> np.ndarray:
    """Poses turning by ``angles`` about ``pole``, then shifted by ``drift``."""
    out = []
    for a, d in zip(angles, drift, strict=True):
        turned = _pose(np.array([0.0, 0.0, a]), np.array([pole]))[0]
        out.append([pole[0] - turned[0] + d[0], pole[1] - turned[1] + d[1], a])
    return np.array(out)


@pytest.mark.parametrize("exact_only", [True, False])
def test_links_found_inside_keep_their_pivots_and_201_points_inside_every_profile(exact_only: bool) -> None:
    # a body turning about a point inside a cambering airfoil and drifting, guided from the ground and from a
    # second body
    targets = (naca4("2412", 1.0), naca4("3412", 1.05), naca4("4412", 1.1))
    body = _about([0.5, 0.03], [0.0, -0.05, -0.1], [[0.0, 0.0], [0.002, 0.001], [0.005, -0.001]])
    other = _about([0.3, 0.02], [0.0, -0.01, -0.03], [[0.0, 0.0], [0.001, 0.0], [0.002, 0.001]])
    limit = 0.01
    for anchor in (np.zeros((3, 3)), other):
        rel = np.array([_relative(ga, gb) for ga, gb in zip(anchor, body, strict=True)])
        found = inside_links(
            targets, body, anchor, rel, 1.1, longest=0.6, structural=limit, exact_only=exact_only
        )
        assert len(found.links) >= 5
        along = np.linspace(0.0, 1.0, 201)[:, None]
        for m, dyad in found.links:
            c = dyad.centre_point
            lengths = []
            for target, ga, gb in zip(targets, anchor, body, strict=True):
                a, w = _pose(ga, c[None])[0], _pose(gb, m[None])[0]
                assert np.all(mpath.Path(target).contains_points(a + along * (w - a)))
                lengths.append(math.dist(a, w))
            assert abs(lengths[0] - dyad.radius) <= 1e-12
            assert max(lengths) - min(lengths) == pytest.approx(dyad.structural_error, abs=1e-12)
            assert max(lengths) - min(lengths) <= (1e-9 * 1.1 if exact_only else limit + 1e-9)
            assert dyad.radius <= 0.6
        if exact_only:
            # exact links: the three positions of the moving pivot lie on one circle about the anchor pivot
            assert all(d.structural_error <= 1e-12 for _, d in found.links)


def test_bundled_wing_plan_has_every_candidate_link_inside_and_the_trailing_edge_bodies_hold_each_other() -> (
    None
):
    """The bundled wing (chord +36 %) with ``ground_region = "inside"``: from root ``s3`` every body gets links,
    the trailing-edge bodies ``s1`` and ``s4b`` (which only each other can hold inside) two between them; every
    candidate link of the plan keeps both pivots and 201 points along it inside every airfoil in its pose
    (matplotlib on the chain's targets, poses applied here)."""
    from linkwork.data import example
    from linkwork.io.problem import load_problem
    from linkwork.mechanization import MechanizeOptions, build_chain
    from linkwork.mechanization.search import plan
    from linkwork.synthesis import synthesize

    chain = build_chain(synthesize(load_problem(example("wing", "mechanize.toml"))))
    options = MechanizeOptions(ground_region="inside", max_link=1.0, anchors="any")
    pl = plan(chain, "s3", options)
    pair = [s for s in pl.steps if s.links == 2]
    assert [(s.body, {c.link.anchor for c in s.candidates}) for s in pair] == [("s4b", {"s1"})]
    along = np.linspace(0.0, 1.0, 201)[:, None]
    links = [c.link for a, b, _ in pl.root_pairs[:5] for c in (a, b)]
    links += [c.link for s in pl.steps for c in s.candidates[:10]]
    assert len(links) >= 20
    for link in links:
        for j, target in enumerate(chain.targets):
            a = _pose(chain.motion(link.anchor)[j], link.centre[None])[0]
            w = _pose(chain.motion(link.body)[j], link.circle[None])[0]
            assert np.all(mpath.Path(target).contains_points(a + along * (w - a))), (link.name, j)
