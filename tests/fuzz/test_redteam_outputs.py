"""Output places a hostile user picks (session 13's red team): an export written over a file of the very folder
it reads, a run whose --out is the folder holding its input, paths with spaces, unicode and leading dashes.

Checked against the files on disk before and after, and the exported file parsed by an outside parser.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import ezdxf
import pytest
from fuzzkit import run_cli, tree

from linkwork.io.spec import dump_spec
from linkwork.linkages.four_bar import four_bar


@pytest.fixture
def home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.fixture
def traced(home: Path) -> Path:
    """A trace folder of a planar four-bar (so that every export kind applies)."""
    (home / "four-bar.toml").write_text(dump_spec(four_bar()), encoding="utf-8")
    run = run_cli(["trace", "four-bar.toml", "--out", "tr", "--no-plots", "--max-steps", "30"], home=None)
    assert run.code == 0, run
    return home / "tr"


@pytest.mark.parametrize(
    ("kind", "name"),
    [("mjcf", "mechanism.toml"), ("mjcf", "report.json"), ("dxf", "path.csv"), ("stl", "points.csv.stl")],
)
def test_an_export_never_overwrites_a_result_of_the_folder_it_reads(
    home: Path, traced: Path, kind: str, name: str
) -> None:
    """``export mjcf tr -o tr/mechanism.toml`` exited 0 and wrote the MJCF over the trace's own mechanism.toml
    (linkwork wrote it, so the manifest let it): every later export of the folder then failed with "invalid
    TOML". A single file may replace an earlier single file, never an entry of a run's results."""
    if name == "points.csv.stl":  # not a result: an export beside them is fine
        assert run_cli(["export", kind, str(traced), "-o", str(traced / name)], home=None).code == 0
        return
    before = tree(traced)
    run = run_cli(["export", kind, str(traced), "-o", str(traced / name)], home=home)
    assert run.code == 2, run
    assert "one of the results of a linkwork run" in run.stderr
    assert tree(traced) == before
    # the folder still exports
    again = run_cli(["export", "mjcf", str(traced), "-o", str(home / "model.xml")], home=None)
    assert again.code == 0, again
    assert ET.parse(home / "model.xml").getroot().tag == "mujoco"


def test_an_export_replaces_its_own_earlier_export(home: Path, traced: Path) -> None:
    out = traced / "drawing.dxf"
    for _ in range(2):
        run = run_cli(["export", "dxf", str(traced), "-o", str(out)], home=None)
        assert run.code == 0, run
    assert len(ezdxf.readfile(str(out)).modelspace().query("CIRCLE")) == 4  # a pivot per revolute joint


@pytest.mark.parametrize("name", ["with space/ünï.dxf", "-dash.dxf", "a'quote\".dxf", "tab\there.dxf"])
def test_export_file_names_users_write(home: Path, traced: Path, name: str) -> None:
    """Odd but legal file names are written as given (and read back by ezdxf)."""
    (home / "with space").mkdir()
    run = run_cli(["export", "dxf", str(traced), f"--out={name}"], home=None)
    assert run.code == 0, run
    assert len(ezdxf.readfile(str(home / name)).modelspace().query("LWPOLYLINE")) >= 3


def test_a_trace_whose_out_is_the_folder_of_its_spec(home: Path) -> None:
    """The spec named like an output (mechanism.toml) in --out is the user's: refused, kept byte for byte."""
    spec = home / "mechanism.toml"
    spec.write_text(dump_spec(four_bar()), encoding="utf-8")
    before = tree(home)
    run = run_cli(["trace", "mechanism.toml", "--out", ".", "--no-plots", "--max-steps", "20"], home=None)
    assert run.code == 2
    assert '"mechanism.toml" exists and was not written by linkwork' in run.stderr
    assert tree(home) == before


def test_a_subnormal_scale_is_refused_not_written_with_three_digits(home: Path, traced: Path) -> None:
    """--scale 1e-320 is positive, so it passed the flag's bound, and wrote subnormal coordinates: a float
    there keeps two or three significant digits, and every facet of the STL was degenerate."""
    run = run_cli(["export", "stl", str(traced), "-o", "tiny.stl", "--scale", "1e-320"], home=home)
    assert run.code == 2 and "expected a size of at least" in run.stderr
    assert not (home / "tiny.stl").exists()
    small = run_cli(["export", "stl", str(traced), "-o", "small.stl", "--scale", "1e-280"], home=None)
    assert small.code == 0, small
    vertices = [
        line.split()[1:] for line in (home / "small.stl").read_text().splitlines() if "vertex" in line
    ]
    finite = [abs(float(v)) for row in vertices for v in row if float(v) != 0.0]
    assert min(finite) > 2.2250738585072014e-308  # normal floats: every digit kept
