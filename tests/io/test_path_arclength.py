"""``path.csv``'s ``s``: the arclength in the unknowns, degrees for revolute unknowns and the length unit for
prismatic ones (docs/tracing.md), checked against the chords of the file's own joint columns."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

import linkwork as lw
from linkwork.io.results import write_path_csv

RAD = np.pi / 180.0


def _columns(file: Path) -> dict[str, np.ndarray]:
    with open(file, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    return {name: np.array([float(r[i]) for r in rows[1:]]) for i, name in enumerate(rows[0])}


@pytest.mark.parametrize("drive", ["A", "D"])
@pytest.mark.parametrize("rod", [3.0, 300.0])
def test_s_is_the_arclength_in_file_units_with_a_slider(tmp_path: Path, drive: str, rod: float) -> None:
    """A slider-crank (crank 1, the rod ``rod`` long: the slider's travel is 2 length units against the crank's
    turn of 1 radian each way) traced in small adaptive steps: the last ``s`` equals the sum of the chords of the
    file's columns A..D (degrees and lengths as written) to 1e-4, whichever joint drives. Written from
    ``np.degrees(arclength)``, the slider's 2 units counted as 115 'degrees'."""
    mech = lw.load("slider-crank", crank=1.0, rod=rod, offset=0.0, theta=30 * RAD)
    if drive == "A":
        trace = lw.trace(mech, drive="A", until=("A", 150 * RAD), max_step=0.5 * RAD)
    else:
        x0 = float(mech.offsets[mech.index("D")])
        trace = lw.trace(mech, drive="D", until=("D", x0 - 1.0), max_step=0.5 * RAD)
    assert trace.stats.unmet is None
    write_path_csv(trace, tmp_path / "path.csv")
    cols = _columns(tmp_path / "path.csv")
    values = np.stack([cols[j] for j in mech.joint_names], axis=1)
    chords = np.linalg.norm(np.diff(values, axis=0), axis=1)
    assert cols["s"][0] == 0.0
    assert np.all(np.diff(cols["s"]) > 0.0)
    np.testing.assert_allclose(cols["s"][-1], chords.sum(), rtol=1e-4)


def test_s_without_a_slider_is_the_arclength_in_degrees(tmp_path: Path) -> None:
    """A four-bar: ``s`` is ``Trace.arclength`` in degrees, bit for bit."""
    mech = lw.load("four-bar")
    trace = lw.trace(mech, until=("A", float(mech.offsets[0]) + 90 * RAD), steps=30)
    write_path_csv(trace, tmp_path / "path.csv")
    np.testing.assert_array_equal(_columns(tmp_path / "path.csv")["s"], np.degrees(trace.arclength))
