"""More than five profiles end to end, and NACA outlines a user makes from the 4-digit formulas.

* ``wing-six``: six profiles mechanized to one DOF (least-squares dyads), the written mechanism traced by the
  kinematic core through all six in order without a defect, the chain within six hundredths of a chord of
  every target profile.
* closed NACA 0012 / 2412 / 4412 contours at chords 1.0 / 1.1 / 1.25 with ``ground_region = "inside"``: one DOF
  with five links, every pivot and link inside every contour in that profile's pose on the traced mechanism
  (matplotlib's point-in-polygon); from a root with no link inside, the error says which pivot of the closest
  link leaves which profile and by how much (checked with the distance to the contour computed here).
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from linkwork.data import example
from linkwork.io.problem import load_problem
from linkwork.io.spec import load_spec
from linkwork.kinematics.closure import jacobian
from linkwork.kinematics.tracer import trace
from linkwork.mechanization import MechanizationError, mechanize, write_mechanization
from linkwork.mechanization.options import options_from_values
from linkwork.synthesis import synthesize

from .geometry_checks import joint_positions


@pytest.mark.slow
def test_six_profiles_mechanize_to_one_dof_and_trace_through_all_six(tmp_path: Path) -> None:
    result = synthesize(load_problem(example("wing-six", "mechanize.toml")))
    assert len(result.targets) == 6
    found = mechanize(result)
    write_mechanization(found, tmp_path)
    report = json.loads((tmp_path / "mechanization.json").read_text())
    assert report["dof"] == 1 and len(report["profiles"]) == 6
    mech = load_spec(tmp_path / "mechanism.toml").mechanism
    drive = report["drive"]
    values = [p["drive_value"] for p in report["profiles"]]
    assert np.all(np.diff(values) > 0) or np.all(np.diff(values) < 0)  # the profiles in order
    path = trace(mech, drive=drive, until=(drive, math.radians(values[-1])))
    assert path.branches[0].end_reason == "reached target"
    assert not path.bifurcations and np.all(path.rank == path.rank[0])  # no branch defect on the way
    for profile in report["profiles"]:
        # least-squares dyads: the shape error grows (joined 0.038 at most; measured 0.0497 at profile 6), but
        # stays within 6 % of the smallest chord (1.0)
        assert profile["e_max"] <= 0.06


def naca4(code: str, chord: float, points: int = 61) -> np.ndarray:
    """Closed NACA 4-digit contour (upper surface TE -> nose -> lower surface TE, closed) from the formulas."""
    m, p, t = int(code[0]) / 100, int(code[1]) / 10, int(code[2:]) / 100
    beta = np.linspace(0.0, math.pi, points)
    x = (1 - np.cos(beta)) / 2
    yt = 5 * t * (0.2969 * np.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1015 * x**4)
    if m == 0:
        yc, dyc = np.zeros_like(x), np.zeros_like(x)
    else:
        front = x < p
        yc = np.where(front, m / p**2 * (2 * p * x - x**2), m / (1 - p) ** 2 * (1 - 2 * p + 2 * p * x - x**2))
        dyc = np.where(front, 2 * m / p**2 * (p - x), 2 * m / (1 - p) ** 2 * (p - x))
    theta = np.arctan(dyc)
    upper = np.column_stack([x - yt * np.sin(theta), yc + yt * np.cos(theta)])[::-1]
    lower = np.column_stack([x + yt * np.sin(theta), yc - yt * np.cos(theta)])[1:]
    outline = np.vstack([upper, lower]) * chord
    return np.vstack([outline, outline[:1]])


CLOSED = {"a": ("0012", 1.0), "b": ("2412", 1.1), "c": ("4412", 1.25)}
CLOSED_PROBLEM = (
    'type = "closed"\nprofiles = ["a.csv", "b.csv", "c.csv"]\npiece_length = 0.03\nmin_pieces = 4\n'
    'design = "CMCM"\nstarts = 4\nseed = 1\nground_region = "inside"\nmax_link = 1.0\n'
)


@pytest.fixture(scope="module")
def closed_naca(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, np.ndarray], object]:
    """The closed contours synthesised (a six-body loop: four segments, two of them arcs split in two)."""
    folder = tmp_path_factory.mktemp("closed-naca")
    contours = {name: naca4(code, chord) for name, (code, chord) in CLOSED.items()}
    for name, points in contours.items():
        np.savetxt(folder / f"{name}.csv", points, delimiter=",", header="x,y", comments="")
    (folder / "problem.toml").write_text(CLOSED_PROBLEM)
    return folder, contours, synthesize(load_problem(folder / "problem.toml"))


@pytest.mark.slow
def test_closed_naca_contours_mechanize_with_every_pivot_and_link_inside_every_profile(
    closed_naca: tuple,
) -> None:
    """The closed loop of six bodies and six joints has Grübler mobility 3 * 6 - 2 * 6 = 6: one DOF takes five
    binary links (the body closing the loop frees one body from its own). The written mechanism, traced by the
    kinematic core from profile 1, reaches profiles 2 and 3 in order; at each, every link's two joints placed
    from the spec file's joint points by the core's body poses, and 201 points along the link between them, lie
    inside that profile's contour (matplotlib's point-in-polygon), and the shape error is the joined chain's
    (exact links, three profiles)."""
    mpath = pytest.importorskip("matplotlib.path")
    folder, contours, result = closed_naca
    found = mechanize(result)
    out = folder / "mechanized"
    write_mechanization(found, out)
    report = json.loads((out / "mechanization.json").read_text())
    mech = load_spec(out / "mechanism.toml").mechanism
    links = list(report["profiles"][0]["pivots"])
    assert len(links) == 5 and all(d["type"] == "RR" for d in report["dyads"])
    # one DOF: the closure Jacobian at profile 1 (all joints at 0) has a one-dimensional null space
    spectrum = np.linalg.svd(jacobian(mech, np.zeros(mech.n_joints)), compute_uv=False)
    assert mech.n_joints - int(np.sum(spectrum > 1e-9 * spectrum[0])) == 1
    drive = report["drive"]
    values = [p["drive_value"] for p in report["profiles"]]
    assert np.all(np.diff(values) > 0) or np.all(np.diff(values) < 0)  # the profiles in order
    revolute = [t == "R" for t in mech.joint_types]
    for j, (profile, name) in enumerate(zip(report["profiles"], CLOSED, strict=True)):
        q = np.zeros(mech.n_joints)
        if j > 0:
            value = (
                math.radians(profile["drive_value"])
                if report["drive_type"] == "R"
                else profile["drive_value"]
            )
            path = trace(mech, drive=drive, until=(drive, value))
            assert path.branches[0].end_reason == "reached target"
            assert not path.bifurcations and np.all(path.rank == path.rank[0])
            q = path.angles[-1]
        shown = np.where(revolute, np.degrees(q), q)
        world = joint_positions(out, dict(zip(mech.joint_names, shown, strict=True)))
        shape = mpath.Path(contours[name])
        for link in links:
            anchor, moving = world[f"{link}a"], world[f"{link}m"]
            along = np.linspace(0.0, 1.0, 201)[:, None]
            assert np.all(shape.contains_points(anchor + along * (moving - anchor))), (link, name)
            # mechanization.json's pivots are where the traced mechanism has them
            written = np.array(profile["pivots"][link])
            assert np.max(np.abs(written - [anchor, moving])) <= 1e-6, (link, name)
        assert abs(profile["e_max"] - profile["joined_e_max"]) <= 1e-9


@pytest.mark.slow
def test_closed_naca_contours_from_a_root_with_no_link_inside_say_which_pivot_leaves_which_profile(
    closed_naca: tuple,
) -> None:
    """Asked to build up from ``s1a`` (the rear of the upper surface), whose every ground link leaves the
    contours, the error names the link that came closest and how far its pivot is outside, checked against
    matplotlib's point-in-polygon and the distance to the contour computed here."""
    mpath = pytest.importorskip("matplotlib.path")
    _, contours, result = closed_naca
    options = replace(options_from_values(result.problem.mechanize_options), root="s1a")
    with pytest.raises(MechanizationError) as info:
        mechanize(result, options)
    message = str(info.value)
    assert "\n" not in message
    found = re.search(
        r"moving pivot \(([-0-9.e]+), ([-0-9.e]+)\)\): the moving pivot of it leaves profile 1 by ([0-9.e-]+)",
        message,
    )
    assert found, message
    x, y, by = (float(v) for v in found.groups())
    contour = contours["a"]  # profile 1, where the pivot is given
    assert not mpath.Path(contour).contains_points([[x, y]])[0]
    a, b = contour[:-1], contour[1:]
    t = np.clip(np.sum(([x, y] - a) * (b - a), axis=1) / np.sum((b - a) ** 2, axis=1), 0.0, 1.0)
    distance = float(np.min(np.linalg.norm(a + t[:, None] * (b - a) - [x, y], axis=1)))
    assert abs(distance - by) <= 5e-4 * max(1.0, by)  # the message prints 4 digits
