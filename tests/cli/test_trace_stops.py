"""How ``linkwork trace`` stops when it cannot finish as asked, and what it keeps:

* SIGTERM or Ctrl-C while tracing (a real process, a real signal) writes the path traced so far, complete and
  valid (path.csv, points.csv, report.json saying where and why it stopped, mechanism.toml), leaves no staging
  folder, and exits 143 / 130 with one line;
* a target on a crank further round than the step budget goes is refused after one cycle (exit 3, one line naming
  --max-steps), not after the whole budget;
* a --deployed-at value branch 0 never reaches: the trace is written, then exit 3 with the range.
"""

from __future__ import annotations

import csv
import json
import re
import signal
import subprocess
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest
from processes import linkwork_command, process_env
from typer.testing import CliRunner, Result

import linkwork as lw
from linkwork.cli import app
from linkwork.io.readback import read_points_csv, read_report
from linkwork.outputs.staging import MANIFEST

runner = CliRunner()
ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


def invoke(*args: str) -> Result:
    result = runner.invoke(app, list(args))
    assert "Traceback" not in result.stdout + result.stderr
    return result


def one_error_line(stderr: str) -> str:
    lines = ANSI.sub("", stderr).strip().splitlines()
    lines = [line for line in lines if not line.startswith("note:")]  # a kernel announcement
    assert len(lines) == 1, lines
    assert lines[0].startswith("error: "), lines[0]
    return lines[0]


def read_path_rows(file: Path) -> tuple[list[str], np.ndarray]:
    """path.csv's header and rows, every row as long as the header and every cell a finite number."""
    with open(file, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    header, body = rows[0], rows[1:]
    assert body and all(len(row) == len(header) for row in body)
    values = np.array(body, dtype=float)
    assert np.all(np.isfinite(values))
    return header, values


def assert_complete_trace_folder(out: Path) -> dict[str, object]:
    """The folder holds a whole trace: files parse, rows agree with each other and with report.json."""
    report = read_report(out / "report.json")
    header, rows = read_path_rows(out / "path.csv")
    assert len(rows) == report["points"]
    branch, step = rows[:, header.index("branch")], rows[:, header.index("step")]
    for entry in report["branches"]:
        mine = step[branch == entry["id"]]
        assert len(mine) >= 1 and np.all(np.diff(mine) == 1)
        assert mine[-1] == entry["steps"]
    points = read_points_csv(out / "points.csv")
    assert len(points.rows) == len(rows)
    tomllib.loads((out / "mechanism.toml").read_text(encoding="utf-8"))
    manifest = json.loads((out / MANIFEST).read_text(encoding="utf-8"))
    written = {"path.csv", "report.json", "points.csv", "mechanism.toml"}
    assert written <= set(manifest["parts"]["run"]) <= {p.name for p in out.iterdir()}
    return report


# ------------------------------------------------------------------------------------ signals
LONG_TRACES = {
    # adaptive steps of 0.01 deg: hundreds of thousands of steps, minutes with the plain-Python kernels
    "adaptive": ["hedgepeth-rods", "--max-step", "0.01", "--max-steps", "1000000"],
    "branches": ["guest-frame", "--branches", "--max-step", "0.01", "--max-steps", "1000000"],
    "target": ["four-bar", "--until", "A=100000", "--max-step", "0.01", "--max-steps", "1000000"],
}


def start_linkwork(args: list[str]) -> subprocess.Popen[str]:
    # the plain-Python kernels: slow and steady, the trace is surely still running when the signal comes
    env = process_env(LINKWORK_JIT="python")
    return subprocess.Popen(
        linkwork_command(args), env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )


def wait_until_tracing(proc: subprocess.Popen[str], timeout: float = 120.0) -> None:
    """Wait for the line ``linkwork trace`` prints before it starts tracing, then a moment more."""
    assert proc.stdout is not None
    deadline = time.monotonic() + timeout
    line = proc.stdout.readline()
    while "unknowns" not in line:
        assert line or proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "the trace never started"
        line = proc.stdout.readline()
    time.sleep(1.5)


@pytest.mark.parametrize("case", sorted(LONG_TRACES))
@pytest.mark.parametrize(
    ("sig", "code"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)], ids=["SIGTERM", "SIGINT"]
)
def test_a_signal_while_tracing_writes_the_path_so_far(
    tmp_path: Path, case: str, sig: int, code: int
) -> None:
    out = tmp_path / "out"
    proc = start_linkwork(["trace", *LONG_TRACES[case], "--no-plots", "-o", str(out)])
    wait_until_tracing(proc)
    assert proc.poll() is None, "the trace ended before the signal: make it longer"
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    name = signal.Signals(sig).name
    assert proc.returncode == code, err
    assert "Traceback" not in err
    line = one_error_line(err)
    assert line.startswith(f"error: interrupted ({name}): the ") and str(out) in line
    report = assert_complete_trace_folder(out)
    assert report["complete"] is False and report["stopped"] == f"interrupted ({name})"
    kinds = [b["end_kind"] for b in report["branches"]]
    assert "interrupted" in kinds or case == "branches"  # with --branches the queue may be what was cut
    assert f"the {report['points']} points traced so far" in line
    if case == "target":
        assert report["target_reached"] is False and "interrupted" in str(report["unmet"])
    assert not list(tmp_path.glob(".linkwork-*")), "a staging folder was left behind"


def test_a_trace_that_is_not_interrupted_is_complete(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = invoke("trace", "four-bar", "--no-plots", "-o", str(out))
    assert result.exit_code == 0, result.stderr
    report = assert_complete_trace_folder(out)
    assert report["complete"] is True and report["stopped"] is None


# ------------------------------------------------------------------------------------ targets beyond the budget
@pytest.mark.parametrize("value", ["1e300", "-1e300", "100000", "1e6"])
def test_a_crank_target_beyond_the_budget_is_refused_after_one_cycle(tmp_path: Path, value: str) -> None:
    out = tmp_path / "out"
    started = time.perf_counter()
    result = invoke("trace", "four-bar", "--until", f"A={value}", "--no-plots", "-o", str(out))
    assert result.exit_code == 3, result.stderr
    line = one_error_line(result.stderr)
    assert line.startswith("error: A cannot reach") and "--max-steps" in line and "cycles" in line
    report = assert_complete_trace_folder(out)
    free = invoke("trace", "four-bar", "--no-plots", "-o", str(tmp_path / "free"))
    cycle = read_report(tmp_path / "free" / "report.json")["branches"][0]["steps"]
    assert free.exit_code == 0
    assert report["branches"][0]["steps"] <= cycle + 10  # one cycle, not the 5000 steps of the budget
    assert report["target_reached"] is False and report["unmet"] == line.removeprefix("error: ")
    assert time.perf_counter() - started < 60.0


def test_a_crank_target_a_few_turns_away_is_reached(tmp_path: Path) -> None:
    result = invoke("trace", "four-bar", "--until", "A=1500", "--no-plots", "-o", str(tmp_path / "out"))
    assert result.exit_code == 0, result.stderr
    report = read_report(tmp_path / "out" / "report.json")
    assert report["target_reached"] is True
    assert report["branches"][0]["end"]["A"] == pytest.approx(1500.0, abs=1e-9)


# ------------------------------------------------------------------------------------ --deployed-at never reached
HOOP = ["hedgepeth-rods", "--set", "n=6", "--until", "A=128.6822"]


@pytest.mark.parametrize(
    ("args", "at"),
    [
        (HOOP, "A=500"),  # beyond the drive's range
        (HOOP, "A=-500"),  # before it
        (HOOP, "B=1e9"),  # another joint
        (["slider-crank"], "D=1e6"),  # a prismatic joint: a length
    ],
    ids=["above", "below", "other-joint", "prismatic"],
)
@pytest.mark.parametrize("plots", [False, True], ids=["no-plots", "plots"])
def test_a_deployed_value_never_reached_writes_the_trace_then_exits_3(
    tmp_path: Path, args: list[str], at: str, plots: bool
) -> None:
    out = tmp_path / "out"
    result = invoke("trace", *args, "--deployed-at", at, *([] if plots else ["--no-plots"]), "-o", str(out))
    if result.exit_code == 2 and "not a joint" in result.stderr:
        pytest.fail(result.stderr)
    assert result.exit_code == 3, result.stderr
    line = one_error_line(result.stderr)
    joint = at.partition("=")[0]
    assert f"deployed at {joint}=" in line and "not on the deployment path" in line and " goes from " in line
    report = assert_complete_trace_folder(out)
    assert report["deployment"] is None
    assert report["deployment_unmet"] == line.removeprefix("error: ")
    assert not (out / "stretch.png").exists()  # a stretch against a deployed shape that is not there
    if plots:
        assert (out / "angles.png").exists()


def test_a_deployed_value_on_the_path_is_measured_there(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = invoke("trace", *HOOP, "--deployed-at", "A=100", "--no-plots", "-o", str(out))
    assert result.exit_code == 0, result.stderr
    report = read_report(out / "report.json")
    assert report["deployment_unmet"] is None
    assert report["deployment"]["deployed"]["at"] == {"joint": "A", "value": 100.0}


def test_trace_help_says_what_is_written_when_a_request_is_not_met() -> None:
    result = invoke("trace", "--help")
    text = " ".join(ANSI.sub("", result.stdout).split())
    assert "nothing is written" not in text
    assert "--max-steps" in text and "130 / 143" in text


def test_more_equal_steps_than_the_budget_are_bad_input(tmp_path: Path) -> None:
    """Paper mode's target is --steps steps away: more than --max-steps can never reach it. Refused before any
    step (exit 2), nothing written, instead of marching the whole budget."""
    out = tmp_path / "out"
    result = invoke("trace", "four-bar", "--until", "A=420", "--steps", "6000", "--no-plots", "-o", str(out))
    assert result.exit_code == 2, result.stderr
    assert "more than the step budget max_steps (5000, --max-steps)" in one_error_line(result.stderr)
    assert not out.exists()


def test_huge_equal_steps_end_with_a_reason_and_keep_the_trace(tmp_path: Path) -> None:
    """2e296 deg a step (more than any number of parts of a step can follow): exit 3, the trace written."""
    out = tmp_path / "out"
    result = invoke(
        "trace", "four-bar", "--until", "A=1e300", "--steps", "5000", "--no-plots", "-o", str(out)
    )
    assert result.exit_code == 3, result.stderr
    assert one_error_line(result.stderr).startswith("error: A did not reach")
    assert_complete_trace_folder(out)


def test_equal_steps_longer_than_a_turn_follow_the_path(tmp_path: Path) -> None:
    """500 deg a step crashed (IndexError traceback, exit 1), then failed; each step is now taken in parts along
    the path: the crank's 200 rows 500 deg apart, every row on the start's assembly (the four-bar's closed form:
    the coupler point C on both circles, the rocker's angle from C, on the side of the start)."""
    out = tmp_path / "out"
    args = ["--until", "A=100000", "--steps", "200", "--no-plots", "-o", str(out)]
    result = invoke("trace", "four-bar", *args)
    assert result.exit_code == 0, result.stderr
    assert_complete_trace_folder(out)
    rows = np.loadtxt(out / "path.csv", delimiter=",", skiprows=1, usecols=(3, 6))  # A, D
    mech = lw.load("four-bar")
    fine = lw.trace(mech, until=("A", float(mech.offsets[0]) + 2 * np.pi), steps=3600)  # 0.1 deg
    a0 = np.degrees(mech.offsets[0])
    assert len(rows) == 201
    assert rows[-1, 0] == pytest.approx(100000.0, abs=1e-9)
    on_grid = np.rint(((rows[:, 0] - a0) % 360.0) * 10).astype(int) % 3600
    d_fine = np.degrees(fine.angles[on_grid, 3])
    assert np.max(np.abs((rows[:, 1] - d_fine + 180.0) % 360.0 - 180.0)) < 1e-8


def test_equal_steps_several_turns_round_reach_the_target(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = invoke("trace", "four-bar", "--until", "A=3600", "--steps", "100", "--no-plots", "-o", str(out))
    assert result.exit_code == 0, result.stderr
    report = read_report(out / "report.json")
    assert report["branches"][0]["steps"] == 100
    assert report["branches"][0]["end"]["A"] == pytest.approx(3600.0, abs=1e-9)


# ------------------------------------------------------------------------------------ every other command
@pytest.mark.parametrize(
    ("sig", "code"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)], ids=["SIGTERM", "SIGINT"]
)
def test_a_signal_during_a_mechanization_is_one_line_and_keeps_the_chain(
    tmp_path: Path, sig: int, code: int
) -> None:
    """A signal during synth's mechanization before any design has passed (the first passes after about twenty
    seconds of the plain-Python kernels) stops with one line and 143 / 130, not SIGTERM's silent kill without
    cleanup; what was written before (the chain) is kept, no mechanization is written, nothing is half-written,
    no staging folder is left. (A design that passed is kept: tests/cli/test_long_command_stops.py.)"""
    out = tmp_path / "out"
    proc = start_linkwork(["synth", "wing/mechanize.toml", "--no-plots", "-o", str(out)])
    deadline = time.monotonic() + 120.0
    while not (out / "chain.json").exists():  # the chain is written before the mechanization starts
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "the chain was never written"
        time.sleep(0.1)
    time.sleep(2.0)  # well into the mechanization (half a minute with the plain-Python kernels)
    assert proc.poll() is None, proc.communicate()
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == code, err
    assert one_error_line(err) == (
        f"error: interrupted ({signal.Signals(sig).name}): no design had passed verification yet; nothing of the "
        f"mechanization is written to {out}/"
    )
    json.loads((out / "chain.json").read_text(encoding="utf-8"))
    assert not (out / "mechanization.json").exists()
    assert not list(tmp_path.glob(".linkwork-*"))
    assert [p.name for p in out.glob(".linkwork-*")] == [MANIFEST]  # no staging inside either
