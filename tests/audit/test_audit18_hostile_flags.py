"""Hostile values of ``linkwork trace``'s flags (DESIGN: bad input is one line and exit code 2, never a traceback;
the help states each flag's bounds). Checked over 40 values (NaN, inf, 0, negatives, huge, empty, unknown joints,
reversed limits, self-couplings): every one gave one line and exit 2 (or 3 for a target beyond the step budget),
except ``--closure-tol`` from about 0.1 up to its stated bound 1e12.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import linkwork as lw
from linkwork.cli import app


@pytest.mark.parametrize(
    "args",
    [
        ["--closure-tol", "nan"],
        ["--max-step", "1e300"],
        ["--limit", "A=5:1"],
        ["--until", "A=inf"],
        ["--couple", "A=A"],
        ["--set", "crank=nan"],
    ],
)
def test_bad_flags_are_one_line_and_exit_2(tmp_path: Path, args: list[str]) -> None:
    """Holds: exit 2, one line on stderr, nothing written."""
    out = tmp_path / "o"
    result = CliRunner().invoke(app, ["trace", "four-bar", *args, "-o", str(out), "--no-plots"])
    assert result.exit_code == 2
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.output
    assert not (out / "path.csv").exists()


def test_a_small_closure_tolerance_traces_the_exact_four_bar_as_before(tmp_path: Path) -> None:
    """Holds: --closure-tol 1e-3 on the (exact) built-in four-bar: the crank turns once, the path closes."""
    tr = lw.trace(lw.load("four-bar"), closure_tol=1e-3)
    assert tr.branches[0].end_kind == lw.StopReason.CLOSED
    assert np.degrees(np.ptp(tr.angles[:, 0])) == pytest.approx(360.0, abs=1e-9)


@pytest.mark.parametrize("tol", ["0.1", "0.3", "0.5"])
def test_a_large_closure_tolerance_within_its_bound_is_not_a_traceback(tmp_path: Path, tol: str) -> None:
    """``linkwork trace four-bar --closure-tol 0.1`` (the help allows 0 < --closure-tol <= 1e12). Got: exit 1 and
    an 85-line traceback ending 'ValueError: operands could not be broadcast together with shapes (0,) (2,)' (or
    (4,)); ``lw.trace(mech, closure_tol=0.5)`` raises the same ValueError. Right: the trace runs (the loop is exact:
    the crank turns once and the path closes) or the value is refused up front in one line, exit 2. Cause:
    kinematics/rank.py: ``Tolerances.with_closure`` raises ``loose`` to 10 x closure >= 1, so in
    ``numerical_rank`` no singular value is 'sure' (``sure = 0``) and ``padded[sure - 1 : candidates]`` is the
    empty slice ``padded[-1:candidates]``. (From 1 up, every singular value is below the raised floor and the
    start is refused as 'mobility 4 at the start (rank 0, 4 unknowns)', exit 2: one line, but not what is wrong.)"""
    out = tmp_path / "o"
    result = CliRunner().invoke(
        app, ["trace", "four-bar", "--closure-tol", tol, "-o", str(out), "--no-plots"]
    )
    assert "Traceback" not in result.output and not isinstance(result.exception, ValueError)
    assert result.exit_code in (0, 2)
