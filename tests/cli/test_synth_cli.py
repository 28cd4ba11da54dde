"""``linkwork synth``: bad input is one line and exit code 2 with no output folder touched; a good problem
writes every contract file with the contract keys."""

from __future__ import annotations

import csv
import json
import math
import shutil
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import svgelements
from typer.testing import CliRunner, Result

from linkwork import data
from linkwork.cli import app
from linkwork.cli import synth as synth_module
from linkwork.errors import SpecError
from linkwork.io.profiles import save_profile
from linkwork.outputs import synthesis as synthesis_outputs

ROOT = Path(__file__).resolve().parents[2]
runner = CliRunner()


def invoke(*args: str) -> Result:
    return runner.invoke(app, ["synth", *args])


@pytest.fixture
def problem(tmp_path: Path) -> Path:
    """A small open problem: three arcs of growing length, quick to synthesise."""
    folder = tmp_path / "problem"
    folder.mkdir()
    for name, sweep in (("short", 1.0), ("mid", 1.3), ("long", 1.6)):
        t = np.linspace(0.0, sweep, 60)
        save_profile(folder / f"{name}.csv", np.column_stack([2.0 * np.sin(t), 2.0 - 2.0 * np.cos(t)]))
    (folder / "problem.toml").write_text(
        'type = "open"\nprofiles = ["short.csv", "mid.csv", "long.csv"]\npiece_length = 0.1\nmin_pieces = 3\n'
        'design = "MC"\nstarts = 2\nmerge_below = 5\nseed = 1\n',
        encoding="utf-8",
    )
    return folder / "problem.toml"


def snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


# ----------------------------------------------------------------------------------------------- refusals


BAD = [
    (
        "piece_length = 0.1",
        'piece_length = "abc"',
        'problem.toml: piece_length: expected a positive number, got "abc"',
    ),
    ('design = "MC"', 'design = "MQ"', "problem.toml: design: expected a design vector of M and C letters"),
    ("seed = 1", "seed = 1\nspeed = 3", "problem.toml: speed: unknown key"),
    ('"mid.csv"', '"gone.csv"', "problem.toml: profiles[1]: file"),
    ('"mid.csv"', '"mid.txt"', "mid.txt: unknown profile format (suffix '.txt')"),
    ("min_pieces = 3", "min_pieces = 40", "min_pieces"),  # refused by the engine: too few pieces per segment
]


@pytest.mark.parametrize(("old", "new", "expected"), BAD)
def test_bad_problem_is_one_line_exit_2_and_no_output(
    problem: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, old: str, new: str, expected: str
) -> None:
    text = problem.read_text(encoding="utf-8")
    assert old in text
    problem.write_text(text.replace(old, new), encoding="utf-8")
    (problem.parent / "mid.txt").write_text("0,0\n1,1\n", encoding="utf-8")
    monkeypatch.chdir(problem.parent)
    out = tmp_path / "out"
    result = invoke("problem.toml", "--out", str(out))
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("error: ")
    assert expected in lines[0]
    assert "Traceback" not in result.output + result.stderr
    assert not out.exists()
    assert not list(tmp_path.glob(".linkwork-*"))  # no staging folder left behind


def test_bad_profile_names_the_profile_file(problem: Path, tmp_path: Path) -> None:
    (problem.parent / "mid.csv").write_text("x,y\n0,0\n1,1\n1,1\n2,0\n", encoding="utf-8")
    result = invoke(str(problem), "--out", str(tmp_path / "out"))
    assert result.exit_code == 2
    expected = "points 2 and 3 repeat (1, 1); expected distinct consecutive points"
    assert result.stderr.strip() == f"error: {problem.parent / 'mid.csv'}: {expected}"


def test_missing_problem_file(tmp_path: Path) -> None:
    result = invoke(str(tmp_path / "nothing.toml"), "--out", str(tmp_path / "out"))
    assert result.exit_code == 2
    assert (
        result.stderr.strip()
        == f"error: {tmp_path / 'nothing.toml'}: file not found; expected a problem file (TOML)"
    )
    assert not (tmp_path / "out").exists()


def test_existing_output_is_left_unchanged_on_error(problem: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert invoke(str(problem), "--out", str(out), "--no-plots").exit_code == 0
    (out / "notes.txt").write_text("mine", encoding="utf-8")
    before = snapshot(out)
    problem.write_text(problem.read_text(encoding="utf-8").replace("seed = 1", "seed = -3"), encoding="utf-8")
    result = invoke(str(problem), "--out", str(out))
    assert result.exit_code == 2
    assert "seed: expected a whole number >= 0, got -3" in result.stderr
    assert snapshot(out) == before


def test_failure_while_writing_leaves_no_half_output(
    problem: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def broken(path: Path, result: object) -> None:
        Path(path).write_text("half", encoding="utf-8")
        raise SpecError("disk full", source=str(path))

    monkeypatch.setattr("linkwork.io.profiles.write_outline_dxf", broken)
    out = tmp_path / "out"
    result = invoke(str(problem), "--out", str(out), "--no-plots")
    assert result.exit_code == 2
    assert "disk full" in result.stderr
    assert not out.exists()
    assert not list(tmp_path.glob(".linkwork-*"))


# ------------------------------------------------------------------------------------------ good problems


def test_writes_every_contract_file_with_the_contract_keys(problem: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = invoke(str(problem), "--out", str(out), "--no-plots")
    assert result.exit_code == 0, result.output + result.stderr
    assert {p.name for p in out.iterdir()} - {".linkwork-manifest.json"} == {
        "chain.json",
        "target_profiles.csv",
        "outline.svg",
        "outline.dxf",
        "problem",  # a copy of the problem and its profiles, for `linkwork mechanize OUT`
    }
    assert (out / "problem" / "problem.toml").read_bytes() == problem.read_bytes()

    chain = json.loads((out / "chain.json").read_text(encoding="utf-8"))
    for key in (
        "profiles",
        "design",
        "segment_matrix",
        "error_matrix",
        "e_max",
        "e_mean",
        "joined",
        "segments",
        "compound",
    ):
        assert key in chain
    assert chain["design"] == "MC"
    pieces = [p["pieces"] for p in chain["profiles"]]
    for profile in chain["profiles"]:
        assert {"arc_length", "pieces", "target_length"} <= set(profile)
    # The three arcs (radius 2) are 2.0, 2.6 and 3.2 long; the sampled polylines are shorter by < 1e-3.
    np.testing.assert_allclose(
        [p["arc_length"] for p in chain["profiles"]], [2.0, 2.6, 3.2], rtol=0, atol=1e-3
    )
    assert {"error_matrix", "e_max", "profiles"} <= set(chain["joined"])
    for profile, m in zip(chain["joined"]["profiles"], pieces, strict=True):
        assert len(profile["points"]) == m + 1  # one chain point per target-profile point
        assert len(profile["joints"]) == len(chain["design"]) + 1
    kinds = [segment["type"] for segment in chain["segments"]]
    assert kinds == ["M", "C"]
    assert "shape" in chain["segments"][0] and "radius" in chain["segments"][1]
    # Every profile is an arc of radius 2: the C-segment's radius comes out near 2 (discrete curvature of
    # chords of 0.1 on radius 2 is within 1e-3 of 1/2).
    assert chain["segments"][1]["radius"] == pytest.approx(2.0, rel=1e-2)
    assert chain["compound"]["merge_below"] == pytest.approx(5.0, abs=1e-12)  # degrees in the file
    assert chain["e_max"] >= 0.0 and chain["joined"]["e_max"] < 0.05

    with open(out / "target_profiles.csv", newline="", encoding="utf-8") as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["profile", "index", "x", "y"]
    assert len(rows) - 1 == sum(m + 1 for m in pieces)

    document = svgelements.SVG.parse(str(out / "outline.svg"))
    paths = [e for e in document.elements() if isinstance(e, svgelements.Path)]
    assert len(paths) == 2 * 3  # target and chain per profile

    drawing = ezdxf.readfile(out / "outline.dxf")
    assert len(drawing.modelspace().query("LWPOLYLINE")) == 2 * 3
    assert {layer.dxf.name for layer in drawing.layers} >= {"short-chain", "mid-target", "long-joints"}


def test_summary_table_and_figures(problem: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = invoke(str(problem), "--out", str(out), "--html")
    assert result.exit_code == 0, result.output + result.stderr
    for text in (
        "Profiles",
        "arc length",
        "Segment matrix",
        "Error matrix after joining",
        "E_max",
        "E_mean",
        "Joint ranges, Eq. 34 (merge below 5 deg, on the targets)",
        "viewer.html",
    ):
        assert text in result.output
    viewer = (out / "viewer.html").read_text(encoding="utf-8")
    assert "<canvas" in viewer and "https://" not in viewer  # the synthesis viewer, self-contained
    for stem in ("profiles", "m_segment", "c_segment", "chain"):
        for suffix in (".png", ".svg"):
            figure = out / f"{stem}{suffix}"
            assert figure.is_file() and figure.stat().st_size > 1000
            assert figure.stat().st_size < 400_000


def test_without_matplotlib_the_figures_are_skipped_with_a_note(
    problem: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(synth_module, "have_matplotlib", lambda: False)
    out = tmp_path / "out"
    result = invoke(str(problem), "--out", str(out))
    assert result.exit_code == 0
    assert "matplotlib is not installed" in result.output
    assert not list(out.glob("*.png"))


def test_help_names_every_option() -> None:
    result = runner.invoke(app, ["synth", "--help"])
    assert result.exit_code == 0
    for option in ("--out", "--no-plots", "--html"):
        assert option in result.output


# ---------------------------------------------------------------------------------------- bundled examples


def test_run_synthesis_example_writes_inputs_and_outputs(tmp_path: Path) -> None:
    result = synthesis_outputs.run_synthesis_example(tmp_path / "demo", "fixed-end", plots=False)
    assert result.problem.kind == "fixed-end"
    assert (tmp_path / "demo" / "problem" / "problem.toml").is_file()
    assert (tmp_path / "demo" / "chain.json").is_file()
    # The copied problem runs again from the output folder.
    again = invoke(
        str(tmp_path / "demo" / "problem" / "problem.toml"), "--out", str(tmp_path / "again"), "--no-plots"
    )
    assert again.exit_code == 0
    first = json.loads((tmp_path / "demo" / "chain.json").read_text(encoding="utf-8"))
    second = json.loads((tmp_path / "again" / "chain.json").read_text(encoding="utf-8"))
    assert first["segment_matrix"] == second["segment_matrix"]  # seeded search: reproducible
    assert math.isclose(first["joined"]["e_max"], second["joined"]["e_max"], rel_tol=0, abs_tol=1e-12)


def test_unknown_example_is_a_spec_error(tmp_path: Path) -> None:
    with pytest.raises(
        SpecError, match=r'unknown example "moon"; expected one of wing, closed, fixed-end, seat'
    ):
        synthesis_outputs.run_synthesis_example(tmp_path, "moon")


def test_example_folder_copy_is_independent_of_the_package(tmp_path: Path) -> None:
    source = data.example("closed").parent
    shutil.copytree(source, tmp_path / "closed")
    result = invoke(str(tmp_path / "closed" / "problem.toml"), "--out", str(tmp_path / "out"), "--no-plots")
    assert result.exit_code == 0
    assert "CCMMCM" in result.output


def test_a_chain_that_cannot_be_joined_is_exit_3_naming_design_and_profile(tmp_path: Path) -> None:
    import importlib.util

    spec = importlib.util.spec_from_file_location("naca", ROOT / "tests" / "synthesis" / "naca.py")
    assert spec is not None and spec.loader is not None
    naca = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(naca)
    for code, chord in (("0012", 1.0), ("2412", 1.1), ("4412", 1.25)):
        save_profile(tmp_path / f"n{code}.csv", naca.naca4(code, chord))
    body = 'type = "closed"\nprofiles = ["n0012.csv", "n2412.csv", "n4412.csv"]\npiece_length = 0.03\nstarts = 2\n'
    # MCCC's first M-segment spans the upper surface: its chord is longer than the other three together
    (tmp_path / "fixed.toml").write_text(body + 'design = "MCCC"\n', encoding="utf-8")
    result = invoke(str(tmp_path / "fixed.toml"), "--out", str(tmp_path / "out"), "--no-plots")
    assert result.exit_code == 3, result.output + result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.output + result.stderr
    assert "design MCCC: profile 'n0012': joining: a chain of chords" in lines[0]
    assert "cannot close on itself" in lines[0]
    # the same design in the auto search is skipped and listed, the run succeeds
    (tmp_path / "auto.toml").write_text(body + 'design = "auto"\nsegments = 4\n', encoding="utf-8")
    result = invoke(str(tmp_path / "auto.toml"), "--out", str(tmp_path / "auto"), "--no-plots")
    assert result.exit_code == 0, result.output + result.stderr
    assert "skipped MCCC: design MCCC: profile 'n0012'" in " ".join(result.output.split())
    chain = json.loads((tmp_path / "auto" / "chain.json").read_text(encoding="utf-8"))
    assert "MCCC" in [s["design"] for s in chain["search"]["skipped"]]
    assert chain["search"]["designs_tried"] == 15
