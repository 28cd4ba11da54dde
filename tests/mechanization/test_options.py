"""Mechanization options: the same keys in a problem file and as flags, checked, in file units (degrees)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from linkwork.data import example
from linkwork.errors import SpecError
from linkwork.io.problem import load_problem
from linkwork.mechanization import GroundRegion, MechanizeOptions, options_from_values
from linkwork.mechanization.options import OPTION_KEYS, parse_region_flag
from linkwork.outputs.mechanization import resolve_options

WING = example("wing").parent


def _problem(tmp_path: Path, extra: str) -> Path:
    for name in ("cruise.dat", "climb.dat", "landing.dat"):
        (tmp_path / name).write_text((WING / name).read_text())
    text = (WING / "mechanize.toml").read_text() + extra
    (tmp_path / "problem.toml").write_text(text)
    return tmp_path / "problem.toml"


def test_every_option_is_a_problem_key_in_file_units(tmp_path: Path) -> None:
    file = _problem(
        tmp_path,
        'dof = 2\ndrive = "J1"\nactuator = "prismatic"\nground_region = "inside"\nlink_offset = 0.5\n'
        'max_link = 0.8\nmin_transmission = 20.0\nanchors = "any"\nattempts = 3\ntime_limit = 12.5\n'
        'root = "s1"\nbinary_links = "both"\ndesigns = 2\nmax_structural_error = 0.002\n',
    )
    problem = load_problem(file)
    # max_link_fraction is the other way of giving max_link (not both)
    assert set(problem.mechanize_options) == set(OPTION_KEYS) - {"max_link_fraction"}
    options = resolve_options(problem)
    assert options.dof == 2 and options.drive == "J1" and options.actuator == "prismatic"
    assert options.ground_region == "inside" and options.anchors == "any" and options.root == "s1"
    assert options.link_offset == 0.5 and options.max_link == 0.8 and options.attempts == 3
    assert options.time_limit == 12.5 and options.binary_links == "both" and options.designs == 2
    assert options.max_structural_error == 0.002 and options.link_limit(5.0) == 0.8  # a length, any size
    assert abs(options.min_transmission - math.radians(20.0)) <= 1e-15  # degrees in the file, radians here


def test_flags_override_the_problem_keys(tmp_path: Path) -> None:
    problem = load_problem(_problem(tmp_path, "dof = 2\nmax_link = 0.8\n"))
    options = resolve_options(problem, {"dof": 1, "ground_region": parse_region_flag("0,0;1,0;1,1")})
    assert options.dof == 1 and options.max_link == 0.8
    assert np.array_equal(options.ground_region, [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])


@pytest.mark.parametrize(
    ("line", "key"),
    [
        ("dof = 0", "dof"),
        ('ground_region = "outside"', "ground_region"),
        ("ground_region = [1.0, 0.0, 0.0, 1.0]", "ground_region"),
        ("ground_region = [[0.0, 0.0], [1.0, 0.0]]", "ground_region"),
        ("min_transmission = 95.0", "min_transmission"),
        ('binary_links = "RR"', "binary_links"),
        ("time_limit = -1", "time_limit"),
    ],
)
def test_a_bad_key_names_the_file_and_the_key(tmp_path: Path, line: str, key: str) -> None:
    file = _problem(tmp_path, line + "\n")
    with pytest.raises(SpecError, match=f"problem.toml: {key}: ") as info:
        load_problem(file)
    assert "\n" not in str(info.value)


def test_max_link_is_a_length_and_max_link_fraction_a_multiple_of_the_largest_extent(tmp_path: Path) -> None:
    assert MechanizeOptions(max_link=0.8).link_limit(2.0) == 0.8
    assert MechanizeOptions(max_link_fraction=0.8).link_limit(2.0) == 1.6
    assert MechanizeOptions().link_limit(2.0) == 3.0  # the default: 1.5 times the largest extent
    with pytest.raises(SpecError, match=r"problem\.toml: max_link_fraction: give max_link"):
        load_problem(_problem(tmp_path, "max_link = 0.8\nmax_link_fraction = 0.5\n"))
    # a flag replaces the file's limit whichever way either is given
    problem = load_problem(_problem(tmp_path, "max_link = 0.8\n"))
    assert resolve_options(problem, {"max_link_fraction": 0.5}).link_limit(2.0) == 1.0
    problem = load_problem(_problem(tmp_path, "max_link_fraction = 0.5\n"))
    assert resolve_options(problem, {"max_link": 0.7}).link_limit(2.0) == 0.7


def test_a_bad_flag_names_the_flag() -> None:
    with pytest.raises(SpecError, match="--max-link: expected a positive length"):
        options_from_values({"max_link": -1.0}, flags=True)
    with pytest.raises(SpecError, match="--ground-region"):
        parse_region_flag("1,a")


def test_ground_regions_box_polygon_and_inside() -> None:
    square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0], [0.0, 0.0]])
    shifted = square + np.array([1.0, 0.0])
    inside = MechanizeOptions(ground_region="inside").region_of((square, shifted), 3.0)
    assert inside.contains([[1.5, 1.0], [0.5, 1.0], [2.5, 1.0]]).tolist() == [True, False, False]
    box = MechanizeOptions(ground_region=(0.0, 0.0, 1.0, 1.0)).region_of((square,), 2.0)
    assert box.contains([[0.5, 0.5], [1.5, 0.5]]).tolist() == [True, False]
    triangle = MechanizeOptions(ground_region=[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]).region_of((square,), 2.0)
    assert triangle.contains([[0.2, 0.2], [0.8, 0.8]]).tolist() == [True, False]
    samples = GroundRegion.inside((square, shifted)).samples(40)
    assert len(samples) > 0 and np.all((samples[:, 0] > 1.0) & (samples[:, 0] < 2.0))
