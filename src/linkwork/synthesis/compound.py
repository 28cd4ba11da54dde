"""Compound segments (Sec. 6): find revolute joints that barely move across the profiles and clamp them.

References
----------
S. A. Shamsudin, A. P. Murray, D. H. Myszka, J. P. Schmiedeler, Mech. Mach. Theory (2013), Eqs. (17), (34).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from linkwork.geometry.angles import wrap
from linkwork.synthesis.joining import join_chain
from linkwork.synthesis.result import Compound, JoinedProfile, Segment, TargetProfile
from linkwork.synthesis.segment_fit import segment_starts

Array = NDArray[np.float64]


def relative_angles(polylines: Sequence[Array], segment_matrix: NDArray[np.int64]) -> Array:
    """``(q - 1, p)`` relative angle ``sigma_j^i`` at every segmentation point between two segments (Sec. 6).

    The turn from the direction ``P`` of the piece entering segmentation point ``k_j^{i+1}`` to that of the piece
    leaving it (Eq. 17), on polyline ``j`` (a target profile or the joined chain, whose points correspond one to
    one). Rows are unwrapped about profile 1 so that ranges across ``+-pi`` come out right.
    """
    starts = segment_starts(segment_matrix)[1:]  # (q - 1, p) joint point indices
    q1, p = starts.shape
    sigma = np.empty((q1, p))
    for j, points in enumerate(polylines):
        k = starts[:, j]
        p_in = points[k] - points[k - 1]
        p_out = points[k + 1] - points[k]
        cross = p_in[:, 0] * p_out[:, 1] - p_in[:, 1] * p_out[:, 0]
        sigma[:, j] = np.arctan2(cross, np.sum(p_in * p_out, axis=1))
    if q1:
        sigma = sigma[:, :1] + wrap(sigma - sigma[:, :1])
    return sigma


def joint_angles(joined: Sequence[JoinedProfile], segment_matrix: NDArray[np.int64]) -> Array:
    """``(q - 1, p)`` relative angle ``sigma_j^i`` at every joint of the joined chain (Sec. 6)."""
    return relative_angles([prof.points for prof in joined], segment_matrix)


def target_joint_angles(targets: Sequence[TargetProfile], segment_matrix: NDArray[np.int64]) -> Array:
    """``(q - 1, p)`` relative angle ``sigma_j^i`` on the target profiles at the segmentation points, as the
    paper measures it (Sec. 6)."""
    return relative_angles([t.points for t in targets], segment_matrix)


def joint_ranges(sigma: Array) -> Array:
    """``(q - 1,)`` range of motion ``max_j sigma_j^i - min_l sigma_l^i`` of each joint (Eq. 34)."""
    if sigma.size == 0:
        return np.zeros(sigma.shape[0])
    return sigma.max(axis=1) - sigma.min(axis=1)


def merge_joints(
    design: str,
    segment_matrix: NDArray[np.int64],
    segments: Sequence[Segment],
    targets: Sequence[TargetProfile],
    joined: Sequence[JoinedProfile],
    threshold: float,
    kind: str,
    *,
    merge_on: str = "targets",
) -> Compound:
    """Merge every joint whose range (Eq. 34) is below ``threshold`` and that touches a C-segment (Sec. 6).

    The ranges are measured both on the target profiles (the paper's choice) and on the joined chain;
    ``merge_on`` (``"targets"`` or ``"chain"``) says which are compared with ``threshold``. A merged joint is
    clamped at its mean angle over the profiles on the joined chain and the chain is joined again. A low-motion
    joint between two M-segments is not merged (the merged link could not follow the profiles better than one
    M-segment would): a note suggests a design with fewer segments instead.
    """
    sigma = joint_angles(joined, segment_matrix)
    ranges = joint_ranges(sigma)
    target_sigma = target_joint_angles(targets, segment_matrix)
    target_ranges = joint_ranges(target_sigma)
    merged, notes = _joints_to_merge(design, target_ranges if merge_on == "targets" else ranges, threshold)
    profiles = tuple(joined)
    if merged:
        mean = sigma.mean(axis=1)
        ties = [
            [(i, float(prof.angles[i + 1] - prof.angles[i] + (mean[i] - sigma[i, j]))) for i in merged]
            for j, prof in enumerate(joined)
        ]
        profiles = join_chain(segments, targets, kind, ties=ties, initial=joined)
    em = np.column_stack([prof.errors for prof in profiles])
    return Compound(
        sigma,
        ranges,
        threshold,
        tuple(merged),
        tuple(notes),
        em,
        float(em.max()),
        profiles,
        target_sigma,
        target_ranges,
        merge_on,
    )


def _joints_to_merge(design: str, ranges: Array, threshold: float) -> tuple[list[int], list[str]]:
    """``(merged, notes)``: the joints whose range is below ``threshold`` and that touch a C-segment, and a note
    for each low-motion joint between two M-segments (left alone)."""
    merged: list[int] = []
    notes: list[str] = []
    for i, rng in enumerate(ranges):
        if not rng < threshold:
            continue
        if design[i] == "M" and design[i + 1] == "M":
            notes.append(
                f"joint {i} between M-segments {i} and {i + 1} moves only {math.degrees(rng):.3g} deg "
                f"(< {math.degrees(threshold):.3g}): consider a design vector with fewer segments"
            )
        else:
            merged.append(i)
    return merged, notes
