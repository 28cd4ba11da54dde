"""``linkwork robustness`` and ``linkwork sweep``: the contract files and keys, and bad input as one line with
exit code 2."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner, Result

from linkwork.cli import app

runner = CliRunner()
ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")
SPECS = Path(__file__).resolve().parents[2] / "examples" / "specs"
STUDIES = Path(__file__).resolve().parents[2] / "examples" / "studies"


def invoke(*args: str) -> Result:
    result = runner.invoke(app, list(args))
    assert "Traceback" not in result.stdout + result.stderr
    return result


def test_robustness_writes_the_contract_files(tmp_path):
    import pyarrow.parquet as pq

    out = tmp_path / "rb"
    res = invoke(
        "robustness", "bennett", "--until", "A=100", "--steps", "20", "--samples", "40",
        "--hinge-position-tol", "1e-4", "--hinge-direction-tol", "0.01", "--seed", "3",
        "--workers", "0", "-o", str(out),
    )  # fmt: skip
    assert res.exit_code == 0, res.stderr
    summary = json.loads((out / "robustness.json").read_text())
    assert summary["samples"] == 40
    assert summary["tolerances"]["hinge_position"] == 1e-4
    assert summary["tolerances"]["hinge_direction_deg"] == pytest.approx(0.01)
    for key in ("misfit_max", "first_order"):
        assert summary[key]["p50"] <= summary[key]["p95"]
    assert summary["misfit_max"]["p95"] <= summary["misfit_max"]["max"]
    assert summary["mobility_kept"] == 0.0
    bands = summary["bands"]
    assert len(bands["drive_deg"]) == 21 and bands["drive_deg"][-1] == pytest.approx(100.0)
    assert len(bands["p50"]) == len(bands["ratio"]) == len(bands["first_order_p50"]) == 21
    table = pq.read_table(out / "samples.parquet").to_pydict()
    assert table["sample"] == list(range(40))
    # per-drive maxima merge exactly: the largest sample equals the largest band value
    assert max(table["misfit_max"]) == pytest.approx(max(bands["max"]), rel=0, abs=0)
    assert np.median(table["misfit_max"]) == pytest.approx(summary["misfit_max"]["p50"])
    at = np.array(table["step_at_max"])
    np.testing.assert_allclose(np.array(table["drive_at_max_deg"]), np.array(bands["drive_deg"])[at])
    assert (out / "misfit_bands.png").read_bytes()[:4] == b"\x89PNG"
    assert (out / "misfit_histogram.png").is_file()


def test_robustness_on_a_spec_file_in_plane(tmp_path):
    out = tmp_path / "fb"
    res = invoke(
        "robustness", str(SPECS / "four-bar.toml"), "--until", "A=100", "--steps", "10", "--samples", "20",
        "--hinge-position-tol", "0.01", "--hinge-direction-tol", "1", "--workers", "0", "--no-plots",
        "-o", str(out),
    )  # fmt: skip
    assert res.exit_code == 0, res.stderr
    summary = json.loads((out / "robustness.json").read_text())
    assert summary["tolerances"]["errors"] == "in-plane"
    assert summary["mobility_kept"] == 1.0 and summary["misfit_max"]["max"] < 1e-10
    assert not (out / "misfit_bands.png").exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--samples", "0"], "--samples"),
        (["--distribution", "cauchy"], "distribution"),
        (["--hinge-direction-tol", "95"], "direction"),
        (["--hinge-position-tol", "-1"], "position"),
        (["--until", "A"], "--until"),
        (["--scheduler", "nonsense"], "scheduler"),
    ],
)
def test_robustness_bad_input_is_one_line_exit_2(tmp_path, args, message):
    base = {
        "--samples": "5", "--hinge-position-tol": "1e-3", "--hinge-direction-tol": "0.1",
        "--until": "A=90", "--distribution": "normal",
    }  # fmt: skip
    for flag, value in zip(args[::2], args[1::2], strict=True):
        base[flag] = value
    flat = [x for kv in base.items() for x in kv]
    res = invoke("robustness", "bennett", *flat, "--workers", "0", "-o", str(tmp_path / "x"))
    assert res.exit_code == 2
    text = ANSI.sub("", res.stderr).strip()
    assert len(text.splitlines()) == 1 and message in text
    assert not (tmp_path / "x").exists()


def test_sweep_writes_table_and_heat_maps(tmp_path):
    import pyarrow.parquet as pq

    study = tmp_path / "s.toml"
    study.write_text(
        'linkage = "bennett"\n[trace]\nuntil = "A=90"\nsteps = 10\n[grid]\nalpha1 = [30, 40]\n'
        "alpha2 = [70, 80, 90]\n",
        encoding="utf-8",
    )
    out = tmp_path / "sw"
    res = invoke("sweep", str(study), "--workers", "0", "-o", str(out))
    assert res.exit_code == 0, res.stderr
    table = pq.read_table(out / "sweep.parquet").to_pydict()
    assert table["alpha1"] == [30, 30, 30, 40, 40, 40] and table["alpha2"] == [70, 80, 90] * 2
    assert table["mobility"] == [1] * 6
    header = (out / "sweep.csv").read_text().splitlines()[0].split(",")
    assert header[:3] == ["alpha1", "alpha2", "mobility"] and header[-1] == "error"
    assert (out / "heatmap_ratio_max.png").is_file() and (out / "sweep_ratio_max.png").is_file()


def test_sweep_where_every_point_fails_exits_3(tmp_path):
    study = tmp_path / "s.toml"
    study.write_text('linkage = "bennett"\n[grid]\nalpha2 = [45]\n', encoding="utf-8")
    res = invoke("sweep", str(study), "--workers", "0", "--no-plots", "-o", str(tmp_path / "o"))
    assert res.exit_code == 3
    assert "twists must differ" in ANSI.sub("", res.stderr)
    assert (tmp_path / "o" / "sweep.csv").is_file()  # what was computed is written


def test_sweep_bad_study_exit_2(tmp_path):
    study = tmp_path / "s.toml"
    study.write_text('linkage = "bennett"\n[grid]\nbogus = [1]\n', encoding="utf-8")
    res = invoke("sweep", str(study), "--workers", "0", "-o", str(tmp_path / "o"))
    assert res.exit_code == 2 and "bogus" in ANSI.sub("", res.stderr)
    assert invoke("sweep", str(tmp_path / "missing.toml")).exit_code == 2


def test_bundled_example_studies_parse():
    from linkwork.studies.study_file import load_study

    for f in sorted(STUDIES.glob("*.toml")):
        assert load_study(f).points()


def test_robustness_target_not_reached_writes_then_exits_3(tmp_path):
    out = tmp_path / "short"
    res = invoke(
        "robustness", "bennett", "--until", "A=170", "--max-steps", "5", "--samples", "10",
        "--hinge-position-tol", "1e-4", "--hinge-direction-tol", "0.01", "--workers", "0", "--no-plots",
        "-o", str(out),
    )  # fmt: skip
    assert res.exit_code == 3
    text = ANSI.sub("", res.stderr).strip()
    assert len(text.splitlines()) == 1 and "A = 170" in text
    summary = json.loads((out / "robustness.json").read_text())
    assert summary["samples"] == 10 and summary["bands"]["drive_deg"][-1] < 170.0


def test_couplings_only_restrict_the_misfit(tmp_path):
    """Coupled joints stay equal in every sample: the least residual is taken over fewer motions (a subset of the
    free loop's plane normal to the path), so no sample's misfit can be smaller than the free loop's."""
    import pyarrow.parquet as pq

    common = [
        "hedgepeth-rods", "--until", "A=100", "--steps", "20", "--samples", "30", "--hinge-position-tol", "1e-4",
        "--hinge-direction-tol", "0.01", "--seed", "5", "--workers", "0", "--no-plots",
    ]  # fmt: skip
    assert invoke("robustness", *common, "-o", str(tmp_path / "free")).exit_code == 0
    res = invoke("robustness", *common, "--couple", "A=C=E", "--couple", "B=D=F", "-o", str(tmp_path / "sym"))
    assert res.exit_code == 0, res.stderr
    free = np.array(pq.read_table(tmp_path / "free" / "samples.parquet")["misfit_max"])
    sym = np.array(pq.read_table(tmp_path / "sym" / "samples.parquet")["misfit_max"])
    assert np.all(sym >= free * (1.0 - 1e-8))  # tolerance: the solves' 1e-8 relative accuracy
    assert np.median(sym / free) > 1.05  # and the restriction is felt
    bad = invoke("robustness", *common, "--couple", "A", "-o", str(tmp_path / "bad"))
    assert bad.exit_code == 2 and "--couple" in ANSI.sub("", bad.stderr)


def test_robustness_short_of_until_keeps_the_study_and_exits_3(tmp_path):
    out = tmp_path / "short"
    res = invoke(
        "robustness", "bennett", "--until", "A=100", "--max-steps", "5", "--samples", "10",
        "--hinge-position-tol", "1e-4", "--hinge-direction-tol", "0.01", "--workers", "0", "--no-plots",
        "-o", str(out),
    )  # fmt: skip
    assert res.exit_code == 3
    line = ANSI.sub("", res.stderr).strip()
    assert line.startswith("error: the nominal path stopped before A = 100 (step budget, at ")
    stopped = float(re.search(r"at ([-0-9.e]+)\)", line).group(1))
    summary = json.loads((out / "robustness.json").read_text())
    assert summary["samples"] == 10
    # where it says it stopped is the last point of the study's drive grid (degrees)
    assert stopped == pytest.approx(summary["bands"]["drive_deg"][-1], abs=1e-4)


def test_robustness_prints_the_normalised_ratio_beside_the_papers(tmp_path):
    """The four-bar example written in millimetres 25 m from the origin: the paper's (raw) ratio grows with the
    distance and the unit, the normalised one printed beside it is the unit file's, and both are robustness.json's."""
    text = (SPECS / "four-bar.toml").read_text()
    far = re.sub(
        r"point = \[([-0-9.]+), ([-0-9.]+)\]",
        lambda m: f"point = [{float(m[1]) * 1000 + 25000.0}, {float(m[2]) * 1000 - 12000.0}]",
        text,
    )
    (tmp_path / "far.toml").write_text(far)
    lines = {}
    for name, spec, tol in (
        ("unit", str(SPECS / "four-bar.toml"), "0.001"),
        ("far", str(tmp_path / "far.toml"), "1"),
    ):
        out = tmp_path / name
        res = invoke(
            "robustness", spec, "--samples", "10", "--hinge-position-tol", tol, "--hinge-direction-tol", "0.01",
            "--workers", "0", "-o", str(out),
        )  # fmt: skip
        assert res.exit_code == 0, res.stderr
        bands = json.loads((out / "robustness.json").read_text())["bands"]
        line = next(x for x in ANSI.sub("", res.stdout).splitlines() if x.startswith("Sec. 5 ratio"))
        found = re.search(r"\): ([-+.\deE]+); normalised \(.*\) ([-+.\deE]+)$", line)
        assert found, line
        paper, normalised = float(found[1]), float(found[2])
        lines[name] = (paper, normalised)
        assert paper == pytest.approx(max(v for v in bands["ratio"] if v is not None), rel=1e-3)
        assert normalised == pytest.approx(
            max(v for v in bands["ratio_normalised"] if v is not None), rel=1e-3
        )
    assert lines["far"][1] == pytest.approx(lines["unit"][1], rel=1e-3)
    assert lines["far"][0] > 1e4 * lines["unit"][0]
