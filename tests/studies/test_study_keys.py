"""Every key of a study file is checked for type, finiteness and range before any grid point runs (issue 19 item
4): one line naming the file and the key and stating the bounds, exit 2, nothing written; the grid is indexed
without being listed, so the work a study asks for is refused up front when it is over the stated limits."""

from __future__ import annotations

import itertools
import re
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from linkwork.cli import app
from linkwork.errors import SpecError
from linkwork.studies.study_file import MAX_GRID_POINTS, Study, load_study
from linkwork.studies.sweep import point_batches, read_study, run_sweep

ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")
LINKAGE = 'linkage = "bennett"\n[trace]\nuntil = "A=90"\nsteps = 5\n[grid]\nalpha1 = [30, 40]\n'
ROBUST = "[robustness]\nsamples = 10\nhinge_position_tol = 0.001\nhinge_direction_tol = 0.05\n"


def sweep(tmp_path: Path, text: str) -> tuple[int, str, Path]:
    study = tmp_path / "study.toml"
    study.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["sweep", str(study), "--workers", "0", "--no-plots", "-o", str(out)])
    text_err = ANSI.sub("", result.stderr)
    assert "Traceback" not in result.stdout + text_err
    return result.exit_code, text_err.strip(), out


@pytest.mark.parametrize(
    ("text", "key", "fragment"),
    [
        ('problem = "seat"\n[grid]\nsegments = ["x"]\n', "grid.segments[0]", '1 <= segments <= 14, got "x"'),
        ('problem = "seat"\n[grid]\nstarts = [[1, 2]]\n', "grid.starts[0]", "got [1, 2]"),
        ('problem = "seat"\n[grid]\nsegments = [22]\ndesign = ["each"]\n', "grid.segments[0]", "got 22"),
        ('problem = "seat"\n[grid]\nmerge_below = [nan]\n', "grid.merge_below[0]", "got nan"),
        ('problem = "seat"\n[grid]\ndesign = ["each", "MC"]\n', "grid.design[0]", "cannot be mixed"),
        ('problem = "seat"\n[grid]\npiece_length = [inf]\n', "grid.piece_length[0]", "got inf"),
        (LINKAGE + ROBUST + "seed = -1\n", "robustness.seed", "0 <= seed <= 9223372036854775807, got -1"),
        (LINKAGE + ROBUST.replace("10", "nan"), "robustness.samples", "got nan"),
        (LINKAGE + ROBUST.replace("0.05", "90"), "robustness.hinge_direction_tol", "< 90, got 90"),
        (LINKAGE.replace("steps = 5", "max_steps = -1"), "trace.max_steps", "1 <= max_steps <= 1e+06, got -1"),
        (LINKAGE.replace("steps = 5", 'branches = "x"'), "trace.branches", 'expected true or false, got "x"'),
        (LINKAGE.replace("steps = 5", "steps = 5.5"), "trace.steps", "got 5.5"),
        (LINKAGE.replace("[30, 40]", '["x"]'), "grid.alpha1[0]", 'expected a finite number, got "x"'),
        (LINKAGE.replace("[30, 40]", "[30, 1e9]"), "grid.alpha1[1]", "from -720 to 720 deg"),
        (LINKAGE.replace("[30, 40]", "{ from = 0, to = 1, count = 0 }"), "grid.alpha1.count", "got 0"),
        (LINKAGE + "[grid.alpha2]\nfrom = 1\nto = 2\ncount = 100000\n", "grid", f"at most {MAX_GRID_POINTS}"),
        ("time_per_point = 0\n" + LINKAGE, "time_per_point", "0 < time_per_point"),
        (LINKAGE + ROBUST.replace("10", "10000000") + "[grid.alpha2]\nfrom = 70\nto = 80\ncount = 20\n",
         "robustness.samples", "expected at most 1e+08"),
    ],
)  # fmt: skip
def test_a_bad_study_key_is_one_line_naming_it_and_nothing_is_written(
    tmp_path: Path, text: str, key: str, fragment: str
) -> None:
    code, err, out = sweep(tmp_path, text)
    assert code == 2, err
    assert len(err.splitlines()) == 1 and err.startswith("error: ")
    assert f"study.toml: {key}:" in err and fragment in err, err
    assert not out.exists()


def test_design_each_with_many_segments_is_refused_at_once(tmp_path: Path) -> None:
    """22 segments used to list 4 million design vectors (1.6 GB) before anything ran."""
    start = time.perf_counter()
    code, err, _ = sweep(tmp_path, 'problem = "seat"\n[grid]\nsegments = [22]\ndesign = ["each"]\n')
    assert code == 2 and "segments" in err
    assert time.perf_counter() - start < 30.0  # seconds: the CLI's start-up, not the listing


def grid_points(study: Study) -> list[dict[str, object]]:
    """The grid listed in full, as the file format describes it (an outside reference for Study.point)."""
    keys = [k for k in study.grid if not (study.each_design and k == "design")]
    out: list[dict[str, object]] = []
    for combo in itertools.product(*(study.grid[k] for k in keys)):
        point = dict(zip(keys, combo, strict=True))
        if not study.each_design:
            out.append(point)
            continue
        for letters in itertools.product("MC", repeat=int(point["segments"])):  # type: ignore[call-overload]
            out.append({**point, "design": "".join(letters)})
    return out


@pytest.mark.parametrize(
    "grid",
    [
        {"a": [1, 2, 3], "b": [4, 5], "c": [6, 7, 8, 9]},
        {},
        {"piece_length": [0.3, 0.4], "segments": [2, 3], "design": ["each"]},
    ],
)
def test_a_grid_point_is_found_by_index_exactly_as_the_listed_grid(grid: dict[str, list[object]]) -> None:
    study = Study(kind="synthesis" if "segments" in grid else "linkage", name="s", target="t", grid=grid)
    listed = grid_points(study)
    assert study.count() == len(listed)
    assert [study.point(i) for i in range(study.count())] == listed


def test_the_largest_grid_is_indexed_without_listing_it(tmp_path: Path) -> None:
    study_file = tmp_path / "s.toml"
    study_file.write_text(
        LINKAGE.replace("[30, 40]", "{ from = 10, to = 20, count = 1000 }")
        + "alpha2 = { from = 70, to = 80, count = 100 }\n",
        encoding="utf-8",
    )
    study = load_study(study_file)
    assert study.count() == MAX_GRID_POINTS
    assert study.point(MAX_GRID_POINTS - 1) == {"alpha1": 20.0, "alpha2": 80.0}
    assert study.point(101) == {"alpha1": study.grid["alpha1"][1], "alpha2": study.grid["alpha2"][1]}
    batches = point_batches(MAX_GRID_POINTS, 2)
    assert batches[0] == (0, 64) and batches[-1][1] == MAX_GRID_POINTS  # a few thousand tasks, not 100,000


def test_a_point_that_raises_keeps_every_other_row(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Whatever one grid point raises (here a ZeroDivisionError while building it) is that point's row."""
    import linkwork.io.spec as spec

    real = spec.resolve_spec

    def fails_at_40(target, params=None, **kwargs):  # type: ignore[no-untyped-def]
        if params and params.get("alpha1") == 40:
            raise ZeroDivisionError("injected")
        return real(target, params, **kwargs)

    study_file = tmp_path / "s.toml"
    study_file.write_text(LINKAGE.replace("[30, 40]", "[30, 40, 50]"), encoding="utf-8")
    study = read_study(study_file)
    monkeypatch.setattr(spec, "resolve_spec", fails_at_40)
    rows = [row for row, _ in run_sweep(study, workers=0)]
    assert [row["alpha1"] for row in rows] == [30, 40, 50]
    assert rows[1]["error"] == "unexpected ZeroDivisionError: injected"
    assert rows[0]["error"] == "" and rows[2]["error"] == "" and rows[2]["mobility"] == 1


def test_a_point_over_its_time_budget_records_why_and_the_study_goes_on(tmp_path: Path) -> None:
    study_file = tmp_path / "s.toml"
    study_file.write_text("time_per_point = 1e-9\n" + LINKAGE, encoding="utf-8")
    rows = [row for row, _ in run_sweep(read_study(study_file), workers=0)]
    assert len(rows) == 2
    assert all(row["error"] == "stopped after time_per_point = 1e-09 s" for row in rows)


def test_read_study_checks_everything_before_any_work(tmp_path: Path) -> None:
    study_file = tmp_path / "s.toml"
    study_file.write_text(LINKAGE.replace("alpha1", "alpha9"), encoding="utf-8")
    with pytest.raises(SpecError, match=r"s\.toml: grid\.alpha9: bennett has no parameter"):
        read_study(study_file)


def test_design_each_over_many_base_points_is_indexed_without_rescanning() -> None:
    """50,000 base points of 2 designs each: every point is found from cumulative counts made once (a scan of
    the base points per lookup was 10^9 steps for the whole grid)."""
    lengths = [0.1 + 1e-6 * i for i in range(50_000)]
    study = Study(kind="synthesis", name="s", target="t", grid={"piece_length": lengths, "segments": [1],
                                                                 "design": ["each"]})  # fmt: skip
    assert study.count() == 100_000
    start = time.perf_counter()
    points = [study.point(i) for i in range(0, 100_000, 7)]
    assert time.perf_counter() - start < 20.0  # seconds, generous for a loaded machine (was minutes)
    assert points[1] == {"piece_length": lengths[3], "segments": 1, "design": "C"}  # index 7 = 3 * 2 + 1
    assert study.point(99_999) == {"piece_length": lengths[-1], "segments": 1, "design": "C"}
