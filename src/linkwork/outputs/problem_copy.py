"""A copy of a synthesis problem (its file and its profiles) in an output folder, so the folder stands alone.

``linkwork synth`` writes it to ``OUT/problem/``; ``linkwork mechanize OUT`` reads it back from there.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path, PurePosixPath
from typing import Any

from linkwork.io.toml_reader import read_toml

#: The problem file's name inside the copy.
PROBLEM_FILE = "problem.toml"


def _plain(name: str) -> bool:
    """True for a relative path that stays inside the problem's folder (no ``..``, not absolute)."""
    path = PurePosixPath(name.replace("\\", "/"))
    return not path.is_absolute() and ".." not in path.parts and ":" not in name


def _toml_line(key: str, value: Any) -> str:
    """``key = value`` for the values a problem file holds (strings, numbers, booleans and lists of them);
    JSON's strings, numbers, booleans and arrays are TOML's."""
    return f"{key} = {json.dumps(value)}"


def copy_problem(problem_file: str | Path, folder: str | Path) -> list[Path]:
    """Copy ``problem_file`` and its profile files into ``folder`` (created); returns the files written.

    The problem file is copied as written when every profile path is a plain relative path; otherwise the
    profiles are copied next to it by their file names and the problem file is rewritten to name them so
    (comments are then not kept).
    """
    source = Path(problem_file)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    table = read_toml(source, "a problem file (TOML)")  # the one checked TOML reader
    profiles = [str(name) for name in table.get("profiles", [])]
    written: list[Path] = []
    if all(_plain(name) for name in profiles):
        targets = profiles
        shutil.copyfile(source, folder / PROBLEM_FILE)
    else:
        targets = copy_names(profiles)
        table = {**table, "profiles": targets}
        if "names" not in table:  # a copy renamed (``2_wing.dat``) keeps its profile's name (``wing``)
            table["names"] = [Path(name).stem for name in profiles]  # as load_problem names them
        lines = [f"# copy of {source.name} written by linkwork synth (profiles copied next to it)"]
        lines += [_toml_line(key, value) for key, value in table.items()]
        (folder / PROBLEM_FILE).write_text("\n".join(lines) + "\n", encoding="utf-8")
    written.append(folder / PROBLEM_FILE)
    for name, target in zip(profiles, targets, strict=True):
        destination = folder / target
        destination.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source.parent / name, destination)
        written.append(destination)
    return written


def copy_names(profiles: list[str]) -> list[str]:
    """The file name of each profile's copy beside the problem: its own file name, or, when that is already
    taken (two folders holding a ``wing.dat``, or ``Wing.dat`` and ``wing.dat``, one file on a file system that
    ignores case), ``<i>_<name>`` with ``i`` its position counted from 1 (and more ``_`` until it is free)."""
    taken: set[str] = set()
    names: list[str] = []
    for index, profile in enumerate(profiles, start=1):
        name = Path(profile).name
        candidate = name
        while candidate.casefold() in taken:
            candidate = f"{index}_{candidate}"
        taken.add(candidate.casefold())
        names.append(candidate)
    return names
