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
    units = "mm"                        # optional: the problem's length unit, carried into DXF/SVG; a DXF
                                        # profile drawn in another ($INSUNITS) is converted into it; without
                                        # it, DXF profiles declaring a unit must agree, and set it

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013), Eq. (11).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from linkwork.errors import SpecError
from linkwork.io.profiles import COINCIDENT, LENGTH_UNITS, check_profile, load_profile, profile_unit
from linkwork.io.toml_reader import TomlReader, escape_line, input_file_problem, key_path, read_toml, show
from linkwork.mechanization.options import OPTION_KEYS, options_from_values
from linkwork.names import canonical
from linkwork.synthesis.problem import KINDS, Problem, ProfileKind
from linkwork.units import METRES

__all__ = ["KEYS", "KINDS", "REQUIRED", "load_problem"]

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


def _settings(reader: TomlReader, table: dict[str, Any]) -> dict[str, Any]:
    """The keyword arguments of :class:`Problem` read from the file's keys, by type only: the ranges are the
    rules of :class:`Problem` itself, so a file and a script get the same message.

    Adding a key is one entry here (and in :data:`KEYS`).
    """
    settings: dict[str, Any] = {}
    settings["kind"] = reader.choice(table, "type", "", KINDS, default="open")
    piece_length = reader.require(table, "piece_length", "", "a positive number")
    if isinstance(piece_length, bool) or not isinstance(piece_length, int | float):
        raise reader.error("piece_length", f"expected a positive number, got {show(piece_length)}")
    settings["piece_length"] = piece_length
    settings["min_pieces"] = _whole(reader, table, "min_pieces", 2, "a whole number of pieces >= 2")
    settings["design"], settings["segments"] = _design(reader, table)
    settings["starts"] = _whole(reader, table, "starts", 5, "a whole number of starts >= 1")
    merge_below = table.get("merge_below", 0.0)
    if isinstance(merge_below, bool) or not isinstance(merge_below, int | float):
        raise reader.error(
            "merge_below", f"expected an angle in degrees, 0 <= merge_below < 180, got {show(merge_below)}"
        )
    try:  # nan stays nan, so the rule's message quotes what the file says
        settings["merge_below"] = math.radians(merge_below)
    except OverflowError:  # a whole number beyond a float
        settings["merge_below"] = math.inf
    settings["seed"] = _whole(reader, table, "seed", 0, "a whole number >= 0")
    settings["mechanize"] = reader.boolean(table, "mechanize", "", default=False)
    if "description" in table and not isinstance(table["description"], str):
        raise reader.error("description", f"expected a string, got {show(table['description'])}")
    settings["merge_on"] = _one_of(reader, table, "merge_on", ("targets", "chain"))
    settings["rank_by"] = _one_of(reader, table, "rank_by", ("error", "joints"))
    tolerance = table.get("e_max_tolerance")
    if tolerance is not None and (isinstance(tolerance, bool) or not isinstance(tolerance, int | float)):
        raise reader.error(
            "e_max_tolerance", f"expected a positive number (profile units), got {show(tolerance)}"
        )
    settings["e_max_tolerance"] = tolerance
    settings["initial_segment_matrix"] = _initial_segment_matrix(reader, table)
    units = table.get("units")
    if units is not None and (not isinstance(units, str) or units not in LENGTH_UNITS):
        raise reader.error("units", f"expected one of {', '.join(LENGTH_UNITS)}, got {show(units)}")
    settings["units"] = units
    options = {key: table[key] for key in OPTION_KEYS if key in table}
    options_from_values(options, source=reader.source)  # checked here: a mistake is found before synthesis
    settings["mechanize_options"] = options
    return settings


def _one_of(reader: TomlReader, table: dict[str, Any], key: str, choices: tuple[str, ...]) -> str:
    """One of ``choices`` (the first is the default), in the words of :class:`Problem`'s rule."""
    value = table.get(key, choices[0])
    if not isinstance(value, str) or value not in choices:
        quoted = ", ".join(f'"{c}"' for c in choices)
        raise reader.error(key, f"expected one of {quoted}, got {show(value)}")
    return value


def _initial_segment_matrix(reader: TomlReader, table: dict[str, Any]) -> np.ndarray | None:
    """``initial_segment_matrix``: as printed in the paper (Eq. 11), one row of whole numbers per profile;
    returned transposed, ``(q, p)``, as the API holds segment matrices (the rows are checked against the
    profiles and the design by :class:`Problem`)."""
    key = "initial_segment_matrix"
    raw = table.get(key)
    if raw is None:
        return None
    expected = "a list of rows of whole numbers, one row per profile (the paper's Eq. 11)"
    rows_ok = isinstance(raw, list) and raw and all(isinstance(row, list) and row for row in raw)
    whole = rows_ok and all(
        isinstance(m, int) and not isinstance(m, bool) and 0 <= m <= 10**6 for row in raw for m in row
    )
    if not whole:
        raise reader.error(key, f"expected {expected}, got {show(raw)}")
    profiles = table.get("profiles")
    count = len(profiles) if isinstance(profiles, list) else len(raw)
    if len(raw) != count or len({len(row) for row in raw}) != 1:
        raise reader.error(
            key,
            f"has {len(raw)} rows of lengths {sorted({len(row) for row in raw})}; expected {count} rows "
            "(one per profile) of equal length (one entry per segment)",
        )
    return np.asarray(raw, dtype=np.int64).T


def _whole(reader: TomlReader, table: dict[str, Any], key: str, default: int, expected: str) -> Any:
    """An integer-typed key (its range is checked by :class:`Problem`)."""
    value = table.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int):
        raise reader.error(key, f"expected {expected}, got {show(value)}")
    return value


def _design(reader: TomlReader, table: dict[str, Any]) -> tuple[str | None, int | None]:
    """``(design, segments)``: a design vector of M and C letters, or ``(None, q)`` for ``"auto"``."""
    expected = 'a design vector of M and C letters such as "MCMC", or "auto"'
    raw = reader.require(table, "design", "", expected)
    if not isinstance(raw, str) or not raw.strip():
        raise reader.error("design", f"expected {expected}, got {show(raw)}")
    segments = table.get("segments")
    if segments is not None and (isinstance(segments, bool) or not isinstance(segments, int)):
        raise reader.error("segments", f"expected a whole number of segments >= 1, got {show(segments)}")
    if segments is not None and segments < 1:
        raise reader.error("segments", f"expected a whole number of segments >= 1, got {show(segments)}")
    if raw.strip().lower() == "auto":
        return None, segments
    design = raw.strip().upper()
    return design, len(design) if segments is None and set(design) <= set("MC") else segments


def _profile_files(reader: TomlReader, table: dict[str, Any]) -> list[str]:
    """The ``profiles`` list of file names."""
    expected = "a list of at least 2 profile files"
    files = reader.require(table, "profiles", "", expected)
    if not isinstance(files, list):
        raise reader.error("profiles", f"expected {expected}, got {show(files)}")
    files = reader.string_list(table, "profiles", "", expected=expected, default=None)
    if len(files) < 2:
        raise reader.error("profiles", f"lists {len(files)} profile(s); expected at least 2 profiles")
    return files


def _names(reader: TomlReader, table: dict[str, Any], files: list[str]) -> list[str]:
    """``names``, or each profile file's name without its folder and extension (its stem)."""
    if "names" not in table:
        return names_from_files(reader, files)
    expected = f"a list of {len(files)} non-empty names"
    return reader.string_list(table, "names", "", expected=expected, default=None)


def names_from_files(reader: TomlReader, files: list[str]) -> list[str]:
    """The profiles' names of a problem without a ``names`` key: each file's stem (``a/wing.csv`` is ``wing``).

    Two files with the same stem (``a/wing.csv`` and ``b/wing.csv``, or ``wing.csv`` and ``wing.dat``) would give
    two profiles one name: that is refused here, at ``profiles``, naming both files (names are compared exactly
    but for Unicode normalisation, :func:`linkwork.names.canonical`, as everywhere in linkwork; where a format ignores case, the name policy keeps them apart, e.g. the DXF
    layers of :func:`linkwork.names.dxf_layers`)."""
    names = [Path(f).stem for f in files]
    first: dict[str, int] = {}
    for index, name in enumerate(names):
        earlier = first.setdefault(canonical(name), index)  # "é" typed two ways is one name
        if earlier != index:
            raise reader.error(
                "profiles",
                f"profiles[{earlier}] {show(files[earlier])} and profiles[{index}] {show(files[index])} would both "
                f"be named {show(name)} (without a names key a profile is named after its file, without the "
                "folder and extension); expected distinct file names, or a names key with one name per profile",
            )
    return names


def _named_after_files(reader: TomlReader, exc: SpecError, files: list[str]) -> SpecError:
    """A broken rule of ``names`` (:class:`Problem`'s) when the names are the files' stems: said of the file
    that gave the name, at ``profiles[i]``, since the problem file has no ``names`` key."""
    key = exc.key or "names"
    index = key[len("names[") : -1] if key.startswith("names[") else ""
    if index.isdigit() and int(index) < len(files):
        i = int(index)
        return reader.error(
            key_path("profiles", i),
            f"the profile is named {show(Path(files[i]).stem)} after its file {show(files[i])} (there is no names "
            f"key), and a name is {exc.detail}; rename the file or add a names key",
        )
    return reader.error(
        "profiles",
        f"the profiles are named after their files (there is no names key), and the names are refused: "
        f"{exc.detail}; rename the files or add a names key",
    )


def _drawing_units(
    reader: TomlReader, folder: Path, files: list[str], units: str | None
) -> tuple[list[float], str | None]:
    """The factor that brings each profile file's coordinates into the problem's units, and those units.

    A DXF drawing declares its unit (``$INSUNITS``; :func:`~linkwork.io.profiles.profile_unit`): with a
    ``units`` key it is converted into them (a drawing in inches in a problem in mm is scaled by 25.4); without
    one, every drawing that declares a unit must declare the same, the coordinates are taken as drawn and the
    problem is in that unit (when it is one of :data:`~linkwork.units.LENGTH_UNITS`, the outputs say so). A
    file that declares none (CSV, Selig, SVG, a unitless DXF) is in the problem's units as written."""
    declared = [profile_unit(folder / name) for name in files]
    if units is not None:
        return [1.0 if unit is None else METRES[unit] / METRES[units] for unit in declared], units
    first = next((i for i, unit in enumerate(declared) if unit is not None), None)
    if first is None:
        return [1.0] * len(files), None
    for index, unit in enumerate(declared):
        if unit is not None and unit != declared[first]:
            raise reader.error(
                key_path("profiles", index),
                f"{show(files[index])} is drawn in {unit} ($INSUNITS) and {show(files[first])} in "
                f"{declared[first]}; expected drawings in one unit, or a units key to convert them into",
            )
    unit = declared[first]
    return [1.0] * len(files), unit if unit in LENGTH_UNITS else None


def _load_profiles(
    reader: TomlReader, folder: Path, files: list[str], kind: ProfileKind, units: str | None = None
) -> tuple[list[Any], str | None]:
    """Each profile file (relative to ``folder``) as a polyline in the problem's units, and those units (see
    :func:`_drawing_units`); a closed problem's must return to its start."""
    for index, name in enumerate(files):
        file = folder / name
        problem = input_file_problem(file)
        if problem is not None:
            what = "not found" if problem == "file not found" else problem
            raise reader.error(
                key_path("profiles", index),
                f'file "{escape_line(str(file))}" {what}; expected a profile file',
            )
    factors, units = _drawing_units(reader, folder, files, units)
    profiles = []
    for index, (name, factor) in enumerate(zip(files, factors, strict=True)):
        file = folder / name
        points = load_profile(file)
        if factor != 1.0:
            points = check_profile(points * factor, source=file)
        if kind == "closed":
            gap = float(np.hypot(*(points[-1] - points[0])))
            size = float(np.hypot(*np.ptp(points, axis=0)))
            if gap > COINCIDENT * size:
                raise reader.error(
                    key_path("profiles", index),
                    f'{show(name)} does not return to its first point (gap {gap:.6g}); type "closed" expects '
                    "the curve to end where it starts (repeat the first point at the end)",
                )
        profiles.append(points)
    return profiles, units


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
        or range (the rules of :class:`Problem`), a profile file that is missing, or a closed problem whose
        profile does not return to its start. Profiles are counted from 0 (``profiles[0]`` is the first).
        An unreadable or malformed profile file is reported naming that file.
    """
    path = Path(path)
    table = read_toml(path, "a problem file (TOML)")
    reader = TomlReader(str(path))
    reader.check_keys(table, "", KEYS)
    files = _profile_files(reader, table)
    settings = _settings(reader, table)
    names = _names(reader, table, files)
    # The rules of the problem, checked before the profile files are read (placeholder polylines of length 0
    # pass every profile rule), so that a bad setting is reported first.
    try:
        Problem(profiles=(np.zeros((2, 2)),) * len(files), names=tuple(names), source=path, **settings)
    except SpecError as exc:
        if "names" in table or not (exc.key or "").startswith("names"):
            raise
        raise _named_after_files(reader, exc, files) from None
    profiles, settings["units"] = _load_profiles(
        reader, path.parent, files, settings["kind"], settings["units"]
    )
    return Problem(profiles=tuple(profiles), names=tuple(names), source=path, **settings)
