"""Shared nominal paths of the studies tests (traced once per session)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import linkwork as lw
from linkwork.io.spec import resolve_spec

SPECS = Path(__file__).resolve().parents[2] / "examples" / "specs"


@pytest.fixture(scope="session")
def four_bar() -> tuple[lw.Mechanism, lw.Trace]:
    """The crank-rocker four-bar of the examples, crank from 45 to 135 deg in 40 equal steps."""
    mech = resolve_spec(SPECS / "four-bar.toml").mechanism
    return mech, lw.trace(mech, until=("A", np.radians(135.0)), steps=40)


@pytest.fixture(scope="session")
def bennett() -> tuple[lw.Mechanism, lw.Trace]:
    """Bennett's linkage (45, 75 deg twists), joint A from 60 to 120 deg in 40 equal steps."""
    mech = lw.load("bennett")
    return mech, lw.trace(mech, until=("A", np.radians(120.0)), steps=40)
