"""Properties of the file readers over generated hostile input (hypothesis, fixed seed): a spec, a problem or a
profile file either reads into a sound value or raises one :class:`~linkwork.errors.LinkworkError` whose
message is one line naming the file; nothing else escapes, nothing hangs."""

from __future__ import annotations

import json
import math
from pathlib import Path

import ezdxf
import numpy as np
from fuzzkit import FUZZ, HOSTILE_TEXT, one_line_error
from hypothesis import given
from hypothesis import strategies as st

from linkwork.errors import LinkworkError
from linkwork.io.problem import load_problem
from linkwork.io.profiles import MAX_COORDINATE, load_profile, save_profile
from linkwork.io.spec import dump_spec, load_spec
from linkwork.linkages.bennett import bennett


def toml_string(text: str) -> str:
    """``text`` as a TOML basic string (json escapes are valid TOML escapes, but for \\/ which JSON avoids)."""
    return json.dumps(text, ensure_ascii=True)


def toml_float(x: float) -> str:
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return repr(x)


scalars = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(toml_float),
    st.integers(min_value=-(10**30), max_value=10**30).map(str),
    st.sampled_from(HOSTILE_TEXT).map(toml_string),
    st.text(max_size=30).map(toml_string),
    st.booleans().map(lambda b: "true" if b else "false"),
    st.just("{}"),
    st.just("{ a = 1 }"),
)
values = st.recursive(
    scalars, lambda inner: st.lists(inner, max_size=4).map(lambda v: "[" + ", ".join(v) + "]"), max_leaves=8
)

SPEC_LINES = dump_spec(bennett()).splitlines()
SPEC_KEYS = [i for i, line in enumerate(SPEC_LINES) if " = " in line and not line.startswith("#")]

#: A planar [mechanism] spec: a four-bar (A and C coupled) with a slider on the rocker.
MECHANISM_LINES = """name = "four-bar"
[mechanism]
planar = true
couple = [["A", "C"]]
fixed = []

[[mechanism.joints]]
name = "A"
type = "R"
bodies = ["ground", "crank"]
point = [0.0, 0.0]

[[mechanism.joints]]
name = "B"
bodies = ["crank", "coupler"]
point = [1.0, 0.0]

[[mechanism.joints]]
name = "C"
bodies = ["coupler", "rocker"]
point = [1.0, 1.0]

[[mechanism.joints]]
name = "D"
bodies = ["rocker", "ground"]
point = [0.0, 1.0]
direction = [0.0, 0.0, 1.0]

[[mechanism.joints]]
name = "E"
type = "P"
bodies = ["rocker", "slider"]
point = [0.0, 1.0]
direction = [1.0, 0.0]
value = 0.5
""".splitlines()
MECHANISM_KEYS = [i for i, line in enumerate(MECHANISM_LINES) if " = " in line]


@FUZZ
@given(edits=st.lists(st.tuples(st.sampled_from(MECHANISM_KEYS), values), min_size=1, max_size=3))
def test_mechanism_spec_reader_reads_or_says_one_line(tmp_path_factory, edits) -> None:  # type: ignore[no-untyped-def]
    lines = list(MECHANISM_LINES)
    for index, value in edits:
        key = lines[index].split(" = ")[0]
        lines[index] = f"{key} = {value}"
    file = tmp_path_factory.mktemp("mechanism") / "fuzz.toml"
    file.write_text("\n".join(lines) + "\n", encoding="utf-8")
    message = one_line_error(lambda: load_spec(file), (LinkworkError,))
    if message is not None:
        assert message.startswith(str(file))
    else:
        mech = load_spec(file).mechanism
        assert np.all(np.isfinite(mech.twists)) and np.all(np.isfinite(mech.offsets))


@FUZZ
@given(edits=st.lists(st.tuples(st.sampled_from(SPEC_KEYS), values), min_size=1, max_size=3),
       extra=st.one_of(st.none(), st.tuples(st.sampled_from(["", "loop", "loop.joints"]), st.text(min_size=1, max_size=12), values)))  # fmt: skip
def test_spec_reader_reads_or_says_one_line(tmp_path_factory, edits, extra) -> None:  # type: ignore[no-untyped-def]
    lines = list(SPEC_LINES)
    for index, value in edits:
        key = lines[index].split(" = ")[0]
        lines[index] = f"{key} = {value}"
    if extra is not None:
        table, key, value = extra
        line = f"{toml_string(key)} = {value}"
        at = {"": 5, "loop": lines.index("[loop]") + 1, "loop.joints": lines.index("[[loop.joints]]") + 1}[
            table
        ]
        lines.insert(at, line)
    file = tmp_path_factory.mktemp("spec") / "fuzz.toml"
    file.write_text("\n".join(lines) + "\n", encoding="utf-8")
    message = one_line_error(lambda: load_spec(file), (LinkworkError,))
    if message is not None:
        assert message.startswith(str(file))
    else:
        mech = load_spec(file).mechanism
        assert np.all(np.isfinite(mech.twists)) and np.all(np.isfinite(mech.offsets))


PROBLEM = {
    "type": '"open"',
    "profiles": '["a.csv", "b.csv"]',
    "piece_length": "0.2",
    "min_pieces": "2",
    "design": '"MC"',
    "starts": "1",
    "merge_below": "5",
    "seed": "3",
    "names": '["a", "b"]',
    "mechanize": "false",
    "segments": "2",
}


@FUZZ
@given(edits=st.dictionaries(st.sampled_from(sorted(PROBLEM)), values, min_size=1, max_size=3),
       dropped=st.sets(st.sampled_from(sorted(PROBLEM)), max_size=2))  # fmt: skip
def test_problem_reader_reads_or_says_one_line(tmp_path_factory, edits, dropped) -> None:  # type: ignore[no-untyped-def]
    folder = tmp_path_factory.mktemp("problem")
    t = np.linspace(0.0, 1.0, 30)
    save_profile(folder / "a.csv", np.column_stack([t, 0.2 * t**2]))
    save_profile(folder / "b.csv", np.column_stack([1.2 * t, 0.3 * t**2]))
    settings = {k: v for k, v in {**PROBLEM, **edits}.items() if k not in dropped}
    file = folder / "problem.toml"
    file.write_text("".join(f"{k} = {v}\n" for k, v in settings.items()), encoding="utf-8")
    message = one_line_error(lambda: load_problem(file), (LinkworkError,))
    if message is None:
        problem = load_problem(file)
        assert problem.starts >= 1 and problem.piece_length > 0 and len(problem.profiles) >= 2
    else:
        assert message.startswith(str(file))


numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.floats(min_value=-10.0, max_value=10.0),
    st.sampled_from([0.0, 1e-300, 1e300, -1e308, 1e12, 1e13]),
)


@FUZZ
@given(rows=st.lists(st.tuples(numbers, numbers), min_size=0, max_size=12),
       junk=st.one_of(st.none(), st.sampled_from(HOSTILE_TEXT)))  # fmt: skip
def test_csv_and_dat_profiles_read_or_say_one_line(tmp_path_factory, rows, junk) -> None:  # type: ignore[no-untyped-def]
    folder = tmp_path_factory.mktemp("profile")
    body = [f"{x!r},{y!r}" for x, y in rows] + ([junk] if junk else [])
    (folder / "p.csv").write_text("x,y\n" + "\n".join(body) + "\n", encoding="utf-8")
    (folder / "p.dat").write_text(
        "name\n" + "\n".join(b.replace(",", " ") for b in body) + "\n", encoding="utf-8"
    )
    for file in (folder / "p.csv", folder / "p.dat"):
        _reads_or_one_line(file)


commands = st.tuples(
    st.sampled_from("MLHVCSQTAZmlhvcsqtaz"), st.lists(numbers.map(lambda v: f"{v:.17g}"), max_size=7)
)


@FUZZ
@given(path=st.lists(commands, min_size=1, max_size=6),
       transform=st.one_of(st.none(), st.sampled_from(["scale(1e308)", "rotate(1e300)", "matrix(0 0 0 0 0 0)",
                                                       "translate(nan)", "scale(1e-308)", "skewX(90)"])))  # fmt: skip
def test_svg_profiles_read_or_say_one_line(tmp_path_factory, path, transform) -> None:  # type: ignore[no-untyped-def]
    d = "M 0 0 " + " ".join(f"{c} {' '.join(args)}" for c, args in path)
    attr = f' transform="{transform}"' if transform else ""
    file = tmp_path_factory.mktemp("svg") / "p.svg"
    file.write_text(f'<svg xmlns="http://www.w3.org/2000/svg"><path{attr} d="{d}"/></svg>', encoding="utf-8")
    _reads_or_one_line(file)


@FUZZ
@given(vertices=st.lists(st.tuples(numbers, numbers, numbers), min_size=0, max_size=6), closed=st.booleans())
def test_dxf_profiles_read_or_say_one_line(tmp_path_factory, vertices, closed) -> None:  # type: ignore[no-untyped-def]
    document = ezdxf.new("R2010")
    document.modelspace().add_lwpolyline(vertices, format="xyb", close=closed)
    file = tmp_path_factory.mktemp("dxf") / "p.dxf"
    try:
        document.saveas(str(file))
    except (ValueError, OverflowError):
        return  # ezdxf itself cannot write this drawing
    _reads_or_one_line(file)


def _reads_or_one_line(file: Path) -> None:
    message = one_line_error(lambda: load_profile(file), (LinkworkError,))
    if message is None:
        points = load_profile(file)
        assert points.shape[1] == 2 and len(points) >= 2
        assert np.all(np.isfinite(points)) and np.abs(points).max() <= MAX_COORDINATE
    else:
        assert message.startswith(str(file))


anything = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**20), max_value=10**20),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(HOSTILE_TEXT),
    st.sampled_from(["auto", "MC", "mc", "open", "closed", "chain", "joints", "targets", "error"]),
)


@FUZZ
@given(settings=st.dictionaries(
    st.sampled_from(["kind", "piece_length", "min_pieces", "design", "segments", "starts", "merge_below", "seed",
                     "merge_on", "rank_by", "e_max_tolerance"]), anything, max_size=4))  # fmt: skip
def test_problem_built_in_a_script_is_sound_or_one_line(settings: dict) -> None:  # type: ignore[type-arg]
    """Problem validates itself: any settings give a Problem whose rules hold, or one SpecError line."""
    from linkwork.synthesis import Problem

    profiles = (np.array([[0.0, 0.0], [3.0, 0.0]]), np.array([[0.0, 0.0], [4.0, 1.0]]))
    base = {"piece_length": 0.3, "design": "MC"}
    message = one_line_error(lambda: Problem(profiles=profiles, **{**base, **settings}), (LinkworkError,))
    if message is None:
        problem = Problem(profiles=profiles, **{**base, **settings})
        assert problem.piece_length > 0 and 1 <= problem.starts <= 1000 and problem.min_pieces >= 2
        assert not isinstance(problem.piece_length, bool) and not isinstance(problem.merge_below, bool)
