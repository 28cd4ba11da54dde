"""The viewer's steady view holds a grounded mechanism (a body called ``ground``) by its ground: the ground body
and its pivots do not move while the crank turns."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np

import linkwork as lw
from linkwork.viz.viewer import DATA_ID, unpack, write_trace_viewer


def test_steady_view_keeps_the_four_bars_ground_still(tmp_path: Path) -> None:
    path = lw.trace(lw.load("four-bar"), drive="A", until=("A", np.radians(200.0)))
    html = write_trace_viewer(path, tmp_path / "viewer.html").read_text(encoding="utf-8")
    data = json.loads(re.search(rf'id="{DATA_ID}">(.*?)</script>', html, re.S).group(1))
    S, poses = unpack(data["steady"]), unpack(data["poses"])
    ground = data["bodies"].index("ground")
    R = S[:, :9].reshape(-1, 3, 3) @ poses[:, ground, :9].reshape(-1, 3, 3)
    t = np.einsum("nij,nj->ni", S[:, :9].reshape(-1, 3, 3), poses[:, ground, 9:]) + S[:, 9:]
    np.testing.assert_allclose(R, np.broadcast_to(np.eye(3), R.shape), atol=1e-6)  # float32 storage
    np.testing.assert_allclose(t, 0.0, atol=1e-6)
    crank = data["bodies"].index("crank")
    assert np.ptp(poses[:, crank, :9], axis=0).max() > 1.0  # while the crank turns round
