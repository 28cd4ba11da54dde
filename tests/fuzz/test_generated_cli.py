"""The fuzz suite generated from the command definitions (issue 19 item 6): every parameter of every command gets
hostile values (see cli_cases.py), each run in-process through the app, and every run must keep the promises:
exit code 0, 2 or 3; no traceback; a failure is one ``error:`` line; --out unchanged on exit 2 and nothing outside
it changed (fuzzkit.run_cli); no user file replaced; no non-finite number in an output; a bounded time per case;
a value that must be refused before any work is refused (exit 2).

CI runs a fixed, seeded sample (``LINKWORK_FUZZ_CASES``, default 40, with every command in it); run every case
with ``LINKWORK_FUZZ=full python -m pytest tests/fuzz/test_generated_cli.py``.
"""

from __future__ import annotations

import csv
import json
import os
import re
import signal
import tempfile
import zlib
from collections.abc import Iterator
from pathlib import Path
from types import FrameType
from typing import Any

import pytest
from cli_cases import (
    REFUSED_OUTS,
    REFUSED_PATHS,
    SLOW,
    Case,
    Param,
    cases,
    command_line,
    commands,
    parameters,
    restore_permissions,
    sample,
    valid,
)
from fuzzkit import run_cli
from typer.testing import CliRunner

from linkwork.cli import app
from linkwork.errors import SpecError

#: Seconds one case may take (a loaded machine; the slowest valid run, a 1-second mechanization, takes ~10).
CASE_SECONDS = int(os.environ.get("LINKWORK_FUZZ_CASE_SECONDS", "180"))


#: Damaged files of a trace folder that ``export`` reads into a traceback today (JSONDecodeError,
#: UnicodeDecodeError, IndexError), found by this suite: ``(command, file, damage)``.


STUDY = 'linkage = "bennett"\n[trace]\nuntil = "A=90"\nsteps = 5\n[grid]\nalpha1 = [30, 40]\n'


def _real_runs() -> dict[str, Path]:
    """Folders written by real runs (a trace, a synthesis) and a study file, made once per test session."""
    home = Path(tempfile.mkdtemp(prefix="linkwork-fuzz-"))
    runner = CliRunner()
    trace, synth = home / "trace", home / "synth"
    for args in (
        ["trace", "bennett", "--max-steps", "40", "--no-plots", "-o", str(trace)],
        ["synth", "wing", "--no-plots", "-o", str(synth)],
    ):
        result = runner.invoke(app, args)
        assert result.exit_code == 0, (args, result.stderr)
    study = home / "study.toml"
    study.write_text(STUDY, encoding="utf-8")
    return {"trace": trace, "synth": synth, "study": study}


FIXTURES = _real_runs()
FOLDER_FILES = {
    token: sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())
    for token, folder in FIXTURES.items()
    if folder.is_dir()
}
ALL = cases(FOLDER_FILES)
FULL = os.environ.get("LINKWORK_FUZZ", "").lower() == "full"
CHOSEN = ALL if FULL else sample(ALL, int(os.environ.get("LINKWORK_FUZZ_CASES", "40")))


def test_the_generator_covers_every_command_and_parameter() -> None:
    """A new command or flag is fuzzed without anyone writing its cases: every parameter of every command of
    the app has generated cases, every required parameter a valid value, every numeric flag declared bounds."""
    params = parameters()
    assert {p.command for p in params} <= set(commands()) and len(commands()) >= 11
    fuzzed = {(c.command, c.target) for c in ALL}
    for param in params:
        # a slow command (the demo) gets only the cases refused before any work
        assert (param.command, param.key) in fuzzed or param.command in SLOW, param
        if param.required:
            assert valid(param) is not None, f"add a valid value of {param.key} to cli_cases.VALID"
        if param.kind in ("int", "float"):
            assert param.limit is not None, f"declare the bounds of {param.key} in cli/options.py FLAG_LIMITS"
    assert {c.command for c in CHOSEN} == set(commands())  # the CI sample runs every command


@pytest.fixture
def home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    monkeypatch.chdir(tmp_path)
    yield tmp_path
    restore_permissions(tmp_path)


class CaseTimeout(Exception):
    """A case ran longer than CASE_SECONDS."""


def _alarm(signum: int, frame: FrameType | None) -> None:
    raise CaseTimeout(f"a case took longer than {CASE_SECONDS} s")


@pytest.mark.parametrize(
    "case",
    [pytest.param(c, id=c.id) for c in CHOSEN],
)
def test_a_generated_hostile_case_keeps_every_promise(home: Path, case: Case) -> None:
    args, out = command_line(case, home, FIXTURES)
    if any(a.startswith(f"{out}/") for a in args) and not out.exists():
        out.mkdir()  # a single-file output goes into a folder of the test's own
    notes = out / "notes.txt"
    before_notes = notes.read_bytes() if notes.is_file() and not out.is_symlink() else None
    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(CASE_SECONDS)
    try:
        run = run_cli(args, out=out, home=home)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    if case.refused_before_work:
        assert run.code == 2, (case.id, run)
    if before_notes is not None:
        assert notes.read_bytes() == before_notes, "a user's file in --out was replaced"
    if (home / "elsewhere" / "notes.txt").exists():
        assert (home / "elsewhere" / "notes.txt").read_text() == "keep\n"
    if run.code in (0, 3):
        for file in _outputs(out):
            assert_finite(file)


def _refused_path_cases() -> list[Case]:
    """Every path of every command (an input file or folder, ``--out``) with each path the file system refuses:
    a name too long, a path through a file, a FIFO."""
    out = []
    for param in parameters():
        if param.key == "--out":
            kinds = REFUSED_OUTS
        elif param.kind == "path" or (valid(param) or "").startswith("{") or param.key == "spec":
            kinds = REFUSED_PATHS
        else:
            continue
        out += [Case(param.command, param.key, kind, refused_before_work=True) for kind in kinds]
    return out


@pytest.mark.parametrize("case", [pytest.param(c, id=c.id) for c in _refused_path_cases()])
def test_a_path_the_file_system_refuses_is_bad_input_in_one_line(home: Path, case: Case) -> None:
    """A path no file can be read from or written to (a name longer than 255 bytes, a path through a file, a
    FIFO) is bad input: exit 2 before any work, one line naming the path (or its flag), never the ``OSError``
    of the first function that touched it (which was exit 3, without saying what was expected) or a hang."""
    args, out = command_line(case, home, FIXTURES)
    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(60)  # a FIFO opened for reading blocks until a writer comes: a hang is a failure
    try:
        run = run_cli(args, out=out, home=home)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    assert run.code == 2, (case.id, run.stderr)
    assert ".linkwork-" not in run.stderr and "Errno" not in run.stderr, (
        run.stderr
    )  # the user's path, in words


def _outputs(out: Path) -> list[Path]:
    if out.is_symlink() or not out.exists():
        return []
    return [p for p in out.rglob("*") if p.is_file() and not p.is_symlink()]


NONFINITE = re.compile(r"(?<![A-Za-z_])[-+]?(nan|inf|infinity)(?![A-Za-z_])", re.IGNORECASE)


def assert_finite(file: Path) -> None:
    """No NaN or infinity in a written file (JSON parsed strictly, CSV cell by cell, text formats by token)."""
    if file.suffix == ".json":

        def refuse(token: str) -> None:
            raise AssertionError(f"{file.name}: non-finite {token}")

        json.loads(file.read_text(encoding="utf-8"), parse_constant=refuse)
    elif file.suffix == ".csv":
        with file.open(encoding="utf-8", newline="") as fh:
            for row in csv.reader(fh):
                for cell in row:
                    assert cell.strip().lower() not in ("nan", "inf", "-inf", "+inf"), (file.name, row)
    elif file.suffix in (".stl", ".dxf", ".dat"):
        text = file.read_bytes().decode("utf-8", errors="replace")
        assert not NONFINITE.search(text), file.name


# ------------------------------------------------------------------------- study keys, from their bounds

#: Hostile TOML values of a numeric key: wrong types, non-finite, huge, negative, zero, just outside.
TOML_VALUES = ['"x"', "[1, 2]", "true", "{ a = 1 }", "nan", "inf", "-inf", "-1", "0", "1e300", "1.5",
               "9223372036854775807"]  # fmt: skip


def study_text(key: str, value: str) -> str:
    """A valid linkage study with ``key`` (a key path) set to ``value`` (TOML text)."""
    sections = {
        "": 'linkage = "bennett"\n',
        "trace": 'until = "A=90"\nsteps = 5\n',
        "grid": "alpha1 = [30, 40]\n",
        "robustness": "samples = 3\nhinge_position_tol = 0.001\nhinge_direction_tol = 0.05\n",
    }
    table, _, name = key.rpartition(".")
    body = re.sub(rf"^{name} = .*\n", "", sections[table], flags=re.MULTILINE)
    sections[table] = body + f"{name} = {value}\n"
    return sections[""] + "".join(f"[{t}]\n{b}" for t, b in sections.items() if t)


def _study_cases() -> list[tuple[str, str, str]]:
    """``(key path, value, study text)`` for every numeric key of a study file (from its declared bounds) and
    every hostile value."""
    from linkwork.studies.study_file import KEY_LIMITS, SYNTHESIS_GRID_LIMITS

    out = []
    for key, limit in KEY_LIMITS.items():
        edges = [repr(limit.low), repr(limit.upper), str(int(limit.low) - 1), str(int(limit.upper) + 1)]
        for value in TOML_VALUES + edges:
            out.append((key, value, study_text(key, value)))
    for key, limit in SYNTHESIS_GRID_LIMITS.items():
        for value in [*TOML_VALUES, repr(limit.low), repr(limit.upper)]:
            out.append((f"grid.{key}[0]", value, f'problem = "seat"\n[grid]\n{key} = [{value}]\n'))
    return out


@pytest.mark.parametrize(("key", "value", "text"), _study_cases(), ids=lambda x: str(x)[:30])
def test_a_hostile_study_key_is_refused_before_any_work(home: Path, key: str, value: str, text: str) -> None:
    """Every numeric key of a study file: a value outside its declared bounds, or of the wrong type, is refused
    before any point runs, in one line naming the file and the key (exit 2); one inside is read."""
    import tomllib

    from linkwork.studies.study_file import KEY_LIMITS, SYNTHESIS_GRID_LIMITS, load_study

    study = home / "study.toml"
    study.write_text(text, encoding="utf-8")
    parsed = tomllib.loads(text)
    name = key.split("[")[0]
    limit = KEY_LIMITS.get(name) or SYNTHESIS_GRID_LIMITS[name.removeprefix("grid.")]
    node: object = parsed
    for part in name.split("."):
        node = node[part]  # type: ignore[index]
    given = node[0] if name.startswith("grid.") else node  # type: ignore[index]
    if not limit.broken(given):  # read, or refused for another stated limit (the work it asks for)
        try:
            assert load_study(study).count() >= 1
        except SpecError as exc:
            assert "study.toml: " in str(exc) and "expected at most" in str(exc) and "\n" not in str(exc)
        return
    with pytest.raises(SpecError) as refused:
        load_study(study)
    assert f"study.toml: {key}: expected " in str(refused.value) and "\n" not in str(refused.value)
    if FULL or zlib.crc32(f"{key}{value}".encode()) % 16 == 0:  # the command line, for a fixed 1/16
        out = home / "out"
        run = run_cli(
            ["sweep", str(study), "--workers", "0", "--no-plots", "-o", str(out)], out=out, home=home
        )
        assert run.code == 2 and str(refused.value) in run.stderr, run


@pytest.mark.parametrize(
    "param",
    [
        pytest.param(p, id=f"{' '.join(p.command)}|{p.flag}")
        for p in parameters()
        if p.flag is not None and p.kind in ("int", "float", "str", "path")
    ],
)
def test_an_option_of_one_value_given_twice_is_refused(home: Path, param: Param) -> None:
    """Every option that takes one value, of every command, given twice (``--until A=80 --until A=90``): click
    kept the last silently, so a slip ran with a value the user did not mean; now one line, exit 2, before any
    work. The short form counts as the long one (``-o a --out b``)."""
    assert param.flag is not None
    short = [o for o in _option(param).opts if len(o) == 2]
    run = run_cli([*param.command, param.flag, "1", *(short or [param.flag]), "1"], home=home)
    assert run.code == 2
    assert run.stderr.strip() == f"error: {param.flag} given twice; expected it once (it takes one value)"


def _option(param: Param) -> Any:
    """The click option of ``param`` in the built app."""
    import typer.main

    command: Any = typer.main.get_command(app)
    for name in param.command:
        command = command.commands[name]
    return next(p for p in command.params if p.name == param.name)


@pytest.mark.parametrize(
    "repeatable", [["--set", "alpha1=40", "--set", "alpha2=130"], ["--no-plots", "--no-plots"]]
)
def test_repeatable_options_and_flags_may_be_repeated(home: Path, repeatable: list[str]) -> None:
    out = home / "out"
    run = run_cli(["trace", "bennett", "--max-steps", "10", "-o", str(out), *repeatable], out=out, home=home)
    assert run.code == 0, run.stderr
