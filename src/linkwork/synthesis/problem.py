"""A shape-change synthesis problem: the design profiles and the settings of the search (Shamsudin et al. 2013)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

ProfileKind = Literal["open", "closed", "fixed-end"]
RankBy = Literal["error", "joints"]
MergeOn = Literal["targets", "chain"]


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

    @property
    def count(self) -> int:
        """``p``, the number of design profiles."""
        return len(self.profiles)
