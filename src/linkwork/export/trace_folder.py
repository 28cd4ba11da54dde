"""Read back a ``linkwork trace --out`` folder: the mechanism (``mechanism.toml`` + ``drawing.json``) and the
traced joint values (``path.csv``), so that exports can rebuild any traced point."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from linkwork.errors import SpecError
from linkwork.io.readback import read_drawing, read_path_csv
from linkwork.io.toml_reader import show
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


DRAWING_KEYS_FROM_SPEC = ("points",)
"""Keys of ``drawing.json`` that ``mechanism.toml`` states (and that are taken from it, never from the drawing)."""


def read_mechanism(folder: Path) -> Mechanism:
    """The mechanism of a trace folder: ``mechanism.toml`` with the drawing parameters of ``drawing.json``
    (both read through :mod:`linkwork.io.readback`: a damaged file is a :class:`SpecError` naming it)."""
    from linkwork.io.spec import load_spec

    spec = folder / "mechanism.toml"
    if not spec.is_file():
        raise SpecError(
            f"{folder}: no mechanism.toml; expected a folder written by `linkwork trace --out` (version 0.2 or later)"
        )
    mech = load_spec(spec).mechanism
    drawing = folder / "drawing.json"
    if drawing.is_file() or drawing.is_symlink():
        meta = {k: v for k, v in read_drawing(drawing).items() if k not in DRAWING_KEYS_FROM_SPEC}
        for key, count in (("rods", mech.n_joints), ("n", mech.n_joints)):
            given = meta.get(key)
            if given is not None and (len(given) if isinstance(given, list) else given) != count:
                raise SpecError(
                    f"expected {count} (one per joint of mechanism.toml), got {show(given)}",
                    source=str(drawing),
                    key=key,
                )
        transmission = meta.get("transmission")
        if transmission and any(j not in mech.joint_names for j in transmission["joints"]):
            raise SpecError(
                f"names joints {transmission['joints']} that mechanism.toml does not have",
                source=str(drawing),
                key="transmission.joints",
            )
        mech = replace(mech, meta={**meta, **mech.meta, "linkage": meta.get("linkage", "")})
    return mech


def read_trace_folder(folder: str | Path) -> TracedFolder:
    """Read a ``linkwork trace --out`` folder (``mechanism.toml``, ``drawing.json``, ``path.csv``), every file
    checked against its schema (:data:`linkwork.io.readback.SCHEMAS`)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise SpecError(f"{folder}: expected a folder written by `linkwork trace --out`")
    mech = read_mechanism(folder)
    table, columns = read_path_csv(folder / "path.csv", mech.joint_names)
    cols = [table.header.index(c) for c in columns]
    values = np.array([[row[c] for c in cols] for row in table.rows], dtype=float).reshape(-1, len(cols))
    revolute = np.array([t == "R" for t in mech.joint_types])
    values[:, revolute] = np.radians(values[:, revolute])
    branch = np.array(table.column("branch"), dtype=np.int64)
    step = np.array(table.column("step"), dtype=np.int64)
    return TracedFolder(mechanism=mech, angles=values, branch=branch, step=step)
