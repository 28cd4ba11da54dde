"""A flag that takes one of a few words refuses any other with one ``error:`` line naming the flag and the words it
takes (exit 2), before any work and without writing the output folder."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from linkwork.cli import app
from linkwork.studies.imperfections import DISTRIBUTIONS

runner = CliRunner()


@pytest.mark.parametrize("word", ["cauchy", "Normal", "uniform ", ""])
def test_robustness_refuses_an_unknown_distribution(tmp_path: Path, word: str) -> None:
    out = tmp_path / "run"
    result = runner.invoke(
        app,
        [
            "robustness", "four-bar", "--samples", "4", "--hinge-position-tol", "1e-3", "--hinge-direction-tol",
            "0.05", "--distribution", word, "-o", str(out), "--no-plots",
        ],
    )  # fmt: skip
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and "--distribution" in lines[0], result.output
    assert all(f'"{name}"' in lines[0] for name in DISTRIBUTIONS) or word == "", result.output
    assert "Traceback" not in result.output
    assert not out.exists()
