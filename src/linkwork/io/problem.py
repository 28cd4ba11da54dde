"""Synthesis problem files: read the TOML file of ``linkwork synth`` into a
:class:`~linkwork.synthesis.problem.Problem`.

The file is data, never code: it is parsed with :mod:`tomllib` and every key is checked for type and range.
Angles are in degrees in the file and in radians in the returned problem. A mistake is reported as a
:class:`~linkwork.errors.SpecError` naming the file, the key and what was expected, for example
``problem.toml: piece_length: expected a positive number, got "abc"``.

Example
-------
.. code-block:: toml

    type = "open"                       # open | closed | fixed-end
    profiles = ["cruise.dat", "climb.dat", "landing.dat"]   # relative to this file
    piece_length = 0.03                 # desired piece length s_d of the target profiles
    min_pieces = 3                      # fewest pieces of any segment on any profile (alpha)
    design = "CMCMC"                    # a design vector, or "auto" with segments = q
    starts = 5                          # initial segment matrices tried (seeded)
    merge_below = 5.0                   # degrees; 0 disables compound segments
    seed = 1
    names = ["cruise", "climb", "landing"]   # optional; file stems by default
    mechanize = false                   # optional; the mechanization options (dof, drive, actuator,
                                        # binary_links, ground_region, link_offset, max_link, min_transmission,
                                        # anchors, attempts, designs, time_limit, root) are keys too:
                                        # docs/mechanization.md
    merge_on = "targets"                # targets | chain: where merge_below's joint ranges are measured
    rank_by = "error"                   # error | joints (fewest joints with E_max <= e_max_tolerance)
    e_max_tolerance = 0.01              # largest acceptable joined E_max, profile units (rank_by = "joints")
    initial_segment_matrix = [[15, 13, 9, 39], [15, 9, 9, 57], [15, 39, 9, 36]]  # Eq. 11: a row per profile
    units = "mm"                        # optional: length unit of the profile files, carried into DXF/SVG
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from linkwork.errors import SpecError
from linkwork.io.profiles import COINCIDENT, LENGTH_UNITS, load_profile
from linkwork.mechanization.options import OPTION_KEYS, options_from_values
from linkwork.synthesis.problem import MergeOn, Problem, ProfileKind, RankBy

KINDS = ("open", "closed", "fixed-end")
"""The values of ``type``."""

KEYS = (
    "type",
    "profiles",
    "piece_length",
    "min_pieces",
    "design",
    "segments",
    "starts",
    "merge_below",
    "seed",
    "names",
    "mechanize",
    "units",
    "description",
    *OPTION_KEYS,
    "merge_on",
    "rank_by",
    "e_max_tolerance",
    "initial_segment_matrix",
)
"""Every key a problem file may hold (``description`` is free text for the reader and is ignored)."""

REQUIRED = ("profiles", "piece_length", "design")
"""Keys without a default."""

T = TypeVar("T")


def _show(value: Any) -> str:
    """A TOML-like rendering of a bad value for an error message."""
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return f"a list of {len(value)}"
    return str(value)


class _Keys:
    """A problem file's table with typed, checked getters that raise :class:`SpecError` naming the key."""

    def __init__(self, table: dict[str, Any], source: str) -> None:
        self.table = table
        self.source = source

    def error(self, key: str, message: str) -> SpecError:
        return SpecError(message, source=self.source, key=key)

    def get(self, key: str, default: T, check: Callable[[Any], T | None], expected: str) -> T:
        if key not in self.table:
            if key in REQUIRED:
                raise self.error(key, f"missing; expected {expected}")
            return default
        value = self.table[key]
        checked = check(value)
        if checked is None:
            raise self.error(key, f"expected {expected}, got {_show(value)}")
        return checked


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value) if math.isfinite(value) else None


def _positive(value: Any) -> float | None:
    number = _number(value)
    return number if number is not None and number > 0.0 else None


def _integer(minimum: int) -> Callable[[Any], int | None]:
    def check(value: Any) -> int | None:
        if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
            return None
        return int(value)

    return check


def _boolean(value: Any) -> bool | None:
    return value if isinstance(value, bool) else None


def _string_list(value: Any) -> list[str] | None:
    if not isinstance(value, list) or not all(isinstance(item, str) and item.strip() for item in value):
        return None
    return list(value)


def _read_table(path: Path) -> dict[str, Any]:
    if not path.exists():
        raise SpecError("file not found; expected a problem file (TOML)", source=str(path))
    if not path.is_file():
        raise SpecError("is a folder; expected a problem file (TOML)", source=str(path))
    try:
        with path.open("rb") as handle:
            return tomllib.load(handle)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"not valid TOML ({exc})", source=str(path)) from None
    except UnicodeDecodeError:
        raise SpecError("not a UTF-8 text file; expected TOML", source=str(path)) from None
    except OSError as exc:
        raise SpecError(f"cannot be read ({exc.strerror})", source=str(path)) from None


def _design(keys: _Keys) -> tuple[str | None, int | None]:
    """``(design, segments)``: a design vector of M and C letters, or ``(None, q)`` for ``"auto"``."""
    raw = keys.get(
        "design",
        "",
        lambda v: v.strip() if isinstance(v, str) and v.strip() else None,
        'a design vector of M and C letters such as "MCMC", or "auto"',
    )
    segments = keys.get("segments", None, _integer(1), "a whole number of segments >= 1")
    if raw.lower() == "auto":
        if segments is None:
            raise keys.error("segments", 'missing; design = "auto" needs the number of segments q, e.g. 4')
        return None, segments
    design = raw.upper()
    wrong = sorted({letter for letter in design if letter not in "MC"})
    if wrong:
        raise keys.error(
            "design",
            f'expected a design vector of M and C letters such as "MCMC", or "auto", got "{raw}" '
            f"(letters {', '.join(wrong)} are not M or C)",
        )
    if segments is not None and segments != len(design):
        raise keys.error(
            "segments",
            f'is {segments} but design "{design}" has {len(design)} segments; give one or the other',
        )
    return design, len(design)


def _initial_segment_matrix(keys: _Keys, profiles: int) -> np.ndarray | None:
    """``initial_segment_matrix``: as printed in the paper (Eq. 11), one row of whole numbers per profile;
    returned transposed, ``(q, p)``, as the API holds segment matrices."""
    raw = keys.get(
        "initial_segment_matrix",
        None,
        lambda v: (
            v
            if isinstance(v, list)
            and v
            and all(
                isinstance(row, list)
                and row
                and all(isinstance(m, int) and not isinstance(m, bool) for m in row)
                for row in v
            )
            else None
        ),
        "a list of rows of whole numbers, one row per profile (the paper's Eq. 11)",
    )
    if raw is None:
        return None
    if len(raw) != profiles or len({len(row) for row in raw}) != 1:
        raise keys.error(
            "initial_segment_matrix",
            f"has {len(raw)} rows of lengths {sorted({len(row) for row in raw})}; expected {profiles} rows "
            "(one per profile) of equal length (one entry per segment)",
        )
    return np.asarray(raw, dtype=np.int64).T


def load_problem(path: str | Path) -> Problem:
    """Read a synthesis problem from a TOML file and its profile files.

    Parameters
    ----------
    path
        The problem file. Its ``profiles`` are files relative to it (see :mod:`linkwork.io.profiles`).

    Returns
    -------
    Problem
        With ``merge_below`` converted from degrees to radians, ``names`` defaulting to the profile file stems
        and ``source`` set to ``path``.

    Raises
    ------
    SpecError
        ``file: key: what was expected`` for an unknown key, a missing required key, a value of the wrong type
        or range, a profile file that is missing, or a closed problem whose profile does not return to its
        start.
        An unreadable or malformed profile file is reported naming that file.
    """
    path = Path(path)
    source = str(path)
    table = _read_table(path)
    keys = _Keys(table, source)
    for key in table:
        if key not in KEYS:
            raise keys.error(key, f"unknown key; expected one of {', '.join(KEYS)}")

    kind: ProfileKind = keys.get(
        "type", "open", lambda v: v if v in KINDS else None, "one of open, closed, fixed-end"
    )
    files: list[str] = keys.get("profiles", [], _string_list, "a list of at least 2 profile files")
    if len(files) < 2:
        raise keys.error("profiles", f"lists {len(files)} file(s); expected at least 2 profile files")
    piece_length = keys.get("piece_length", 0.0, _positive, "a positive number")
    min_pieces = keys.get(
        "min_pieces", 2, _integer(2), "a whole number of pieces >= 2 (a C-segment needs an interior point)"
    )
    design, segments = _design(keys)
    starts = keys.get("starts", 5, _integer(1), "a whole number of starts >= 1")
    merge_below_deg = keys.get(
        "merge_below",
        0.0,
        lambda v: v if (n := _number(v)) is not None and 0.0 <= n < 180.0 else None,
        "an angle in degrees, 0 <= merge_below < 180",
    )
    seed = keys.get("seed", 0, _integer(0), "a whole number >= 0")
    mechanize = keys.get("mechanize", False, _boolean, "true or false")
    mechanize_options = {key: table[key] for key in OPTION_KEYS if key in table}
    options_from_values(mechanize_options, source=source)  # checked here: a mistake is found before synthesis
    merge_on: MergeOn = keys.get(
        "merge_on", "targets", lambda v: v if v in ("targets", "chain") else None, 'one of "targets", "chain"'
    )
    rank_by: RankBy = keys.get(
        "rank_by", "error", lambda v: v if v in ("error", "joints") else None, 'one of "error", "joints"'
    )
    e_max_tolerance = keys.get("e_max_tolerance", None, _positive, "a positive number (profile units)")
    if rank_by == "joints" and e_max_tolerance is None:
        raise keys.error("e_max_tolerance", 'missing; rank_by = "joints" needs the largest acceptable E_max')
    initial_sm = _initial_segment_matrix(keys, len(files))
    if initial_sm is not None and design is None:
        raise keys.error("initial_segment_matrix", 'needs a design vector, not design = "auto"')
    if initial_sm is not None and design is not None and initial_sm.shape[0] != len(design):
        raise keys.error(
            "initial_segment_matrix",
            f'has {initial_sm.shape[0]} entries per row but design "{design}" has {len(design)} segments',
        )
    units: str | None = keys.get(
        "units", None, lambda v: v if v in LENGTH_UNITS else None, f"one of {', '.join(LENGTH_UNITS)}"
    )
    keys.get("description", "", lambda v: v if isinstance(v, str) else None, "a string")
    stems = [Path(name).stem for name in files]
    names = keys.get("names", stems, _string_list, f"a list of {len(files)} non-empty names")
    if len(names) != len(files):
        raise keys.error(
            "names", f"lists {len(names)} names for {len(files)} profiles; expected one per profile"
        )
    if len(set(names)) != len(names):
        raise keys.error("names", "repeats a name; expected a different name for every profile")

    profiles = []
    for index, name in enumerate(files, start=1):
        file = path.parent / name
        if not file.is_file():
            raise keys.error(f"profiles[{index}]", f'file "{file}" not found; expected a profile file')
        points = load_profile(file)
        if kind == "closed":
            gap = float(np.hypot(*(points[-1] - points[0])))
            size = float(np.hypot(*np.ptp(points, axis=0)))
            if gap > COINCIDENT * size:
                raise keys.error(
                    f"profiles[{index}]",
                    f'"{name}" does not return to its first point (gap {gap:.6g}); type "closed" expects the '
                    "curve to end where it starts (repeat the first point at the end)",
                )
        profiles.append(points)

    return Problem(
        profiles=tuple(profiles),
        kind=kind,
        piece_length=piece_length,
        min_pieces=min_pieces,
        design=design,
        segments=segments,
        starts=starts,
        merge_below=math.radians(float(merge_below_deg)),
        seed=seed,
        names=tuple(names),
        source=path,
        mechanize=mechanize,
        mechanize_options=mechanize_options,
        merge_on=merge_on,
        rank_by=rank_by,
        e_max_tolerance=e_max_tolerance,
        initial_segment_matrix=initial_sm,
        units=units,
    )
