"""The interactive viewers' HTML files, read without a browser: self-contained (no address of another host
anywhere in the file), carrying the data of every branch and every profile, correct poses, small enough.

References: the body poses come from :func:`linkwork.kinematics.closure.body_poses` (the core, not the viewer);
the angles from the traced path itself; sizes from the issue (< 5 MB for Guest's frame with its 13 branches).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import linkwork as lw
from linkwork.cli import app
from linkwork.kinematics.closure import body_poses
from linkwork.viz.viewer import (
    DATA_ID,
    joint_turns,
    unpack,
    write_synthesis_viewer,
    write_trace_viewer,
)

#: float32 storage of poses and angles: relative precision about 6e-8, so 1e-5 is ample for unit-size linkages.
F32 = 1e-5


def page_data(html: str) -> dict:
    """The JSON the page carries in <script type="application/json" id="linkwork-data">."""
    match = re.search(rf'<script type="application/json" id="{DATA_ID}">(.*?)</script>', html, re.S)
    assert match is not None, "no data element"
    return json.loads(match.group(1))


def assert_self_contained(html: str) -> None:
    """Nothing in the page could make the browser fetch from another host: no URL with a scheme and host at
    all, no element that loads a file (script src, link, img, iframe, CSS url() or @import), no fetch/XHR."""
    assert re.search(r"(?i)\b(?:https?|ftp|wss?):/", html) is None
    assert re.search(r"(?i)//[a-z0-9-]+\.[a-z]{2,}/", html) is None, "a protocol-relative address"
    assert re.search(r"(?i)<(?:script|img|iframe|source|audio|video)[^>]*\ssrc\s*=", html) is None
    assert re.search(r"(?i)<link\b", html) is None
    assert re.search(r"(?i)url\(|@import", html) is None
    assert re.search(r"\bfetch\(|XMLHttpRequest|WebSocket|EventSource|importScripts", html) is None


@pytest.fixture(scope="module")
def guest_path() -> lw.Trace:
    return lw.trace(lw.load("guest-frame"), branches=True, max_steps=6000)


@pytest.fixture(scope="module")
def guest_page(guest_path: lw.Trace, tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_trace_viewer(guest_path, tmp_path_factory.mktemp("guest") / "viewer.html")


def test_guest_frame_viewer_is_self_contained_and_small(guest_page: Path) -> None:
    html = guest_page.read_text(encoding="utf-8")
    assert_self_contained(html)
    size = guest_page.stat().st_size
    assert size < 5_000_000, f"{size / 1e6:.2f} MB"


def test_guest_frame_viewer_embeds_every_branch(guest_path: lw.Trace, guest_page: Path) -> None:
    data = page_data(guest_page.read_text(encoding="utf-8"))
    mech = guest_path.mechanism
    assert [b["id"] for b in data["branches"]] == [b.id for b in guest_path.branches]
    assert len(data["branches"]) == 7  # the start loop and six arcs between the bifurcation points, each once
    assert data["points"] == data["points_traced"] == len(guest_path.branch)
    angles = unpack(data["angles"])
    poses = unpack(data["poses"])
    assert poses.shape == (len(guest_path.branch), len(mech.bodies), 12)
    for b in data["branches"]:
        rows = slice(b["start"], b["start"] + b["count"])
        expected = np.degrees(guest_path.angles[guest_path.of_branch(b["id"])])
        assert b["count"] == len(expected)
        # float32 degrees: 1e-4 deg absolute on angles of a few hundred degrees.
        np.testing.assert_allclose(angles[rows], expected, rtol=0, atol=1e-4)
    # Every bifurcation point is reachable from every branch that leaves or reaches it.
    assert len(data["bifurcations"]) == len(guest_path.bifurcations) == 6
    for bif, located in zip(data["bifurcations"], guest_path.bifurcations, strict=True):
        leaving = {data["branches"][bi]["id"] for bi, row in bif["visits"] if row == 0}
        children = {b.id for b in guest_path.branches if b.bifurcation == located.id}
        assert children <= leaving
        assert any(data["branches"][bi]["id"] == located.branch for bi, _ in bif["visits"])


def test_poses_are_the_cores_body_poses(guest_path: lw.Trace, guest_page: Path) -> None:
    data = page_data(guest_page.read_text(encoding="utf-8"))
    poses = unpack(data["poses"])
    mech = guest_path.mechanism
    for i in (0, 500, len(guest_path.branch) - 1):
        ref = body_poses(mech, angles=guest_path.angles[i])
        for b, name in enumerate(mech.bodies):
            np.testing.assert_allclose(poses[i, b, :9].reshape(3, 3), ref[name][:3, :3], rtol=0, atol=F32)
            np.testing.assert_allclose(poses[i, b, 9:], ref[name][:3, 3], rtol=0, atol=F32)


def _steadied(data: dict) -> np.ndarray:
    """The body poses the page draws in its "steady" view: each point's whole-mechanism motion times the poses."""
    S, poses = unpack(data["steady"]), unpack(data["poses"])
    R, t = poses[:, :, :9].reshape(*poses.shape[:2], 3, 3), poses[:, :, 9:]
    SR = S[:, :9].reshape(-1, 3, 3)
    np.testing.assert_allclose(SR @ SR.transpose(0, 2, 1), np.broadcast_to(np.eye(3), SR.shape), atol=1e-5)
    np.testing.assert_allclose(np.linalg.det(SR), 1.0, atol=1e-5)
    return np.concatenate(
        [(SR[:, None] @ R).reshape(*poses.shape[:2], 9), np.einsum("nij,nbj->nbi", SR, t) + S[:, None, 9:]],
        axis=2,
    )


def test_steady_view_stands_the_bundle_up_and_lays_the_hexagon_level(tmp_path: Path) -> None:
    from linkwork.linkages.hedgepeth_rods import deployed_angles, rod_frame

    path = lw.trace(lw.load("hedgepeth-rods", n=6), until=("A", deployed_angles(6)[0]), steps=60)
    data = page_data(write_trace_viewer(path, tmp_path / "viewer.html").read_text(encoding="utf-8"))
    steadied = _steadied(data)
    # The rods' apex points (start of each rod's frame) in the steady view, first and last point.
    apexes = [
        np.array(
            [
                P[:3, :3] @ rod_frame(6, i)[:3, 3] + P[:3, 3]
                for i, P in enumerate(
                    [np.vstack([np.c_[row[:9].reshape(3, 3), row[9:]], [0, 0, 0, 1]]) for row in steadied[k]]
                )
            ]
        )
        for k in (0, -1)
    ]
    flat = apexes[1]
    assert np.ptp(flat[:, 2]) < 1e-5, "the deployed hexagon lies level"
    bundle_axis = apexes[0][1] - apexes[0][0]  # consecutive apex points of the bundle: along its axis
    assert abs(bundle_axis[2]) / np.linalg.norm(bundle_axis) > 0.999, "the bundle stands upright"
    # No drifting: the centroid of all the rods' vertices stays at the origin.
    from linkwork.viz.solids import body_meshes

    meshes = body_meshes(path.mechanism)
    for row in steadied:
        cloud = [
            m.vertices @ r[:9].reshape(3, 3).T + r[9:] for m, r in zip(meshes.values(), row, strict=True)
        ]
        assert np.linalg.norm(np.concatenate(cloud).mean(axis=0)) < 1e-5


def test_steady_view_starts_each_branch_where_its_parent_is(guest_path: lw.Trace, guest_page: Path) -> None:
    data = page_data(guest_page.read_text(encoding="utf-8"))
    steadied = _steadied(data)
    angles = np.radians(unpack(data["angles"]))
    by_id = {b["id"]: b for b in data["branches"]}
    for b in data["branches"]:
        if b["parent"] is None:
            continue
        parent = by_id[b["parent"]]
        rows = np.arange(parent["start"], parent["start"] + parent["count"])
        d = np.angle(np.exp(1j * (angles[rows] - angles[b["start"]])))
        k = rows[np.argmin(np.linalg.norm(d, axis=1))]
        gap = np.abs(steadied[b["start"]] - steadied[k]).max()
        assert gap < 0.05, f"branch {b['id']} jumps by {gap:.3f} when it leaves its parent"


def test_long_paths_are_thinned_keeping_ends_and_bifurcation_points(
    guest_path: lw.Trace, tmp_path: Path
) -> None:
    page = write_trace_viewer(guest_path, tmp_path / "viewer.html", max_points=400)
    data = page_data(page.read_text(encoding="utf-8"))
    assert data["points_traced"] == len(guest_path.branch) and data["points"] < 600
    step = unpack(data["step"])
    for b, br in zip(data["branches"], guest_path.branches, strict=True):
        steps = step[b["start"] : b["start"] + b["count"]]
        full = guest_path.step[guest_path.of_branch(br.id)]
        assert steps[0] == full[0] and steps[-1] == full[-1], "a branch lost an end"
    for bif in data["bifurcations"]:
        assert len(bif["visits"]) >= 2


def test_title_cannot_break_out_of_the_page(tmp_path: Path) -> None:
    path = lw.trace(lw.load("bennett"), steps=5, until=("A", 2.0))
    page = write_trace_viewer(path, tmp_path / "v.html", title="</script><script>alert(1)</script> & <b>")
    html = page.read_text(encoding="utf-8")
    # Only the page's own two <script> elements close; the title is text everywhere else.
    assert html.count("</script>") == 2
    assert "<title>&lt;/script&gt;" in html
    assert page_data(html)["title"].startswith("</script>")


def test_trace_command_writes_the_viewer(tmp_path: Path) -> None:
    out = tmp_path / "hoop"
    hoop = ["hedgepeth", "--set", "n=6", "--until", "A=87.0067", "--steps", "20"]
    result = CliRunner().invoke(app, ["trace", *hoop, "--no-plots", "--html", "--out", str(out)])
    assert result.exit_code == 0, result.output
    page = out / "viewer.html"
    assert page.is_file() and "viewer.html" in result.output
    html = page.read_text(encoding="utf-8")
    assert_self_contained(html)
    data = page_data(html)
    assert data["points"] == 21 and [j["name"] for j in data["joints"]] == list("ABCDEF")
    # The last point is the paper's deployed angle (Eq. 10), degrees in the page.
    assert unpack(data["angles"])[-1, 0] == pytest.approx(87.0067, abs=1e-3)


def test_synthesis_viewer_carries_every_profile(tmp_path: Path) -> None:
    from linkwork.data import example
    from linkwork.io.problem import load_problem
    from linkwork.synthesis import synthesize

    result = synthesize(load_problem(example("wing")))
    page = write_synthesis_viewer(result, tmp_path / "viewer.html")
    html = page.read_text(encoding="utf-8")
    assert_self_contained(html)
    assert page.stat().st_size < 1_000_000
    data = page_data(html)
    assert [t["name"] for t in data["targets"]] == [t.name for t in result.targets]
    assert data["design"] == result.design and len(data["segments"]) == len(result.design)
    for shown, joined, target in zip(data["joined"], result.joined, result.targets, strict=True):
        np.testing.assert_allclose(shown["points"], joined.points, rtol=0, atol=1e-12)
        np.testing.assert_allclose(shown["joints"], joined.joints, rtol=0, atol=1e-12)
        assert len(shown["points"]) == len(target.points)
        assert len(shown["turns"]) == len(result.design) - 1


def test_joint_turns_of_simple_chains() -> None:
    # A straight chain does not turn; an L turns 90 degrees left, its mirror image 90 degrees right.
    straight = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]])
    ell = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [1.0, 2.0]])
    np.testing.assert_allclose(joint_turns(straight, [1, 2]), [0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(joint_turns(ell, [1, 2]), [90.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(joint_turns(ell * [1, -1], [1]), [-90.0], atol=1e-12)
