"""The copy of a problem that `linkwork synth` keeps in OUT/problem/: it loads to the same problem."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

from linkwork.io.problem import load_problem
from linkwork.outputs.problem_copy import copy_problem

WING = Path(__file__).resolve().parents[2] / "examples" / "wing"


def test_profiles_outside_the_problem_folder_are_copied_next_to_it(tmp_path: Path) -> None:
    shutil.copytree(WING, tmp_path / "shapes")
    (tmp_path / "run").mkdir()
    text = (WING / "mechanize.toml").read_text()
    for name in ("cruise.dat", "climb.dat", "landing.dat"):
        text = text.replace(f'"{name}"', f'"../shapes/{name}"')
    problem = tmp_path / "run" / "problem.toml"
    problem.write_text(text + "ground_region = [[0.1, -0.02], [0.6, -0.02], [0.6, 0.04]]\n")
    written = copy_problem(problem, tmp_path / "copy")
    assert {p.name for p in written} == {"problem.toml", "cruise.dat", "climb.dat", "landing.dat"}
    original, copy = load_problem(problem), load_problem(tmp_path / "copy" / "problem.toml")
    for a, b in zip(original.profiles, copy.profiles, strict=True):
        assert np.array_equal(a, b)
    assert copy.design == original.design and copy.mechanize == original.mechanize
    assert copy.mechanize_options == original.mechanize_options


def test_plain_relative_profiles_keep_the_problem_file_as_written(tmp_path: Path) -> None:
    written = copy_problem(WING / "mechanize.toml", tmp_path / "copy")
    assert written[0].read_text() == (WING / "mechanize.toml").read_text()  # comments kept
    assert load_problem(written[0]).design == "MCMC"
