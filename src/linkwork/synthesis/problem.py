"""A shape-change synthesis problem: the design profiles and the settings of the search (Shamsudin et al. 2013)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from linkwork.errors import SpecError
from linkwork.limits import MAX_SEED
from linkwork.messages import escape_line, show
from linkwork.names import MAX_NAME_CHARS, canonical, name_problem

ProfileKind = Literal["open", "closed", "fixed-end"]
RankBy = Literal["error", "joints"]
MergeOn = Literal["targets", "chain"]

KINDS: tuple[ProfileKind, ...] = ("open", "closed", "fixed-end")
"""The values of ``kind`` (``type`` in a problem file)."""

MAX_STARTS = 1000
"""The most initial segment matrices one design vector's search may start from."""

MAX_AUTO_SEGMENTS = 14
"""The most segments ``q`` of a design search (``design = "auto"`` segments all ``2**q - 1`` design vectors with a
C, then joins them in order of a lower bound on E_max, pruned: q = 12 takes seconds, q = 14 about four times that)."""

MAX_SEARCHES = 100_000
"""The most segment-matrix searches one synthesis may run: design vectors tried (``2**segments`` for
``design = "auto"``, else 1) times ``starts``."""

MAX_PIECES = 2000
"""The most pieces ``m_j = ceil(C_j / s_d)`` of a target profile (Eq. 3): ``piece_length`` must be at least
the longest profile's arc length divided by this."""


@dataclass(frozen=True)
class Problem:
    """Everything ``linkwork synth`` needs, in the API's units (lengths as given, angles in radians).

    Attributes
    ----------
    profiles
        The design curves, each a polyline of shape ``(N_j, 2)``. A closed profile's polyline returns to its
        first point (its last row equals its first).
    kind
        ``"open"``, ``"closed"`` or ``"fixed-end"`` (each profile's chain pinned at that profile's own first
        and last points, Eq. 32).
    piece_length
        The desired piece length ``s_d`` of the target profiles (Sec. 2 of the paper).
    min_pieces
        The fewest pieces any segment may span on any profile.
    design
        A design vector such as ``"MCMC"``, or ``None`` to search every design vector of ``segments`` segments.
    segments
        ``q``, the number of segments, when ``design`` is ``None``.
    starts
        How many initial segment matrices the search starts from (seeded, reproducible).
    merge_below
        Joint-range threshold (radians) below which adjacent segments are merged into a compound segment
        (Sec. 6); ``0`` disables merging.
    merge_on
        Where the joint ranges that ``merge_below`` is compared with are measured (Eq. 34): ``"targets"``, on
        the target profiles as the paper does, or ``"chain"``, on the joined chain.
    rank_by
        How the design vectors of ``design = None`` are ranked: ``"error"``, by the joined ``E_max``;
        ``"joints"``, fewest joints among those whose joined ``E_max`` is at most ``e_max_tolerance``, then by
        error (the trade-off of Sec. 5).
    e_max_tolerance
        The largest acceptable joined ``E_max`` (profile units) for ``rank_by = "joints"``.
    initial_segment_matrix
        ``(q, p)`` the segment matrix the search starts from (Eq. 11, transposed: one row per segment), or
        ``None`` for the even split.
    seed
        Seed of the random generator of the initial segment matrices.
    names
        A name per profile (file stem by default).
    source
        The problem file this came from, if any (for messages and relative paths).
    mechanize
        Whether ``linkwork synth`` also mechanizes the chain.
    mechanize_options
        The mechanization keys of the problem file, in file units (degrees), already checked; read them with
        :func:`linkwork.mechanization.options_from_values`.
    units
        The length unit of the profile files (``"mm"``, ``"cm"``, ``"m"``, ``"in"``, ``"ft"``, ``"um"``), carried
        into the DXF (``$INSUNITS``) and SVG (width and height) drawings; ``None``: unitless.
    """

    profiles: tuple[NDArray[np.float64], ...]
    kind: ProfileKind = "open"
    piece_length: float = 0.1
    min_pieces: int = 2
    design: str | None = None
    segments: int | None = None
    starts: int = 5
    merge_below: float = 0.0
    seed: int = 0
    names: tuple[str, ...] = field(default=())
    source: Path | None = None
    mechanize: bool = False
    mechanize_options: Mapping[str, Any] = field(default_factory=dict)
    merge_on: MergeOn = "targets"
    rank_by: RankBy = "error"
    e_max_tolerance: float | None = None
    initial_segment_matrix: NDArray[np.int64] | None = None
    units: str | None = None

    def __post_init__(self) -> None:
        """Check every rule of a problem; a broken one is a :class:`SpecError` naming the problem file's key
        with the same words as the file reader."""
        for key, message in _broken_rules(self):
            raise SpecError(
                message, source=None if self.source is None else escape_line(str(self.source)), key=key
            )

    @property
    def count(self) -> int:
        """``p``, the number of design profiles."""
        return len(self.profiles)

    @property
    def auto_design(self) -> bool:
        """Whether the search tries every design vector of ``segments`` segments (``design`` is ``None`` or
        ``"auto"``) rather than one given design vector."""
        return self.design is None or (isinstance(self.design, str) and self.design.strip().lower() == "auto")


def _real(value: Any) -> bool:
    """A number (``True`` and ``False`` are not)."""
    return isinstance(value, int | float | np.integer | np.floating) and not isinstance(
        value, bool | np.bool_
    )


def _whole(value: Any, minimum: int, maximum: int | None = None) -> bool:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        return False
    return bool(minimum <= value and (maximum is None or value <= maximum))


def _broken_rules(problem: Problem) -> list[tuple[str, str]]:
    """``(key, message)`` of the first broken rule of ``problem`` (empty when it is sound); keys and units are
    those of the problem file (degrees for ``merge_below``), profiles are counted from 0."""
    p = problem
    if p.kind not in KINDS:
        return [("type", f'expected one of "open", "closed", "fixed-end", got {show(p.kind)}')]
    if not isinstance(p.profiles, tuple | list):  # a generator has no length; None is no profile
        return [
            ("profiles", f"expected a tuple of polylines of shape (N, 2), got {type(p.profiles).__name__}")
        ]
    if len(p.profiles) < 2:
        return [("profiles", f"lists {len(p.profiles)} profile(s); expected at least 2 profiles")]
    if not (_real(p.piece_length) and math.isfinite(p.piece_length) and p.piece_length > 0):
        return [("piece_length", f"expected a positive number, got {show(p.piece_length)}")]
    if not _whole(p.min_pieces, 2):
        return [
            (
                "min_pieces",
                "expected a whole number of pieces >= 2 (a C-segment needs an interior point), "
                f"got {show(p.min_pieces)}",
            )
        ]
    broken = _design_rules(p)
    if broken:
        return broken
    if not _whole(p.starts, 1, MAX_STARTS):
        return [
            (
                "starts",
                f"expected a whole number of starts, 1 <= starts <= {MAX_STARTS}, got {show(p.starts)}",
            )
        ]
    searches = (2 ** int(p.segments or 1) if p.auto_design else 1) * int(p.starts)
    if searches > MAX_SEARCHES:
        return [
            (
                "starts",
                f'design "auto" with segments = {p.segments} and starts = {p.starts} is {searches} searches of the '
                f"segment matrix; expected at most {MAX_SEARCHES} (fewer segments or starts)",
            )
        ]
    merge = p.merge_below
    if not (_real(merge) and 0.0 <= merge < math.pi):
        shown = f"{math.degrees(merge):g}" if _real(merge) else show(merge)
        return [("merge_below", f"expected an angle in degrees, 0 <= merge_below < 180, got {shown}")]
    if not _whole(p.seed, 0):
        return [("seed", f"expected a whole number >= 0, got {show(p.seed)}")]
    if p.seed > MAX_SEED:  # the bound of every seed (limits.SEED), the largest whole number TOML holds
        return [("seed", f"expected a whole number <= {MAX_SEED}, got {show(p.seed)}")]
    return _ranking_rules(p) or _name_rules(p) or _profile_rules(p)


def _ranking_rules(p: Problem) -> list[tuple[str, str]]:
    """``merge_on``, ``rank_by`` with its ``e_max_tolerance``, and an initial segment matrix's design."""
    from linkwork.units import LENGTH_UNITS

    if p.units is not None and (not isinstance(p.units, str) or p.units not in LENGTH_UNITS):
        return [("units", f"expected one of {', '.join(LENGTH_UNITS)}, got {show(p.units)}")]
    if p.merge_on not in ("targets", "chain"):
        return [("merge_on", f'expected one of "targets", "chain", got {show(p.merge_on)}')]
    if p.rank_by not in ("error", "joints"):
        return [("rank_by", f'expected one of "error", "joints", got {show(p.rank_by)}')]
    tol = p.e_max_tolerance
    if tol is not None and not (_real(tol) and math.isfinite(tol) and tol > 0):
        return [("e_max_tolerance", f"expected a positive number (profile units), got {show(tol)}")]
    if p.rank_by == "joints" and tol is None:
        return [("e_max_tolerance", 'missing; rank_by = "joints" needs the largest acceptable E_max')]
    sm = p.initial_segment_matrix
    if sm is not None:
        if p.auto_design:
            return [("initial_segment_matrix", 'needs a design vector, not design = "auto"')]
        design = (p.design or "").strip()
        rows = np.asarray(sm).shape[0] if np.asarray(sm).ndim == 2 else -1
        if rows != len(design):
            return [
                (
                    "initial_segment_matrix",
                    f'has {rows} entries per row but design "{design.upper()}" has {len(design)} segments',
                )
            ]
    return []


def _design_rules(p: Problem) -> list[tuple[str, str]]:
    """The design vector and the number of segments."""
    expected = 'a design vector of M and C letters such as "MCMC", or "auto"'
    if p.auto_design:
        if p.segments is None:
            return [("segments", 'missing; design = "auto" needs the number of segments q, e.g. 4')]
        if not _whole(p.segments, 1, MAX_AUTO_SEGMENTS):
            return [
                (
                    "segments",
                    f"expected a whole number of segments, 1 <= segments <= {MAX_AUTO_SEGMENTS} for design "
                    f'"auto" (an exhaustive search over 2**segments design vectors), got {show(p.segments)}',
                )
            ]
        return []
    if not isinstance(p.design, str) or not p.design.strip():
        return [("design", f"expected {expected}, got {show(p.design)}")]
    design = p.design.strip().upper()
    wrong = sorted({letter for letter in design if letter not in "MC"})
    if wrong:
        letters = show(", ".join(wrong))[1:-1]
        return [("design", f"expected {expected}, got {show(p.design)} (letters {letters} are not M or C)")]
    most = MAX_PIECES // 2
    if len(design) > most:  # every segment takes at least 2 of a profile's at most MAX_PIECES pieces
        return [
            (
                "design",
                f"has {len(design)} segments; expected at most {most} (each segment takes at least 2 of a "
                f"profile's at most {MAX_PIECES} pieces), got {show(p.design)}",
            )
        ]
    if p.segments is not None and p.segments != len(design):
        return [
            (
                "segments",
                f'is {show(p.segments)} but design "{design}" has {len(design)} segments; give one or the other',
            )
        ]
    return []


def _name_rules(p: Problem) -> list[tuple[str, str]]:
    """One distinct, non-empty name per profile (or none: numbered names are used)."""
    if not p.names:
        return []
    if not all(isinstance(n, str) and n.strip() for n in p.names):
        return [("names", f"expected a list of {len(p.profiles)} non-empty names")]
    if len(p.names) != len(p.profiles):
        return [
            (
                "names",
                f"lists {len(p.names)} names for {len(p.profiles)} profiles; expected one per profile",
            )
        ]
    for index, name in enumerate(p.names):
        if len(name) > MAX_NAME_CHARS:
            return [(f"names[{index}]", f"expected at most {MAX_NAME_CHARS} characters, got {len(name)}")]
        if name_problem(name) is not None:
            return [(f"names[{index}]", f"expected {name_problem(name)}, got {show(name)}")]
    first: dict[str, int] = {}
    for index, name in enumerate(p.names):
        earlier = first.setdefault(canonical(name), index)  # "é" typed two ways is one name
        if earlier != index:
            return [
                (
                    "names",
                    f"repeats {show(name)} (names[{earlier}] and names[{index}]); expected a different name for "
                    "every profile",
                )
            ]
    return []


def _profile_rules(p: Problem) -> list[tuple[str, str]]:
    """Each profile a finite ``(N, 2)`` polyline, short enough in pieces for :data:`MAX_PIECES`."""
    length = 0.0
    for index, profile in enumerate(p.profiles):
        key = f"profiles[{index}]"
        try:  # rows of unequal length, text, None: numpy's own error would not name the profile
            points = np.asarray(profile, dtype=float)
        except (TypeError, ValueError):
            return [(key, "expected a polyline of shape (N, 2) with N >= 2 of numbers")]
        if points.ndim != 2 or points.shape[1] != 2 or points.shape[0] < 2:
            return [(key, f"expected a polyline of shape (N, 2) with N >= 2, got shape {points.shape}")]
        if not np.all(np.isfinite(points)):
            return [(key, "has a non-finite coordinate; expected finite numbers")]
        with np.errstate(over="ignore", invalid="ignore"):
            length = max(length, float(np.sum(np.hypot(*np.diff(points, axis=0).T))))
    if not length / float(p.piece_length) <= MAX_PIECES:
        return [
            (
                "piece_length",
                f"expected at least 1/{MAX_PIECES} of the longest profile's arc length ({length:.6g}), "
                f"i.e. piece_length >= {length / MAX_PIECES:.6g}, got {show(p.piece_length)}",
            )
        ]
    return []
