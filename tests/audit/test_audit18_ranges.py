"""The ranges the files report, checked against the law of cosines (written here) on four-bars the built-in
``four-bar`` makes (ground A-D = 2; crank A-B, coupler B-C, rocker C-D as set):

* the crank's extremes, where coupler and rocker line up: ``|BD| = coupler +- rocker`` with
  ``|BD|^2 = crank^2 + ground^2 - 2 crank ground cos A``;
* the rocker's extremes, where crank and coupler line up: ``|AC| = coupler +- crank``.

``report.json``'s branch ``range`` counts the located folds, so the drive's range is exact (docs/tracing.md,
"Folds of the drive"); ``sweep.csv``'s ``<joint>_min`` / ``<joint>_max`` are "the range of every joint"
(docs/robustness.md, "Parameter studies") of the same trace and must say the same.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from linkwork.cli import app

GROUND = 2.0


def crank_extremes(crank: float, coupler: float, rocker: float) -> list[float]:
    """The crank angles (deg, in [0, 180]) where coupler and rocker line up (law of cosines); a full turn has
    none."""
    out = []
    for bd in (coupler + rocker, abs(coupler - rocker)):
        c = (crank**2 + GROUND**2 - bd**2) / (2 * crank * GROUND)
        if abs(c) <= 1:
            out.append(float(np.degrees(np.arccos(c))))
    return sorted(out)


def rocker_extremes(crank: float, coupler: float, rocker: float) -> list[float]:
    """The rocker's angle at D (deg, from D->A, the start's side: above the ground line) where crank and coupler
    line up."""
    out = []
    for ac in (coupler + crank, coupler - crank):
        c = (rocker**2 + GROUND**2 - ac**2) / (2 * rocker * GROUND)
        out.append(float(np.degrees(np.arccos(c))))
    return sorted(out)


#: (crank, coupler, rocker): a triple rocker (the crank swings between its two extremes, 28.955 and 117.280 deg) and
#: a non-Grashof linkage whose crank swings through 180 deg between +-22.332 deg.
CASES = [(1.5, 1.0, 2.0), (2.5, 3.0, 2.0)]


def study(tmp_path: Path) -> list[dict[str, str]]:
    text = f"""name = "four-bars"
linkage = "four-bar"

[trace]
max_steps = 3000

[grid]
crank = [{CASES[0][0]}, {CASES[1][0]}]
coupler = [{CASES[0][1]}, {CASES[1][1]}]
rocker = [2.0]
"""
    path = tmp_path / "study.toml"
    path.write_text(text)
    result = CliRunner().invoke(app, ["sweep", str(path), "-o", str(tmp_path / "sweep"), "--no-plots"])
    assert result.exit_code == 0, result.output
    with (tmp_path / "sweep" / "sweep.csv").open() as fh:
        return list(csv.DictReader(fh))


def trace_report(tmp_path: Path, crank: float, coupler: float) -> dict:
    out = tmp_path / f"t{crank}-{coupler}"
    args = [
        "trace",
        "four-bar",
        "--set",
        f"crank={crank}",
        "--set",
        f"coupler={coupler}",
        "--set",
        "rocker=2",
    ]
    result = CliRunner().invoke(app, [*args, "-o", str(out), "--no-plots"])
    assert result.exit_code == 0, result.output
    return json.loads((out / "report.json").read_text())


@pytest.mark.parametrize(("crank", "coupler", "rocker"), CASES)
def test_report_json_holds_the_cranks_extremes(
    tmp_path: Path, crank: float, coupler: float, rocker: float
) -> None:
    """Holds: report.json's range of the crank A is its law-of-cosines swing to 1e-7 deg (a swing through 0 reads
    [e, 360 - e])."""
    lo, hi = trace_report(tmp_path, crank, coupler)["branches"][0]["range"]["A"]
    ext = crank_extremes(crank, coupler, rocker)
    ref = ext if len(ext) == 2 else [ext[0], 360.0 - ext[0]]
    assert abs(lo - ref[0]) < 1e-7 and abs(hi - ref[1]) < 1e-7


def test_sweep_csv_holds_the_same_crank_range_as_the_trace(tmp_path: Path) -> None:
    """Got (sweep.csv): A_min, A_max = 28.95513, 117.27922 (triple rocker) and 22.33274, 337.66818 (non-Grashof),
    where the law of cosines (and report.json of the same trace) give 28.95502, 117.27961 and 22.33165, 337.66835:
    off by up to 1.1e-3 deg. Right: the same range as report.json's, to 1e-7 deg. Cause: studies/sweep.py
    (_linkage_row) takes the min and max over the rows only, where io/results.py (branch_range) also counts the
    located folds ``Trace.folds``."""
    rows = study(tmp_path)
    assert len(rows) == 4
    for row in rows:
        crank, coupler = float(row["crank"]), float(row["coupler"])
        if (crank, coupler, 2.0) not in CASES:
            continue
        ext = crank_extremes(crank, coupler, 2.0)
        ref = ext if len(ext) == 2 else [ext[0], 360.0 - ext[0]]
        assert abs(float(row["A_min"]) - ref[0]) < 1e-7
        assert abs(float(row["A_max"]) - ref[1]) < 1e-7


def test_report_json_holds_the_rockers_swing(tmp_path: Path) -> None:
    """The crank-rocker (crank 1, coupler 2.5, rocker 2: Grashof, the crank turns fully). The rocker D's reading is
    the turn of the ground relative to the rocker (joint D's bodies are [rocker, ground]), so its swing is the
    rocker's absolute swing, 122.08995 - 44.04863 = 78.04133 deg by the law of cosines. Got: report.json range D
    [57.91027, 135.95087] spans 78.04061 deg (7.2e-4 deg short): the min and max of the rows of 2-deg steps, with
    no extreme located (io/results.py branch_range counts the drive's folds only). Right: the
    extremes to 1e-7 deg, as the drive's are, or docs/tracing.md saying that only the drive's range is exact."""
    rng = trace_report(tmp_path, 1.0, 2.5)["branches"][0]["range"]["D"]
    swing = np.diff(rocker_extremes(1.0, 2.5, 2.0))[0]
    assert abs((rng[1] - rng[0]) - swing) < 1e-7


@pytest.mark.parametrize("steps", [10, 45, 200])
def test_a_paper_folds_step_is_a_row_of_its_branch(tmp_path: Path, steps: int) -> None:
    """Holds for the value: the triple rocker (crank 1.5, coupler 1, rocker 2) in equal steps from 60 to 150 deg
    turns back at its law-of-cosines extreme 117.27961 deg (1e-7), the branch ending 'drive turning point'."""
    trace = CliRunner().invoke(
        app,
        [
            *_triple_rocker_args(),
            "--until",
            "A=150",
            "--steps",
            str(steps),
            "-o",
            str(tmp_path / "p"),
            "--no-plots",
        ],
    )
    assert trace.exit_code == 3
    report = json.loads((tmp_path / "p" / "report.json").read_text())
    (fold,) = report["folds"]
    assert abs(fold["value"] - crank_extremes(1.5, 1.0, 2.0)[1]) < 1e-7
    assert report["branches"][0]["end_kind"] == "turning"


def _triple_rocker_args() -> list[str]:
    return ["trace", "four-bar", "--set", "crank=1.5", "--set", "coupler=1", "--set", "rocker=2"]


@pytest.mark.parametrize("steps", [10, 45, 200])
def test_a_paper_folds_step_is_the_row_just_before_it(tmp_path: Path, steps: int) -> None:
    """``Fold.step`` is 'the step of the branch just before it' (kinematics/trace_result.py), report.json's
    ``folds[k].step`` and the printed 'fold ... (after step N)' the same. In paper mode the branch ends at the fold,
    so that is its last row. Got (report.json, the triple rocker to A = 150 in 10, 45 and 200 equal steps): step
    22, 39 and 135 for branches of 6, 28 and 127 steps (path.csv rows 0..6, 0..28, 0..127; the elliptic trammel
    to X = -2.5 in 10 steps: 'after step 51' for rows 0..8). Adaptive traces are right (the 7R and this triple
    rocker: the fold lies between rows step and step + 1). Right: the last row's step (6, 28, 127). Suspected
    cause: the marcher records the fold at the march's own step counter, which in paper mode also counts the
    parts of long steps and the steps tried and rejected while approaching the fold (kinematics/marcher.py,
    where Fold is built)."""
    out = tmp_path / "p"
    CliRunner().invoke(
        app, [*_triple_rocker_args(), "--until", "A=150", "--steps", str(steps), "-o", str(out), "--no-plots"]
    )
    report = json.loads((out / "report.json").read_text())
    (fold,) = report["folds"]
    assert fold["step"] == report["branches"][0]["steps"]
