"""Hostile inputs whose failure lay outside the red team's layers (session 13), fixed in the layer that owns each
(they were strict xfails; each docstring or comment says what happened before):

- ``lw.trace`` with NaN, infinity, ``None``, a string, a bool or a wrong shape for a setting gave an internal
  ``ValueError``/``TypeError``/``IndexError``, a ``RuntimeWarning``, or a trace with a step of 0 or -1; now one
  :class:`~linkwork.errors.SpecError` naming the argument (``kinematics.trace_arguments``).
- ``lw.trace(mech, max_step=nan)`` never returned (run here in a child process with a deadline).
- ``--set KEY=1 --set KEY=2`` kept the last silently; ``--out ''`` wrote into the working folder.
- a study whose ``trace.until`` names a joint the linkage does not have ran every grid point, then exit 3.
- an infeasible problem's line did not name the problem file; a problem's ``dof`` and ``ground_region`` were not
  bounded like their flags; profile names went raw into CSV cells (a formula in a spreadsheet).
- ``export dxf TRACE --set`` ignored ``--set``; ``mechanize --problem`` said the designs differed when only E_max
  did; a Bennett linkage at scale 1e5 (its bound 1e6) was refused as not closing (an absolute tolerance).
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fuzzkit import run_cli

import linkwork as lw
from linkwork.io.profiles import save_profile


@pytest.fixture(scope="module")
def bennett() -> lw.Mechanism:
    return lw.load("bennett")


TRACE_ARGUMENTS: dict[str, dict[str, Any]] = {
    "until-nan": {"until": ("A", math.nan), "steps": 10},
    "until-inf": {"until": ("A", math.inf), "steps": 10},
    "until-None": {"until": ("A", None), "steps": 10},
    "until-one-item": {"until": ("A",), "steps": 10},
    "until-array": {"until": ("A", np.array([1.0])), "steps": 10},
    "steps-nan": {"steps": math.nan, "until": ("A", 1.0)},
    "max_step-None": {"max_step": None, "max_steps": 20},
    "max_step-str": {"max_step": "0.1", "max_steps": 20},
    "max_step-zero": {"max_step": 0.0, "max_steps": 20},
    "max_step-negative": {"max_step": -1.0, "max_steps": 20},
    "max_steps-float": {"max_steps": 20.5},
    "max_steps-None": {"max_steps": None},
    "max_steps-inf": {"max_steps": math.inf},
    "limits-None": {"limits": {"A": None}, "max_steps": 20},
    "limits-list": {"limits": [("A", (0.0, 1.0))], "max_steps": 20},
    "limits-three": {"limits": {"A": (0.0, 1.0, 2.0)}, "max_steps": 20},
}


@pytest.mark.parametrize("arguments", list(TRACE_ARGUMENTS.values()), ids=list(TRACE_ARGUMENTS))
def test_trace_settings_that_are_not_numbers_are_one_spec_error(
    bennett: lw.Mechanism, arguments: dict[str, Any]
) -> None:
    import warnings

    name = next(iter(arguments))  # the argument each case makes hostile comes first
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(lw.SpecError) as info:
            lw.trace(bennett, **arguments)
    assert name in str(info.value)


def test_a_nan_step_is_refused_not_a_hang() -> None:
    script = textwrap.dedent(
        """
        import math, linkwork as lw
        try:
            lw.trace(lw.load("bennett"), max_step=math.nan, max_steps=20)
        except lw.SpecError as exc:
            print("refused:", exc)
        """
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    try:
        done = subprocess.run(
            [sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=30, check=False
        )
    except subprocess.TimeoutExpired:
        pytest.fail("lw.trace(max_step=nan) did not return within 30 s")
    assert done.stdout.startswith("refused:"), done.stdout + done.stderr


def test_a_set_key_given_twice_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    run = run_cli(["show", "bennett", "--set", "alpha1=45", "--set", "alpha1=60"], home=tmp_path)
    assert run.code == 2
    assert "alpha1" in run.stderr and "twice" in run.stderr


def test_a_study_until_an_unknown_joint_is_bad_input(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    Path("study.toml").write_text(
        'linkage = "bennett"\n[trace]\nuntil = "Q=90"\nsteps = 5\n[grid]\nalpha1 = [30, 40]\n',
        encoding="utf-8",
    )
    run = run_cli(["sweep", "study.toml", "-o", "out", "--workers", "0", "--no-plots"], home=tmp_path)
    assert run.code == 2, run
    assert not (tmp_path / "out").exists()


def test_an_infeasible_problem_names_its_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    t = np.linspace(0.0, 1.0, 30)
    save_profile(tmp_path / "a.csv", np.column_stack([t, 0.2 * t**2]))
    save_profile(tmp_path / "b.csv", np.column_stack([1.2 * t, 0.3 * t**2]))
    Path("problem.toml").write_text(
        'profiles = ["a.csv", "b.csv"]\npiece_length = 0.1\ndesign = "MC"\nmin_pieces = 1000\n',
        encoding="utf-8",
    )
    run = run_cli(["synth", "problem.toml", "-o", "out", "--no-plots"], home=tmp_path)
    assert run.code == 2
    assert run.stderr.startswith("error: problem.toml: min_pieces: "), run.stderr


def test_an_empty_out_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "notes.txt").write_text("the user's\n", encoding="utf-8")
    run = run_cli(["trace", "bennett", "--out", "", "--no-plots", "--max-steps", "10"], home=None)
    assert run.code == 2, run
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]


@pytest.mark.parametrize(
    "line",
    [
        "dof = 1000000000000",
        "ground_region = [-1e300, -1e300, 1e300, 1e300]",
        "ground_region = [[0, 0], [1, 1], [1, 0], [0, 1]]",  # a bow tie: which side is inside?
    ],
)
def test_problem_mechanization_keys_have_the_bounds_of_their_flags(tmp_path: Path, line: str) -> None:
    from linkwork.io.problem import load_problem

    t = np.linspace(0.0, 1.0, 30)
    save_profile(tmp_path / "a.csv", np.column_stack([t, 0.2 * t**2]))
    save_profile(tmp_path / "b.csv", np.column_stack([1.2 * t, 0.3 * t**2]))
    file = tmp_path / "problem.toml"
    file.write_text(
        f'profiles = ["a.csv", "b.csv"]\npiece_length = 0.1\ndesign = "MC"\n{line}\n', encoding="utf-8"
    )
    with pytest.raises(lw.SpecError):
        load_problem(file)


def test_export_with_set_on_a_trace_folder_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    assert run_cli(["trace", "four-bar", "-o", "tr", "--no-plots", "--max-steps", "20"], home=None).code == 0
    run = run_cli(["export", "dxf", "tr", "-o", "x.dxf", "--set", "crank=5"], home=tmp_path)
    assert run.code == 2 and "--set" in run.stderr


def test_a_bennett_linkage_at_a_large_allowed_scale_moves_as_at_scale_one() -> None:
    reference = lw.trace(lw.load("bennett"), until=("A", math.radians(120)), steps=20)
    large = lw.trace(lw.load("bennett", scale=1e5), until=("A", math.radians(120)), steps=20)
    np.testing.assert_allclose(large.angles, reference.angles, rtol=0, atol=1e-9)


def test_profile_names_in_target_profiles_csv_never_start_a_formula(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import csv

    monkeypatch.chdir(tmp_path)
    t = np.linspace(0.0, 1.0, 30)
    save_profile(tmp_path / "a.csv", np.column_stack([t, 0.2 * t**2]))
    save_profile(tmp_path / "b.csv", np.column_stack([1.2 * t, 0.3 * t**2]))
    Path("problem.toml").write_text(
        'profiles = ["a.csv", "b.csv"]\npiece_length = 0.1\ndesign = "MC"\nstarts = 1\n'
        'names = ["=HYPERLINK(\\"http://example.invalid\\",\\"x\\")", "@SUM(1+1)"]\n',
        encoding="utf-8",
    )
    assert run_cli(["synth", "problem.toml", "-o", "out", "--no-plots"], home=None).code == 0
    with open(tmp_path / "out" / "target_profiles.csv", newline="", encoding="utf-8") as handle:
        cells = [row[0] for row in csv.reader(handle)][1:]
    assert cells and not any(cell[:1] in "=+-@\t\r" for cell in cells)


def test_mechanize_with_another_problem_says_what_differs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    t = np.linspace(0.0, 1.0, 40)
    for i, k in enumerate([0.2, 0.3, 0.4]):
        save_profile(tmp_path / f"p{i}.csv", np.column_stack([(1 + 0.1 * i) * t, k * t**2]))
    base = 'piece_length = 0.1\ndesign = "MC"\nstarts = 1\n'
    Path("three.toml").write_text('profiles = ["p0.csv", "p1.csv", "p2.csv"]\n' + base, encoding="utf-8")
    Path("two.toml").write_text('profiles = ["p0.csv", "p1.csv"]\n' + base, encoding="utf-8")
    assert run_cli(["synth", "three.toml", "-o", "s3", "--no-plots"], home=None).code == 0
    run = run_cli(
        ["mechanize", "s3", "--problem", "two.toml", "-o", "m", "--no-plots", "--time-limit", "3"], home=None
    )
    assert run.code == 2
    line = run.stderr
    designs = line.split("design ")[1:]
    assert "E_max" in line or "profile" in line or len({d.split(")")[0].strip('"') for d in designs}) > 1, (
        line
    )
