"""The one flag checker (issue 19 item 4): every numeric flag of every command is refused outside its declared
bounds (``FLAG_LIMITS``) as the command line is parsed, in one line naming the flag and the bounds, before any
work starts; the bounds and the flags come from the app itself, so a new flag is covered."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from cli_cases import Case, command_line, parameters
from fuzzkit import run_cli
from test_generated_cli import FIXTURES

from linkwork.cli.options import FLAG_LIMITS
from linkwork.limits import Limit, machine_cores

NUMERIC = [p for p in parameters() if p.kind in ("int", "float")]


def outside(limit: Limit) -> list[str]:
    """Values just outside ``limit`` (for a real flag, non-finite ones too; a whole-number flag refuses
    those as it parses them)."""
    if limit.whole:
        return [str(int(limit.low) - 1), str(int(limit.upper) + 1)]
    step = 1e-6 * max(1.0, abs(limit.upper - limit.low))
    values = [repr(limit.low - step), repr(limit.upper + step), "nan", "inf", "-inf"]
    if limit.open_low:
        values.append(repr(limit.low))
    if limit.open_high:
        values.append(repr(limit.upper))
    return values


@pytest.mark.parametrize("param", NUMERIC, ids=lambda p: f"{' '.join(p.command)} {p.flag}")
def test_every_numeric_flag_is_refused_outside_its_bounds(tmp_path: Path, param) -> None:  # type: ignore[no-untyped-def]
    limit = FLAG_LIMITS[param.flag]
    for i, value in enumerate(outside(limit)):
        home = tmp_path / str(i)
        home.mkdir()
        args, out = command_line(Case(param.command, param.flag, value), home, FIXTURES)
        run = run_cli(args, out=out, home=home)
        assert run.code == 2, (args, run)
        assert (
            f"error: {param.flag} " in run.stderr and f"expected {limit.expected(param.flag)}" in run.stderr
        )


def test_workers_are_capped_by_the_machine(tmp_path: Path) -> None:
    cores = os.cpu_count() or 1
    assert machine_cores() == cores
    run = run_cli(["sweep", "s.toml", "--workers", str(cores + 1)])
    assert run.code == 2
    assert f"0 <= --workers <= {cores} (the cores of this machine, os.cpu_count())" in run.stderr
