"""The profiles' names of a synthesis problem without a ``names`` key come from the file names: every way two
files would give one name (the same file name in two folders, the same stem with two extensions) is one line at
``profiles`` naming both files and what to do, never a message about a ``names`` key the file does not have; a
file name that makes a refused name is said of that file. Names are compared exactly (``Wing`` and ``wing`` are
two names), and what ignores case keeps them apart: the DXF layers and the copy of the problem a synth folder
holds."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from linkwork.cli import app
from linkwork.errors import SpecError
from linkwork.io.problem import load_problem
from linkwork.io.profiles import save_profile
from linkwork.names import MAX_NAME_CHARS
from linkwork.outputs.problem_copy import copy_names, copy_problem

SETTINGS = """
type = "open"
piece_length = 0.25
min_pieces = 3
design = "mcm"
starts = 2
merge_below = 0
seed = 7
"""


def profile(folder: Path, name: str, scale: float = 1.0) -> str:
    """Write a profile file ``name`` (relative to ``folder``, folders made) and return ``name``."""
    x = np.linspace(0.0, 3.0, 31)
    file = folder / name
    file.parent.mkdir(parents=True, exist_ok=True)
    save_profile(file, np.column_stack([scale * x, 0.1 * scale * x**2]))
    return name


def problem(folder: Path, files: list[str], extra: str = "") -> Path:
    path = folder / "problem.toml"
    listed = ", ".join(f'"{f}"' for f in files)
    path.write_text(f"profiles = [{listed}]\n{SETTINGS}{extra}", encoding="utf-8")
    return path


COLLIDING = {
    "two-folders": ["a/wing.csv", "b/wing.csv"],
    "two-extensions": ["wing.csv", "wing.dat"],
    "folder-and-extension": ["wing.csv", "b/wing.dat"],
    "third-repeats-first": ["wing.csv", "other.csv", "b/wing.csv"],
}


@pytest.mark.parametrize("case", sorted(COLLIDING))
def test_two_files_giving_one_name_are_named_at_profiles(tmp_path: Path, case: str) -> None:
    files = [profile(tmp_path, f, 1.0 + 0.1 * k) for k, f in enumerate(COLLIDING[case])]
    path = problem(tmp_path, files)
    with pytest.raises(SpecError) as info:
        load_problem(path)
    message = str(info.value)
    first, second = files[0], files[-1]
    assert info.value.key == "profiles"
    assert message.startswith(f"{path}: profiles: ")
    assert f'"{first}"' in message and f'"{second}"' in message
    assert 'would both be named "wing"' in message
    assert "distinct file names" in message and "names key" in message
    assert "repeats" not in message  # the old message, about a names key the file does not have


def test_the_command_line_says_the_same_in_one_line(tmp_path: Path) -> None:
    files = [profile(tmp_path, "a/wing.csv"), profile(tmp_path, "b/wing.csv", 1.2)]
    path = problem(tmp_path, files)
    result = CliRunner().invoke(app, ["synth", str(path), "--no-plots", "-o", str(tmp_path / "out")])
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and '"a/wing.csv"' in lines[0]
    assert "Traceback" not in result.stdout + result.stderr
    assert not (tmp_path / "out").exists()


def test_a_names_key_resolves_the_collision(tmp_path: Path) -> None:
    files = [profile(tmp_path, "a/wing.csv"), profile(tmp_path, "b/wing.csv", 1.2)]
    loaded = load_problem(problem(tmp_path, files, 'names = ["cruise", "climb"]\n'))
    assert loaded.names == ("cruise", "climb")


def test_names_that_differ_in_case_are_two_names(tmp_path: Path) -> None:
    files = [profile(tmp_path, "a/Wing.csv"), profile(tmp_path, "b/wing.csv", 1.2)]
    assert load_problem(problem(tmp_path, files)).names == ("Wing", "wing")


def test_a_repeated_name_in_the_names_key_names_both_entries(tmp_path: Path) -> None:
    files = [profile(tmp_path, "a.csv"), profile(tmp_path, "b.csv", 1.2), profile(tmp_path, "c.csv", 1.4)]
    with pytest.raises(SpecError) as info:
        load_problem(problem(tmp_path, files, 'names = ["one", "two", "one"]\n'))
    assert info.value.key == "names"
    assert 'repeats "one" (names[0] and names[2])' in str(info.value)


def test_a_file_name_making_a_refused_name_is_said_of_that_file(tmp_path: Path) -> None:
    long = "w" * (MAX_NAME_CHARS + 1) + ".csv"
    try:
        files = [profile(tmp_path, "a.csv"), profile(tmp_path, long, 1.2)]
    except OSError:  # a file system with shorter names than linkwork's limit
        pytest.skip("the file system refuses the long file name")
    with pytest.raises(SpecError) as info:
        load_problem(problem(tmp_path, files))
    assert info.value.key == "profiles[1]"
    message = str(info.value)
    assert "after its file" in message and "there is no names key" in message
    assert f"at most {MAX_NAME_CHARS} characters" in message


@pytest.mark.parametrize(
    ("profiles", "expected"),
    [
        (["wing.dat", "other.dat"], ["wing.dat", "other.dat"]),
        (["a/wing.dat", "b/wing.dat"], ["wing.dat", "2_wing.dat"]),
        (["a/Wing.dat", "b/wing.dat"], ["Wing.dat", "2_wing.dat"]),  # one file where case is ignored
        (["a/wing.dat", "b/2_wing.dat", "c/wing.dat"], ["wing.dat", "2_wing.dat", "3_wing.dat"]),
    ],
)
def test_the_copies_of_the_profiles_never_share_a_file_name(profiles: list[str], expected: list[str]) -> None:
    names = copy_names(profiles)
    assert names == expected
    assert len({n.casefold() for n in names}) == len(names)


def test_a_copied_problem_keeps_its_profiles_names(tmp_path: Path) -> None:
    """Profiles from other folders are copied beside the problem, renamed where two file names would be one on a
    file system that ignores case; the copy reads back with the same profiles' names."""
    source = tmp_path / "src"
    files = [profile(tmp_path, "a/Wing.csv"), profile(tmp_path, "b/wing.csv", 1.2)]
    source.mkdir()
    path = problem(source, [f"../{f}" for f in files])
    original = load_problem(path)
    copy_problem(path, tmp_path / "copy")
    copied = load_problem(tmp_path / "copy" / "problem.toml")
    assert copied.names == original.names == ("Wing", "wing")
    table = tomllib.loads((tmp_path / "copy" / "problem.toml").read_text(encoding="utf-8"))
    assert len({f.casefold() for f in table["profiles"]}) == 2
    for a, b in zip(original.profiles, copied.profiles, strict=True):
        np.testing.assert_array_equal(a, b)
    assert math.isclose(original.piece_length, copied.piece_length)
