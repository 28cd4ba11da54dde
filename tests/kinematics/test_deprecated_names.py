"""Names renamed in 0.2.0 keep working for one release, each with a DeprecationWarning naming the new one."""

from __future__ import annotations

import numpy as np
import pytest

import linkwork as lw
from linkwork.io.results import path_rows, report_dict
from linkwork.viz.snapshots import drive_label


@pytest.fixture(scope="module")
def bennett_trace() -> lw.Trace:
    return lw.trace(lw.load("bennett"), until=("A", np.radians(80.0)), steps=10)


def test_lw_path_is_trace_with_a_warning() -> None:
    with pytest.warns(DeprecationWarning, match="linkwork.Trace"):
        alias = lw.Path
    assert alias is lw.Trace


def test_path_keyword_still_passes_the_trace(bennett_trace: lw.Trace) -> None:
    with pytest.warns(DeprecationWarning, match=r"path_rows\(trace=\.\.\.\)"):
        old = path_rows(path=bennett_trace)
    assert old == path_rows(bennett_trace) == path_rows(trace=bennett_trace)
    with pytest.warns(DeprecationWarning):
        label = drive_label(path=bennett_trace, i=3)
    assert label == drive_label(bennett_trace, 3)
    with pytest.warns(DeprecationWarning):
        rep = report_dict(path=bennett_trace)
    assert rep["points"] == 11 == len(bennett_trace.angles)
