"""One name policy: how a name a user wrote (a joint, body, point, profile or linkage name) is written into every
format linkwork writes, and a record of every name that had to change.

A name is any text (the spec reader bounds its length); every format has its own rules, and this module is the
one place they are applied. One function per format:

- :func:`csv_columns` -- a CSV column: a name that would clash with a fixed column of the file (``branch``,
  ``step``, ``s``, ``sigma_1``, ``residual`` in ``path.csv``; ``ratio`` whose ``ratio_max`` is a fixed column of
  ``sweep.csv``) is written with the prefix :data:`COLUMN_PREFIX` (``joint:step``), and so is every name that
  starts with the prefix itself, so the mapping is one to one and the reader finds every joint's column again.
- :func:`xml_text` -- XML character data and attribute values (MJCF, 3MF, SVG): markup escaped, characters XML
  1.0 forbids replaced by U+FFFD.
- :func:`xml_names` -- names that must be unique and may be reserved (MJCF bodies: ``world`` is MuJoCo's).
- :func:`stl_names` -- ASCII STL ``solid`` names: one word of letters, digits and ``_.-`` holding no STL keyword,
  unique per file.
- :func:`dxf_layers` -- DXF layer names: none of ``<>/\\":;?*|=,`` or control characters, unique.
- :func:`mathtext` -- matplotlib text: every ``$`` escaped, so mathtext never starts inside a name.
- :func:`html_text` -- HTML text and attribute values.

Names are kept and compared in one form, :func:`canonical` (Unicode NFC): "é" typed as one character (U+00E9)
and as ``e`` with a combining accent (U+0301) look the same on every screen, so they are one name, in a file's
duplicate checks, in the bodies a joint joins and in a flag naming a joint.

Every function that may change a name returns a :class:`NameMap`; its :attr:`NameMap.changes` are the names
written differently, and :func:`describe` turns them into one line for the command's summary.
"""

from __future__ import annotations

import html
import re
import unicodedata
from collections.abc import Collection, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TypeVar

__all__ = [
    "COLUMN_PREFIX",
    "FORMULA_START",
    "MAX_NAME_CHARS",
    "MJCF_RESERVED",
    "NAME_RULE",
    "NameMap",
    "canonical",
    "csv_cell",
    "csv_columns",
    "describe",
    "dxf_layers",
    "html_text",
    "mathtext",
    "name_problem",
    "stl_names",
    "xml_attribute",
    "xml_names",
    "xml_text",
]

MAX_NAME_CHARS = 100
"""The longest name (of a joint, profile or linkage) accepted, in characters."""

COLUMN_PREFIX = "joint:"
"""The prefix of a CSV column whose joint name clashes with a fixed column (``step`` is written ``joint:step``)."""

FORMULA_START = frozenset("=+-@\t\r")
"""Characters that make a spreadsheet read a cell as a formula when it starts with one (``=HYPERLINK(...)``):
a CSV column name starting with one is written with :data:`COLUMN_PREFIX`."""


T = TypeVar("T")


def csv_cell(value: T) -> T | str:
    """A CSV cell a spreadsheet shows as written: text starting with a :data:`FORMULA_START` character gets a
    leading apostrophe (``'=HYPERLINK(...)``), the mark spreadsheets read as "text follows"; anything else (a
    number) is returned as it is."""
    if isinstance(value, str) and value[:1] in FORMULA_START:
        return "'" + value
    return value


def canonical(name: str) -> str:
    """``name`` in the one form linkwork keeps and compares names in: Unicode NFC (canonical composition), so
    names that differ only in how an accented letter was typed are the same name. NFC, not NFKC: "ﬁ" and "fi",
    or "x²" and "x2", are different text to a reader, not different spellings of one."""
    return unicodedata.normalize("NFC", name)


MJCF_RESERVED = frozenset({"world"})
"""Body names MuJoCo reserves (the world body)."""

NAME_RULE = "a name without line breaks or control characters"
"""What a name a user writes in a file must be (the words of every reader's message): see :func:`name_problem`."""

#: Characters no name may hold: C0 and C1 control characters (line breaks, escape sequences, ``\x9b`` the
#: one-byte CSI), the line and paragraph separators, and the bidirectional embeddings, overrides and isolates
#: (U+202A-U+202E, U+2066-U+2069) that reorder what follows them on screen ("Trojan Source",
#: CVE-2021-42574): a name is printed in tables and error lines, and written in CSV headers and drawings, where
#: any of these would break a line or make it read as something else. (The same characters that
#: :func:`linkwork.messages.escape_line` escapes; a tab is refused unless a reader allows it.)
_UNSAFE_IN_NAME = re.compile("[\x00-\x08\x0a-\x1f\x7f-\x9f\u2028\u2029\u202a-\u202e\u2066-\u2069]")


def name_problem(name: str, *, tab: bool = False) -> str | None:
    """Why ``name`` cannot be a name a user writes in a file (a linkage, joint, body, point, profile or study
    name), or ``None`` when it can: it holds a character of :data:`_UNSAFE_IN_NAME` (a tab only when ``tab``
    is false). The message is :data:`NAME_RULE`; the caller adds the key and the value."""
    if _UNSAFE_IN_NAME.search(name) or (not tab and "\t" in name):
        return NAME_RULE
    return None


_XML_FORBIDDEN = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")
_DXF_FORBIDDEN = re.compile('[<>/\\\\":;?*|=,`\x00-\x1f\x7f\ud800-\udfff]')
_SURROGATE = re.compile("[\ud800-\udfff]")
_STL_FORBIDDEN = re.compile(r"[^A-Za-z0-9_.-]")
_STL_KEYWORDS = re.compile(r"(?i)solid|facet|loop|vertex|normal|outer")


def _stl_word(name: str) -> str:
    """One STL solid name: letters, digits and ``_.-`` (anything else becomes ``_``), and no STL keyword inside
    it (``solid`` is written ``s_olid``), so a reader that looks for keywords in a line is not misled."""
    word = _STL_FORBIDDEN.sub("_", name)
    return _STL_KEYWORDS.sub(lambda m: m.group(0)[0] + "_" + m.group(0)[1:], word) or "part"


@dataclass(frozen=True)
class NameMap(Mapping[str, str]):
    """Names as written in one format: ``map[name]`` is how ``name`` is written there.

    ``fmt`` says which format (``"path.csv"``, ``"MJCF body"``); :attr:`changes` lists every name written
    differently, as ``(name, written, why)``.
    """

    fmt: str
    written: dict[str, str] = field(default_factory=dict)
    reasons: dict[str, str] = field(default_factory=dict)

    def __getitem__(self, name: str) -> str:
        return self.written[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self.written)

    def __len__(self) -> int:
        return len(self.written)

    @property
    def changes(self) -> list[tuple[str, str, str]]:
        """``(name, written, why)`` for every name written differently."""
        return [(n, w, self.reasons.get(n, "")) for n, w in self.written.items() if n != w]


def describe(*maps: NameMap) -> str | None:
    """One line naming every changed name of ``maps`` (``None`` when nothing changed), for a command's summary.

    Names are shown with control characters escaped, so the line stays one line."""
    parts = []
    for m in maps:
        for name, written, why in m.changes:
            parts.append(f"{m.fmt}: {_show(name)} written as {_show(written)} ({why})")
    return "names changed for the file formats: " + "; ".join(parts) if parts else None


def _show(text: str) -> str:
    shown = text if len(text) <= 40 else text[:37] + "..."
    escaped = re.sub(
        r"[\x00-\x1f\x7f-\x9f\u2028\u2029\u202a-\u202e\u2066-\u2069]",
        lambda m: (
            f"\\u{ord(m.group(0)):04x}" if repr(m.group(0))[1:-1] == m.group(0) else repr(m.group(0))[1:-1]
        ),
        shown,
    )
    return '"' + escaped.replace('"', '\\"') + '"'


def _unique(wanted: Sequence[str], taken: Collection[str] = (), *, fold: bool = False) -> list[str]:
    """``wanted`` made unique: a written name already used (by an earlier one or by ``taken``) gets ``_2``,
    ``_3``.. until it is free (compared ignoring case with ``fold``)."""
    key = str.lower if fold else str
    used = {key(t) for t in taken}
    out: list[str] = []
    for candidate in wanted:
        written, k = candidate, 1
        while key(written) in used:
            k += 1
            written = f"{candidate}_{k}"
        used.add(key(written))
        out.append(written)
    return out


def _mapped(
    fmt: str, names: Sequence[str], wanted: Sequence[str], reasons: dict[str, str], **kw: object
) -> NameMap:
    """The :class:`NameMap` of distinct ``names`` to ``wanted`` made unique (see :func:`_unique`)."""
    written = _unique(wanted, **kw)  # type: ignore[arg-type]
    for name, want, got in zip(names, wanted, written, strict=True):
        if want != got:
            reasons[name] = (reasons[name] + "; " if name in reasons else "") + "made unique"
    return NameMap(fmt, dict(zip(names, written, strict=True)), reasons)


def csv_columns(
    fmt: str,
    names: Iterable[str],
    fixed: Collection[str],
    *,
    suffixes: Sequence[str] = ("",),
    patterns: Sequence[str] = (),
) -> NameMap:
    """The column stem of every name in a CSV file with ``fixed`` columns (and columns matching the regular
    expressions ``patterns``, e.g. ``sigma_\\d+``): a name whose column (the name plus any of ``suffixes``)
    would be a fixed one, that starts with :data:`COLUMN_PREFIX`, or that starts with a character a spreadsheet
    takes for a formula (:data:`FORMULA_START`: a file opened in a spreadsheet must not run a user's name as a
    formula), is written with that prefix. The mapping is one to one (a prefixed stem never equals an unprefixed
    one), so reading the file back finds every name's column again through this same function."""
    compiled = [re.compile(p) for p in patterns]
    written: dict[str, str] = {}
    reasons: dict[str, str] = {}
    for name in names:
        columns = [name + s for s in suffixes]
        clash = [c for c in columns if c in fixed or any(p.fullmatch(c) for p in compiled)]
        encodable = not _SURROGATE.search(name)
        formula = name[:1] in FORMULA_START
        if clash or name.startswith(COLUMN_PREFIX) or formula or not encodable:
            # a lone surrogate (only a Python caller can make one) cannot be written as UTF-8: its escape is
            written[name] = COLUMN_PREFIX + name.encode("utf-8", "backslashreplace").decode("utf-8")
            reasons[name] = (
                f"{clash[0]!r} is a fixed column"
                if clash
                else "not encodable as UTF-8"
                if not encodable
                else f"starts with {name[:1]!r}, which a spreadsheet reads as a formula"
                if formula
                else f"starts with {COLUMN_PREFIX!r}"
            )
        else:
            written[name] = name
    return NameMap(fmt, written, reasons)


def xml_text(text: str) -> str:
    """``text`` as XML character data or a (double- or single-quoted) attribute value: markup characters
    escaped, characters XML 1.0 does not allow (control characters but tab, line feed and carriage return, lone
    surrogates, U+FFFE, U+FFFF) replaced by U+FFFD."""
    text = _XML_FORBIDDEN.sub("\ufffd", text)
    return (
        text.replace("&", "&amp;")
        .replace("<", "&lt;")
        .replace(">", "&gt;")
        .replace('"', "&quot;")
        .replace("'", "&apos;")
    )


def xml_attribute(text: str) -> str:
    """``text`` as a double-quoted XML attribute (quotes included); line breaks and tabs written as character
    references so a parser keeps them (attribute values are otherwise normalised to spaces)."""
    escaped = xml_text(text).replace("\n", "&#10;").replace("\r", "&#13;").replace("\t", "&#9;")
    return f'"{escaped}"'


def xml_names(fmt: str, names: Iterable[str], reserved: Collection[str] = ()) -> NameMap:
    """Names as XML attribute values that must be unique among themselves and avoid ``reserved`` ones: a
    reserved name gets ``_1`` (then ``_2``.. while taken), characters XML forbids become ``_``; escape the
    result with :func:`xml_attribute` when writing it."""
    names = _distinct(names)
    wanted: list[str] = []
    reasons: dict[str, str] = {}
    for name in names:
        clean = _XML_FORBIDDEN.sub("_", name).strip() or "_"
        if clean != name:
            reasons[name] = "characters XML does not allow"
        if clean in reserved:
            reasons[name] = f"{clean!r} is reserved"
        wanted.append(clean)
    return _mapped(fmt, names, wanted, reasons, taken=reserved)


def stl_names(names: Sequence[str]) -> tuple[list[str], NameMap]:
    """ASCII STL ``solid`` names of parts (in order; two parts may bear the same name): one word (see
    :func:`_stl_word`; spaces and line breaks become ``_``), never empty, unique within the file. Returns the
    names in order and the changes."""
    wanted = [_stl_word(name) for name in names]
    written = _unique(wanted)
    changed = {n: w for n, w in zip(names, written, strict=True) if n != w}
    reasons = {
        n: "made unique" if _stl_word(n) == n else "an STL solid name is one word of letters, digits and _.-"
        for n in changed
    }
    return written, NameMap("STL solid", changed, reasons)


def dxf_layers(names: Iterable[str], taken: Collection[str] = ()) -> NameMap:
    """DXF layer names: the characters DXF forbids (``<>/\\":;?*|=,`` and control characters) become ``_``, at
    most 255 characters, never empty, unique (also among the ``taken`` layers)."""
    names = _distinct(names)
    wanted: list[str] = []
    reasons: dict[str, str] = {}
    for name in names:
        clean = _DXF_FORBIDDEN.sub("_", name).strip()[:240] or "_"
        if clean != name:
            reasons[name] = "characters a DXF layer name may not hold"
        wanted.append(clean)
    return _mapped("DXF layer", names, wanted, reasons, taken=taken, fold=True)


def mathtext(text: str) -> str:
    """``text`` drawn literally by matplotlib: each ``$`` escaped as ``\\$``, so mathtext never starts inside a
    name (a backslash outside mathtext is drawn as it is)."""
    return _SURROGATE.sub("\ufffd", text).replace("$", r"\$")


def html_text(text: str) -> str:
    """``text`` as HTML text or a quoted attribute value (``<>&"'`` escaped)."""
    return html.escape(_SURROGATE.sub("\ufffd", text), quote=True)


def _distinct(names: Iterable[str]) -> list[str]:
    return list(dict.fromkeys(names))
