"""Paper mode's cubic predictor (:func:`linkwork.kinematics.march.extrapolate`): it changes the work, not the path.

Run with the plain-Python twins of the kernels, in which the predictor can be switched off: the rows of a
paper-mode trace are the same with and without it (the corrector holds the drive, so it converges to the same
point whatever it starts from), and with it one Gauss-Newton iteration closes each step of the hexagon."""

from __future__ import annotations

import collections
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

import linkwork as lw
from linkwork.kinematics import jit
from linkwork.kinematics.trace_result import Trace
from linkwork.linkages.hedgepeth_rods import deployed_angles

STEPS = 200


@pytest.fixture
def twins(monkeypatch: pytest.MonkeyPatch) -> Iterator[dict[str, Any]]:
    """The scope of the twin of ``march`` (patchable), with the plain-Python kernels selected."""
    monkeypatch.setenv("LINKWORK_JIT", "python")
    scope = jit.python_backend().march.__globals__
    yield scope


def hexagon_trace() -> Trace:
    mech = lw.load("hedgepeth-rods", n=6)
    return lw.trace(mech, until=("A", float(deployed_angles(6)[0])), steps=STEPS)


def counted(scope: dict[str, Any], name: str, found: collections.Counter[str]) -> Any:
    original = scope[name]

    def call(*args: Any) -> Any:
        found[name] += 1
        return original(*args)

    return call


def test_the_cubic_predictor_changes_the_work_not_the_path(
    twins: dict[str, Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    corrector_scope = twins["correct_in"].__globals__  # each twin has globals of its own
    found: collections.Counter[str] = collections.Counter()
    monkeypatch.setitem(twins, "extrapolate", counted(twins, "extrapolate", found))
    monkeypatch.setitem(corrector_scope, "evaluate_in", counted(corrector_scope, "evaluate_in", found))
    with_cubic = hexagon_trace()
    assert found["extrapolate"] == STEPS - 1  # every step after the first
    assert found["evaluate_in"] <= 2 * STEPS + 1  # the predicted point, then the corrected one: closed
    monkeypatch.setitem(twins, "extrapolate", lambda *args: False)  # the tangent predictor alone
    found.clear()
    tangent_only = hexagon_trace()
    assert found["evaluate_in"] >= 3 * STEPS - 1  # the tangent alone leaves two iterations a step
    np.testing.assert_allclose(with_cubic.angles, tangent_only.angles, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(with_cubic.sigma, tangent_only.sigma, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(with_cubic.test, tangent_only.test, rtol=1e-10)
    assert with_cubic.residual.max() < 1e-12 and tangent_only.residual.max() < 1e-12
