"""Synthesis problem files: a good file becomes a Problem in API units; every mistake is one line naming the
file and the key."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from linkwork.errors import SpecError
from linkwork.io.problem import load_problem
from linkwork.io.profiles import save_profile
from linkwork.synthesis.problem import MAX_PIECES, Problem

GOOD = """
type = "open"
profiles = ["a.csv", "sub/b.csv"]
piece_length = 0.25
min_pieces = 3
design = "mcm"
starts = 2
merge_below = 30
seed = 7
"""


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    x = np.linspace(0.0, 3.0, 31)
    save_profile(tmp_path / "a.csv", np.column_stack([x, 0.1 * x**2]))
    (tmp_path / "sub").mkdir()
    save_profile(tmp_path / "sub" / "b.csv", np.column_stack([1.3 * x, 0.2 * x**2]))
    t = np.linspace(0.0, 2.0 * math.pi, 41)
    ring = np.column_stack([np.cos(t), np.sin(t)])
    ring[-1] = ring[0]
    save_profile(tmp_path / "ring.csv", ring)
    save_profile(tmp_path / "open_ring.csv", ring[:-1])
    return tmp_path


def write(folder: Path, text: str) -> Path:
    path = folder / "problem.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_good_problem_in_api_units(folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = write(folder, GOOD)
    monkeypatch.chdir("/")  # profiles resolve relative to the problem file, not the working folder
    problem = load_problem(path)
    assert problem.kind == "open"
    assert problem.count == 2
    assert problem.profiles[0].shape == (31, 2)
    np.testing.assert_allclose(problem.profiles[1][-1], [3.9, 1.8], rtol=0, atol=1e-12)
    assert problem.piece_length == 0.25
    assert problem.min_pieces == 3
    assert problem.design == "MCM"  # letters upper-cased
    assert problem.segments == 3
    assert problem.starts == 2
    assert problem.merge_below == pytest.approx(math.pi / 6, abs=1e-15)  # degrees in the file, radians inside
    assert problem.seed == 7
    assert problem.names == ("a", "b")  # file stems by default
    assert problem.source == path
    assert problem.mechanize is False


def test_auto_design_and_names(folder: Path) -> None:
    text = GOOD.replace('design = "mcm"', 'design = "auto"\nsegments = 4\nnames = ["cruise", "landing"]')
    problem = load_problem(write(folder, text))
    assert problem.design is None
    assert problem.segments == 4
    assert problem.names == ("cruise", "landing")


def test_closed_problem_accepts_closed_curves(folder: Path) -> None:
    text = GOOD.replace('type = "open"', 'type = "closed"').replace(
        '"a.csv", "sub/b.csv"', '"ring.csv", "ring.csv"'
    )
    text = text.replace("seed = 7", 'seed = 7\nnames = ["one", "two"]')
    problem = load_problem(write(folder, text))
    np.testing.assert_array_equal(problem.profiles[0][0], problem.profiles[0][-1])


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        (
            "piece_length = 0.25",
            'piece_length = "abc"',
            'piece_length: expected a positive number, got "abc"',
        ),
        ("piece_length = 0.25", "piece_length = -1", "piece_length: expected a positive number, got -1"),
        ("piece_length = 0.25", "piece_length = 0", "piece_length: expected a positive number, got 0"),
        ("piece_length = 0.25", "piece_length = true", "piece_length: expected a positive number, got true"),
        ("piece_length = 0.25", "piece_length = nan", "piece_length: expected a positive number, got nan"),
        ("piece_length = 0.25", "", "piece_length: missing; expected a positive number"),
        ("seed = 7", "seed = 7\ncolour = 'red'", "colour: unknown key; expected one of type, profiles"),
        (
            'type = "open"',
            'type = "spiral"',
            'type: expected one of "open", "closed", "fixed-end", got "spiral"',
        ),
        (
            'design = "mcm"',
            'design = "MXC"',
            'design: expected a design vector of M and C letters such as "MCMC"',
        ),
        ('design = "mcm"', "design = 5", "design: expected a design vector of M and C letters"),
        ('design = "mcm"', "", "design: missing; expected a design vector"),
        (
            'design = "mcm"',
            'design = "auto"',
            'segments: missing; design = "auto" needs the number of segments',
        ),
        ('design = "mcm"', 'design = "MCM"\nsegments = 4', 'segments: is 4 but design "MCM" has 3 segments'),
        (
            'design = "mcm"',
            'design = "auto"\nsegments = 0',
            "segments: expected a whole number of segments >= 1",
        ),
        ("min_pieces = 3", "min_pieces = 1.5", "min_pieces: expected a whole number of pieces >= 2"),
        ("min_pieces = 3", "min_pieces = 1", "min_pieces: expected a whole number of pieces >= 2"),
        ("starts = 2", "starts = 0", "starts: expected a whole number of starts, 1 <= starts <= 1000, got 0"),
        (
            "merge_below = 30",
            "merge_below = 200",
            "merge_below: expected an angle in degrees, 0 <= merge_below < 180",
        ),
        ("merge_below = 30", "merge_below = -1", "merge_below: expected an angle in degrees"),
        (
            "merge_below = 30",
            'merge_below = "5"',
            'merge_below: expected an angle in degrees, 0 <= merge_below < 180, got "5"',
        ),
        ("seed = 7", "seed = -1", "seed: expected a whole number >= 0, got -1"),
        ("seed = 7", 'seed = 7\nmechanize = "yes"', 'mechanize: expected true or false, got "yes"'),
        (
            "seed = 7",
            'seed = 7\nnames = ["one"]',
            "names: lists 1 names for 2 profiles; expected one per profile",
        ),
        ("seed = 7", 'seed = 7\nnames = ["one", "one"]', 'names: repeats "one" (names[0] and names[1])'),
        ("seed = 7", 'seed = 7\nnames = ["one", 2]', "names[1]: expected a list of 2 non-empty names, got 2"),
        ('"a.csv", "sub/b.csv"', '"a.csv"', "profiles: lists 1 profile(s); expected at least 2 profiles"),
        (
            'profiles = ["a.csv", "sub/b.csv"]',
            'profiles = "a.csv"',
            'profiles: expected a list of at least 2 profile files, got "a.csv"',
        ),
        ('"a.csv", "sub/b.csv"', '"a.csv", "gone.csv"', 'profiles[1]: file "'),
        ("seed = 7", "seed = 7\n[extra]\nkey = 1", "extra: unknown key"),
        ('type = "open"', 'type = "open', "invalid TOML"),
    ],
)
def test_bad_key_is_one_line_naming_file_and_key(folder: Path, old: str, new: str, expected: str) -> None:
    assert old in GOOD
    path = write(folder, GOOD.replace(old, new))
    with pytest.raises(SpecError) as info:
        load_problem(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: ")
    assert expected in message


def test_the_message_of_the_design_notes(folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(folder)
    write(folder, GOOD.replace("piece_length = 0.25", 'piece_length = "abc"'))
    with pytest.raises(SpecError) as info:
        load_problem("problem.toml")
    assert str(info.value) == 'problem.toml: piece_length: expected a positive number, got "abc"'
    assert (info.value.source, info.value.key) == ("problem.toml", "piece_length")


def test_missing_profile_names_the_file(folder: Path) -> None:
    path = write(folder, GOOD.replace('"sub/b.csv"', '"sub/gone.csv"'))
    with pytest.raises(SpecError, match=r"profiles\[1\]: file \".*sub/gone.csv\" not found"):
        load_problem(path)


def test_bad_profile_content_names_the_profile_file(folder: Path) -> None:
    (folder / "a.csv").write_text("x,y\n0,0\n", encoding="utf-8")
    with pytest.raises(SpecError) as info:
        load_problem(write(folder, GOOD))
    assert (
        str(info.value) == f"{folder / 'a.csv'}: a single point (0, 0); expected a curve of at least 2 points"
    )


def test_closed_problem_refuses_an_open_curve(folder: Path) -> None:
    text = GOOD.replace('type = "open"', 'type = "closed"').replace(
        '"a.csv", "sub/b.csv"', '"ring.csv", "open_ring.csv"'
    )
    with pytest.raises(SpecError, match=r'profiles\[1\]: "open_ring.csv" does not return to its first point'):
        load_problem(write(folder, text))


def test_missing_or_unreadable_problem_file(tmp_path: Path) -> None:
    with pytest.raises(SpecError, match=r"gone.toml: file not found; expected a problem file \(TOML\)$"):
        load_problem(tmp_path / "gone.toml")
    with pytest.raises(SpecError, match=r"is a folder; expected a problem file"):
        load_problem(tmp_path)
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"\xff\xfe\x81 = 1")
    with pytest.raises(SpecError, match=r"binary.toml: "):
        load_problem(binary)


@pytest.mark.parametrize(
    ("line", "settings"),
    [
        ("starts = 0", {"starts": 0}),
        ("starts = 1000000000", {"starts": 10**9}),
        ("min_pieces = 1", {"min_pieces": 1}),
        ("piece_length = -2", {"piece_length": -2}),
        ('type = "spiral"', {"kind": "spiral"}),
        ("seed = -1", {"seed": -1}),
        ("merge_below = 200", {"merge_below": math.radians(200)}),
        ('design = "auto"\nsegments = 50', {"design": None, "segments": 50}),
        ('design = "MXC"', {"design": "MXC"}),
    ],
)
def test_problem_validates_itself_with_the_file_readers_words(
    folder: Path, line: str, settings: dict[str, object]
) -> None:
    """A Problem built in a script and a problem file with the same mistake give the same message."""
    key = line.split(" ")[0]
    text = "\n".join(row for row in GOOD.splitlines() if not row.startswith(key) and "design" not in row)
    path = write(folder, text + "\n" + (line if "design" in line else line + '\ndesign = "mcm"'))
    with pytest.raises(SpecError) as from_file:
        load_problem(path)
    good = {"piece_length": 0.25, "min_pieces": 3, "design": "mcm", "starts": 2, "seed": 7}
    profile = np.array([[0.0, 0.0], [3.0, 0.0]])
    with pytest.raises(SpecError) as from_api:
        Problem(profiles=(profile, profile), source=path, **{**good, **settings})  # type: ignore[arg-type]
    assert str(from_api.value) == str(from_file.value)
    assert "\n" not in str(from_file.value)


def test_piece_length_limit_relative_to_the_profile(folder: Path) -> None:
    """The smallest piece length is the longest profile's arc length / MAX_PIECES; profile b is
    (1.3 x, 0.2 x^2), x in [0, 3], of arc length int_0^3 sqrt(1.69 + 0.16 x^2) dx (a 31-point polyline of it
    is shorter by less than 1e-3 relative)."""
    x = np.linspace(0.0, 3.0, 300001)
    arc = float(np.trapezoid(np.sqrt(1.69 + 0.16 * x**2), x))
    with pytest.raises(SpecError) as info:
        load_problem(write(folder, GOOD.replace("piece_length = 0.25", "piece_length = 0.001")))
    bound = float(str(info.value).split("piece_length >= ")[1].split(",")[0])
    assert bound == pytest.approx(arc / MAX_PIECES, rel=1e-3)
    assert str(info.value).endswith("got 0.001")
    ok = GOOD.replace("piece_length = 0.25", f"piece_length = {1.01 * arc / MAX_PIECES}")
    assert load_problem(write(folder, ok)).piece_length > 0


def test_one_reader_for_both_file_kinds_hints_at_a_mistyped_key(folder: Path, tmp_path: Path) -> None:
    """The problem file and the spec file share one reader: the same did-you-mean hint and value quoting."""
    from linkwork.io.spec import load_spec

    path = write(folder, GOOD.replace("piece_length = 0.25", "piece_lenght = 0.25"))
    with pytest.raises(SpecError) as problem_error:
        load_problem(path)
    assert str(problem_error.value).startswith(
        f'{path}: piece_lenght: unknown key; did you mean "piece_length"?'
    )
    spec = tmp_path / "spec.toml"
    spec.write_text('nmae = "x"\n', encoding="utf-8")
    with pytest.raises(SpecError) as spec_error:
        load_spec(spec)
    assert str(spec_error.value).startswith(f'{spec}: nmae: unknown key; did you mean "name"?')


def test_the_search_is_bounded_by_a_stated_budget(folder: Path) -> None:
    """design "auto" with 12 segments tries 2**12 = 4096 design vectors: 100 starts each is 409600 searches."""
    text = GOOD.replace('design = "mcm"', 'design = "auto"\nsegments = 12').replace(
        "starts = 2", "starts = 100"
    )
    with pytest.raises(SpecError) as info:
        load_problem(write(folder, text))
    assert str(info.value).endswith(
        'starts: design "auto" with segments = 12 and starts = 100 is 409600 searches of the segment matrix; '
        "expected at most 100000 (fewer segments or starts)"
    )
