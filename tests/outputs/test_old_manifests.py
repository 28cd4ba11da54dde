"""Output folders written before fingerprints existed (a manifest of format 2, or the earliest list of names,
written here by hand): the next command into such a folder behaves as it would in a current folder, except
where only a fingerprint could tell a user's file from linkwork's.

The upgrade rule (docs/architecture.md, the writer): an entry an old manifest lists is linkwork's only if it was
not modified after that manifest was written (the old writer wrote its manifest after every entry), so a result a
user edited since is refused as a changed one is (exit 2, unchanged); and a stale one is removed only when the
command writes anew, unchanged, some of the entries the old manifest lists in the same part (else a manifest
copied into a user's folder could list a user's file: tests/fuzz/test_redteam_second.py).

The reference is the same commands run into a folder with a current manifest, and hashlib's sha256 of the files.

Was: the stale ``viewer.html`` of an old trace folder stayed, no longer listed, so a later ``trace --html`` was
refused ("exists and was not written by linkwork"); an edited ``path.csv`` of an old folder was written over; an
``export -o mine.stl`` over the ``mine.stl`` an old manifest listed was refused, every time.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from linkwork.cli import app
from linkwork.io.writer import MANIFEST

ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")
TRACE = ["trace", "four-bar", "--until", "A=120", "--no-plots"]
OLD_FORMATS = ["format-2", "list"]


def invoke(*args: object) -> tuple[int, str]:
    result = CliRunner().invoke(app, [str(a) for a in args])
    assert "Traceback" not in result.stdout + result.stderr
    return result.exit_code, ANSI.sub("", result.stderr)


def entries(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` but the manifest, by relative path, with its bytes."""
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name != MANIFEST
    }


def sha256(path: Path) -> str:
    return "sha256:" + hashlib.sha256(path.read_bytes()).hexdigest()


def make_old(folder: Path, old_format: str, *, files: tuple[str, ...] = (), age: float = 120.0) -> int:
    """Rewrite ``folder``'s manifest as an older linkwork wrote it (no fingerprints), the run's entries and
    ``files`` listed, every entry last modified ``age`` seconds ago and the manifest a minute later (as the old
    writer left them: the manifest written after every entry). Returns the manifest's time (ns)."""
    current = json.loads((folder / MANIFEST).read_text())
    run = sorted(current["parts"]["run"])
    if old_format == "list":
        assert not files, "the earliest format listed a run's entries only"
        data: object = run
    else:
        data = {"format": 2, "parts": {"run": run}, "files": sorted(files)}
    (folder / MANIFEST).write_text(json.dumps(data))
    then = time.time_ns() - int(age * 1e9)
    for item in folder.rglob("*"):
        os.utime(item, ns=(then, then), follow_symlinks=False)
    written = then + 60 * 10**9
    os.utime(folder / MANIFEST, ns=(written, written))
    return written


@pytest.mark.parametrize("old_format", OLD_FORMATS)
def test_a_run_into_an_old_folder_removes_its_stale_entries_as_in_a_current_one(
    tmp_path: Path, old_format: str
) -> None:
    old, current = tmp_path / "old", tmp_path / "current"
    for out in (old, current):
        assert invoke(*TRACE, "--html", "-o", out)[0] == 0
    make_old(old, old_format)
    assert "viewer.html" in entries(old)
    for args in (["--until", "A=100"], ["--until", "A=90", "--html"], ["--until", "A=80"]):
        for out in (old, current):
            code, err = invoke(*TRACE[:2], *args, "--no-plots", "-o", out)
            assert code == 0, err
        # the stale viewer.html removed, then written again, then removed (report.json's timings differ)
        assert sorted(entries(old)) == sorted(entries(current))
    manifest, reference = (json.loads((out / MANIFEST).read_text()) for out in (old, current))
    assert {k: v for k, v in manifest.items() if k != "fingerprints"} == {
        k: v for k, v in reference.items() if k != "fingerprints"
    }
    assert manifest["format"] == 3 and manifest["legacy"] == {}
    assert manifest["fingerprints"] == {name: sha256(old / name) for name in manifest["parts"]["run"]}


@pytest.mark.parametrize("old_format", OLD_FORMATS)
def test_a_result_edited_since_an_old_manifest_is_refused_and_kept(tmp_path: Path, old_format: str) -> None:
    out = tmp_path / "old"
    assert invoke(*TRACE, "--html", "-o", out)[0] == 0
    make_old(out, old_format)
    with (out / "path.csv").open("a") as handle:  # saved by a spreadsheet now: newer than the manifest
        handle.write("my note\n")
    before = entries(out)
    manifest = (out / MANIFEST).read_bytes()
    code, err = invoke(*TRACE[:2], "--until", "A=100", "--no-plots", "-o", out)
    assert code == 2 and '"path.csv" holds something else than linkwork wrote there' in err
    assert entries(out) == before and (out / MANIFEST).read_bytes() == manifest


def test_a_single_file_an_old_manifest_lists_is_replaced_unless_edited_since(tmp_path: Path) -> None:
    """``export stl -o mine.stl`` into a folder whose format-2 manifest lists ``mine.stl``: replaced (and
    fingerprinted) as in a current folder; edited after the old manifest, refused."""
    out = tmp_path / "old"
    assert invoke(*TRACE, "-o", out)[0] == 0
    for folder, edited in ((out, False), (tmp_path / "edited", True)):
        if edited:
            assert invoke(*TRACE, "-o", folder)[0] == 0
        assert invoke("export", "stl", folder, "-o", folder / "mine.stl")[0] == 0
        make_old(folder, "format-2", files=("mine.stl",))
        if edited:
            (folder / "mine.stl").write_bytes(b"the user's own mesh")
        code, err = invoke("export", "stl", folder, "--scale", "2", "-o", folder / "mine.stl")
        if edited:
            assert code == 2 and "holds something else than linkwork wrote there" in err
            assert (folder / "mine.stl").read_bytes() == b"the user's own mesh"
        else:
            assert code == 0, err
            manifest = json.loads((folder / MANIFEST).read_text())
            assert manifest["files"] == ["mine.stl"]
            assert manifest["fingerprints"]["mine.stl"] == sha256(folder / "mine.stl")


def test_an_old_entry_keeps_its_manifests_time_across_later_commands(tmp_path: Path) -> None:
    """A run into an old folder leaves the single file ``mine.stl`` listed with the old manifest's time: edited
    after that run (so older than the new manifest, newer than the old one), it is still refused."""
    out = tmp_path / "old"
    assert invoke(*TRACE, "-o", out)[0] == 0
    assert invoke("export", "stl", out, "-o", out / "mine.stl")[0] == 0
    written = make_old(out, "format-2", files=("mine.stl",), age=600.0)
    assert invoke(*TRACE[:2], "--until", "A=100", "--no-plots", "-o", out)[0] == 0
    manifest = json.loads((out / MANIFEST).read_text())
    assert manifest["files"] == ["mine.stl"] and manifest["legacy"] == {"mine.stl": written}
    edit = written + 30 * 10**9  # between the old manifest and the run's new one
    (out / "mine.stl").write_bytes(b"the user's own mesh")
    os.utime(out / "mine.stl", ns=(edit, edit))
    assert (out / MANIFEST).stat().st_mtime_ns > edit
    code, err = invoke("export", "stl", out, "-o", out / "mine.stl")
    assert code == 2 and "holds something else than linkwork wrote there" in err
    assert (out / "mine.stl").read_bytes() == b"the user's own mesh"
