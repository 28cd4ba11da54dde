"""``mechanization.json`` and ``mechanism.toml``: what a mechanized design is, in file units (degrees)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from linkwork.mechanization.assemble import spec_text
from linkwork.mechanization.mechanize import Mechanization, RankedDesign
from linkwork.mechanization.verify import link_pivots


def _value(kind: str, value: float) -> float:
    return math.degrees(value) if kind == "R" else float(value)


def mechanization_dict(result: Mechanization) -> dict[str, Any]:
    """The ``mechanization.json`` contract: ``dof``, ``drive``, ``dyads`` and per profile ``drive_value``,
    ``angles`` {joint: degrees (lengths for prismatic joints)}, ``e_max`` beside ``joined_e_max``, and ``pivots``
    {link: [[x, y] anchor pivot, [x, y] moving pivot]} in that profile's pose; ``limits`` the link-length and
    structural-error bounds used; angles in degrees. ``complete`` is false, and ``stopped`` says why
    (``"interrupted (SIGTERM)"``), when a signal stopped the search: the design is then the best that passed
    before it (``null`` when the search ran to its end)."""
    design, check = result.design, result.verification
    mech = design.mechanism()
    size = design.chain.size
    kinds = dict(zip(mech.joint_names, mech.joint_types, strict=True))
    d_kind = kinds[design.drive]
    profiles = []
    for j, state in enumerate(check.states):
        profiles.append(
            {
                "profile": j + 1,
                "drive_value": _value(d_kind, state.drive_value),
                "angles": {
                    name: _value(kinds[name], float(v))
                    for name, v in zip(mech.joint_names, state.values, strict=True)
                },
                "e_max": state.e_max,
                "joined_e_max": float(design.chain.joined_errors[j]),
                "deviation": state.deviation,
                "pivots": {
                    name: [[float(v) for v in point] for point in pair]
                    for name, pair in link_pivots(design, mech, state.values).items()
                },
            }
        )
    return {
        "name": design.name,
        "complete": result.complete,
        "stopped": result.stopped,
        "dof": check.dof,
        "rank": check.rank,
        "drive": design.drive,
        "drive_type": d_kind,
        "drive_unit": "deg" if d_kind == "R" else "length",
        "joints": [{"name": n, "type": kinds[n]} for n in mech.joint_names],
        "bodies": [b.name for b in design.chain.bodies],
        "dyads": [link.to_dict() for link in design.links],
        "profiles": profiles,
        "e_max": max(s.e_max for s in check.states),
        "joined_e_max": float(max(design.chain.joined_errors)),
        "max_structural_error": max((link.structural_error for link in design.links), default=0.0),
        "limits": _limits(result, size),
        "recut": _recut(result),
        "max_condition": check.max_condition,
        "verification": {
            "passed": check.passed,
            "traced": check.traced,
            "status": "traced" if check.traced else check.reason,
            "checks": [
                "dof from the Jacobian rank",
                "order (monotonic drive)",
                "branch (no singular configuration)",
                "circuit (same assembly mode at every profile)",
            ]
            if check.traced
            else [
                "dof from the Jacobian rank",
                "closure of every profile's configuration",
                "full Jacobian rank at every profile",
            ],
            "attempts": result.attempts,
            "rejected": list(result.rejected),
        },
        "quality": result.ranked[0].quality.to_dict(d_kind) if result.ranked else None,
        "designs": [_ranked(rank, r) for rank, r in enumerate(result.ranked, start=1)],
        "notes": list(design.notes),
        "seconds": result.seconds,
        "trace_command": f"linkwork trace mechanism.toml --drive {design.drive} --until {design.drive}=<drive_value>",
    }


def _recut(result: Mechanization) -> dict[str, Any] | None:
    """The chain re-cut with monotonic C-segment piece counts, when the mechanism follows it: the segment matrix
    followed and the synthesised one (a row per segment, a column per profile), and the synthesised chain's
    ``E_max`` on every profile beside the re-cut chain's (``profiles[k].joined_e_max``); ``None`` otherwise."""
    recut = result.recut
    if recut is None:
        return None
    return {
        "segment_matrix": recut.segment_matrix.tolist(),
        "synthesised_segment_matrix": recut.before.tolist(),
        "synthesised_joined_e_max": [float(e) for e in recut.joined_before],
        "note": recut.describe(),
    }


def _limits(result: Mechanization, size: float) -> dict[str, Any]:
    """The bounds the search kept: ``max_link`` (a length, profile units) and the same as a multiple of the
    profiles' largest extent ``size``, and ``max_structural_error`` (a length; ``None`` when not bounded by the
    designer)."""
    options = result.options
    if options is None:
        return {}
    longest = options.link_limit(size)
    return {
        "max_link": longest,
        "max_link_fraction": longest / size,
        "largest_extent": size,
        "max_structural_error": options.max_structural_error,
        "structural_error_cut": options.structural_limit(size),
    }


def _ranked(rank: int, ranked: RankedDesign) -> dict[str, Any]:
    """One of the best designs: its rank, quality factor and parts, drive and links."""
    mech = ranked.design.mechanism()
    kind = mech.joint_types[mech.index(ranked.design.drive)]
    return {
        "rank": rank,
        **ranked.quality.to_dict(kind),
        "drive": ranked.design.drive,
        "e_max": max(s.e_max for s in ranked.verification.states),
        "dyads": [link.to_dict() for link in ranked.design.links],
    }


def write_mechanization(result: Mechanization, folder: str | Path) -> list[Path]:
    """Write ``mechanism.toml`` and ``mechanization.json`` into ``folder``; returns their paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    spec = folder / "mechanism.toml"
    spec.write_text(spec_text(result.design), encoding="utf-8")
    report = folder / "mechanization.json"
    report.write_text(
        json.dumps(mechanization_dict(result), indent=2, allow_nan=False) + "\n", encoding="utf-8"
    )
    return [spec, report]
