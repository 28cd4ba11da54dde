"""The one TOML validation layer of linkwork's input files (linkage specs and synthesis problems).

A file is data, never code: it is parsed with :mod:`tomllib`, then read through :class:`TomlReader`, whose typed
getters raise one-line :class:`~linkwork.errors.SpecError`\\ s naming the file, the key path and what was
expected, quoting the value that was found (:func:`show`), and hinting at the closest valid key or choice.

Key paths join tables with dots and count array items **from 0**: ``loop.joints[2].alpha`` is the ``alpha`` of
the third ``[[loop.joints]]`` block, ``profiles[0]`` the first profile of a problem file.
"""

from __future__ import annotations

import math
import re
import tomllib
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from linkwork.errors import SpecError
from linkwork.messages import closest, escape_line, show
from linkwork.names import MAX_NAME_CHARS

__all__ = [
    "MAX_FILE_BYTES",
    "MAX_MAGNITUDE",
    "MAX_NAME_CHARS",
    "TomlReader",
    "check_input_file",
    "closest",
    "input_file_problem",
    "key_path",
    "read_toml",
    "show",
]

MAX_FILE_BYTES = 16 * 1024 * 1024
"""The largest input file read (16 MiB); a larger one is refused with a message."""

MAX_MAGNITUDE = 1e12
"""The largest absolute value of a number in a file (a length, a coordinate, an angle)."""


def key_path(path: str, key: str | int) -> str:
    """Join a key path: ``loop`` and ``joints`` give ``loop.joints``, then 2 gives ``loop.joints[2]``.

    A key that is not a plain TOML bare key is shown quoted and escaped, so the path stays one line.
    """
    if isinstance(key, int):
        return f"{path}[{key}]"
    if not re.fullmatch(r"[A-Za-z0-9_-]{1,64}", key):
        key = show(key)
    return f"{path}.{key}" if path else key


def input_file_problem(path: Path) -> str | None:
    """What keeps ``path`` from being read as an input file (``"file not found"``, ``"is a folder"``, ``"is not a
    regular file ..."``, ``"cannot be read (File name too long)"``), or ``None`` when it is a regular file."""
    try:
        if not path.exists():
            return "file not found"
        if path.is_dir():
            return "is a folder"
        if not path.is_file():  # reading a FIFO would block, a device might never end
            return "is not a regular file (a FIFO, socket or device)"
    except OSError as exc:  # ENAMETOOLONG, EACCES on a folder on the way: Path.exists lets these through
        return f"cannot be read ({exc.strerror or exc})"
    return None


def check_input_file(path: Path, what: str) -> None:
    """Refuse an input ``path`` that cannot be read as a file (see :func:`input_file_problem`) with one
    :class:`SpecError` naming it and ``what`` was expected (``"a linkage spec file (TOML)"``). Every reader of a
    user's file starts here."""
    problem = input_file_problem(path)
    if problem is not None:
        raise SpecError(f"{problem}; expected {what}", source=escape_line(str(path)))


def read_toml(path: Path, what: str) -> dict[str, Any]:
    """The parsed TOML file ``path``; any problem becomes a :class:`SpecError` naming the file (and line).

    ``what`` says what the file should be, e.g. ``"a linkage spec file (TOML)"``.
    """
    expected = f"expected {what}"
    check_input_file(path, what)
    source = escape_line(str(path))
    try:
        if path.stat().st_size > MAX_FILE_BYTES:
            raise SpecError(
                f"is {path.stat().st_size} bytes, larger than the limit of {MAX_FILE_BYTES}; {expected}",
                source=source,
            )
        # "utf-8-sig": a byte-order mark (Notepad writes one) is not part of the text; as U+FEFF it would be an
        # "invalid statement" at line 1, column 1, which names nothing the user can see in the file.
        text = path.read_bytes().decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = exc.object[: exc.start].count(b"\n") + 1
        raise SpecError(
            f"not a UTF-8 text file (byte {exc.object[exc.start]:#04x} at line {line}); {expected}",
            source=source,
        ) from None
    except OSError as exc:
        raise SpecError(f"cannot be read ({exc.strerror}); {expected}", source=source) from None
    try:
        return tomllib.loads(text)
    except RecursionError:
        raise SpecError(f"invalid TOML: nested too deeply; {expected}", source=source) from None
    except ValueError as exc:
        if isinstance(exc, tomllib.TOMLDecodeError):
            raise _decode_error(exc, text, source) from None
        # Python refuses to read a whole number of more than sys.get_int_max_str_digits() digits (4300): tomllib
        # lets that ValueError out, with a traceback
        digits = re.search(r"[0-9][0-9_]{999,}", text)
        where = f"line {text.count(chr(10), 0, digits.start()) + 1}" if digits else None
        raise SpecError(
            f"invalid TOML: a number of thousands of digits; expected numbers within +-{MAX_MAGNITUDE:g}",
            source=source,
            key=where,
        ) from None


def _decode_error(exc: tomllib.TOMLDecodeError, text: str, source: str) -> SpecError:
    """The one-line error of a TOML syntax error ``exc`` in ``text``, with its line and column."""
    message = str(exc)
    match = re.search(r"\s*\(at line (\d+), column (\d+)\)$", message)
    if match:
        where = f"line {match.group(1)}, column {match.group(2)}"
        message = message[: match.start()]
    else:
        where = f"line {text.count(chr(10)) + 1} (end of file)"
        message = message.replace(" (at end of document)", "")
    return SpecError(f"invalid TOML: {escape_line(message)}", source=source, key=where)


class TomlReader:
    """Typed getters over parsed TOML tables that raise one-line :class:`SpecError`\\ s naming file and key.

    Every getter takes the table, the key and the key path of the table (``""`` at the top level). A missing
    key returns ``default``; with ``default=None`` and ``required`` set, a missing key is an error.

    Attributes
    ----------
    source
        The file being read, first in every message (control characters escaped).
    degrees
        Whether angles in the file are degrees (converted to radians by :meth:`number` with ``angle=True``).
    elsewhere
        For an unknown key, where it belongs instead (shown when no valid key is close).
    """

    def __init__(self, source: str, elsewhere: Mapping[str, str] | None = None) -> None:
        self.source = escape_line(source)  # a file name may hold a line break: the message stays one line
        self.degrees = True
        self.elsewhere = dict(elsewhere or {})

    def error(self, key: str, message: str) -> SpecError:
        """The :class:`SpecError` of ``key`` (a full key path) with ``message``."""
        return SpecError(message, source=self.source, key=key or None)

    def table(self, value: Any, path: str, allowed: Sequence[str], form: str | None = None) -> dict[str, Any]:
        """``value`` checked to be a table with only ``allowed`` keys."""
        if not isinstance(value, dict):
            raise self.error(path, f"expected a table{f' {form}' if form else ''}, got {show(value)}")
        self.check_keys(value, path, allowed)
        return value

    def check_keys(self, table: Mapping[str, Any], path: str, allowed: Sequence[str]) -> None:
        """Refuse a key not in ``allowed``, with a did-you-mean hint."""
        for key in table:
            if key in allowed:
                continue
            close = closest(key, allowed)
            hint = f'did you mean "{close}"? ' if close else ""
            elsewhere = self.elsewhere.get(key)
            where = f' ("{key}" belongs in {elsewhere})' if elsewhere and not close else ""
            raise self.error(
                key_path(path, key), f"unknown key; {hint}expected one of {', '.join(allowed)}{where}"
            )

    def require(self, table: Mapping[str, Any], key: str, path: str, expected: str) -> Any:
        """The raw value of a key that must be present."""
        if key not in table:
            raise self.error(key_path(path, key), f"missing; expected {expected}")
        return table[key]

    def string(
        self, table: Mapping[str, Any], key: str, path: str, *, default: str | None, limit: int | None = None
    ) -> str:
        """A non-empty string of at most ``limit`` characters."""
        if key not in table:
            if default is None:
                raise self.error(key_path(path, key), "missing; expected a non-empty string")
            return default
        value = table[key]
        if not isinstance(value, str) or not value.strip():
            raise self.error(key_path(path, key), f"expected a non-empty string, got {show(value)}")
        if limit is not None and len(value) > limit:
            raise self.error(
                key_path(path, key), f"expected at most {limit} characters, got {len(value)}: {show(value)}"
            )
        return value

    def choice(
        self, table: Mapping[str, Any], key: str, path: str, choices: Sequence[str], *, default: str
    ) -> str:
        """One of ``choices`` (a close miss gets a did-you-mean hint)."""
        if key not in table:
            return default
        value = table[key]
        if not isinstance(value, str) or value not in choices:
            quoted = " or ".join(f'"{c}"' for c in choices)
            if len(choices) > 2:
                quoted = "one of " + ", ".join(f'"{c}"' for c in choices)
            close = closest(value, choices, cutoff=0.5) if isinstance(value, str) else None
            hint = f' (did you mean "{close}"?)' if close else ""
            raise self.error(key_path(path, key), f"expected {quoted}, got {show(value)}{hint}")
        return value

    def boolean(self, table: Mapping[str, Any], key: str, path: str, *, default: bool) -> bool:
        """``true`` or ``false``."""
        if key not in table:
            return default
        value = table[key]
        if not isinstance(value, bool):
            raise self.error(key_path(path, key), f"expected true or false, got {show(value)}")
        return value

    def integer(
        self,
        table: Mapping[str, Any],
        key: str,
        path: str,
        *,
        default: int | None,
        minimum: int,
        maximum: int | None = None,
        what: str = "a whole number",
    ) -> int | None:
        """A whole number in ``[minimum, maximum]``; the message states the bounds."""
        if key not in table:
            return default
        value = table[key]
        bounds = f"{minimum} <= {key}" + (f" <= {maximum}" if maximum is not None else "")
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(key_path(path, key), f"expected {what}, {bounds}, got {show(value)}")
        if value < minimum or (maximum is not None and value > maximum):
            raise self.error(key_path(path, key), f"expected {what}, {bounds}, got {show(value)}")
        return int(value)

    def number(
        self,
        table: Mapping[str, Any],
        key: str,
        path: str,
        *,
        default: float | None = None,
        angle: bool = False,
        required: str | None = None,
    ) -> float:
        """A finite number (an angle is converted to radians when the file is in degrees)."""
        if key not in table:
            if default is None:
                raise self.error(key_path(path, key), f"missing; expected {required or 'a number'}")
            return default
        value = self.scalar(table[key], key_path(path, key))
        return math.radians(value) if angle and self.degrees else value

    def scalar(self, value: Any, key: str) -> float:
        """``value`` as a finite float (``key`` is the full key path for the message)."""
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.error(key, f"expected a number, got {show(value)}")
        try:
            number = float(value)
        except OverflowError:
            number = math.inf
        if not math.isfinite(number):
            raise self.error(key, f"expected a finite number, got {show(value)}")
        if abs(number) > MAX_MAGNITUDE:
            raise self.error(key, f"expected a number within +-{MAX_MAGNITUDE:g}, got {show(value)}")
        return number

    def vector(
        self,
        table: Mapping[str, Any],
        key: str,
        path: str,
        *,
        sizes: Sequence[int] = (3,),
        nonzero: bool = False,
        default: Sequence[float] | None = None,
    ) -> NDArray[np.float64]:
        """A list of finite numbers of one of the allowed ``sizes`` (non-zero and of finite norm if asked)."""
        full = key_path(path, key)
        shapes = " or ".join(f"[{', '.join('xyz'[:n])}]" for n in sizes)
        counts = " or ".join(str(n) for n in sizes)
        if key not in table:
            if default is None:
                raise self.error(full, f"missing; expected a list of {counts} numbers {shapes}")
            return np.asarray(default, dtype=float)
        value = table[key]
        if not isinstance(value, list):
            raise self.error(full, f"expected a list of {counts} numbers {shapes}, got {show(value)}")
        if len(value) not in sizes:
            raise self.error(
                full, f"expected a list of {counts} numbers {shapes}, got a list of {len(value)}"
            )
        out = np.array([self.scalar(item, key_path(full, i)) for i, item in enumerate(value)])
        if nonzero:
            scale = float(np.max(np.abs(out)))
            if not scale > 0.0:
                raise self.error(full, f"expected a non-zero direction vector, got {show(value)}")
            # Only the direction counts: scaled to a largest component of 1, its norm can neither overflow
            # (a direction of 1e12s) nor underflow (one of 1e-300s).
            return out / scale
        return out

    def string_list(
        self, table: Mapping[str, Any], key: str, path: str, *, expected: str, default: list[str] | None
    ) -> list[str]:
        """A list of non-empty strings."""
        if key not in table:
            if default is None:
                raise self.error(key_path(path, key), f"missing; expected {expected}")
            return default
        value = table[key]
        if not isinstance(value, list):
            raise self.error(key_path(path, key), f"expected {expected}, got {show(value)}")
        for index, item in enumerate(value):
            if not isinstance(item, str) or not item.strip():
                raise self.error(
                    key_path(key_path(path, key), index), f"expected {expected}, got {show(item)}"
                )
        return list(value)
