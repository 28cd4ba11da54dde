"""Read back a ``linkwork trace --out`` folder: the mechanism (``mechanism.toml`` + ``drawing.json``) and the
traced joint values (``path.csv``), so that exports can rebuild any traced point."""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from linkwork.errors import SpecError
from linkwork.kinematics.mechanism import Mechanism


@dataclass(frozen=True)
class TracedFolder:
    """A trace folder read back: ``angles`` ``(N, n)`` radians (``mechanism.joint_names`` order), with the
    ``branch`` and ``step`` of every row of ``path.csv``."""

    mechanism: Mechanism
    angles: NDArray[np.float64]
    branch: NDArray[np.int64]
    step: NDArray[np.int64]

    def point(self, branch: int = 0, point: int = 0) -> NDArray[np.float64]:
        """Joint values (radians) at step ``point`` of ``branch`` (a negative ``point`` counts from its end)."""
        rows = np.flatnonzero(self.branch == branch)
        if rows.size == 0:
            raise SpecError(f"no branch {branch}; the trace has branches {sorted(set(self.branch.tolist()))}")
        if not -rows.size <= point < rows.size:
            raise SpecError(f"branch {branch} has points 0..{rows.size - 1}, got --point {point}")
        return self.angles[rows[point]]


def read_mechanism(folder: Path) -> Mechanism:
    """The mechanism of a trace folder: ``mechanism.toml`` with the drawing parameters of ``drawing.json``."""
    from linkwork.io.spec import load_spec

    spec = folder / "mechanism.toml"
    if not spec.is_file():
        raise SpecError(
            f"{folder}: no mechanism.toml; expected a folder written by `linkwork trace --out` (version 0.2 or later)"
        )
    mech = load_spec(spec).mechanism
    drawing = folder / "drawing.json"
    if drawing.is_file():
        meta = json.loads(drawing.read_text())
        if isinstance(meta, dict):
            mech = replace(mech, meta={**meta, **mech.meta, "linkage": meta.get("linkage", "")})
    return mech


def read_trace_folder(folder: str | Path) -> TracedFolder:
    """Read a ``linkwork trace --out`` folder (``mechanism.toml``, ``drawing.json``, ``path.csv``)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise SpecError(f"{folder}: expected a folder written by `linkwork trace --out`")
    mech = read_mechanism(folder)
    with open(folder / "path.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    header, body = rows[0], rows[1:]
    missing = [n for n in mech.joint_names if n not in header]
    if missing or not body:
        raise SpecError(
            f"{folder / 'path.csv'}: expected columns branch, step and {', '.join(mech.joint_names)}"
        )
    cols = [header.index(n) for n in mech.joint_names]
    values = np.array([[float(r[c]) for c in cols] for r in body])
    revolute = np.array([t == "R" for t in mech.joint_types])
    values[:, revolute] = np.radians(values[:, revolute])
    branch = np.array([int(r[header.index("branch")]) for r in body], dtype=np.int64)
    step = np.array([int(r[header.index("step")]) for r in body], dtype=np.int64)
    return TracedFolder(mechanism=mech, angles=values, branch=branch, step=step)
