"""The second red-team round (hostile inputs of kinds the fuzz suite did not cover), one property per kind of
failure, each over every input of that kind the app or the library declares, and each failing on the code before
its fix in the one layer every command goes through:

- a numeric flag's text: every int and float flag of every command, typed as no person types a number (``1_0``,
  Arabic-Indic digits, spaces around it, ``3.0`` for a whole number), was taken by click (``--steps 1_0`` traced
  10 steps, exit 0) instead of following the rule of ``--set``, ``--until`` and profile files;
- the environment numba and matplotlib read as they load (``NUMBA_NUM_THREADS=0``, ``MPLBACKEND=garbage``):
  a traceback, exit 1;
- a summary line broken by the console inside a path (``COLUMNS=10`` on a pipe);
- ``--max-step`` (and ``max_step``) below the tracer's smallest step: the whole budget spent advancing nothing;
- a problem file's mechanization keys above their flags' bounds (``time_limit = 1e308``);
- the Python API given the wrong types (``lw.load(3)``, ``lw.trace("four-bar")``, ``progress=3``,
  ``max_steps=2**70``): Python's or numpy's errors from inside; numpy scalars refused by ``lw.load``.
"""

from __future__ import annotations

import inspect
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from cli_cases import Case, command_line, parameters
from fuzzkit import run_cli
from test_generated_cli import FIXTURES

import linkwork as lw
from linkwork import limits
from linkwork.cli.common import environment_misuse
from linkwork.cli.options import FLAG_LIMITS
from linkwork.data import problem_file
from linkwork.errors import SpecError
from linkwork.io.problem import load_problem
from linkwork.outputs.staging import console

NUMERIC = [p for p in parameters() if p.kind in ("int", "float")]

#: Numbers as no person types them, each taken by click's conversion before (Python's ``int``/``float``).
ODD_NUMBERS = ["1_0", "\u0661", " 1", "1 ", "\uff11"]


@pytest.mark.parametrize("param", NUMERIC, ids=lambda p: f"{' '.join(p.command)} {p.flag}")
def test_a_numeric_flag_typed_as_no_person_types_a_number_is_refused(tmp_path: Path, param) -> None:  # type: ignore[no-untyped-def]
    """Every numeric flag of every command follows ``limits.PLAIN_NUMBER`` / ``PLAIN_INTEGER``, the rule of
    ``--set``, ``--until`` and profile files, and the line names the flag, the value and the flag's bounds."""
    values = ODD_NUMBERS + (["1.0", "1e0"] if param.kind == "int" else [])
    for i, value in enumerate(values):
        home = tmp_path / str(i)
        home.mkdir()
        args, out = command_line(Case(param.command, param.flag, value), home, FIXTURES)
        run = run_cli(args, out=out, home=home)
        assert run.code == 2, (args, run)
        assert f"error: {param.flag} " in run.stderr, run.stderr
        limit = FLAG_LIMITS.get(param.flag)
        if limit is not None:
            assert limit.expected(param.flag) in run.stderr


def test_environment_values_numba_and_matplotlib_refuse_are_one_line() -> None:
    """The values numba and matplotlib refuse with a traceback as they load are refused before any work; the
    ones they take pass. Checked against the libraries themselves: numba's thread count is read by a fresh
    interpreter, matplotlib's backend by its own validator."""
    from matplotlib.rcsetup import validate_backend

    for threads in ["0", "-1", "x", "", "2.5", "\u0663", "1", "2", " 3", "64"]:
        refused = environment_misuse({"NUMBA_NUM_THREADS": threads}) is not None
        numba_takes = threads.strip().isascii() and threads.strip().isdigit() and int(threads) >= 1
        assert refused == (not numba_takes), threads
    for backend in [
        "garbage",
        "Agg",
        "agg",
        "svg",
        "pdf",
        "module://matplotlib_inline.backend_inline",
        "tkagg",
    ]:
        try:
            validate_backend(backend)
            taken = True
        except ValueError:
            taken = False
        assert (environment_misuse({"MPLBACKEND": backend}) is None) == taken, backend
    assert environment_misuse({}) is None


def test_a_refused_environment_is_one_line_in_a_real_process(tmp_path: Path) -> None:
    """As real processes (numba is imported with linkwork, before any command): one line, exit 2, no
    traceback; run side by side."""
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_NUM_THREADS", "MPLBACKEND")}
    script = [sys.executable, "-c", "from linkwork.cli import main; main()", "linkages"]
    runs = {
        name: subprocess.Popen(
            script, env={**env, name: value}, stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=tmp_path
        )
        for name, value in [("NUMBA_NUM_THREADS", "0"), ("MPLBACKEND", "garbage")]
    }
    for name, process in runs.items():
        _, err = process.communicate(timeout=120)
        text = err.decode()
        assert process.returncode == 2, text
        assert "Traceback" not in text
        assert text.strip().splitlines() == [text.strip()] and text.startswith(
            f"error: environment variable {name}="
        )


def test_a_summary_line_is_never_broken_inside_a_path(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """On a pipe with a narrow ``COLUMNS`` the console broke ``wrote ... to PATH`` inside the path and the file
    names; every plain line is printed whole (a terminal wraps it for the eye)."""
    out = tmp_path / ("a-folder-name-longer-than-any-terminal-" * 3)
    for columns in ["10", "1", "0", "40"]:
        monkeypatch.setenv("COLUMNS", columns)
        with console.capture() as captured:
            console.print(f"wrote path.csv, report.json to {out}/")
        assert captured.get() == f"wrote path.csv, report.json to {out}/\n"
    monkeypatch.setenv("COLUMNS", "10")
    run = run_cli(["trace", "four-bar", "--until", "A=120", "--no-plots", "-o", str(out)])
    assert run.code == 0, run
    assert f"mechanism.toml to {out}/" in run.stdout


def test_max_step_below_the_tracers_smallest_step_is_refused() -> None:
    """The flag's lower bound is the tracer's own smallest step (read from ``lw.trace``'s signature), and the
    API refuses a largest step below its smallest: ``max_step=1e-320`` ran 5,000 steps that moved nothing."""
    min_step = inspect.signature(lw.trace).parameters["min_step"].default
    assert limits.SMALLEST_STEP_DEGREES == pytest.approx(math.degrees(min_step), rel=1e-15)
    assert FLAG_LIMITS["--max-step"].low == limits.SMALLEST_STEP_DEGREES
    mech = lw.load("four-bar")
    for max_step, smallest in [(1e-320, 1e-9), (1e-10, 1e-9), (0.01, 0.02)]:
        with pytest.raises(SpecError, match="expected at least min_step"):
            lw.trace(mech, max_step=max_step, min_step=smallest, max_steps=10)
    assert len(lw.trace(mech, max_step=1e-9, min_step=1e-9, max_steps=3).branches) == 1


@pytest.mark.parametrize("key", sorted(limits.MECHANIZE))
def test_a_problem_key_cannot_ask_what_its_flag_refuses(tmp_path: Path, key: str) -> None:
    """Every mechanization option has one bound for its flag and its problem-file key: a value above the flag's
    bound (``time_limit = 1e308``, ``link_offset = 1e300``, ``attempts = 10**9``) is refused naming the key."""
    limit = limits.MECHANIZE[key]
    source = problem_file("closed")
    folder = tmp_path / "closed"
    shutil.copytree(source.parent, folder)
    above = int(limit.upper) * 10 + 1 if limit.whole else limit.upper * 1e3
    problem = folder / source.name
    problem.write_text(problem.read_text() + f"mechanize = true\n{key} = {above!r}\n", encoding="utf-8")
    with pytest.raises(SpecError) as refused:
        load_problem(problem)
    message = str(refused.value)
    assert f"{key}:" in message and "\n" not in message, message
    within = limit.upper if not limit.open_high else (limit.upper - 1)
    problem.write_text(
        problem.read_text().replace(f"{key} = {above!r}", f"{key} = {within!r}"), encoding="utf-8"
    )
    if key != "min_transmission":  # 89 degrees is a bound, not a design anyone meets
        load_problem(problem)


@pytest.mark.parametrize("value", [3, None, b"four-bar", ["four-bar"], 2.5, {"spec": "x"}])
def test_the_api_refuses_what_is_not_a_name_or_a_path_as_one_spec_error(value: object) -> None:
    with pytest.raises(SpecError, match=r"spec=.*expected a built-in name or the path"):
        lw.load(value)  # type: ignore[arg-type]
    with pytest.raises(SpecError, match=r"problem=.*expected a Problem"):
        lw.synthesize(value)  # type: ignore[arg-type]
    with pytest.raises(SpecError, match=r"mech=.*expected a Mechanism"):
        lw.trace(value)  # type: ignore[arg-type]


def test_the_api_refuses_settings_that_failed_inside_the_trace() -> None:
    mech = lw.load("four-bar")
    for settings, words in [
        ({"progress": 3}, "progress=3: expected a function"),
        ({"branches": "no"}, "branches='no': expected True or False"),
        ({"max_steps": 2**70}, "max_steps=.*1 <= max_steps <= 1000000"),
        ({"until": ("A", 2.0), "steps": 2**70}, "steps=.*1 <= steps <= 1000000"),
    ]:
        with pytest.raises(SpecError, match=words):
            lw.trace(mech, **settings)  # type: ignore[arg-type]
    assert lw.trace(mech, branches=np.bool_(False), max_steps=5).branches


@pytest.mark.parametrize(
    ("name", "key", "plain", "numpy_values"),
    [
        ("bennett", "alpha1", 0.5, [np.float32(0.5), np.float64(0.5), np.array(0.5), np.float16(0.5)]),
        ("hedgepeth", "n", 6, [np.int64(6), np.int32(6), np.uint8(6), np.array(6)]),
    ],
)
def test_lw_load_takes_numpy_numbers_as_the_numbers_they_hold(
    name: str, key: str, plain: float, numpy_values: list[object]
) -> None:
    """``lw.load("bennett", alpha1=np.float32(0.5))`` was refused ("got 0.5") while ``lw.trace`` takes numpy's
    numbers: the mechanism equals the one from the plain number (twists compared bit for bit)."""
    expected = lw.load(name, **{key: plain})
    for value in numpy_values:
        got = lw.load(name, **{key: value})
        assert np.array_equal(got.twists, expected.twists), value
    with pytest.raises(SpecError):
        lw.load(name, **{key: np.array([plain, plain])})


HUGE = "9" * 5000
"""A whole number of 5,000 digits: Python's ``int`` refuses more than 4,300 with a ``ValueError`` that tomllib
and ``--set`` let out as a traceback."""


def test_a_number_of_thousands_of_digits_is_one_line_in_every_toml_file(tmp_path: Path) -> None:
    """Every TOML file goes through ``read_toml``: a spec, a problem and a study holding a 5,000-digit number
    are one ``SpecError`` naming the file and the line."""
    from linkwork.io.spec_writer import dump_spec
    from linkwork.studies.sweep import read_study

    spec = tmp_path / "spec.toml"
    spec.write_text(
        dump_spec(lw.load("four-bar")) + f"\n[[points]]\nname = 'Q'\nbody = 'crank'\nposition = [{HUGE}, 0]\n"
    )
    problem = tmp_path / "closed" / "problem.toml"
    shutil.copytree(problem_file("closed").parent, problem.parent)
    problem.write_text(problem.read_text().replace("seed = 1", f"seed = {HUGE}"))
    study = tmp_path / "study.toml"
    study.write_text(f'name = "s"\nlinkage = "bennett"\n[grid]\nalpha1 = [{HUGE}]\n')
    for file, read in [(spec, lw.load), (problem, load_problem), (study, read_study)]:
        with pytest.raises(SpecError) as refused:
            read(file)
        message = str(refused.value)
        assert str(file) in message and "line " in message and "\n" not in message and len(message) < 300


def test_a_set_value_or_a_flag_of_thousands_of_digits_is_one_line() -> None:
    for args in (
        ["show", "hedgepeth", "--set", f"n={HUGE}"],
        ["show", "bennett", "--set", f"alpha1={HUGE}"],
        ["trace", "four-bar", "--until", "A=120", "--steps", HUGE],
    ):
        run = run_cli(args)
        assert run.code == 2 and "expected" in run.stderr and len(run.stderr) < 400, run


@pytest.mark.parametrize("typed", ["1_0", "\u0661\u0660", "1 0", "0x10"])
def test_joint_values_typed_in_study_files_and_region_flags_follow_the_one_rule(
    tmp_path: Path, typed: str
) -> None:
    """``trace.until``, ``criteria.deployed_at`` and ``--ground-region`` read their numbers with Python's
    ``float`` (``"A=1_0"`` was A at 10 degrees) while ``--until`` and ``--deployed-at`` refuse them."""
    from linkwork.mechanization.options import parse_region_flag
    from linkwork.studies.search import load_search
    from linkwork.studies.sweep import read_study

    study = tmp_path / "study.toml"
    study.write_text(
        f'name = "s"\nlinkage = "bennett"\n[trace]\nuntil = "A={typed}"\n[grid]\nalpha1 = [30]\n'
    )
    with pytest.raises(SpecError, match=r"trace\.until"):
        read_study(study)
    search = tmp_path / "search.toml"
    text = (Path(__file__).parents[2] / "examples" / "studies" / "rect-frame-search.toml").read_text()
    search.write_text(text.replace('deployed_at = "A=0"', f'deployed_at = "A={typed}"'))
    with pytest.raises(SpecError, match=r"criteria\.deployed_at"):
        load_search(search)
    with pytest.raises(SpecError, match="--ground-region"):
        parse_region_flag(f"{typed},0,20,20")
    assert parse_region_flag(" 10, 0,20,20") == [10.0, 0.0, 20.0, 20.0]


@pytest.mark.parametrize(
    "planted",
    [
        ["thesis.docx"],  # the earliest format: a list of names
        {"format": 2, "parts": {"run": ["thesis.docx", "path.csv"]}, "files": []},
        {"format": 2, "parts": {"mechanize": ["thesis.docx"]}, "files": ["thesis.docx"]},
        {
            "format": 3,
            "parts": {"run": ["thesis.docx"]},
            "files": [],
            "fingerprints": {"thesis.docx": "sha256:0"},
        },
    ],
    ids=["list", "format-2-run", "format-2-file", "format-3-wrong-print"],
)
def test_a_manifest_copied_into_a_users_folder_never_costs_a_file(tmp_path: Path, planted: object) -> None:
    """A ``.linkwork-manifest.json`` that came with a copied or unpacked folder may list any name; a run into
    that folder removed a user's ``thesis.docx`` as a stale entry of the earlier run, and an export wrote over a
    user's file it listed. Removal and overwriting now need the entry's fingerprint (its bytes' sha256) to match
    what linkwork wrote; the run's own results are still replaced as a whole."""
    import json as json_module

    out = tmp_path / "results"
    out.mkdir()
    (out / "thesis.docx").write_bytes(b"precious")
    (out / ".linkwork-manifest.json").write_text(json_module.dumps(planted))
    for args in (
        ["trace", "four-bar", "--until", "A=120", "--no-plots", "--html", "-o", str(out)],
        ["trace", "bennett", "--max-steps", "10", "--no-plots", "-o", str(out)],
    ):
        run = run_cli(args)
        assert run.code == 0, run
        assert (out / "thesis.docx").read_bytes() == b"precious"
    assert not (out / "viewer.html").exists()  # the first run's own stale entry is removed
    run = run_cli(["export", "stl", str(out), "-o", str(out / "thesis.docx")])
    assert run.code == 2 and (out / "thesis.docx").read_bytes() == b"precious"


def test_an_output_changed_since_linkwork_wrote_it_is_kept(tmp_path: Path) -> None:
    """A result a user edited (``path.csv`` saved by a spreadsheet) is theirs now: the next run into the folder
    refuses (exit 2, the file named) instead of writing over it; a copy of the folder is still linkwork's."""
    out = tmp_path / "results"
    assert run_cli(["trace", "four-bar", "--until", "A=120", "--no-plots", "-o", str(out)]).code == 0
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    with (out / "path.csv").open("a") as handle:
        handle.write("my note\n")
    edited = (out / "path.csv").read_bytes()
    run = run_cli(["trace", "four-bar", "--until", "A=100", "--no-plots", "-o", str(out)], out=out)
    assert run.code == 2 and '"path.csv" holds something else than linkwork wrote' in run.stderr
    assert (out / "path.csv").read_bytes() == edited
    assert run_cli(["trace", "four-bar", "--until", "A=100", "--no-plots", "-o", str(copy)]).code == 0


@pytest.mark.parametrize("rise", [0.1, 1e-3, -2.0])
def test_a_3d_dxf_polyline_leaving_its_plane_is_refused_not_flattened(tmp_path: Path, rise: float) -> None:
    """A 3-D POLYLINE whose vertices climb (z = rise * x) was read as its x-y projection, exit 0; one in a plane
    z = constant is still read, as ezdxf's own vertices say."""
    ezdxf = pytest.importorskip("ezdxf")
    from linkwork.io.profiles import load_profile

    circle = [(math.cos(t * math.pi / 30), math.sin(t * math.pi / 30)) for t in range(40)]
    climbing = tmp_path / "climbing.dxf"
    document = ezdxf.new()
    document.modelspace().add_polyline3d([(x, y, rise * x) for x, y in circle])
    document.saveas(climbing)
    with pytest.raises(SpecError, match="3-D POLYLINE's z runs from"):
        load_profile(climbing)
    flat = tmp_path / "flat.dxf"
    document = ezdxf.new()
    document.modelspace().add_polyline3d([(x, y, 5.0) for x, y in circle])
    document.saveas(flat)
    points = load_profile(flat)
    assert np.allclose(points, np.array(circle), rtol=0, atol=1e-12)


def test_two_runs_into_one_out_take_turns(tmp_path: Path) -> None:
    """Two commands writing into one ``--out`` at once: the second waits while the first holds the folder
    (``io.writer.folder_lock``), so neither is refused as if the other's fresh entries were a user's, and no
    run's files are mixed with another's. Shown with the lock held by the test: a real ``trace`` writes nothing
    into the folder until it is released; then four runs at once all succeed, leaving one run's files."""
    import time

    from linkwork.io.writer import folder_lock

    out = tmp_path / "results"
    out.mkdir()
    script = [sys.executable, "-c", "from linkwork.cli import main; main()"]
    with folder_lock(out):
        process = subprocess.Popen(
            [*script, "trace", "four-bar", "--until", "A=120", "--no-plots", "-o", str(out)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
        )
        time.sleep(4.0)  # time to trace the four-bar several times over: it waits for the folder
        assert process.poll() is None and not (out / "report.json").exists()
    _, err = process.communicate(timeout=120)
    assert process.returncode == 0, err.decode()
    assert (out / "report.json").exists() and not list(tmp_path.glob(".linkwork-*"))
    runs = [
        subprocess.Popen(
            [*script, "trace", name, "--no-plots", "--max-steps", "30", "-o", str(out)],
            stderr=subprocess.PIPE,
        )
        for name in ["four-bar", "hedgepeth-rods", "bennett", "hedgepeth-rods"]
    ]
    for run in runs:
        _, err = run.communicate(timeout=120)
        assert run.returncode == 0, err.decode()
    import json as json_module

    joints = json_module.loads((out / "report.json").read_text())["joints"]
    header = (out / "path.csv").read_text().splitlines()[0].split(",")
    assert header[3 : 3 + len(joints)] == joints  # the files of one run, not a mix
