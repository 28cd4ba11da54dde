"""Snapshots and animations: files of the right kind, the frames the branch asks for, rigid steadying."""

from __future__ import annotations

import time
from pathlib import Path as FilePath

import matplotlib
import numpy as np
import pytest

from linkwork.errors import LinkworkError
from linkwork.kinematics.tracer import Path, trace
from linkwork.linkages import deployed_angle, hedgepeth
from linkwork.linkages.guest import guest_frame
from linkwork.viz import animate
from linkwork.viz.animate import animate_path, path_frames
from linkwork.viz.snapshots import branch_indices, deployment_sequence, steady_transforms

matplotlib.use("Agg")


@pytest.fixture(scope="module")
def hexagon() -> Path:
    return trace(hedgepeth(6), until=("A", deployed_angle(6)))


@pytest.fixture(scope="module")
def guest() -> Path:
    return trace(guest_frame(), branches=True, max_steps=120)


def test_branch_frames_run_from_first_to_last_point(hexagon: Path) -> None:
    idx = branch_indices(hexagon, 0, 6)
    assert len(idx) == 6
    assert idx[0] == 0 and idx[-1] == len(hexagon.angles) - 1  # exact indices
    assert np.all(np.diff(hexagon.arclength[idx]) > 0)  # strictly along the branch


def test_unknown_branch_is_a_clear_error(hexagon: Path) -> None:
    with pytest.raises(LinkworkError, match="no branch 7"):
        branch_indices(hexagon, 7, 6)


def test_hexagon_deployment_sequence_png_is_fast(hexagon: Path, tmp_path: FilePath) -> None:
    started = time.perf_counter()
    out = deployment_sequence(hexagon, tmp_path / "hexagon.png")
    elapsed = time.perf_counter() - started
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"  # exact signature
    assert elapsed < 5.0  # seconds
    assert out.stat().st_size < 400_000  # bytes


@pytest.mark.parametrize(("suffix", "magic"), [(".svg", b"<?xml"), (".pdf", b"%PDF")])
def test_vector_formats_by_suffix(guest: Path, tmp_path: FilePath, suffix: str, magic: bytes) -> None:
    out = deployment_sequence(guest, tmp_path / f"guest{suffix}", frames=3)
    assert out.read_bytes()[: len(magic)] == magic  # exact header


def test_unknown_suffix_is_refused(guest: Path, tmp_path: FilePath) -> None:
    with pytest.raises(LinkworkError, match=r"\.png, \.svg or \.pdf"):
        deployment_sequence(guest, tmp_path / "guest.jpg")
    assert not (tmp_path / "guest.jpg").exists()


def test_steadying_moves_are_proper_rigid_motions(hexagon: Path) -> None:
    T = steady_transforms(hexagon.mechanism, hexagon.angles[::10])
    R = T[:, :3, :3]
    np.testing.assert_allclose(R @ np.swapaxes(R, 1, 2), np.broadcast_to(np.eye(3), R.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)


def test_all_branches_are_animated_in_turn(guest: Path) -> None:
    idx = path_frames(guest, None, max_frames=30)
    branches = [int(b) for b in guest.branch[idx]]
    assert set(branches) == {int(b) for b in guest.branch}  # every branch appears
    assert branches == sorted(branches)  # one after the other
    assert len(idx) <= 30 + len(set(branches))  # at most one extra frame per branch from rounding


def test_gif_is_written_and_mp4_skip_is_reported(
    guest: Path, tmp_path: FilePath, monkeypatch: pytest.MonkeyPatch
) -> None:
    from PIL import Image

    monkeypatch.setattr(animate.shutil, "which", lambda name: None)
    result = animate_path(guest, tmp_path / "guest.gif", branch=0, max_frames=6, size=160)
    assert result.mp4 is None and "ffmpeg" in result.mp4_skipped
    assert result.gif is not None and result.gif.read_bytes()[:6] == b"GIF89a"  # exact header
    with Image.open(result.gif) as im:
        assert im.n_frames == result.frames == 6  # exact count
        im.seek(0)
        first = np.asarray(im.convert("RGB")).astype(int)
        im.seek(5)
        last = np.asarray(im.convert("RGB")).astype(int)
    assert np.mean(np.abs(first - last)) > 1.0  # the drawing changes (mean grey-level difference)
    assert result.gif.stat().st_size < 3_000_000  # bytes
