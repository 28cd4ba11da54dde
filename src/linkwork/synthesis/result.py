"""The results of shape-change synthesis: target profiles, segments, the joined chain and compound segments.

Every class here is a frozen dataclass of plain numpy arrays; :meth:`SynthesisResult.to_dict` gives the
``chain.json`` contract of the design notes (angles in degrees there, radians everywhere in the API).

Layout conventions
------------------
* ``p`` profiles, ``q`` segments. The segment matrix and every error matrix have shape ``(q, p)``: row
  ``e`` is segment ``e``, column ``j`` is profile ``j`` (the transpose of the paper's printed ``p x q``
  matrices, Eqs. 11, 25), so column ``j`` sums to the piece count ``m_j`` of profile ``j``.
* Joint ``i`` (0-based) is the revolute joint between segments ``i`` and ``i + 1``; there are ``q - 1``.
* A segment's *local frame* puts its first point at the origin and its chord (first point to last point) along
  ``+x``.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013),
Eqs. (1)-(7), (11), (15), (19)-(22), (24)-(25), (29), (31), (34).
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from linkwork.names import csv_cell
from linkwork.synthesis.frames import arc_length, to_local_frame
from linkwork.synthesis.problem import Problem

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]
SegmentKind = Literal["M", "C"]


def _points(a: Array) -> list[list[float]]:
    """JSON-ready ``[[x, y], ...]``."""
    return [[float(x), float(y)] for x, y in np.asarray(a, dtype=float)]


def _matrix(a: NDArray[Any]) -> list[list[float]]:
    """JSON-ready nested lists of a matrix."""
    return np.asarray(a).tolist()


def _floats(values: Sequence[float] | Array) -> list[float]:
    """JSON-ready list of numbers."""
    return [float(v) for v in values]


def _degrees(radians: Sequence[float] | Array) -> list[float]:
    """JSON-ready list of angles in degrees (files and tables use degrees; the API radians)."""
    return [math.degrees(float(v)) for v in radians]


@dataclass(frozen=True)
class TargetProfile:
    """A design profile resampled at equal arc-length increments (Sec. 2, Eqs. 1-7).

    Attributes
    ----------
    points
        ``(m_j + 1, 2)`` target points ``z_j``; a closed profile lists its first point again at the end.
    arc_length
        ``C_j``, the arc length of the design polyline (Eq. 2).
    pieces
        ``m_j*``, the number of pieces (Eq. 3 and the decrease that follows it).
    target_length
        The mean chord ``s_bar_j = S_j / m_j`` (Eq. 5), the achieved piece length.
    name
        The profile's name.
    """

    points: Array
    arc_length: float
    pieces: int
    target_length: float
    name: str = ""

    @property
    def length(self) -> float:
        """``S_j``, the total length of the target polyline (Eq. 6)."""
        return arc_length(self.points)


@dataclass(frozen=True)
class Segment:
    """One segment of the chain and its instance on every profile (Secs. 3.3, 3.4).

    Attributes
    ----------
    kind
        ``"M"`` (rigid mean segment, an RR link) or ``"C"`` (constant-curvature segment, an RPR chain).
    pieces
        ``(p,)`` pieces ``m_j^e`` the segment spans on each profile (equal for an M-segment).
    starts
        ``(p,)`` index of the segment's first point on each target profile (``k_j^e - 1``, 0-based).
    shape
        M-segment: ``(m + 1, 2)`` mean shape in the local frame. C-segment: ``None`` (see ``local_points``).
    curvature
        C-segment: the mean signed curvature ``1 / r`` (positive turning left). M-segment: ``None``.
    piece_length
        C-segment: the mean piece length ``s_bar^e`` over the profiles (Eq. 20 with its ``1/p``).
        M-segment: the mean chord of its shape.
    instances
        Per profile, the ``(m_j^e + 1, 2)`` points of the segment placed where it best fits that profile
        (Eq. 15), before joining.
    errors
        ``(p,)`` largest point-to-point distance of each instance to its profile (Eq. 21).
    """

    kind: SegmentKind
    pieces: IntArray
    starts: IntArray
    shape: Array | None
    curvature: float | None
    piece_length: float
    instances: tuple[Array, ...]
    errors: Array

    @property
    def radius(self) -> float | None:
        """C-segment radius ``1 / curvature`` (``inf`` when straight); ``None`` for an M-segment."""
        if self.curvature is None:
            return None
        return math.inf if self.curvature == 0.0 else 1.0 / self.curvature

    @property
    def lengths(self) -> Array:
        """``(p,)`` polyline length of the segment on each profile (C: ``L_j^e = m_j^e s_bar^e``, Eq. 19)."""
        return np.array([arc_length(pts) for pts in self.instances])

    def local_points(self, j: int) -> Array:
        """The ``(m_j^e + 1, 2)`` points of the instance on profile ``j`` in the segment's local frame."""
        if self.shape is not None:
            return self.shape
        return to_local_frame(self.instances[j])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description: type, the M shape or the C curvature/radius, pieces and lengths."""
        out: dict[str, Any] = {"type": self.kind, "pieces": [int(m) for m in self.pieces]}
        if self.kind == "M":
            assert self.shape is not None
            out["shape"] = _points(self.shape)
        else:
            radius = self.radius
            out["curvature"] = float(self.curvature or 0.0)
            out["radius"] = None if radius is None or math.isinf(radius) else float(radius)
        out["piece_length"] = float(self.piece_length)
        out["lengths"] = _floats(self.lengths)
        out["errors"] = _floats(self.errors)
        return out


@dataclass(frozen=True)
class JoinedProfile:
    """The chain joined by revolute joints and posed to match one profile (Sec. 5).

    Attributes
    ----------
    joints
        ``(q + 1, 2)`` positions of the segmentation points: chain start, the ``q - 1`` joints, chain end.
    points
        ``(m_j + 1, 2)`` the chain's point matching each target-profile point, one to one.
    angles
        ``(q,)`` chord angle ``theta_j^e`` of each segment (radians), as in Eqs. 29 and 31.
    errors
        ``(q,)`` largest point-to-point distance on each segment (Eq. 21 on the joined chain).
    """

    joints: Array
    points: Array
    angles: Array
    errors: Array

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: joints, points, angles (degrees) and errors."""
        return {
            "joints": _points(self.joints),
            "points": _points(self.points),
            "angles": _degrees(self.angles),
            "errors": _floats(self.errors),
        }


@dataclass(frozen=True)
class Compound:
    """Joints of small motion merged into compound segments (Sec. 6).

    Attributes
    ----------
    joint_angles
        ``(q - 1, p)`` relative angle ``sigma_j^i`` at joint ``i`` on profile ``j`` (radians) before merging,
        on the joined chain: the turn from its last piece of segment ``i`` to its first piece of segment
        ``i + 1``. A merged joint is clamped at the mean of its row.
    joint_ranges
        ``(q - 1,)`` range of motion ``max_j sigma - min_j sigma`` of each joint (Eq. 34) on the joined chain,
        radians.
    threshold
        ``merge_below`` (radians).
    merged
        Joints removed, clamped at their mean angle ``mean_j sigma_j^i``.
    notes
        Advice, e.g. a small-motion joint between two M-segments (not merged: choose fewer segments).
    error_matrix
        ``(q, p)`` errors of the chain after merging (Eq. 21).
    e_max
        Largest entry of ``error_matrix`` (Eq. 22).
    profiles
        The merged chain posed on every profile.
    target_angles
        ``(q - 1, p)`` the same relative angles measured on the target profiles at the segmentation points, as
        the paper does (Sec. 6).
    target_ranges
        ``(q - 1,)`` their ranges (Eq. 34).
    merge_on
        ``"targets"`` or ``"chain"``: which ranges ``threshold`` was applied to.
    """

    joint_angles: Array
    joint_ranges: Array
    threshold: float
    merged: tuple[int, ...]
    notes: tuple[str, ...]
    error_matrix: Array
    e_max: float
    profiles: tuple[JoinedProfile, ...]
    target_angles: Array | None = None
    target_ranges: Array | None = None
    merge_on: str = "chain"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready, angles in degrees."""
        return {
            "joint_ranges": _degrees(self.joint_ranges),
            "joint_angles": _matrix(np.degrees(self.joint_angles)),
            "ranges": {
                "targets": None if self.target_ranges is None else _degrees(self.target_ranges),
                "chain": _degrees(self.joint_ranges),
            },
            "merge_on": self.merge_on,
            "merge_below": math.degrees(self.threshold),
            "merged": [int(i) for i in self.merged],
            "notes": list(self.notes),
            "error_matrix": _matrix(self.error_matrix),
            "e_max": float(self.e_max),
            "profiles": [prof.to_dict() for prof in self.profiles],
        }


@dataclass(frozen=True)
class DesignScore:
    """How one design vector fared in the search: its best segment matrix and errors before/after joining.

    ``joined_e_max`` is ``None`` for a design that was not joined: skipped (its chain cannot meet the closure
    or end constraint) or pruned (``bound``, a lower bound on its joined ``E_max``, exceeds the best found).
    ``joints`` counts the chain's joints (the paper's measure of complexity, Sec. 5).
    """

    design: str
    segment_matrix: IntArray
    e_max: float
    e_mean: float
    joined_e_max: float | None
    bound: float = 0.0
    joints: int = 0

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {
            "design": self.design,
            "segment_matrix": _matrix(self.segment_matrix),
            "e_max": float(self.e_max),
            "e_mean": float(self.e_mean),
            "joined_e_max": None if self.joined_e_max is None else float(self.joined_e_max),
            "bound": float(self.bound),
            "joints": int(self.joints),
        }


@dataclass(frozen=True)
class SearchStats:
    """Statistics of the segment-matrix search.

    Attributes
    ----------
    search
        ``"paper"`` (Sec. 4 adjustment rules) or ``"refined"`` (paper, then a local search over
        segmentation points).
    designs
        Every design vector tried: the joined ones best first (in the order of ``rank_by``), then the skipped
        ones, then the pruned ones, then those a signal left unjoined.
    starts
        Initial segment matrices per design vector.
    iterations
        Adjustment iterations over all designs and starts.
    evaluations
        Segment fits requested; ``cache_hits`` of them were answered from the cache.
    cache_hits
        See ``evaluations``.
    seconds
        Wall time of :func:`linkwork.synthesis.synthesize`.
    paper_e_max
        ``E_max`` the paper's search reached for the chosen design (before any refinement).
    designs_tried
        Number of design vectors whose segment matrix was searched.
    skipped
        ``(design, reason)`` of every design vector whose chain could not be joined.
    pruned
        Number of design vectors not joined because their lower bound could not beat the best.
    rank_by, e_max_tolerance
        The ranking of the design vectors (see :class:`~linkwork.synthesis.problem.Problem`).
    stopped
        Why the search stopped before its end (``"interrupted (SIGTERM)"``, a signal held by the command line),
        so that the design chosen is the best of those joined before it; ``None`` when it ran to its end.
    not_searched
        Design vectors whose segment matrix was never searched (after a signal).
    not_joined
        Design vectors searched but not joined (after a signal: the joining stops once one design is joined).
    """

    search: str
    designs: tuple[DesignScore, ...]
    starts: int
    iterations: int
    evaluations: int
    cache_hits: int
    seconds: float
    paper_e_max: float
    designs_tried: int = 0
    skipped: tuple[tuple[str, str], ...] = ()
    pruned: int = 0
    rank_by: str = "error"
    e_max_tolerance: float | None = None
    stopped: str | None = None
    not_searched: int = 0
    not_joined: int = 0

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {
            "search": self.search,
            "complete": self.stopped is None,
            "stopped": self.stopped,
            "not_searched": self.not_searched,
            "not_joined": self.not_joined,
            "designs": [d.to_dict() for d in self.designs],
            "designs_tried": self.designs_tried,
            "skipped": [{"design": d, "reason": r} for d, r in self.skipped],
            "pruned": self.pruned,
            "rank_by": self.rank_by,
            "e_max_tolerance": self.e_max_tolerance,
            "starts": self.starts,
            "iterations": self.iterations,
            "evaluations": self.evaluations,
            "cache_hits": self.cache_hits,
            "seconds": self.seconds,
            "paper_e_max": self.paper_e_max,
        }


@dataclass(frozen=True)
class SynthesisResult:
    """Everything :func:`linkwork.synthesis.synthesize` found for a :class:`Problem`.

    Attributes
    ----------
    problem
        The problem solved.
    targets
        The ``p`` target profiles (Sec. 2).
    design
        The design vector, e.g. ``"CMMMC"``.
    segment_matrix
        ``(q, p)`` pieces per segment and profile (Sec. 3.2); column ``j`` sums to ``targets[j].pieces``.
    error_matrix
        ``(q, p)`` errors ``E_j^e`` after segmentation (Eq. 21).
    e_max, e_mean
        ``E_max`` (Eq. 22) and ``E_bar`` (Eq. 24) of ``error_matrix``.
    segments
        The ``q`` segments.
    joined_error_matrix
        ``(q, p)`` errors of the joined chain (Sec. 5).
    joined_e_max
        Largest entry of ``joined_error_matrix``.
    joined
        The joined chain posed on every profile.
    compound
        Merged joints (Sec. 6), or ``None`` when merging is disabled (``merge_below == 0``).
    stats
        Search statistics and the ranking of design vectors.
    history
        ``E_max`` after every adjustment iteration, a tuple per initial segment matrix, for the chosen design.
    """

    problem: Problem
    targets: tuple[TargetProfile, ...]
    design: str
    segment_matrix: IntArray
    error_matrix: Array
    e_max: float
    e_mean: float
    segments: tuple[Segment, ...]
    joined_error_matrix: Array
    joined_e_max: float
    joined: tuple[JoinedProfile, ...]
    compound: Compound | None
    stats: SearchStats
    history: tuple[tuple[float, ...], ...] = field(default=())

    def to_dict(self) -> dict[str, Any]:
        """The ``chain.json`` contract: lengths as given, angles in degrees; ``complete`` false and ``stopped``
        the reason (``"interrupted (SIGTERM)"``) when a signal stopped the design search (the chain is then the
        best found before it), ``null`` otherwise."""
        return {
            "complete": self.stats.stopped is None,
            "stopped": self.stats.stopped,
            "kind": self.problem.kind,
            "piece_length": float(self.problem.piece_length),
            "min_pieces": int(self.problem.min_pieces),
            "units": self.problem.units,
            "profiles": [
                {
                    "name": t.name,
                    "arc_length": float(t.arc_length),
                    "pieces": int(t.pieces),
                    "target_length": float(t.target_length),
                    "length": t.length,
                }
                for t in self.targets
            ],
            "design": self.design,
            "segment_matrix": _matrix(self.segment_matrix),
            "error_matrix": _matrix(self.error_matrix),
            "e_max": float(self.e_max),
            "e_mean": float(self.e_mean),
            "joined": {
                "error_matrix": _matrix(self.joined_error_matrix),
                "e_max": float(self.joined_e_max),
                "profiles": [prof.to_dict() for prof in self.joined],
            },
            "segments": [seg.to_dict() for seg in self.segments],
            "compound": None if self.compound is None else self.compound.to_dict(),
            "search": self.stats.to_dict(),
        }

    # ---------------------------------------------------------------------------------------- notebook use
    def plot(self, kind: str = "chain") -> Any:
        """A matplotlib ``Figure``: ``kind="chain"`` (the chain before and after joining, Fig. 8),
        ``"profiles"`` (design and target profiles, Fig. 3), ``"errors"`` (every segment's error on every
        profile, Eq. 21) or ``"compound"`` (merged joints, Fig. 10; without a compound stage, ``merge_below = 0``,
        the joined chain with every joint's range of motion, Eq. 34). Needs ``linkwork[viz]``."""
        from linkwork.viz import synthesis_plots

        kinds = {
            "chain": synthesis_plots.plot_chain,
            "profiles": synthesis_plots.plot_profiles,
            "errors": synthesis_plots.plot_errors,
            "compound": synthesis_plots.plot_compound,
        }
        if kind not in kinds:
            raise ValueError(f"Expected kind one of {', '.join(kinds)}, got {kind!r}")
        return kinds[kind](self)

    def __repr__(self) -> str:
        """A few lines a notebook user can read: profiles, design, errors, compound joints."""
        names = ", ".join(f"{t.name or j + 1} ({t.pieces} pieces)" for j, t in enumerate(self.targets))
        lines = [
            f"SynthesisResult ({self.problem.kind}): {len(self.targets)} profiles: {names}",
            f"  design {self.design} ({len(self.segments)} segments), piece length {self.problem.piece_length:.6g}",
            f"  E_max {self.e_max:.4g} / E_mean {self.e_mean:.4g} after segmentation; "
            f"E_max {self.joined_e_max:.4g} after joining",
        ]
        if self.compound is not None:
            merged = ", ".join(str(i + 1) for i in self.compound.merged) or "none"
            lines.append(f"  compound: joints merged {merged}; E_max {self.compound.e_max:.4g}")
        lines.append(
            f"  search: {len(self.stats.designs)} design(s) ranked, {self.stats.evaluations} evaluations "
            f"in {self.stats.seconds:.3g} s"
        )
        lines.append("  .plot('chain'|'profiles'|'errors'|'compound'), .joined, .segments, .to_dict()")
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        """The interactive viewer (the same page ``linkwork synth --html`` writes), inline in Jupyter."""
        from linkwork.viz.inline import synthesis_html

        return synthesis_html(self)


def target_profile_rows(targets: Sequence[TargetProfile]) -> list[tuple[str, int, float, float]]:
    """Rows ``(profile, index, x, y)`` of every target point, index 0-based along each profile."""
    return [
        (t.name or str(j + 1), i, float(x), float(y))
        for j, t in enumerate(targets)
        for i, (x, y) in enumerate(t.points)
    ]


def write_target_profiles_csv(targets: Sequence[TargetProfile], path: str | Path) -> None:
    """Write ``target_profiles.csv``: header ``profile,index,x,y`` then one row per target point (a profile
    name a spreadsheet would run as a formula is written as text, :func:`~linkwork.names.csv_cell`)."""
    with open(path, "w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(("profile", "index", "x", "y"))
        for row in target_profile_rows(targets):
            writer.writerow((csv_cell(row[0]), row[1], repr(row[2]), repr(row[3])))
