"""Names equal but for Unicode normalisation are one name (``linkwork.names.canonical``, NFC).

"é" typed as one character (U+00E9) and as "e" with a combining accent (U+0301) look the same on every screen;
a user who writes one in a spec file and the other in a flag, or both in one file, means one joint or body. The
reference is :func:`unicodedata.normalize` and the strings themselves, written out code point by code point here.
"""

from __future__ import annotations

import json
import unicodedata
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import linkwork as lw
from linkwork.cli import app
from linkwork.errors import SpecError
from linkwork.io.problem import load_problem
from linkwork.io.profiles import save_profile
from linkwork.names import canonical

COMPOSED = "\u00e9"  # é, one code point
DECOMPOSED = "e\u0301"  # e + combining acute accent
BAR_COMPOSED = "b\u00e2r"  # bâr
BAR_DECOMPOSED = "ba\u0302r"


EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "specs" / "four-bar.toml"


def four_bar(joint_b: str, joint_c: str, crank_1: str, crank_2: str) -> str:
    """The crank-rocker of examples/specs/four-bar.toml with joints ``A, joint_b, joint_c, D`` and the crank's
    body written ``crank_1`` at joint A and ``crank_2`` at joint B."""
    text = EXAMPLE.read_text(encoding="utf-8")
    for old, new in [
        ('name = "B"', f'name = "{joint_b}"'),
        ('name = "C"', f'name = "{joint_c}"'),
        ('bodies = ["ground", "crank"]', f'bodies = ["ground", "{crank_1}"]'),
        ('bodies = ["crank", "coupler"]', f'bodies = ["{crank_2}", "coupler"]'),
    ]:
        assert text.count(old) == 1, old  # the example as this test reads it
        text = text.replace(old, new)
    return text


def test_the_two_forms_differ_as_strings_and_not_as_names() -> None:
    assert COMPOSED != DECOMPOSED and len(DECOMPOSED) == 2
    assert canonical(DECOMPOSED) == canonical(COMPOSED) == unicodedata.normalize("NFC", DECOMPOSED)
    assert canonical("\ufb01") == "\ufb01"  # NFC, not NFKC: the ligature fi is other text than "fi"


def test_a_body_written_two_ways_is_one_body(tmp_path: Path) -> None:
    """The crank's body written "bâr" precomposed at A and decomposed at B closes the loop: the four-bar
    traces as the one written alike (same rows)."""
    mixed = tmp_path / "mixed.toml"
    mixed.write_text(four_bar("B", "C", BAR_COMPOSED, BAR_DECOMPOSED), encoding="utf-8")
    alike = tmp_path / "alike.toml"
    alike.write_text(four_bar("B", "C", BAR_COMPOSED, BAR_COMPOSED), encoding="utf-8")
    a, b = lw.load(str(mixed)), lw.load(str(alike))
    assert a.bodies == b.bodies and len(a.loops) == 1
    until = ("A", float(a.offsets[0] + np.pi / 2))
    ta, tb = lw.trace(a, until=until, steps=9), lw.trace(b, until=until, steps=9)
    assert np.array_equal(ta.angles, tb.angles)


def test_joint_names_equal_but_for_normalisation_are_a_duplicate(tmp_path: Path) -> None:
    spec = tmp_path / "dup.toml"
    spec.write_text(four_bar(COMPOSED, DECOMPOSED, "crank", "crank"), encoding="utf-8")
    with pytest.raises(SpecError, match="duplicate joint name") as caught:
        lw.load(str(spec))
    assert "mechanism.joints[2].name" in str(caught.value)
    result = CliRunner().invoke(app, ["trace", str(spec), "-o", str(tmp_path / "out")])
    assert result.exit_code == 2, result.output
    assert "duplicate joint name" in result.output and "Traceback" not in result.output
    assert not (tmp_path / "out").exists()


def test_a_flag_finds_the_joint_written_the_other_way(tmp_path: Path) -> None:
    """The joint named with a decomposed "é" in the file is driven by ``--drive`` / ``--until`` with the
    precomposed one, and by the Python API's index either way; the files name it in one (NFC) form."""
    spec = tmp_path / "accent.toml"
    spec.write_text(four_bar("B", "C" + DECOMPOSED, "crank", "crank"), encoding="utf-8")
    mech = lw.load(str(spec))
    assert mech.index("C" + COMPOSED) == mech.index("C" + DECOMPOSED) == 2
    assert mech.has_joint("C" + COMPOSED) and mech.has_joint("C" + DECOMPOSED) and not mech.has_joint("C")
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["trace", str(spec), "--drive", "A", "--until", "A=90", "-o", str(out)])
    assert result.exit_code == 0, result.output
    header = (out / "path.csv").read_text(encoding="utf-8").splitlines()[0]
    assert "C" + COMPOSED in header and "C" + DECOMPOSED not in header
    out2 = tmp_path / "out2"
    result = CliRunner().invoke(
        app, ["trace", str(spec), "--drive", "C" + COMPOSED, "--until", f"C{DECOMPOSED}=20", "-o", str(out2)]
    )
    assert result.exit_code in (0, 3), result.output  # the rocker's range decides; the joint is found
    assert "unknown joint" not in result.output
    report = json.loads((out2 / "report.json").read_text(encoding="utf-8"))
    assert report["drive"] == "C" + COMPOSED


def test_a_mechanism_built_in_python_keeps_names_in_one_form() -> None:
    mech = lw.load("four-bar")
    names = list(mech.joint_names)
    names[1] = DECOMPOSED
    from dataclasses import replace

    other = replace(mech, joint_names=tuple(names))
    assert other.joint_names[1] == COMPOSED and other.index(DECOMPOSED) == 1
    names[2] = COMPOSED
    with pytest.raises(SpecError, match="unique"):
        replace(mech, joint_names=tuple(names))


def test_profile_names_equal_but_for_normalisation_are_refused(tmp_path: Path) -> None:
    x = np.linspace(0.0, 3.0, 31)
    save_profile(tmp_path / "a.csv", np.column_stack([x, 0.1 * np.sin(x)]))
    save_profile(tmp_path / "b.csv", np.column_stack([x, 0.2 * np.sin(x)]))
    problem = tmp_path / "problem.toml"
    problem.write_text(
        f'profiles = ["a.csv", "b.csv"]\nnames = ["wing{COMPOSED}", "wing{DECOMPOSED}"]\ntype = "open"\n'
        'piece_length = 0.25\nmin_pieces = 3\ndesign = "mcm"\n',
        encoding="utf-8",
    )
    with pytest.raises(SpecError, match="repeats") as caught:
        load_problem(str(problem))
    assert "names" in str(caught.value)
    # named after their files: two files whose stems differ only in normal form
    save_profile(tmp_path / f"w{COMPOSED}.csv", np.column_stack([x, 0.1 * np.sin(x)]))
    save_profile(tmp_path / f"w{DECOMPOSED}.csv", np.column_stack([x, 0.2 * np.sin(x)]))
    problem.write_text(
        f'profiles = ["w{COMPOSED}.csv", "w{DECOMPOSED}.csv"]\ntype = "open"\npiece_length = 0.25\n'
        'min_pieces = 3\ndesign = "mcm"\n',
        encoding="utf-8",
    )
    with pytest.raises(SpecError, match="would both be named"):
        load_problem(str(problem))
