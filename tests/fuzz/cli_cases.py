"""Hostile command lines generated from the command definitions (issue 19 item 6).

:func:`parameters` walks the typer app as built (every command and subcommand, every option and argument, with
its type and, for a number, its bounds from ``FLAG_LIMITS``); :func:`cases` derives hostile values for each one
(wrong types, non-finite, huge, negative, zero, empty, just outside the bounds, hostile names, missing, empty,
binary and damaged files, symbolic links, read-only folders) and puts each into an otherwise valid command line.
A new command or flag is fuzzed without anyone writing its cases: only a required parameter with a new name needs
a valid value in :data:`VALID` (a test says so).

Values that need files are tokens (``{trace}``, ``@damaged:path.csv:truncate``) made real in each case's own
folder by :func:`materialize`.
"""

from __future__ import annotations

import os
import random
import shutil
import stat
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import typer.main

from linkwork.cli import app
from linkwork.cli.common import check_flags
from linkwork.cli.options import FLAG_LIMITS
from linkwork.limits import Limit


@dataclass(frozen=True)
class Param:
    """One parameter of one command, as the fuzz suite sees it."""

    command: tuple[str, ...]
    name: str
    flag: str | None  # the longest option name; None for an argument
    kind: str  # "int", "float", "bool", "str", "list", "path"
    required: bool
    limit: Limit | None

    @property
    def key(self) -> str:
        """The name of the parameter in VALID and in case ids: its flag, or its argument name."""
        return self.flag or self.name


def _kind(param: Any) -> str:
    annotation = param.type_descriptor.annotation
    if getattr(param, "is_flag", False) or annotation is bool:
        return "bool"
    if annotation is int:
        return "int"
    if annotation is float:
        return "float"
    if annotation is Path:
        return "path"
    if annotation == list[str]:
        return "list"
    return "str"


def parameters() -> list[Param]:
    """Every parameter of every (sub)command of the app, in the order of ``--help``."""
    root = typer.main.get_command(app)
    check_flags(root)
    out: list[Param] = []

    def walk(command: Any, path: tuple[str, ...]) -> None:
        for name, sub in getattr(command, "commands", {}).items():
            walk(sub, (*path, name))
        if getattr(command, "commands", None) is not None:
            return
        for p in command.params:
            is_option = p.param_type_name == "option"
            flag = max(p.opts, key=len) if is_option else None
            kind = _kind(p)
            limit = FLAG_LIMITS.get(flag) if flag and kind in ("int", "float") else None
            out.append(Param(path, p.name, flag, kind, bool(p.required), limit))

    walk(root, ())
    return out


def commands() -> list[tuple[str, ...]]:
    """Every command path of the app (with parameters or not)."""
    out: list[tuple[str, ...]] = []

    def walk(command: Any, path: tuple[str, ...]) -> None:
        subs = getattr(command, "commands", None)
        if subs is None:
            out.append(path)
            return
        for name, sub in subs.items():
            walk(sub, (*path, name))

    walk(typer.main.get_command(app), ())
    return sorted(out)


#: A valid value of each required parameter (by flag or argument name; ``command:name`` for one command only),
#: and of the output folder or file. Tokens in braces are made by :func:`materialize`.
VALID: dict[str, str] = {
    "spec": "bennett",
    "export mjcf:spec": "{trace}",
    "export dxf:spec": "{trace}",
    "trace_dir": "{trace}",
    "folder": "{synth}",
    "problem": "wing",
    "study_file": "{study}",
    "--samples": "5",
    "--hinge-position-tol": "1e-3",
    "--hinge-direction-tol": "0.1",
    "--out": "{out}",
    "export stl:--out": "{out}/parts.stl",
    "export mjcf:--out": "{out}/model.xml",
    "export dxf:--out": "{out}/drawing.dxf",
}

#: Settings that keep a valid run short (applied unless the case fuzzes that very flag).
QUICK: dict[tuple[str, ...], list[str]] = {
    ("trace",): ["--max-steps", "40", "--no-plots"],
    ("robustness",): ["--until", "A=90", "--steps", "5", "--workers", "0", "--no-plots"],
    ("sweep",): ["--workers", "0", "--no-plots"],
    ("synth",): ["--no-plots", "--time-limit", "1", "--attempts", "1"],
    ("mechanize",): ["--no-plots", "--time-limit", "1", "--attempts", "1"],
    ("demo",): ["--no-plots"],
}

#: Commands whose valid run takes minutes: only their cases that must be refused before any work are run.
SLOW = {("demo",)}

HOSTILE_NAMES = [
    "",
    "a\nb",
    "\x1b[31mred",
    "$HOME",
    "\\foo",
    "<&",
    "[/]",
    "A" * 5000,
    "ü∑",
    "..",
    "a/b",
    "-x",
]
HOSTILE_NUMBERS = ["nan", "inf", "-inf", "1e400", "-1", "0", "", "x", "1e12", "-99999999999999999999999"]
HOSTILE_PAIRS = ["=", "A=nan", "A=inf", "A=1e400", "a\nb=1", "$x=1", "A", "A=C=E", "[/]=1", "zz=1"]
#: A read-only folder only stops a user who is not root (the superuser writes anyway).
READ_ONLY = [] if os.geteuid() == 0 else ["@readonly-folder"]
FILE_KINDS = ["@missing", "@empty", "@binary", "@folder", "@symlink-user", *READ_ONLY]
OUT_KINDS = [
    "@out-user-file",
    "@out-symlink",
    "@out-with-user-file",
    *(["@out-readonly"] if READ_ONLY else []),
]
DAMAGES = ["truncate", "empty", "binary", "short-rows", "symlink"]
#: Paths the file system refuses to look up, or that are no file to read: a name longer than 255 bytes, a path
#: through a user's file, a FIFO (reading it would block for ever). Every path of every command gets each and
#: must refuse it before any work (exit 2, one line), never as an ``OSError`` (exit 3) or a hang.
REFUSED_PATHS = ["@long-name", "@through-file", "@fifo"]
REFUSED_OUTS = ["@out-long-name", "@out-through-file"]
#: Longer than any file system's limit on one name (255 bytes).
LONG_NAME = "n" * 300


def valid(param: Param) -> str | None:
    """The valid value of ``param`` (``None``: it has none and is left out unless required)."""
    return VALID.get(f"{' '.join(param.command)}:{param.key}", VALID.get(param.key))


def _numbers(param: Param) -> list[str]:
    values = list(HOSTILE_NUMBERS)
    if param.kind == "int":
        values.append("1.5")
    if param.limit is not None:
        low, high = param.limit.low, param.limit.upper
        step = 1 if param.limit.whole else abs(high - low) * 1e-9 or 1e-9
        # just outside both ends, and the low end itself (the high end is valid and can be hours of work)
        values += [repr(low - step), repr(high + step), repr(low)]
    return values


@dataclass(frozen=True)
class Case:
    """One command line with one hostile value: ``command``, the parameter fuzzed and its value."""

    command: tuple[str, ...]
    target: str
    value: str
    refused_before_work: bool = False

    @property
    def id(self) -> str:
        shown = self.value.encode("unicode_escape").decode()
        shown = shown if self.value.startswith("@") else shown[:24]
        return f"{' '.join(self.command)}|{self.target}|{shown}"


def _values(param: Param, folder_files: dict[str, list[str]]) -> Iterator[tuple[str, bool]]:
    """Hostile values of ``param`` and whether each must be refused before any work starts."""
    if param.kind in ("int", "float"):
        for value in _numbers(param):
            yield value, value in ("nan", "inf", "-inf", "1e400", "", "x", "1.5")
    elif param.kind == "bool":
        yield "@present", False
    elif param.kind == "list":
        for value in HOSTILE_PAIRS + HOSTILE_NAMES[:4]:
            yield value, False
    elif param.key == "--out":
        for value in OUT_KINDS:
            yield value, value == "@out-user-file"
    else:
        base = valid(param) or ""
        for value in HOSTILE_NAMES:
            yield value, False
        if param.kind != "path" and not base:
            return  # a name (a joint, a body), not a file
        for value in FILE_KINDS:
            yield value, True
        token = base.strip("{}")
        for file in folder_files.get(token, [""] if base.startswith("{") and token != "out" else []):
            for how in DAMAGES:
                if how == "short-rows" and not file.endswith(".csv"):
                    continue
                yield f"@damaged:{token}:{file}:{how}", False


def cases(folder_files: dict[str, list[str]]) -> list[Case]:
    """Every generated case. ``folder_files`` lists the files of each real-run folder token (``trace``:
    ``["path.csv", ...]``), whose damaged copies are fuzzed where a command reads that folder."""
    out = [Case(command, "", "@plain") for command in commands() if command not in SLOW]  # each as it is
    for param in parameters():
        for value, early in _values(param, folder_files):
            case = Case(param.command, param.key, value, early)
            if param.command in SLOW and not early:
                continue
            out.append(case)
    return out


def sample(all_cases: list[Case], count: int, seed: int = 19) -> list[Case]:
    """A fixed, seeded subset of ``count`` cases with at least one case of every command and parameter kind."""
    rng = random.Random(seed)
    chosen: dict[str, Case] = {}
    by_command: dict[tuple[str, ...], list[Case]] = {}
    for case in all_cases:
        by_command.setdefault(case.command, []).append(case)
    for group in by_command.values():
        pick = rng.choice(group)
        chosen[pick.id] = pick
    rest = [c for c in all_cases if c.id not in chosen]
    for case in rng.sample(rest, max(0, min(len(rest), count - len(chosen)))):
        chosen[case.id] = case
    return sorted(chosen.values(), key=lambda c: c.id)


def command_line(case: Case, home: Path, fixtures: dict[str, Path]) -> tuple[list[str], Path]:
    """The argument list of ``case`` made real in ``home`` (files copied or damaged there), and its --out."""
    params = [p for p in parameters() if p.command == case.command]
    out = home / "out"
    args = list(case.command)
    options: list[str] = []
    positional: list[str] = []
    for param in params:
        value: str | None
        if param.key == case.target:
            value = case.value
        elif param.required or param.key == "--out":
            value = valid(param)
        else:
            continue
        if value is None:
            raise AssertionError(f"no valid value for {' '.join(param.command)} {param.key}: add it to VALID")
        if param.key == "--out" and value.startswith("@out"):
            value = materialize_out(value, out, (valid(param) or "").partition("{out}/")[2])
        else:
            value = materialize(value, home, fixtures, out)
        if param.flag is None:
            positional.append(value)
        elif param.kind == "bool":
            options.append(param.flag)
        else:
            options += [param.flag, value]
    quick = QUICK.get(case.command, [])
    for i in range(0, len(quick)):
        flag = quick[i]
        if not flag.startswith("--") or flag == case.target or flag in options:
            continue
        takes_value = i + 1 < len(quick) and not quick[i + 1].startswith("--")
        options += [flag, quick[i + 1]] if takes_value else [flag]
    return [*args, *positional, *options], out


def materialize(value: str, home: Path, fixtures: dict[str, Path], out: Path) -> str:
    """A token made real in ``home``: ``{trace}`` a copy of a real trace folder, ``@binary`` a binary file..."""
    if "{out}" in value:
        return value.replace("{out}", str(out))
    if value.startswith("{") and value.endswith("}"):
        return _copy(fixtures, value.strip("{}"), home)
    if not value.startswith("@"):
        return value
    user = home / "user.txt"
    user.write_text("the user's own file\n", encoding="utf-8")
    target = home / "input"
    match value.split(":")[0]:
        case "@missing":
            return str(home / "missing.toml")
        case "@empty":
            target.write_bytes(b"")
        case "@binary":
            target.write_bytes(bytes(range(256)) * 8)
        case "@folder":
            target.mkdir()
        case "@symlink-user":
            target.symlink_to(user)
        case "@readonly-folder":
            target.mkdir()
            (target / "inside.toml").write_text("x = 1\n", encoding="utf-8")
            target.chmod(stat.S_IRUSR | stat.S_IXUSR)
        case "@long-name":
            return str(home / f"{LONG_NAME}.toml")
        case "@through-file":
            return str(user / "input.toml")
        case "@fifo":
            target = home / "input.toml"
            os.mkfifo(target)
        case "@present" | "@plain":
            return value
        case "@damaged":
            _, token, file, how = value.split(":", 3)
            copied = Path(_copy(fixtures, token, home))
            damage(copied / file if file else copied, how, user)  # a file of a folder, or the file itself
            return str(copied)
    return str(target)


def materialize_out(value: str, out: Path, file_name: str = "") -> str:
    """A hostile --out: a user's file, a link to a user's folder, a read-only folder, a folder with a user file,
    a name too long, a path through a user's file. ``file_name`` is the file a single-file output writes
    (``parts.stl``), whose suffix a refused path keeps so that it is refused for the path, not the suffix."""
    home = out.parent
    match value:
        case "@out-long-name":
            return str(home / (LONG_NAME + Path(file_name).suffix))
        case "@out-through-file":
            out.write_text("the user's own file\n", encoding="utf-8")
            return str(out / (file_name or "inside"))
        case "@out-user-file":
            out.write_text("the user's own file\n", encoding="utf-8")
        case "@out-symlink":
            (home / "elsewhere").mkdir()
            (home / "elsewhere" / "notes.txt").write_text("keep\n", encoding="utf-8")
            out.symlink_to(home / "elsewhere")
        case "@out-readonly":
            out.mkdir()
            out.chmod(stat.S_IRUSR | stat.S_IXUSR)
        case "@out-with-user-file":
            out.mkdir()
            (out / "notes.txt").write_text("the user's own notes\n", encoding="utf-8")
    return str(out)


def _copy(fixtures: dict[str, Path], token: str, home: Path) -> str:
    source = fixtures[token]
    target = home / source.name
    if source.is_dir():
        shutil.copytree(source, target, symlinks=True)
    else:
        shutil.copy2(source, target)
    return str(target)


def damage(file: Path, how: str, user: Path) -> None:
    """Damage one file of a real run the ways a disk, an editor or a person does."""
    data = file.read_bytes()
    match how:
        case "truncate":
            file.write_bytes(data[: len(data) // 2])
        case "empty":
            file.write_bytes(b"")
        case "binary":
            file.write_bytes(bytes(range(256)) * 4)
        case "short-rows":
            lines = data.decode("utf-8").splitlines() or [""]
            file.write_text("\n".join([lines[0], *(",".join(r.split(",")[:-1]) for r in lines[1:])]) + "\n")
        case "symlink":
            file.unlink()
            file.symlink_to(user)


def restore_permissions(home: Path) -> None:
    """Make every folder under ``home`` writable again (so the test's folder can be removed)."""
    for root, dirs, _ in os.walk(home):
        for d in dirs:
            path = Path(root) / d
            if not path.is_symlink():
                path.chmod(stat.S_IRWXU)
