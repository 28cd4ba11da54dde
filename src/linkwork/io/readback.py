"""The one reader of every file linkwork reads back: a schema per file (:data:`SCHEMAS`), checked once on read.

Every command that reads a file linkwork wrote (``export`` a trace folder, ``mechanize`` a synth folder, the
demo reading its own results) goes through the functions here, so that a damaged file is one
:class:`~linkwork.errors.SpecError` (exit 2) naming the file, the row or key, and what was expected, and never a
traceback. A new command that reads one of these files gets the same checks by calling the same function.

:data:`SCHEMAS` maps each file name to its schema (:mod:`linkwork.io.schema`): :class:`~linkwork.io.schema.CsvSchema`
(fixed and whole-number columns), :class:`~linkwork.io.schema.JsonSchema` (keys and their kinds) or
:class:`~linkwork.io.schema.TomlSchema` (read by linkwork's checked TOML readers). Tools that derive damaged
files from the schemas (the fuzz suite) enumerate it.
"""

from __future__ import annotations

import importlib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from linkwork.io.drawing import LENGTH_UNITS
from linkwork.io.schema import (
    BOOLEAN,
    INTEGER,
    NUMBER,
    POSITIVE,
    TEXT,
    Choice,
    CsvSchema,
    CsvTable,
    JsonSchema,
    ListOf,
    Nullable,
    OneOf,
    Table,
    TomlSchema,
)
from linkwork.names import NameMap, csv_columns

__all__ = [
    "PATH_FIXED",
    "PATH_PATTERNS",
    "SCHEMAS",
    "path_columns",
    "points_columns",
    "read_chain",
    "read_drawing",
    "read_mechanization",
    "read_path_csv",
    "read_points_csv",
    "read_report",
    "read_schema",
]

PATH_FIXED = ("branch", "step", "s", "residual")
"""The fixed columns of ``path.csv`` (with ``sigma_1`` .. ``sigma_k``, :data:`PATH_PATTERNS`)."""

PATH_PATTERNS = (r"sigma_\d+",)
"""Fixed columns of ``path.csv`` given as patterns."""

POINTS_FIXED = ("branch", "step", "transmission")
"""The fixed columns of ``points.csv`` (then ``<name>_x``, ``_y``, ``_z`` per joint and named point)."""


def path_columns(joints: Sequence[str]) -> NameMap:
    """The column of every joint in ``path.csv``: its name, or ``joint:<name>`` when the name clashes with a
    fixed column (:func:`linkwork.names.csv_columns`); the writer and the reader both use this."""
    return csv_columns("path.csv", joints, PATH_FIXED, patterns=PATH_PATTERNS)


def points_columns(names: Sequence[str]) -> NameMap:
    """The column stem of every joint and named point in ``points.csv`` (``<stem>_x``, ``_y``, ``_z``), by the
    same rule as :func:`path_columns` (a stem never clashes with ``branch``, ``step`` or ``transmission``)."""
    return csv_columns("points.csv", names, POINTS_FIXED, suffixes=("_x", "_y", "_z"))


def _toml(reader: str) -> Any:
    """A reader named ``module:function`` (imported when called: study files are read by a higher layer)."""

    def read(path: Path) -> Any:
        module, _, name = reader.partition(":")
        return getattr(importlib.import_module(module), name)(path)

    read.__doc__ = f"Read the file with {reader}."
    return read


_UNITS = Choice(tuple(LENGTH_UNITS))
_ROD = Table(required={"phi": NUMBER, "omega": NUMBER, "psi": NUMBER, "v": ListOf(NUMBER, 3)})
_CONFIG = Table(values=NUMBER)

SCHEMAS: dict[str, JsonSchema | CsvSchema | TomlSchema] = {
    "path.csv": CsvSchema(
        "path.csv",
        "the path.csv that `linkwork trace` writes (branch,step,s,<joints>,sigma_1..,residual)",
        fixed=PATH_FIXED,
        integers=("branch", "step"),
    ),
    "points.csv": CsvSchema(
        "points.csv",
        "the points.csv that `linkwork trace` writes (branch,step,<name>_x,_y,_z..)",
        fixed=("branch", "step"),
        integers=("branch", "step"),
    ),
    "report.json": JsonSchema(
        "report.json",
        "the report.json that `linkwork trace` writes",
        Table(
            required={"joints": ListOf(TEXT)},
            optional={
                "name": TEXT,
                "drive": Nullable(TEXT),
                "joint_types": ListOf(TEXT),
                "rank": INTEGER,
                "mobility": INTEGER,
                "points": INTEGER,
                "bifurcations": ListOf(Table()),
                "folds": ListOf(Table()),
                "branches": ListOf(Table(optional={"id": INTEGER, "start": _CONFIG, "end": _CONFIG})),
            },
        ),
    ),
    "drawing.json": JsonSchema(
        "drawing.json",
        "the drawing.json that `linkwork trace` writes (the linkage's drawing parameters)",
        Table(
            optional={
                "linkage": TEXT,
                "convention": TEXT,
                "rods": ListOf(_ROD),
                "n": INTEGER,
                "width": POSITIVE,
                "length": POSITIVE,
                "section": POSITIVE,
                "transmission": Table(required={"kind": TEXT, "joints": ListOf(TEXT, 3)}),
            },
        ),
    ),
    "chain.json": JsonSchema(
        "chain.json",
        "the chain.json that `linkwork synth` writes",
        Table(
            required={"design": TEXT, "joined": Table(required={"e_max": NUMBER})},
            optional={
                "units": Nullable(_UNITS),
                "e_max": NUMBER,
                "e_mean": NUMBER,
                "complete": BOOLEAN,
                "stopped": Nullable(TEXT),
            },
        ),
    ),
    "mechanization.json": JsonSchema(
        "mechanization.json",
        "the mechanization.json that `linkwork mechanize` writes",
        Table(
            required={
                "dof": INTEGER,
                "drive": TEXT,
                "profiles": ListOf(Table(required={"e_max": NUMBER})),
            },
            optional={
                "verified": OneOf((BOOLEAN, Table())),
                "complete": BOOLEAN,
                "stopped": Nullable(TEXT),
            },
        ),
    ),
    "mechanism.toml": TomlSchema(
        "mechanism.toml", "a linkage spec file (TOML)", _toml("linkwork.io.spec:load_spec")
    ),
    "problem.toml": TomlSchema(
        "problem.toml", "a problem file (TOML)", _toml("linkwork.io.problem:load_problem")
    ),
    "study.toml": TomlSchema(
        "study.toml", "a study file (TOML)", _toml("linkwork.studies.study_file:load_study")
    ),
}
"""The schema of every file linkwork reads back, keyed by file name (a study file may have any name; its
schema is keyed ``study.toml``)."""


def read_schema(name: str, path: Path) -> Any:
    """Read ``path`` with the schema of file ``name`` (a key of :data:`SCHEMAS`)."""
    schema = SCHEMAS[name]
    return schema.read(path)


def read_path_csv(path: Path, joints: Sequence[str]) -> tuple[CsvTable, list[str]]:
    """``path.csv`` with a column for every joint (through :func:`path_columns`); returns the table and the
    joints' column names in order."""
    columns = [path_columns(joints)[j] for j in joints]
    schema = SCHEMAS["path.csv"]
    assert isinstance(schema, CsvSchema)
    return schema.read(path, columns), columns


def read_points_csv(path: Path) -> CsvTable:
    """``points.csv``, checked."""
    schema = SCHEMAS["points.csv"]
    assert isinstance(schema, CsvSchema)
    return schema.read(path)


def read_report(path: Path) -> dict[str, Any]:
    """``report.json``, checked."""
    return read_schema("report.json", path)


def read_drawing(path: Path) -> dict[str, Any]:
    """``drawing.json``, checked."""
    return read_schema("drawing.json", path)


def read_chain(path: Path) -> dict[str, Any]:
    """``chain.json``, checked."""
    return read_schema("chain.json", path)


def read_mechanization(path: Path) -> dict[str, Any]:
    """``mechanization.json``, checked."""
    return read_schema("mechanization.json", path)
