"""Closed and fixed-end chains mechanized to one DOF: the body closing the loop frees one body from its link.

A chain of ``n`` bodies and ``g`` joints (pinned joints included) has Grübler mobility ``3 n - 2 g``; one DOF takes
one binary link fewer than that. The bundled ``closed`` and ``fixed-end`` examples, built up with one link per
body, had one link too many and no design moved. Here the written mechanism has a one-dimensional null space of
its closure Jacobian (numpy's SVD), the link count is Grübler's, and the kinematic core traces it from profile 1
through every profile in order, the shape error there the joined chain's (exact links, three profiles).
"""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from linkwork.data import example
from linkwork.io.problem import load_problem
from linkwork.io.spec import load_spec
from linkwork.kinematics.closure import jacobian
from linkwork.kinematics.tracer import trace
from linkwork.mechanization import mechanize, write_mechanization
from linkwork.synthesis import synthesize


def _mechanized(name: str, folder: Path) -> tuple[dict, Path]:
    found = mechanize(synthesize(load_problem(example(name))))
    write_mechanization(found, folder)
    return json.loads((folder / "mechanization.json").read_text()), folder


@pytest.mark.parametrize("name", ["fixed-end", pytest.param("closed", marks=pytest.mark.slow)])
def test_closed_and_fixed_end_examples_mechanize_to_one_dof_and_trace_through_every_profile(
    name: str, tmp_path: Path
) -> None:
    report, folder = _mechanized(name, tmp_path)
    mech = load_spec(folder / "mechanism.toml").mechanism
    spec = tomllib.loads((folder / "mechanism.toml").read_text())["mechanism"]["joints"]
    links = {d["name"] for d in report["dyads"]}
    chain_joints = [j for j in spec if not any(j["name"].startswith(link) for link in links)]
    bodies = {b for j in chain_joints for b in j["bodies"]} - {"ground"}
    # Grübler for the chain alone, less one DOF: the binary links a one-DOF mechanism takes
    assert len(links) == 3 * len(bodies) - 2 * len(chain_joints) - 1
    spectrum = np.linalg.svd(jacobian(mech, np.zeros(mech.n_joints)), compute_uv=False)
    assert mech.n_joints - int(np.sum(spectrum > 1e-9 * spectrum[0])) == 1
    drive = report["drive"]
    values = [p["drive_value"] for p in report["profiles"]]
    assert np.all(np.diff(values) > 0) or np.all(np.diff(values) < 0)  # the profiles in order
    for profile in report["profiles"][1:]:
        value = (
            math.radians(profile["drive_value"]) if report["drive_type"] == "R" else profile["drive_value"]
        )
        path = trace(mech, drive=drive, until=(drive, value))
        assert path.branches[0].end_reason == "reached target"
        assert not path.bifurcations and np.all(path.rank == path.rank[0])
    for profile in report["profiles"]:
        assert abs(profile["e_max"] - profile["joined_e_max"]) <= 1e-9
