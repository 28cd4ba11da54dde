"""``linkwork trace``, ``linkages`` and ``show``: the contract files (docs/architecture.md, "Contracts":
commands and outputs), the paper's deployment of the six-rod Hedgepeth hoop, and bad input as one line with exit code 2.

References come from the paper: the deployed angle of the n = 6 hoop, theta_A = 87.0067 deg (Eq. 10), the
symmetry A = C = E, B = D = F along its whole path (Sec. 5), rank 5 and mobility 1, no bifurcation, and the
paper's 200 equal steps of the drive.
"""

from __future__ import annotations

import csv
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner, Result

from linkwork.cli import app

runner = CliRunner()

#: The paper's deployed hinge angle of the six-rod hoop (degrees), Eq. (10) rounded as printed.
DEPLOYED_A = 87.0067
HOOP = ["hedgepeth", "--set", "n=6", "--until", f"A={DEPLOYED_A}"]
JOINTS = ["A", "B", "C", "D", "E", "F"]
COLUMNS = ["branch", "step", "s", *JOINTS, *[f"sigma_{i}" for i in range(1, 7)], "residual"]
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


def invoke(*args: str) -> Result:
    """Run ``linkwork ARGS`` in-process; no traceback ever reaches the user."""
    result = runner.invoke(app, list(args))
    assert "Traceback" not in result.stdout + result.stderr
    return result


def read_csv(file: Path) -> tuple[list[str], dict[str, np.ndarray]]:
    """Header and columns of a path.csv (every value is a number)."""
    with open(file, newline="") as fh:
        rows = list(csv.reader(fh))
    header, body = rows[0], np.array(rows[1:], dtype=float)
    return header, {name: body[:, i] for i, name in enumerate(header)}


@pytest.fixture(scope="module")
def adaptive(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The hoop traced to deployment with adaptive steps and figures."""
    out = tmp_path_factory.mktemp("adaptive") / "out"
    result = invoke("trace", *HOOP, "--out", str(out))
    assert result.exit_code == 0, result.stderr
    return out


@pytest.fixture(scope="module")
def paper(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The hoop traced to deployment in the paper's 200 equal steps of A, without figures."""
    out = tmp_path_factory.mktemp("paper") / "out"
    result = invoke("trace", *HOOP, "--steps", "200", "--no-plots", "--out", str(out))
    assert result.exit_code == 0, result.stderr
    return out


# ------------------------------------------------------------------------------------------------ path.csv


@pytest.mark.parametrize("mode", ["adaptive", "paper"])
def test_path_csv_has_exactly_the_contract_columns(mode: str, request: pytest.FixtureRequest) -> None:
    header, _ = read_csv(request.getfixturevalue(mode) / "path.csv")
    assert header == COLUMNS


@pytest.mark.parametrize("mode", ["adaptive", "paper"])
def test_hoop_lands_on_the_deployed_angle_in_degrees(mode: str, request: pytest.FixtureRequest) -> None:
    _, col = read_csv(request.getfixturevalue(mode) / "path.csv")
    # Degrees, not radians: the start is the folded bundle (0) and the last row is the target (1e-9 deg).
    assert col["A"][0] == pytest.approx(0.0, abs=1e-12)
    assert col["A"][-1] == pytest.approx(DEPLOYED_A, abs=1e-9)
    assert np.all(col["branch"] == 0)
    np.testing.assert_array_equal(col["step"], np.arange(len(col["step"])))
    assert np.all(np.diff(col["s"]) > 0.0)  # arclength grows (strictly)
    assert col["residual"].max() < 1e-11  # every point closes the loop (1e-11)


@pytest.mark.parametrize("mode", ["adaptive", "paper"])
def test_hoop_stays_symmetric_on_every_row(mode: str, request: pytest.FixtureRequest) -> None:
    _, col = read_csv(request.getfixturevalue(mode) / "path.csv")
    # The paper's Sec. 5: A = C = E and B = D = F at all stages (1e-8 deg).
    np.testing.assert_allclose(col["C"], col["A"], rtol=0.0, atol=1e-8)
    np.testing.assert_allclose(col["E"], col["A"], rtol=0.0, atol=1e-8)
    np.testing.assert_allclose(col["D"], col["B"], rtol=0.0, atol=1e-8)
    np.testing.assert_allclose(col["F"], col["B"], rtol=0.0, atol=1e-8)


def test_paper_mode_takes_200_equal_steps_of_the_drive(paper: Path) -> None:
    _, col = read_csv(paper / "path.csv")
    assert len(col["A"]) == 201  # the start and 200 steps, exactly
    # Equal increments of A, each the 200th part of the way (1e-12 deg).
    np.testing.assert_allclose(np.diff(col["A"]), DEPLOYED_A / 200, rtol=0.0, atol=1e-12)


def test_singular_values_show_one_zero_and_five_nonzero(paper: Path) -> None:
    _, col = read_csv(paper / "path.csv")
    sigma = np.column_stack([col[f"sigma_{i}"] for i in range(1, 7)])
    assert np.all(np.diff(sigma, axis=1) <= 0.0)  # descending (exact)
    assert sigma[:, 4].min() > 1e-2  # fifth non-zero along the whole path (above 1e-2)
    assert sigma[:, 5].max() < 1e-12  # sixth zero: mobility 1 (below 1e-12)


# --------------------------------------------------------------------------------------------- report.json


def test_report_states_rank_mobility_and_no_bifurcation(adaptive: Path) -> None:
    report = json.loads((adaptive / "report.json").read_text())
    assert {"joints", "rank", "mobility", "bifurcations", "branches", "max_condition"} <= set(report)
    assert report["joints"] == JOINTS
    assert report["rank"] == 5
    assert report["mobility"] == 1
    assert report["bifurcations"] == []
    # sigma_1 / sigma_5 stays moderate along the hoop's path; finite and >= 1 (exact bounds).
    assert 1.0 <= report["max_condition"] < 1e3


def test_report_lists_the_single_branch_that_reached_its_target(adaptive: Path) -> None:
    report = json.loads((adaptive / "report.json").read_text())
    _, col = read_csv(adaptive / "path.csv")
    [branch] = report["branches"]
    assert {"id", "parent", "steps", "end_reason"} <= set(branch)
    assert branch["id"] == 0
    assert branch["parent"] is None
    assert branch["steps"] == len(col["A"]) - 1  # one row per step plus the start (exact)
    assert branch["end_reason"] == "reached target"


def test_max_condition_raw_is_the_largest_ratio_of_the_csv_singular_values(paper: Path) -> None:
    report = json.loads((paper / "report.json").read_text())
    _, col = read_csv(paper / "path.csv")
    ratio = col["sigma_1"] / col["sigma_5"]  # rank 5: sigma_5 is the smallest non-zero one
    assert report["max_condition_raw"] == pytest.approx(ratio.max(), rel=1e-12)
    # max_condition is the same ratio on the normalised Jacobian (frame and unit free): finite, >= 1.
    assert 1.0 <= report["max_condition"] < 1e3


# ------------------------------------------------------------------------------------------------- figures


def test_no_plots_writes_no_figure(paper: Path) -> None:
    names = sorted(p.name for p in paper.iterdir() if p.name != ".linkwork-manifest.json")
    assert names == ["drawing.json", "mechanism.toml", "path.csv", "points.csv", "report.json"]
    assert not list(paper.glob("*.png"))


def test_figures_are_valid_png_files(adaptive: Path) -> None:
    pytest.importorskip("matplotlib")
    image = pytest.importorskip("PIL.Image")
    for name in ("angles.png", "singular_values.png"):
        file = adaptive / name
        assert file.read_bytes()[:8] == PNG_SIGNATURE
        with image.open(file) as png:
            png.verify()  # raises on a truncated or corrupt file
        with image.open(file) as png:
            assert png.format == "PNG"
            assert min(png.size) >= 100  # a real figure, not an empty canvas (pixels)


# ---------------------------------------------------------------------------------------- linkages / show


def test_linkages_lists_hedgepeth() -> None:
    result = invoke("linkages")
    assert result.exit_code == 0
    assert "hedgepeth" in result.stdout


def test_show_prints_a_spec_that_trace_accepts_and_that_traces_the_same_path(tmp_path: Path) -> None:
    shown = invoke("show", "hedgepeth", "--set", "n=4")
    assert shown.exit_code == 0
    spec = tmp_path / "hoop4.toml"
    spec.write_text(shown.stdout, encoding="utf-8")
    # n = 4 deploys at A = 120 deg (Eq. 10); compare 40 equal steps of A row by row.
    until = ["--until", "A=120", "--steps", "40", "--no-plots"]
    builtin = invoke("trace", "hedgepeth", "--set", "n=4", *until, "--out", str(tmp_path / "builtin"))
    from_file = invoke("trace", str(spec), *until, "--out", str(tmp_path / "file"))
    assert builtin.exit_code == 0, builtin.stderr
    assert from_file.exit_code == 0, from_file.stderr
    header_a, a = read_csv(tmp_path / "builtin" / "path.csv")
    header_b, b = read_csv(tmp_path / "file" / "path.csv")
    assert header_a == header_b == ["branch", "step", "s", "A", "B", "C", "D", *header_a[7:]]
    assert len(a["A"]) == len(b["A"]) == 41
    for joint in "ABCD":
        np.testing.assert_allclose(b[joint], a[joint], rtol=0.0, atol=1e-9, err_msg=joint)


def test_show_spec_reaches_the_same_deployed_shape_with_adaptive_steps(tmp_path: Path) -> None:
    spec = tmp_path / "hoop4.toml"
    spec.write_text(invoke("show", "hedgepeth", "--set", "n=4").stdout, encoding="utf-8")
    until = ["--until", "A=120", "--no-plots"]
    assert invoke("trace", "hedgepeth", "--set", "n=4", *until, "--out", str(tmp_path / "a")).exit_code == 0
    assert invoke("trace", str(spec), *until, "--out", str(tmp_path / "b")).exit_code == 0
    _, a = read_csv(tmp_path / "a" / "path.csv")
    _, b = read_csv(tmp_path / "b" / "path.csv")
    # Adaptive steps may land on different intermediate points; the end is the same (1e-9 deg):
    # the deployed square has A = C = 120 and B = D = 60 (Eq. 13 at theta_A = 120 deg).
    for joint, value in zip("ABCD", (120.0, 60.0, 120.0, 60.0), strict=True):
        assert b[joint][-1] == pytest.approx(a[joint][-1], abs=1e-9)
        assert a[joint][-1] == pytest.approx(value, abs=1e-9)


def test_each_bifurcation_names_its_row_of_path_csv(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert invoke("trace", "guest-frame", "--branches", "--no-plots", "--out", str(out)).exit_code == 0
    report = json.loads((out / "report.json").read_text())
    _, col = read_csv(out / "path.csv")
    joints = report["joints"]
    assert len(report["bifurcations"]) > 2  # Guest's frame bifurcates on its first branch and later ones
    for bif in report["bifurcations"]:
        row = (col["branch"] == bif["branch"]) & (col["step"] == bif["step"])
        assert row.sum() == 1, bif["id"]
        # The located point lies within one step (2 deg of arclength) of the row at which it was detected.
        gap = np.array([col[j][row][0] - bif["angles"][j] for j in joints])
        assert np.abs((gap + 180.0) % 360.0 - 180.0).max() < 2.0, bif["id"]


# ---------------------------------------------------------------------------------------------- bad input


def bad_toml(tmp_path: Path) -> str:
    file = tmp_path / "broken.toml"
    file.write_text('name = "broken"\n[loop\nconvention = "dh"\n', encoding="utf-8")
    return str(file)


BAD_INPUT = {
    "unknown linkage": (lambda t: ["trace", "no-such-linkage"], "no-such-linkage"),
    "unknown --set key": (lambda t: ["trace", "hedgepeth", "--set", "m=6"], '"m"'),
    "odd n": (lambda t: ["trace", "hedgepeth", "--set", "n=5"], "even"),
    "--until without =": (lambda t: ["trace", "hedgepeth", "--until", "A87"], "JOINT=VALUE"),
    "--until unknown joint": (lambda t: ["trace", "hedgepeth", "--until", "Z=30"], '--until "Z"'),
    "--until infinite value": (lambda t: ["trace", "hedgepeth", "--until", "A=inf"], "--until"),
    "negative --max-step": (lambda t: ["trace", "hedgepeth", "--max-step", "-1"], "--max-step"),
    "missing spec file": (lambda t: ["trace", str(t / "missing.toml")], "not found"),
    "TOML syntax error": (lambda t: ["trace", bad_toml(t)], "line 2"),
    "--steps without --until": (lambda t: ["trace", "hedgepeth", "--steps", "10"], "until"),
    "--limit without a colon": (lambda t: ["trace", "hedgepeth", "--limit", "A=10"], "JOINT=LO:HI"),
    "--limit empty range": (lambda t: ["trace", "hedgepeth", "--limit", "A=10:5"], "LO < HI"),
    "--limit unknown joint": (lambda t: ["trace", "hedgepeth", "--limit", "Z=0:10"], "'Z'"),
    "--limit excluding the start": (lambda t: ["trace", "hedgepeth", "--limit", "A=10:20"], "outside"),
    "--closure-tol not positive": (lambda t: ["trace", "hedgepeth", "--closure-tol", "0"], "--closure-tol"),
}


def assert_one_error_line(stderr: str, fragment: str) -> None:
    lines = ANSI.sub("", stderr).strip().splitlines()
    assert len(lines) == 1, lines
    assert lines[0].startswith("error:"), lines[0]
    assert fragment in lines[0]


@pytest.mark.parametrize("case", BAD_INPUT)
def test_bad_input_is_one_error_line_exit_2_and_no_output(case: str, tmp_path: Path) -> None:
    args, fragment = BAD_INPUT[case]
    out = tmp_path / "out"
    result = invoke(*args(tmp_path), "--out", str(out))
    assert result.exit_code == 2
    assert_one_error_line(result.stderr, fragment)
    assert not out.exists()
    assert not list(tmp_path.glob(".linkwork-*"))  # no staging folder left behind


# ------------------------------------------------------------------------------------------- the real script


def linkwork_script() -> str:
    """The installed ``linkwork`` console script (next to this Python, else on PATH)."""
    beside = Path(sys.executable).with_name("linkwork")
    found = str(beside) if beside.exists() else shutil.which("linkwork")
    if found is None:
        pytest.skip("the linkwork script is not installed")
    return found


def script_env() -> dict[str, str]:
    return {k: v for k, v in os.environ.items() if k not in ("FORCE_COLOR", "CLICOLOR_FORCE")} | {
        "NO_COLOR": "1"
    }


def test_installed_script_traces_the_hoop(tmp_path: Path) -> None:
    out = tmp_path / "out"
    done = subprocess.run(
        [linkwork_script(), "trace", *HOOP, "--no-plots", "--out", str(out)],
        capture_output=True, text=True, cwd=tmp_path, env=script_env(), timeout=300, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stdout + done.stderr
    header, col = read_csv(out / "path.csv")
    assert header == COLUMNS
    assert col["A"][-1] == pytest.approx(DEPLOYED_A, abs=1e-9)
    assert json.loads((out / "report.json").read_text())["mobility"] == 1


def test_installed_script_reports_bad_input_without_traceback(tmp_path: Path) -> None:
    out = tmp_path / "out"
    done = subprocess.run(
        [linkwork_script(), "trace", "hedgepeth", "--set", "n=5", "--out", str(out)],
        capture_output=True, text=True, cwd=tmp_path, env=script_env(), timeout=300, check=False,
    )  # fmt: skip
    assert done.returncode == 2
    assert "Traceback" not in done.stdout + done.stderr
    assert_one_error_line(done.stderr, "even")
    assert not out.exists()


def test_help_lists_every_command() -> None:
    result = invoke("--help")
    assert result.exit_code == 0
    for command in ("trace", "linkages", "show", "synth", "demo"):
        assert re.search(rf"^\W*{command}\b", ANSI.sub("", result.stdout), re.MULTILINE), command


# ------------------------------------------------------------------- requests that cannot be met, limits (issue 9)

FOUR_BAR = str(Path(__file__).resolve().parents[2] / "examples" / "specs" / "four-bar.toml")


def rocker_range_deg() -> tuple[float, float]:
    """Range of the four-bar's rocker joint D from its start, by the law of cosines in triangle A-C-D at the two
    positions where crank (sqrt 2) and coupler (|BC|) are collinear (|AC| = |BC| -/+ sqrt 2)."""
    ground, rocker, coupler = 4.0, float(np.hypot(0.5, 3.0)), float(np.hypot(2.5, 2.0))

    def at_d(ac: float) -> float:
        return float(np.degrees(np.arccos((ground**2 + rocker**2 - ac**2) / (2 * ground * rocker))))

    start = at_d(float(np.hypot(3.5, 3.0)))
    return at_d(coupler - np.sqrt(2.0)) - start, at_d(coupler + np.sqrt(2.0)) - start


def test_unreachable_target_exits_3_with_one_line_and_writes_the_path(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = invoke("trace", FOUR_BAR, "--until", "D=-95", "--no-plots", "--out", str(out))
    assert result.exit_code == 3
    lo, hi = rocker_range_deg()
    assert_one_error_line(
        result.stderr, f"D never reaches -95.00 deg on this path: its range is [{lo:.2f}, {hi:.2f}] deg"
    )
    report = json.loads((out / "report.json").read_text())
    assert report["target_reached"] is False and report["unmet"].startswith("D never reaches")
    branch = report["branches"][0]
    assert branch["end_reason"] == "closed path" and branch["mobility"] == 1
    np.testing.assert_allclose(branch["range"]["D"], [lo, hi], atol=1e-7)  # the folds of the drive count
    assert branch["range"]["A"] == pytest.approx([45.0, 405.0], abs=1e-9)  # the crank turned once
    _, col = read_csv(out / "path.csv")
    assert len(col["D"]) == branch["steps"] + 1


def test_limit_ends_the_branch_on_the_limit_and_is_reported(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = invoke("trace", FOUR_BAR, "--limit", "D=-5:30", "--no-plots", "--out", str(out))
    assert result.exit_code == 0, result.stderr
    report = json.loads((out / "report.json").read_text())
    assert report["branches"][0]["end_reason"] == "limit D"
    assert report["branches"][0]["range"]["D"][0] == pytest.approx(-5.0, abs=1e-9)
    # the same end, structured (degrees in the file)
    assert (report["branches"][0]["end_kind"], report["branches"][0]["end_joint"]) == ("limit", "D")
    assert report["branches"][0]["end_value"] == pytest.approx(-5.0, abs=1e-9)
    assert report["target_reached"] is None


def test_report_states_the_closure_tolerance_and_the_largest_misfit(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = invoke("trace", FOUR_BAR, "--closure-tol", "1e-9", "--no-plots", "--out", str(out))
    assert result.exit_code == 0, result.stderr
    report = json.loads((out / "report.json").read_text())
    assert report["closure_tol"] == 1e-9
    assert report["max_misfit"] == pytest.approx(report["max_residual"]) and report["max_misfit"] <= 1e-9


def test_trace_help_documents_the_exit_codes_and_new_flags() -> None:
    result = invoke("trace", "--help")
    text = ANSI.sub("", result.stdout)
    assert result.exit_code == 0
    for fragment in (
        "Exit codes",
        "0 done as asked",
        "2 bad input",
        "3 the request",
        "--limit",
        "--closure-tol",
    ):
        assert fragment in " ".join(text.split()), fragment


def rounded_bennett(tmp_path: Path) -> Path:
    """examples/specs/bennett-hinge-lines.toml with every number rounded to 6 decimals: a rigid loop, strictly."""
    text = (
        Path(__file__).resolve().parents[2] / "examples" / "specs" / "bennett-hinge-lines.toml"
    ).read_text()
    rounded = re.sub(r"-?\d+\.\d{7,}", lambda m: f"{float(m.group()):.6f}", text)
    file = tmp_path / "bennett-rounded.toml"
    file.write_text(rounded)
    return file


def test_rounded_hinge_lines_are_refused_then_traced_within_the_closure_tolerance(tmp_path: Path) -> None:
    spec = str(rounded_bennett(tmp_path))
    refused = invoke("trace", spec, "--no-plots", "--out", str(tmp_path / "strict"))
    assert refused.exit_code == 2
    assert_one_error_line(refused.stderr, "--closure-tol")
    out = tmp_path / "out"
    result = invoke("trace", spec, "--closure-tol", "1e-5", "--no-plots", "--out", str(out))
    assert result.exit_code == 0, result.stderr
    report = json.loads((out / "report.json").read_text())
    assert report["branches"][0]["end_reason"] == "closed path"
    assert report["closure_tol"] == 1e-5 and 1e-9 < report["max_misfit"] <= 1e-5
    # Bennett's closed form (alpha 45/75 deg): tan(A/2) tan(B/2) = k, to the order of the rounding
    _, col = read_csv(out / "path.csv")
    a, b = np.radians(col["A"]) / 2, np.radians(col["B"]) / 2
    k = np.sin(np.radians(60.0)) / np.sin(np.radians(15.0))
    assert np.max(np.abs(np.sin(a) * np.sin(b) - k * np.cos(a) * np.cos(b))) < 1e-4
