"""linkwork search: criteria, the paper's claim that rect-frame members bifurcate, resuming, exit 3, Dask."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import linkwork as lw
from linkwork.cli import app
from linkwork.kinematics.closure import jacobian
from linkwork.outputs.search import RECORDS

FACES = ["auto", "oiioii", "ioiooi", "iiiiio", "oooiio"]


def study(folder: Path, criteria: str, *, name: str = "frames", grid: str | None = None) -> Path:
    grid = grid or f'width = [0.5, 1.0]\ncuts = ["EW", "NS"]\nfaces = {json.dumps(FACES)}'
    text = f'name = {json.dumps(name)}\nlinkage = "rect-frame"\n[trace]\nmax_steps = 800\n[grid]\n{grid}\n'
    file = folder / "study.toml"
    file.write_text(text + f"[criteria]\n{criteria}\n", encoding="utf-8")
    return file


def search(args: list[str]) -> tuple[int, str]:
    result = CliRunner().invoke(app, ["search", *args])
    return result.exit_code, result.output


def read_csv(file: Path) -> list[dict[str, str]]:
    with file.open(newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def test_the_search_finds_frames_whose_mobility_rises_above_one(tmp_path: Path) -> None:
    """G&P Sec. 6: "many examples of structures with mobility higher than one in at least one intermediate
    configuration". Every ranked member has a located bifurcation on its path, where the Jacobian computed
    here from its joint values has lost a rank (sigma_5 / sigma_1 < 1e-7), and Guest's frame is among them."""
    out = tmp_path / "out"
    code, output = search([str(study(tmp_path, "min_bifurcations = 1")), "-o", str(out), "--workers", "0"])
    assert code == 0, output
    ranked = read_csv(out / "ranked.csv")
    assert len(ranked) >= 3
    assert all(int(r["mobility_max"]) >= 2 for r in ranked)
    assert any(r["cuts"] == "EW" and r["faces"] in ("auto", "oiioii") for r in ranked)  # Guest's frame
    for r in ranked[:3]:
        mech = lw.load("rect-frame", width=float(r["width"]), cuts=r["cuts"], faces=r["faces"])
        tr = lw.trace(mech, max_steps=800)
        bif = next(b for b in tr.bifurcations if b.kind == "bifurcation")
        s = np.linalg.svd(jacobian(mech, mech.q_from_angles(bif.angles)), compute_uv=False)
        assert s[4] / s[0] < 1e-7 and s[3] / s[0] > 1e-3
    candidates = read_csv(out / "candidates.csv")
    assert len(candidates) == 20
    gallery = (out / "gallery.html").read_text()
    for r in ranked[:3]:
        link = f"viewers/candidate-{int(r['index']):05d}.html"
        assert link in gallery and (out / link).is_file()


def test_mobility_criterion_names_the_rise_and_ranks_the_rest(tmp_path: Path) -> None:
    """With ``mobility = 1`` the same members fail, each with its first failed criterion; passing ones are ranked
    by membrane stretch (ascending) and the Parquet table holds the same rows as the CSV."""
    import pyarrow.parquet as pq

    out = tmp_path / "out"
    code, output = search(
        [str(study(tmp_path, "mobility = 1\nmax_bifurcations = 0")), "-o", str(out), "--workers", "0"]
    )
    assert code == 0, output
    rows = read_csv(out / "candidates.csv")
    rises = [r for r in rows if r["mobility_max"] == "2"]
    assert rises and all(r["reason"] == "mobility: rises to 2 on the path (wanted 1)" for r in rises)
    rigid = [r for r in rows if r["mobility_start"] == "0"]
    assert all(r["reason"].startswith("mobility: 0 at the start") for r in rigid)
    ranked = read_csv(out / "ranked.csv")
    assert [int(r["rank"]) for r in ranked] == list(range(1, len(ranked) + 1))
    stretch = [float(r["membrane_stretch"]) for r in ranked]
    assert stretch == sorted(stretch)
    assert all(r["passes"] == "True" for r in ranked)
    table = pq.read_table(out / "candidates.parquet").to_pylist()
    assert [t["index"] for t in table] == [int(r["index"]) for r in rows]
    assert [t["reason"] for t in table] == [r["reason"] for r in rows]


def test_no_candidate_passing_exits_3_with_the_closest(tmp_path: Path) -> None:
    out = tmp_path / "out"
    file = study(
        tmp_path, "mobility = 1\nmax_membrane_stretch = 0.0001", grid='width = [0.5, 1.0]\ncuts = ["NS"]'
    )
    code, output = search([str(file), "-o", str(out), "--workers", "0"])
    assert code == 3
    assert "no candidate meets the criteria; the closest is width=" in output
    summary = json.loads((out / "search.json").read_text())
    assert summary["passing"] == 0 and summary["closest"] is not None
    assert (out / "gallery.html").is_file() and (out / "candidates.csv").is_file()


def test_an_interrupted_search_resumes_and_loses_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C after some candidates: their records stay; the re-run traces only the others and writes the same
    table as an uninterrupted search."""
    import linkwork.studies.search as search_module

    file = study(tmp_path, "mobility = 1")
    whole = tmp_path / "whole"
    assert search([str(file), "-o", str(whole), "--workers", "0", "--gallery", "0"])[0] == 0

    real = search_module.evaluate
    calls = {"n": 0}

    def stops_after_seven(*args, **kwargs):  # type: ignore[no-untyped-def]
        calls["n"] += 1
        if calls["n"] > 7:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    out = tmp_path / "out"
    monkeypatch.setattr(search_module, "evaluate", stops_after_seven)
    code, _ = search([str(file), "-o", str(out), "--workers", "0", "--gallery", "0"])
    assert code != 0 and not (out / "candidates.csv").exists()
    kept = (out / RECORDS).read_text().splitlines()
    assert len(kept) == 1 + 7  # the header and every finished candidate

    calls["n"] = -1000  # no more interruptions; count the candidates traced again
    code, output = search([str(file), "-o", str(out), "--workers", "0", "--gallery", "0"])
    assert code == 0, output
    assert calls["n"] == -1000 + 20 - 7
    assert (out / "candidates.csv").read_text() == (whole / "candidates.csv").read_text()
    assert "resuming: 7 of 20" in output

    # the study changed: its records are not reused
    changed = study(tmp_path, "mobility = 1\nmax_flatness = 0.5")
    code, output = search([str(changed), "-o", str(out), "--workers", "0", "--gallery", "0"])
    assert code == 0 and "starting afresh" in output


def test_bad_criteria_are_refused_in_one_line(tmp_path: Path) -> None:
    out = tmp_path / "out"
    for criteria, expected in [
        ("mobilty = 1", 'did you mean "mobility"'),
        ("max_membrane_stretch = -1", "expected a number >= 0"),
        ('rank_by = ["speed"]', "criteria.rank_by[0]: expected one of"),
        ('deployed_at = "A"', "criteria.deployed_at"),
        ('deployed_at = "Q=0"', "no joint 'Q'; joints are A, B, C, D, E, F"),
        ("mobility = 1.5", "criteria.mobility"),
    ]:
        code, output = search([str(study(tmp_path, criteria)), "-o", str(out)])
        assert code == 2 and expected in output, (criteria, output)
        assert output.count("\n") <= 2
    no_table = tmp_path / "none.toml"
    no_table.write_text('linkage = "rect-frame"\n[grid]\nwidth = [1.0]\n', encoding="utf-8")
    code, output = search([str(no_table), "-o", str(out)])
    assert code == 2 and "[criteria]" in output
    assert not out.exists()


def test_gallery_escapes_the_names_a_user_wrote(tmp_path: Path) -> None:
    out = tmp_path / "out"
    file = study(tmp_path, "mobility = 1", name="<script>alert(1)</script> & co", grid='faces = ["oiioii"]')
    assert search([str(file), "-o", str(out), "--workers", "0"])[0] == 3  # Guest's frame bifurcates
    page = (out / "gallery.html").read_text()
    assert "<script>" not in page and "&lt;script&gt;alert(1)&lt;/script&gt; &amp; co" in page
    viewers = list((out / "viewers").glob("*.html"))
    assert viewers and all("alert(1)</script>" not in v.read_text() for v in viewers)


def test_a_distributed_scheduler_gives_the_same_table(tmp_path: Path) -> None:
    """The same study on a Dask cluster reached by --scheduler (127.0.0.1, stopped at the end) and in one
    process: the same candidates.csv (see :func:`assert_same_table`)."""
    from dask.distributed import LocalCluster

    file = study(tmp_path, "mobility = 1")
    here = tmp_path / "here"
    assert search([str(file), "-o", str(here), "--workers", "0", "--gallery", "0"])[0] == 0
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=":0"
    ) as cluster:
        there = tmp_path / "there"
        code, output = search(
            [str(file), "-o", str(there), "--scheduler", cluster.scheduler_address, "--gallery", "0"]
        )
    assert code == 0, output
    assert_same_table(read_csv(there / "candidates.csv"), read_csv(here / "candidates.csv"))


def assert_same_table(got: list[dict[str, str]], want: list[dict[str, str]]) -> None:
    """The same rows: every text, whole number and pass/fail equal; measures equal to 1e-9 (a worker may trace
    with the compiled kernels and this process with their plain-Python twins: the same arithmetic up to the last
    bits of sin and cos)."""
    assert [list(r) for r in got] == [list(r) for r in want]
    for a, b in zip(got, want, strict=True):
        for key in a:
            try:
                x, y = float(a[key]), float(b[key])
            except ValueError:
                assert a[key] == b[key], key
                continue
            if a[key].lstrip("-").isdigit() or not np.isfinite(y):
                assert a[key] == b[key], key
            else:
                assert x == pytest.approx(y, rel=1e-9, abs=1e-12), key


@pytest.mark.slow
def test_a_search_over_hundreds_of_members_completes_with_table_and_gallery(tmp_path: Path) -> None:
    """256 members (every face choice of Guest's cuts, four widths) on two local workers."""
    faces = json.dumps(["".join(f) for f in __import__("itertools").product("io", repeat=6)])
    file = study(
        tmp_path,
        "mobility = 1\nmax_bifurcations = 0",
        grid=f'width = [0.4, 0.6, 0.8, 1.0]\ncuts = ["EW"]\nfaces = {faces}',
    )
    out = tmp_path / "out"
    code, output = search([str(file), "-o", str(out), "--workers", "2"])
    assert code == 0, output
    assert len(read_csv(out / "candidates.csv")) == 256
    ranked = read_csv(out / "ranked.csv")
    assert ranked and len(list((out / "viewers").iterdir())) == min(12, len(ranked))


def test_stalled_members_are_mobile_to_first_order_only() -> None:
    """The members the search fails as "rigid to second order" (before: "the path stops", after rows off the
    loop) are: with t the Jacobian's null vector at the flat start and w its left null vector, w . H(t, t) != 0 (H
    the closure Hessian, computed here from kinematics.closure), so no curve leaves the start; the members it
    traces have w . H(t, t) = 0. Over the 36 mobile face choices of Guest's cuts."""
    import itertools

    from linkwork.kinematics.closure import hessian
    from linkwork.studies.search import Criteria, SearchStudy, evaluate
    from linkwork.studies.study_file import Study

    search_study = SearchStudy(
        Study(kind="linkage", name="t", target="rect-frame", grid={}, max_steps=300), Criteria(mobility=1)
    )
    stalled = moving = 0
    for faces in ("".join(f) for f in itertools.product("io", repeat=6)):
        mech = lw.load("rect-frame", faces=faces)
        u, s, vt = np.linalg.svd(jacobian(mech, np.zeros(6)))
        if s[4] < 1e-9 * s[0]:
            continue  # mobility two: no single tangent
        if s[5] > 1e-9 * s[0]:
            continue  # rigid
        second = abs(u[:, -1] @ np.einsum("eij,i,j->e", hessian(mech, np.zeros(6)), vt[-1], vt[-1]))
        row = evaluate(search_study, {"faces": faces}).row
        if row["reason"].startswith("mobility: rigid to second order"):
            stalled += 1
            assert second > 1e-3, faces
        else:
            moving += 1
            assert second < 1e-12, faces
    assert stalled > 0 and moving > 0 and stalled + moving == 36


#: Ways a record line of a search can be damaged (by hand, by a disk) while staying a JSON object: each record so
#: damaged must be traced again, never read as a candidate's row (they were a KeyError or an IndexError traceback,
#: or, with a negative index, the last candidate's row taken for another).
RECORD_DAMAGES = {
    "only an index": lambda row: {"index": row["index"]},
    "index past the grid": lambda row: {**row, "index": 99999},
    "negative index": lambda row: {**row, "index": -1},
    "index of another candidate": lambda row: {**row, "index": 1 - row["index"]},
    "index a float": lambda row: {**row, "index": float(row["index"])},
    "index a bool": lambda row: {**row, "index": False},
    "a measure as text": lambda row: {**row, "membrane_stretch": "x"},
    "a measure as a list": lambda row: {**row, "bundle_ratio": [1]},
    "passes as text": lambda row: {**row, "passes": "yes"},
    "a parameter changed": lambda row: {**row, "width": 123.0},
}


@pytest.mark.parametrize("damage", sorted(RECORD_DAMAGES))
def test_a_damaged_record_is_traced_again(tmp_path: Path, damage: str) -> None:
    file = study(tmp_path, "mobility = 1", grid='width = [0.5, 1.0]\ncuts = ["NS"]')
    out = tmp_path / "out"
    args = [str(file), "-o", str(out), "--workers", "0", "--gallery", "1"]
    code, output = search(args)
    assert code in (0, 3), output
    whole = (out / "candidates.csv").read_text()
    lines = (out / RECORDS).read_text().splitlines()
    row = json.loads(lines[1])
    (out / RECORDS).write_text("\n".join([lines[0], json.dumps(RECORD_DAMAGES[damage](row))]) + "\n")
    again, output = search(args)
    assert again == code, output
    assert "resuming" not in output  # the only record kept was the damaged one: nothing is resumed
    assert (out / "candidates.csv").read_text() == whole


@pytest.mark.parametrize("kind", ["folder link", "records link", "a file for the folder"])
def test_search_records_are_never_written_through_a_link(tmp_path: Path, kind: str) -> None:
    """``OUT/.linkwork-search`` a link to a user's folder: the records were written into it; a user's file of that
    name was a 'File exists' exit 3."""
    file = study(tmp_path, "mobility = 1", grid='width = [0.5]\ncuts = ["NS"]')
    out, user = tmp_path / "out", tmp_path / "user"
    out.mkdir()
    user.mkdir()
    (user / "notes.txt").write_text("keep\n", encoding="utf-8")
    records = out / RECORDS
    if kind == "folder link":
        records.parent.symlink_to(user)
    elif kind == "records link":
        records.parent.mkdir()
        records.symlink_to(user / "notes.txt")
    else:
        records.parent.write_text("the user's file\n", encoding="utf-8")
    result = CliRunner().invoke(app, ["search", str(file), "-o", str(out), "--workers", "0"])
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: --out ") and ".linkwork-search" in lines[0]
    assert sorted(p.name for p in user.iterdir()) == ["notes.txt"]
    assert (user / "notes.txt").read_text() == "keep\n"


def test_a_link_planted_beside_the_records_is_never_written_through(tmp_path: Path) -> None:
    """The records' header was written to ``records.part`` and renamed: a link planted under that name had the
    user's file it pointed to overwritten with the header, then every record appended to it."""
    file = study(tmp_path, "mobility = 1", grid='width = [0.5]\ncuts = ["NS"]')
    out, notes = tmp_path / "out", tmp_path / "notes.txt"
    notes.write_text("keep\n", encoding="utf-8")
    (out / RECORDS).parent.mkdir(parents=True)
    (out / RECORDS).with_suffix(".part").symlink_to(notes)
    code, output = search([str(file), "-o", str(out), "--workers", "0", "--gallery", "0"])
    assert code in (0, 3), output
    assert notes.read_text(encoding="utf-8") == "keep\n"
    assert len((out / RECORDS).read_text().splitlines()) == 2  # the header and the one candidate
