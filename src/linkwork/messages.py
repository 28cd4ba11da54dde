"""Message formatting every layer uses: a value quoted on one line for an error message, and one-line escaping.

On the ground floor (it imports nothing of linkwork): the file readers, the problem's own rules, the registry of
built-ins, the writers and the command line all quote values the same way.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Sequence
from typing import Any

__all__ = ["SHOW_CHARS", "SHOW_PATH_CHARS", "closest", "escape_line", "show", "show_path"]

SHOW_CHARS = 40
"""The longest string :func:`show` quotes whole; a longer one is cut, ending in ``...``."""


def show(value: Any) -> str:
    """A short, one-line, TOML-like rendering of a value for an error message.

    Strings are quoted with newlines and other control characters escaped (``"a\\nb"``) and cut after 40
    characters, so that a hostile value can never break the one line an error is.
    """
    if isinstance(value, str):
        shown = value if len(value) <= SHOW_CHARS else value[: SHOW_CHARS - 3] + "..."
        return '"' + escape_line(shown).replace('"', '\\"') + '"'
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        text = "[" + ", ".join(show(item) for item in value[:8]) + "]"
        return text if len(text) <= 60 and len(value) <= 8 else f"a list of {len(value)}"
    if isinstance(value, int) and abs(value) >= 10**30:
        return f"an integer of {len(str(abs(value)))} digits"
    return escape_line(str(value))


SHOW_PATH_CHARS = 500
"""The longest path :func:`show_path` quotes whole (a path is cut later than a value: the user needs to find it)."""


def show_path(path: Any) -> str:
    """A path for a message: quoted, whole up to 500 characters, control characters escaped, on one line."""
    text = str(path)
    text = text if len(text) <= SHOW_PATH_CHARS else text[: SHOW_PATH_CHARS - 3] + "..."
    return '"' + escape_line(text).replace('"', '\\"') + '"'


#: Characters never printed as they are: C0 and C1 control characters (C1 holds ``\x9b``, the one-byte CSI
#: that some terminals read as the start of an escape sequence, and ``\x85``, a line break), the line and
#: paragraph separators, and the bidirectional embeddings, overrides and isolates (U+202A-U+202E,
#: U+2066-U+2069), which reorder the rest of a line on screen ("Trojan Source", CVE-2021-42574), so that a
#: message would not read as what it says.
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u2028\u2029\u202a-\u202e\u2066-\u2069]")


def escape_line(text: str) -> str:
    """``text`` with line breaks, other control characters and bidirectional controls written as escapes
    (``\\n``, ``\\x1b``, ``\\u202e``), so that it prints as one line that reads in the order it is stored."""
    return _CONTROL.sub(_escape, text)


def _escape(match: re.Match[str]) -> str:
    char = match.group(0)
    shown = repr(char)[1:-1]
    return shown if shown != char else f"\\u{ord(char):04x}"


def closest(word: str, choices: Sequence[str], cutoff: float = 0.6) -> str | None:
    """The choice closest to a mistyped ``word`` (ignoring case), or ``None`` when none is close."""
    if len(word) > 100:
        return None
    lowered = {choice.lower(): choice for choice in choices}
    if word.lower() in lowered:
        return lowered[word.lower()]
    close = difflib.get_close_matches(word.lower(), list(lowered), n=1, cutoff=cutoff)
    return lowered[close[0]] if close else None
