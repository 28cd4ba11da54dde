"""Snapshots and animations: files of the right kind, the frames the branch asks for, rigid steadying."""

from __future__ import annotations

import itertools
import re
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import matplotlib
import numpy as np
import pytest
from numpy.typing import NDArray

from linkwork.errors import LinkworkError
from linkwork.kinematics.trace_result import Trace
from linkwork.kinematics.tracer import trace
from linkwork.linkages import deployed_angle, hedgepeth
from linkwork.linkages.guest import guest_frame
from linkwork.viz import animate
from linkwork.viz.animate import animate_path, path_frames
from linkwork.viz.snapshots import branch_indices, deployment_sequence, steady_transforms

matplotlib.use("Agg")


@pytest.fixture(scope="module")
def hexagon() -> Trace:
    return trace(hedgepeth(6), until=("A", deployed_angle(6)))


@pytest.fixture(scope="module")
def guest() -> Trace:
    return trace(guest_frame(), branches=True, max_steps=120)


def test_branch_frames_run_from_first_to_last_point(hexagon: Trace) -> None:
    idx = branch_indices(hexagon, 0, 6)
    assert len(idx) == 6
    assert idx[0] == 0 and idx[-1] == len(hexagon.angles) - 1  # exact indices
    assert np.all(np.diff(hexagon.arclength[idx]) > 0)  # strictly along the branch


def test_unknown_branch_is_a_clear_error(hexagon: Trace) -> None:
    with pytest.raises(LinkworkError, match="no branch 7"):
        branch_indices(hexagon, 7, 6)


def test_hexagon_deployment_sequence_png_is_fast(hexagon: Trace, tmp_path: Path) -> None:
    started = time.perf_counter()
    out = deployment_sequence(hexagon, tmp_path / "hexagon.png")
    elapsed = time.perf_counter() - started
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"  # exact signature
    assert elapsed < 5.0  # seconds
    assert out.stat().st_size < 400_000  # bytes


@pytest.mark.parametrize(("suffix", "magic"), [(".svg", b"<?xml"), (".pdf", b"%PDF")])
def test_vector_formats_by_suffix(guest: Trace, tmp_path: Path, suffix: str, magic: bytes) -> None:
    out = deployment_sequence(guest, tmp_path / f"guest{suffix}", frames=3)
    assert out.read_bytes()[: len(magic)] == magic  # exact header


def test_unknown_suffix_is_refused(guest: Trace, tmp_path: Path) -> None:
    with pytest.raises(LinkworkError, match=r"\.png, \.svg or \.pdf"):
        deployment_sequence(guest, tmp_path / "guest.jpg")
    assert not (tmp_path / "guest.jpg").exists()


def test_steadying_moves_are_proper_rigid_motions(hexagon: Trace) -> None:
    T = steady_transforms(hexagon.mechanism, hexagon.angles[::10])
    R = T[:, :3, :3]
    np.testing.assert_allclose(R @ np.swapaxes(R, 1, 2), np.broadcast_to(np.eye(3), R.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)


def test_all_branches_are_animated_in_turn(guest: Trace) -> None:
    idx = path_frames(guest, None, max_frames=30)
    branches = [int(b) for b in guest.branch[idx]]
    assert set(branches) == {int(b) for b in guest.branch}  # every branch appears
    assert branches == sorted(branches)  # one after the other
    assert len(idx) <= 30 + len(set(branches))  # at most one extra frame per branch from rounding


def decoded_mp4(path: Path) -> tuple[tuple[int, int], list[NDArray[np.int64]]]:
    """The frame size ``(width, height)`` and the RGB frames of a video, decoded by ffmpeg into a stream of
    binary PPM images (``P6 width height 255`` then the pixels, one after another)."""
    ffmpeg = animate.find_ffmpeg()
    assert ffmpeg is not None
    cmd = [ffmpeg, "-v", "error", "-i", str(path), "-f", "image2pipe", "-c:v", "ppm", "-"]
    data = subprocess.run(cmd, capture_output=True, check=True).stdout
    sizes, frames, at = set(), [], 0
    header = re.compile(rb"P6\s+(\d+)\s+(\d+)\s+255\s")
    while at < len(data):
        m = header.match(data, at)
        assert m is not None, f"not a PPM frame at byte {at}"
        w, h = int(m[1]), int(m[2])
        pixels = np.frombuffer(data, dtype=np.uint8, count=w * h * 3, offset=m.end())
        frames.append(pixels.reshape(h, w, 3).astype(np.int64))
        sizes.add((w, h))
        at = m.end() + w * h * 3
    assert len(sizes) == 1  # every frame the same size
    return sizes.pop(), frames


def test_mp4_decodes_to_the_frames_written(
    guest: Trace, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    written: list[NDArray[np.uint8]] = []
    write_mp4 = animate.write_mp4

    def keep(images: list[NDArray[np.uint8]], *args: Any) -> Path:
        written.extend(images)
        return write_mp4(images, *args)

    monkeypatch.setattr(animate, "write_mp4", keep)
    started = time.perf_counter()
    # An odd size: the MP4 is cropped to even sides (yuv420p); with ffmpeg found, an .mp4 name writes no GIF.
    result = animate_path(guest, tmp_path / "guest.mp4", branch=0, max_frames=6, size=161)
    elapsed = time.perf_counter() - started
    assert result.mp4 == tmp_path / "guest.mp4" and result.gif is None and result.mp4_skipped == ""
    assert not (tmp_path / "guest.gif").exists()
    assert result.frames == len(written) == 6  # exact count
    assert written[0].shape == (161, 161, 3)  # exact: the rendered frames
    size, frames = decoded_mp4(result.mp4)
    assert size == (160, 160)  # exact: even sides
    assert len(frames) == result.frames  # exact: every frame written is in the file, no more
    for k, frame in enumerate(frames):
        errors = [np.mean(np.abs(frame - img[:160, :160])) for img in written]
        assert errors[k] < 2.5  # mean grey levels: H.264 + yuv420p of the frame written ...
        assert int(np.argmin(errors)) == k  # ... and closer to it than to any other (frames in order)
    for a, b in itertools.pairwise(frames):
        assert np.mean(np.abs(a - b)) > 1.0  # the drawing moves between consecutive frames
    assert result.mp4.stat().st_size < 200_000  # bytes
    assert elapsed < 10.0  # seconds


def test_ffmpeg_on_path_comes_first(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(animate.shutil, "which", lambda name: f"/opt/bin/{name}")
    assert animate.find_ffmpeg() == "/opt/bin/ffmpeg"


def test_imageio_ffmpeg_binary_is_the_fallback(monkeypatch: pytest.MonkeyPatch) -> None:
    import imageio_ffmpeg

    monkeypatch.setattr(animate.shutil, "which", lambda name: None)
    monkeypatch.delenv("IMAGEIO_FFMPEG_EXE", raising=False)
    exe = animate.find_ffmpeg()
    assert exe is not None and exe == imageio_ffmpeg.get_ffmpeg_exe()
    assert Path(exe).is_file()


@pytest.mark.parametrize("missing", ["package", "binary"])
def test_gif_is_written_and_mp4_skip_is_reported(
    guest: Trace, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, missing: str
) -> None:
    from PIL import Image

    monkeypatch.setattr(animate.shutil, "which", lambda name: None)
    if missing == "package":
        monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # import fails
    else:
        # imageio-ffmpeg returns this variable's path untested: a file that is not there.
        monkeypatch.setenv("IMAGEIO_FFMPEG_EXE", str(tmp_path / "no-ffmpeg"))
    assert animate.find_ffmpeg() is None
    result = animate_path(guest, tmp_path / "guest.mp4", branch=0, max_frames=6, size=160)
    assert result.mp4 is None and not (tmp_path / "guest.mp4").exists()
    assert "ffmpeg is not on PATH" in result.mp4_skipped and "imageio-ffmpeg" in result.mp4_skipped
    assert result.gif == tmp_path / "guest.gif"  # something is always written
    assert result.gif.read_bytes()[:6] == b"GIF89a"  # exact header
    with Image.open(result.gif) as im:
        assert im.n_frames == result.frames == 6  # exact count
        im.seek(0)
        first = np.asarray(im.convert("RGB")).astype(int)
        im.seek(5)
        last = np.asarray(im.convert("RGB")).astype(int)
    assert np.mean(np.abs(first - last)) > 1.0  # the drawing changes (mean grey-level difference)
    assert result.gif.stat().st_size < 3_000_000  # bytes


def test_failing_ffmpeg_leaves_no_mp4(guest: Trace, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # A stand-in ffmpeg that reads the frames, writes half a file to its output argument and fails.
    fake = tmp_path / "ffmpeg"
    fake.write_text(
        '#!/bin/sh\nfor a in "$@"; do last="$a"; done\ncat > /dev/null\n'
        'printf half > "$last"\necho "encoder exploded" >&2\nexit 1\n'
    )
    fake.chmod(0o755)
    monkeypatch.setattr(animate, "find_ffmpeg", lambda: str(fake))
    with pytest.raises(LinkworkError, match=r"ffmpeg failed writing guest\.mp4: encoder exploded"):
        animate_path(guest, tmp_path / "out" / "guest.mp4", branch=0, max_frames=3, size=80)
    assert list((tmp_path / "out").iterdir()) == []  # exact: no half-written .mp4 (and no GIF)


def _moved(mech: Any, angles: NDArray[np.float64]) -> NDArray[np.float64]:
    """Every body mesh's vertices as the steady drawing places them, per configuration."""
    from linkwork.viz.snapshots import mesh_clouds

    clouds = mesh_clouds(mech, angles)
    moves = steady_transforms(mech, angles)
    return np.einsum("nij,nvj->nvi", moves[:, :3, :3], clouds) + moves[:, None, :3, 3]


@pytest.mark.parametrize(
    ("name", "until_deg"), [("four-bar", 420.0), ("bennett", None), ("bricard-threefold", None)]
)
def test_the_same_configuration_is_drawn_the_same_way(name: str, until_deg: float | None) -> None:
    """sequence.png drew the four-bar's frames (a) and (f), A = 60 and 420 deg (one configuration), in
    different poses: chained fits drift around a closed path (Bennett's ends 0.73 apart). A grounded mechanism is
    now drawn on its ground, and a closed path's drift is spread back along it: both ends coincide, and no frame
    moves much more than the chained fits moved it."""
    import linkwork as lw
    from linkwork.viz.snapshots import follow, mesh_clouds

    mech = lw.load(name)
    until = None if until_deg is None else ("A", float(np.radians(until_deg)))
    path = trace(mech, drive="A", until=until)
    rows = path.angles[branch_indices(path, 0, 0)]
    gap = (rows[-1] - rows[0] + np.pi) % (2 * np.pi) - np.pi
    assert np.abs(gap).max() < 1e-9  # the path ends where it began
    moved = _moved(mech, rows)
    size = float(np.ptp(moved[0], axis=0).max())
    assert np.abs(moved[-1] - moved[0]).max() < 1e-9 * size
    clouds = mesh_clouds(mech, rows)
    chained = follow(clouds)
    before = np.einsum("nij,nvj->nvi", chained[:, :3, :3], clouds) + chained[:, None, :3, 3]
    step_now = np.abs(np.diff(moved, axis=0)).max()
    step_before = np.abs(np.diff(before, axis=0)).max()
    ground_moves = mech.bodies[0] == "ground"  # drawn on its ground, the other links move more than the fit
    assert step_now < (3.0 if ground_moves else 1.2) * step_before


def test_a_grounded_mechanism_keeps_its_ground_still() -> None:
    import linkwork as lw
    from linkwork.viz.solids import body_meshes, place

    mech = lw.load("four-bar")
    path = trace(mech, drive="A", until=("A", float(np.radians(200.0))))
    moves = steady_transforms(mech, path.angles)
    bodies = body_meshes(mech)
    ground = [
        place(mech, {"ground": bodies["ground"]}, [], row)[0].transformed(T)
        for row, T in zip(path.angles, moves, strict=True)
    ]
    np.testing.assert_allclose(
        [g.vertices for g in ground], np.repeat(ground[0].vertices[None], len(ground), axis=0), atol=1e-12
    )


def test_the_viewer_draws_a_closed_path_s_ends_alike() -> None:
    """The viewer's steady mode uses the same fits: Bennett's closed loop ends in the pose it began in (the page
    carries the moves as float32)."""
    import linkwork as lw
    from linkwork.viz.snapshots import mesh_clouds
    from linkwork.viz.viewer import trace_viewer_data
    from linkwork.viz.viewer_page import unpack

    path = trace(lw.load("bennett"))
    assert len(path.branches) == 1 and path.branches[0].end_reason == "closed path"
    rows = unpack(trace_viewer_data(path)["steady"]).astype(float)
    moves = np.zeros((len(rows), 4, 4))
    moves[:, :3, :3] = rows[:, :9].reshape(-1, 3, 3)
    moves[:, :3, 3] = rows[:, 9:]
    ends = mesh_clouds(path.mechanism, path.angles[[0, -1]])
    first = ends[0] @ moves[0, :3, :3].T + moves[0, :3, 3]
    last = ends[1] @ moves[-1, :3, :3].T + moves[-1, :3, 3]
    assert np.abs(first - last).max() < 1e-5 * float(np.ptp(first, axis=0).max())  # float32 round-off
