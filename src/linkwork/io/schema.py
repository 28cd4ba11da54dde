"""A small declarative schema language for the files linkwork reads back, and the one place they are checked.

A schema says what a file holds; :meth:`JsonSchema.read` and :meth:`CsvSchema.read` read a file and check it
once, so that a damaged file (empty, truncated, binary or not UTF-8, short rows, non-numeric or non-finite cells,
missing keys, wrong types, truncated JSON) is one :class:`~linkwork.errors.SpecError` naming the file, the row
or key, and what was expected. The schemas of linkwork's own files are listed in
:data:`linkwork.io.readback.SCHEMAS`.

JSON values are described by :class:`Value` objects: :data:`NUMBER` (finite), :data:`INTEGER`, :data:`TEXT`,
:data:`BOOLEAN`, :class:`ListOf`, :class:`Table` (an object with keys, each required or optional),
:class:`Nullable` and :class:`OneOf`. A CSV file is a header row, then rows of as many cells: some columns whole
numbers, some text, every other one a finite number.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from linkwork.errors import SpecError
from linkwork.io.toml_reader import MAX_FILE_BYTES, check_input_file, escape_line, key_path, show

__all__ = [
    "BOOLEAN",
    "INTEGER",
    "NUMBER",
    "POSITIVE",
    "TEXT",
    "Choice",
    "CsvSchema",
    "CsvTable",
    "JsonSchema",
    "ListOf",
    "Nullable",
    "OneOf",
    "Table",
    "TomlSchema",
    "Value",
    "read_text",
]


MAX_CSV_BYTES = 256 * 1024 * 1024
"""The largest result table read back (256 MiB: a long trace of many branches writes tens of MiB)."""


def read_text(path: Path, what: str, max_bytes: int = MAX_FILE_BYTES) -> str:
    """The UTF-8 text of ``path`` (at most ``max_bytes``); a missing, unreadable, oversized, binary or non-UTF-8
    file is a :class:`SpecError` naming it and ``what`` was expected."""
    source = escape_line(str(path))
    expected = f"expected {what}"
    check_input_file(path, what)
    try:
        size = path.stat().st_size
        if size > max_bytes:
            raise SpecError(
                f"is {size} bytes, larger than the limit of {max_bytes}; {expected}", source=source
            )
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError:
        raise SpecError(f"not a UTF-8 text file; {expected}", source=source) from None
    except OSError as exc:
        raise SpecError(f"cannot be read ({exc.strerror or exc}); {expected}", source=source) from None
    if "\x00" in text:
        raise SpecError(f"holds NUL bytes (a binary file); {expected}", source=source)
    if not text.strip():
        raise SpecError(f"is empty; {expected}", source=source)
    return text


class Value:
    """What a JSON value must be; :meth:`check` raises :class:`SpecError` naming the key path."""

    expected: str

    def check(self, value: Any, key: str, source: str) -> None:  # pragma: no cover - every kind overrides it
        raise NotImplementedError

    def fail(self, value: Any, key: str, source: str) -> SpecError:
        return SpecError(f"expected {self.expected}, got {show(value)}", source=source, key=key or None)


@dataclass(frozen=True)
class _Scalar(Value):
    expected: str
    accept: Callable[[Any], bool]

    def check(self, value: Any, key: str, source: str) -> None:
        if not self.accept(value):
            raise self.fail(value, key, source)


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


NUMBER = _Scalar("a finite number", _is_number)
POSITIVE = _Scalar("a positive finite number", lambda v: _is_number(v) and v > 0)
INTEGER = _Scalar("a whole number", lambda v: isinstance(v, int) and not isinstance(v, bool))
TEXT = _Scalar("a text", lambda v: isinstance(v, str))
BOOLEAN = _Scalar("true or false", lambda v: isinstance(v, bool))


@dataclass(frozen=True)
class Choice(Value):
    """One of the texts ``choices``."""

    choices: tuple[str, ...]

    @property
    def expected(self) -> str:  # type: ignore[override]
        return "one of " + ", ".join(self.choices)

    def check(self, value: Any, key: str, source: str) -> None:
        if not isinstance(value, str) or value not in self.choices:
            raise self.fail(value, key, source)


@dataclass(frozen=True)
class Nullable(Value):
    """``null`` or ``inner``."""

    inner: Value

    @property
    def expected(self) -> str:  # type: ignore[override]
        return f"null or {self.inner.expected}"

    def check(self, value: Any, key: str, source: str) -> None:
        if value is not None:
            self.inner.check(value, key, source)


@dataclass(frozen=True)
class OneOf(Value):
    """Any of ``kinds`` (the first that accepts the value)."""

    kinds: tuple[Value, ...]

    @property
    def expected(self) -> str:  # type: ignore[override]
        return " or ".join(k.expected for k in self.kinds)

    def check(self, value: Any, key: str, source: str) -> None:
        for kind in self.kinds:
            try:
                kind.check(value, key, source)
                return
            except SpecError:
                continue
        raise self.fail(value, key, source)


@dataclass(frozen=True)
class ListOf(Value):
    """A list of ``item`` (of exactly ``length`` items when given)."""

    item: Value
    length: int | None = None

    @property
    def expected(self) -> str:  # type: ignore[override]
        count = f"{self.length} " if self.length is not None else ""
        return f"a list of {count}items, each {self.item.expected}"

    def check(self, value: Any, key: str, source: str) -> None:
        if not isinstance(value, list) or (self.length is not None and len(value) != self.length):
            raise self.fail(value, key, source)
        for i, item in enumerate(value):
            self.item.check(item, key_path(key, i), source)


@dataclass(frozen=True)
class Table(Value):
    """A JSON object: ``required`` and ``optional`` keys with their kinds; other keys are allowed (a newer
    linkwork may add keys) unless ``closed``, and with ``values`` every other key's value must be of that kind."""

    required: Mapping[str, Value] = field(default_factory=dict)
    optional: Mapping[str, Value] = field(default_factory=dict)
    values: Value | None = None
    expected = "an object"

    def check(self, value: Any, key: str, source: str) -> None:
        if not isinstance(value, dict):
            raise self.fail(value, key, source)
        for name, kind in self.required.items():
            if name not in value:
                raise SpecError(f"missing; expected {kind.expected}", source=source, key=key_path(key, name))
            kind.check(value[name], key_path(key, name), source)
        for name, kind in self.optional.items():
            if name in value:
                kind.check(value[name], key_path(key, name), source)
        if self.values is not None:
            for name, item in value.items():
                if name not in self.required and name not in self.optional:
                    self.values.check(item, key_path(key, str(name)), source)


@dataclass(frozen=True)
class JsonSchema:
    """A JSON file: its name, what it is, and the kind of its top-level value (a :class:`Table`)."""

    file: str
    what: str
    top: Table

    def read(self, path: Path) -> dict[str, Any]:
        """The checked content of ``path``; any damage is one :class:`SpecError` naming the file and key."""
        source = escape_line(str(path))
        text = read_text(path, self.what)

        def refuse_constant(name: str) -> float:
            raise ValueError(f"{name} is not a JSON number")

        try:
            value = json.loads(text, parse_constant=refuse_constant)
        except RecursionError:
            raise SpecError(f"nested too deeply; expected {self.what}", source=source) from None
        except json.JSONDecodeError as exc:
            raise SpecError(
                f"invalid JSON ({escape_line(exc.msg)}); expected {self.what}",
                source=source,
                key=f"line {exc.lineno}, column {exc.colno}",
            ) from None
        except ValueError as exc:
            raise SpecError(
                f"invalid JSON ({escape_line(str(exc))}); expected {self.what}", source=source
            ) from None
        self.top.check(value, "", source)
        return value


@dataclass(frozen=True)
class CsvTable:
    """A CSV file read back: its header and one ``numbers`` array row per line (``int`` for whole-number
    columns, ``float`` otherwise), text columns as read."""

    header: list[str]
    rows: list[list[Any]]
    source: str

    def column(self, name: str) -> list[Any]:
        """Every row's value of column ``name``."""
        k = self.header.index(name)
        return [row[k] for row in self.rows]


@dataclass(frozen=True)
class CsvSchema:
    """A CSV file: a header row naming its columns, then at least ``min_rows`` rows of as many cells.

    ``fixed`` columns must be present; ``integers`` hold whole numbers, ``texts`` any text (present or not),
    every other column a finite number. Columns beyond the fixed ones (one per joint or point) are named by the
    file's reader through ``required``."""

    file: str
    what: str
    fixed: tuple[str, ...]
    integers: tuple[str, ...] = ()
    texts: tuple[str, ...] = ()
    min_rows: int = 1
    max_bytes: int = MAX_CSV_BYTES

    def read(self, path: Path, required: Iterable[str] = ()) -> CsvTable:
        """The checked rows of ``path``, with the columns ``fixed`` and ``required``; one :class:`SpecError`
        naming the file, the line and the column for any damage."""
        source = escape_line(str(path))
        text = read_text(path, self.what, self.max_bytes)
        if not text.endswith("\n"):  # linkwork ends every row with a line end: the file was cut off
            raise SpecError(
                f"truncated (the last line has no line end); expected {self.what}",
                source=source,
                key=f"line {text.count(chr(10)) + 1}",
            )
        reader = csv.reader(io.StringIO(text, newline=""))
        try:
            header = next(reader)
        except (StopIteration, csv.Error) as exc:
            raise SpecError(f"no header row ({exc}); expected {self.what}", source=source) from None
        wanted = [*self.fixed, *required]
        missing = [c for c in dict.fromkeys(wanted) if c not in header]
        if missing:
            raise SpecError(
                f"no column {show(missing[0])}; expected the columns {', '.join(show(c) for c in wanted[:12])}"
                f"{' ...' if len(wanted) > 12 else ''} ({self.what})",
                source=source,
                key="line 1",
            )
        duplicate = [c for c in header if header.count(c) > 1]
        if duplicate:
            raise SpecError(
                f"column {show(duplicate[0])} appears twice; expected {self.what}",
                source=source,
                key="line 1",
            )
        kinds = [self._kind(c) for c in header]
        rows: list[list[Any]] = []
        try:
            for cells in reader:
                line = f"line {reader.line_num}"
                if not cells:
                    continue
                if len(cells) != len(header):
                    raise SpecError(
                        f"has {len(cells)} cells, expected {len(header)} (one per column of the header)",
                        source=source,
                        key=line,
                    )
                rows.append(
                    [
                        _cell(kind, cell, name, source, line)
                        for kind, cell, name in zip(kinds, cells, header, strict=True)
                    ]
                )
        except csv.Error as exc:
            raise SpecError(
                f"not a CSV row ({escape_line(str(exc))}); expected {self.what}",
                source=source,
                key=f"line {reader.line_num}",
            ) from None
        if len(rows) < self.min_rows:
            raise SpecError(
                f"has {len(rows)} rows; expected at least {self.min_rows} ({self.what})", source=source
            )
        return CsvTable(header, rows, source)

    def _kind(self, column: str) -> str:
        if column in self.integers:
            return "int"
        if column in self.texts:
            return "text"
        return "float"


def _cell(kind: str, cell: str, column: str, source: str, line: str) -> Any:
    """One CSV cell as its column's kind."""
    where = f"{line}, column {show(column)}"
    if kind == "text":
        return cell
    if kind == "int":
        try:
            return int(cell)
        except ValueError:
            raise SpecError(f"expected a whole number, got {show(cell)}", source=source, key=where) from None
    try:
        value = float(cell)
    except ValueError:
        raise SpecError(f"expected a number, got {show(cell)}", source=source, key=where) from None
    if not math.isfinite(value):
        raise SpecError(f"expected a finite number, got {show(cell)}", source=source, key=where)
    return value


@dataclass(frozen=True)
class TomlSchema:
    """A TOML file linkwork reads back through its own checked reader (a spec, a problem or a study file):
    ``read`` is that reader (every key checked for type and range, see :mod:`linkwork.io.toml_reader`)."""

    file: str
    what: str
    read: Callable[[Path], Any]


Schema = JsonSchema | CsvSchema | TomlSchema
"""Any file schema."""
