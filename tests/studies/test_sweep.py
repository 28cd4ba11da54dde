"""Parameter studies: the grid, one row per point, and results checked against closed forms.

* Bennett's linkage keeps mobility 1 for every pair of different twists, and its joint B follows the closed form
  ``tan(B/2) = K / tan(A/2)`` (Bennett 1914): the range of B over the traced A interval must be the closed form's.
* A synthesis study gives one row per combination, each the same as a direct ``synthesize`` of that problem.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from linkwork.errors import SpecError
from linkwork.linkages.bennett import bennett_angles
from linkwork.studies.study_file import load_study
from linkwork.studies.sweep import run_sweep


def _write(tmp_path: Path, text: str) -> Path:
    f = tmp_path / "study.toml"
    f.write_text(text, encoding="utf-8")
    return f


def test_linkage_grid_rows_match_bennett_closed_form(tmp_path):
    study = load_study(
        _write(
            tmp_path,
            """
linkage = "bennett"
[trace]
until = "A=100"
steps = 20
[grid]
alpha1 = [30, 45]
alpha2 = { from = 70, to = 90, count = 3 }
""",
        )
    )
    assert [p["alpha2"] for p in study.points()[:3]] == [70.0, 80.0, 90.0]
    rows = [row for row, _ in run_sweep(study, workers=0)]
    assert len(rows) == 6
    for row in rows:
        assert row["error"] == "" and row["mobility"] == 1 and row["bifurcations"] == 0
        a1, a2 = np.radians(row["alpha1"]), np.radians(row["alpha2"])
        theta = np.radians(np.linspace(60.0, 100.0, 2001))
        b = np.degrees([bennett_angles(t, a1, a2)[1] for t in theta])
        b = np.where(b < 0, b + 360.0, b) if row["B_min"] > 0 else b
        # tolerance: the closed form on a fine grid of A brackets the traced extremes to 1e-3 deg
        assert abs(row["B_min"] - b.min()) < 1e-3 and abs(row["B_max"] - b.max()) < 1e-3
        assert abs(row["A_max"] - 100.0) < 1e-9


def test_failed_point_keeps_its_row_with_the_reason(tmp_path):
    study = load_study(
        _write(tmp_path, 'linkage = "bennett"\n[trace]\nuntil = "A=100"\n[grid]\nalpha2 = [45, 75]\n')
    )
    rows = [row for row, _ in run_sweep(study, workers=0)]
    assert "twists must differ" in rows[0]["error"]  # alpha1 = alpha2 = 45 deg is a parallelogram
    assert rows[1]["error"] == "" and rows[1]["mobility"] == 1


def test_robustness_columns_per_grid_point(tmp_path):
    study = load_study(
        _write(
            tmp_path,
            """
linkage = "bennett"
[trace]
until = "A=100"
steps = 10
[grid]
scale = [1.0, 2.0]
[robustness]
samples = 30
hinge_position_tol = 1e-4
hinge_direction_tol = 0.0
seed = 2
""",
        )
    )
    rows = [row for row, _ in run_sweep(study, workers=0)]
    assert rows[0]["misfit_p50"] > 0 and rows[0]["mobility_kept"] == 0.0
    # The same position errors on a linkage twice the size: the same absolute misfit (no direction errors,
    # misfit is translation-like), up to second-order terms of relative size tol / L = 1e-4.
    assert abs(rows[1]["misfit_p50"] / rows[0]["misfit_p50"] - 1.0) < 1e-3


@pytest.mark.parametrize(
    ("text", "key"),
    [
        ('linkage = "bennett"\nspec = "x.toml"\n', "exactly one"),
        ('linkage = "bennett"\n[grid]\nalpha1 = []\n', "grid.alpha1"),
        ('linkage = "bennett"\n[grid]\nalpha1 = { from = 1, to = 2 }\n', "grid.alpha1"),
        ('linkage = "bennett"\n[trace]\nuntil = "A"\n', "trace.until"),
        ('linkage = "bennett"\n[trace]\nspeed = 1\n', "trace.speed"),
        ('problem = "seat"\n[grid]\nalpha1 = [1]\n', "grid.alpha1"),
        ('linkage = "bennett"\n[robustness]\nsamples = 3\n', "robustness.hinge_position_tol"),
    ],
)
def test_bad_study_files_say_which_key(tmp_path, text, key):
    with pytest.raises(SpecError, match=key.replace(".", r"\.")):
        load_study(_write(tmp_path, text))


def test_synthesis_grid_matches_direct_runs(tmp_path):
    from linkwork import data
    from linkwork.io.problem import load_problem
    from linkwork.synthesis import synthesize

    study = load_study(
        _write(tmp_path, 'problem = "closed"\n[grid]\npiece_length = [0.1, 0.12]\nstarts = [1]\n')
    )
    rows = [row for row, _ in run_sweep(study, workers=0)]
    assert len(rows) == 2
    base = load_problem(data.example("closed"))
    for row in rows:
        assert row["error"] == ""
        direct = synthesize(replace(base, piece_length=row["piece_length"], starts=1))
        assert row["design"] == direct.design and row["e_max"] == pytest.approx(direct.e_max, rel=1e-12)


def test_design_search_one_task_per_design_matches_auto(tmp_path):
    """``design = "each"``: every design vector of 3 segments as its own task; the best row is what the
    built-in search (``design = "auto"``, same seeds per design) chooses."""
    from linkwork import data
    from linkwork.io.problem import load_problem
    from linkwork.studies.sweep import prepare_study
    from linkwork.synthesis import synthesize

    study = prepare_study(
        load_study(
            _write(tmp_path, 'problem = "closed"\n[grid]\nsegments = [3]\ndesign = "each"\nstarts = [1]\n')
        )
    )
    rows = [row for row, _ in run_sweep(study, workers=0)]
    assert [row["design"] for row in rows] == ["MMM", "MMC", "MCM", "MCC", "CMM", "CMC", "CCM", "CCC"]
    ok = [row for row in rows if not row["error"]]
    assert "MMM" in [
        row["design"] for row in rows if row["error"]
    ]  # no C-segment: infeasible, with its reason
    auto = synthesize(replace(load_problem(data.example("closed")), design=None, segments=3, starts=1))
    best = min(ok, key=lambda row: (row["e_max"], row["e_mean"]))
    assert best["design"] == auto.design and best["e_max"] == pytest.approx(auto.e_max, rel=1e-12)


def test_spec_file_study_is_one_point(tmp_path):
    spec = Path(__file__).resolve().parents[2] / "examples" / "specs" / "four-bar.toml"
    study = load_study(_write(tmp_path, f'spec = "{spec}"\n[trace]\nuntil = "A=100"\nsteps = 11\n'))
    [(row, _)] = run_sweep(study, workers=0)
    assert row["error"] == "" and row["mobility"] == 1 and row["points"] == 12
    assert row["A_min"] == pytest.approx(45.0) and row["A_max"] == pytest.approx(100.0)
