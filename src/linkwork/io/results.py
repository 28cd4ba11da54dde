"""Result files of a trace: ``path.csv`` (one row per traced point) and ``report.json`` (the summary).

Angles are written in degrees (prismatic joints in length units); the column and key names are a contract
(docs/architecture.md, "Contracts").
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import numpy as np

from linkwork.deprecation import trace_keyword
from linkwork.io.deployment_report import deployment_entry
from linkwork.io.readback import path_columns
from linkwork.io.readback import points_columns as csv_stems
from linkwork.io.writer import json_text, require_finite
from linkwork.kinematics.deployment import Deployment
from linkwork.kinematics.extremes import joint_ranges
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.trace_result import Bifurcation, Branch, Fold, Trace


def file_units(mech: Mechanism, values: np.ndarray) -> np.ndarray:
    """Joint values (radians, any leading shape) in file units: degrees for revolute joints, lengths as they are
    for prismatic ones; a copy."""
    revolute = np.array([t == "R" for t in mech.joint_types])
    out = np.array(values, dtype=float, copy=True)
    out[..., revolute] = np.degrees(out[..., revolute])
    return out


@trace_keyword
def file_arclength(trace: Trace) -> np.ndarray:
    """The arclength along each branch in file units: in the unknowns measured in degrees for revolute unknowns
    and in the length unit for prismatic ones (``path.csv``'s ``s``, the viewer's arclength axis); a copy.

    Without a prismatic unknown this is ``degrees(Trace.arclength)``. With one it is
    ``Trace.arclength_in_file_units``, which the tracer sums over every part of each step (a long paper row's parts
    turn, so no rescaling of its chord gives it), where the trace has it. Where it does not (the closed form's
    rows without parts, a trace built by hand), each row's increment of ``Trace.arclength`` is rescaled by its
    chord's ratio ``|du_file| / |du|`` (``du`` the unknowns' change over the row, ``du_file`` the same in file
    units): exact where the increment is the row's chord, as it is for those rows. A branch starts where
    ``Trace.arclength`` starts it (0).
    """
    s = np.asarray(trace.arclength, dtype=float)
    if trace.arclength_in_file_units is not None:
        return np.array(trace.arclength_in_file_units, dtype=float)
    mech = trace.mechanism
    prismatic = np.array(
        [any(mech.joint_types[j] == "P" for j in members) for members in mech.group_members()], dtype=bool
    )
    if not prismatic.any() or len(s) == 0:
        return np.degrees(s)
    u = mech.u_from_q(np.asarray(trace.angles, dtype=float))
    in_file = np.where(prismatic, 1.0, np.degrees(1.0))
    out = np.empty_like(s)
    for branch in np.unique(trace.branch):
        rows = np.flatnonzero(trace.branch == branch)
        rows = rows[np.argsort(trace.step[rows], kind="stable")]
        du = np.diff(u[rows], axis=0)
        chord = np.linalg.norm(du, axis=1)
        chord_file = np.linalg.norm(du * in_file, axis=1)
        ds = np.diff(s[rows])
        safe = np.where(chord > 0.0, chord, 1.0)
        step = np.where(chord > 0.0, ds * chord_file / safe, np.degrees(ds))
        out[rows] = np.concatenate([[np.degrees(s[rows[0]])], np.degrees(s[rows[0]]) + np.cumsum(step)])
    return out


def _display(trace: Trace, values: np.ndarray) -> np.ndarray:
    """Joint values of ``trace``'s mechanism in file units (:func:`file_units`)."""
    return file_units(trace.mechanism, values)


@trace_keyword
def path_rows(trace: Trace) -> tuple[list[str], list[list[Any]]]:
    """Header and rows of ``path.csv``: ``branch,step,s,<joints>,sigma_1..sigma_k,residual`` (a joint whose name
    is one of the fixed columns is written ``joint:<name>``, :func:`linkwork.io.readback.path_columns`)."""
    columns = path_columns(trace.mechanism.joint_names)
    names = [columns[n] for n in trace.mechanism.joint_names]
    k = trace.sigma.shape[1]
    header = ["branch", "step", "s", *names, *[f"sigma_{i + 1}" for i in range(k)], "residual"]
    angles = _display(trace, trace.angles)
    s_deg = file_arclength(trace)
    rows = []
    for i in range(len(trace.branch)):
        rows.append(
            [
                int(trace.branch[i]),
                int(trace.step[i]),
                float(s_deg[i]),
                *map(float, angles[i]),
                *map(float, trace.sigma[i]),
                float(trace.residual[i]),
            ]
        )
    return header, rows


@trace_keyword
def write_path_csv(trace: Trace, file: Path) -> None:
    """Write ``path.csv`` (floats with 17 significant digits, so nothing is lost)."""
    header, rows = path_rows(trace)
    require_finite([[v for v in row if isinstance(v, float)] for row in rows], "path.csv: the traced values")
    with open(file, "w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(header)
        for row in rows:
            writer.writerow([f"{v:.17g}" if isinstance(v, float) else v for v in row])


@trace_keyword
def branch_range(trace: Trace, branch: int | None) -> dict[str, list[float]]:
    """``{joint: [min, max]}`` over one branch (``None``: every branch), in file units (degrees, or lengths for
    prismatic joints): the rows, the drive's located folds and every joint's located turning points
    (:func:`linkwork.kinematics.extremes.joint_ranges`), so each joint's range is its swing to
    ``Tolerances.locate``, not only what the rows sampled."""
    ranges = joint_ranges(trace, branch)
    names = trace.mechanism.joint_names
    values = _display(trace, np.array([[ranges[name][side] for name in names] for side in (0, 1)]))
    return {name: [float(values[0, j]), float(values[1, j])] for j, name in enumerate(names)}


@trace_keyword
def report_dict(
    trace: Trace,
    assembly: Any | None = None,
    deployment: Deployment | None = None,
    *,
    deployment_unmet: str | None = None,
) -> dict[str, Any]:
    """The content of ``report.json`` (``deployment``: the measures of :meth:`Trace.deployment`, default
    deployed configuration unless given; ``deployment_unmet``: why the deployed configuration asked for is not on
    the path, and then ``deployment`` is ``null``)."""
    mech = trace.mechanism
    names = list(mech.joint_names)
    cond = trace.condition()
    out: dict[str, Any] = {
        "name": mech.name,
        "joints": names,
        "joint_types": list(mech.joint_types),
        "units": {
            "angles": "deg",
            "s": "deg (arclength in the unknowns; prismatic unknowns in the length unit)",
        },
        "drive": trace.drive,
        "mode": trace.stats.mode,
        "unknowns": mech.n_unknowns,
        "couplings": [[names[j] for j in group] for group in mech.group_members() if len(group) > 1],
        "fixed": [names[j] for j in np.flatnonzero(mech.groups < 0)],
        "equations": mech.n_equations,
        **_rank_entries(trace),
        "points": len(trace.branch),
        "max_residual": float(trace.residual.max()),
        "closure_tol": float(trace.stats.closure_tol),
        "max_misfit": float(trace.stats.max_misfit),
        "target_reached": (trace.stats.unmet is None) if trace.stats.has_target else None,
        "unmet": trace.stats.unmet,
        "complete": trace.stats.stopped is None,
        "stopped": trace.stats.stopped,
        "max_condition": trace.max_condition,
        "max_condition_raw": trace.max_condition_raw,
        "condition_at_end": float(cond[-1]) if len(cond) else None,
        "bifurcations": [_bifurcation_entry(trace, b) for b in trace.bifurcations],
        "folds": [_fold_entry(trace, f) for f in trace.folds],
        "branches": [_branch_entry(trace, br) for br in trace.branches],
        "seconds": trace.stats.seconds,
    }
    out["deployment"] = None if deployment_unmet else deployment_entry(trace, deployment)
    out["deployment_unmet"] = deployment_unmet
    if assembly is not None:
        out["assembly"] = _assembly_entry(assembly, names)
    return out


def _rank_entries(trace: Trace) -> dict[str, Any]:
    """``rank`` and ``mobility`` at the start, and their ranges along the path away from the bifurcation points
    (where the rank drops by definition)."""
    mech = trace.mechanism
    start_rank = int(trace.stats.start_rank)
    regular = np.ones(len(trace.rank), dtype=bool)
    for b in trace.bifurcations:
        diff = trace.angles - b.angles
        revolute = np.array([kind == "R" for kind in mech.joint_types])
        diff[:, revolute] = (diff[:, revolute] + np.pi) % (2.0 * np.pi) - np.pi  # the point, a turn away
        regular &= np.linalg.norm(diff, axis=1) > 1e-6
    ranks = trace.rank[regular] if np.any(regular) else trace.rank
    return {
        "rank": start_rank,
        "mobility": mech.n_unknowns - start_rank,
        "rank_along_path": {"min": int(ranks.min()), "max": int(ranks.max())},
        "mobility_along_path": {
            "min": int(mech.n_unknowns - ranks.max()),
            "max": int(mech.n_unknowns - ranks.min()),
        },
    }


def _named(trace: Trace, angles: np.ndarray) -> dict[str, float]:
    """One configuration as ``{joint: value}`` in file units."""
    return dict(zip(trace.mechanism.joint_names, map(float, _display(trace, angles)), strict=True))


def _bifurcation_entry(trace: Trace, b: Bifurcation) -> dict[str, Any]:
    """One entry of ``bifurcations``."""
    return {
        "id": b.id,
        "branch": b.branch,
        "step": b.step,
        "angles": _named(trace, b.angles),
        "rank": b.rank,
        "singular_values": [float(x) for x in b.sigma],
        "tangents": [[float(x) for x in t] for t in b.tangents],
        "method": b.method,
        "residual": b.residual,
        "accuracy": b.bracket,
        "kind": b.kind,
        "dimension": b.dimension,
    }


def _fold_entry(trace: Trace, f: Fold) -> dict[str, Any]:
    """One entry of ``folds``: where the drive turns back, and its value there."""
    return {
        "branch": f.branch,
        "step": f.step,
        "drive": trace.drive,
        "value": float(_display(trace, f.angles)[trace.mechanism.index(trace.drive)]),
        "angles": _named(trace, f.angles),
    }


def _branch_entry(trace: Trace, br: Branch) -> dict[str, Any]:
    """One entry of ``branches``: how it was found and ended, its range, first and last configurations."""
    on_branch = trace.angles[trace.branch == br.id]
    return {
        "id": br.id,
        "parent": br.parent,
        "bifurcation": br.bifurcation,
        "direction": br.direction,
        "steps": br.steps,
        "end_reason": br.end_reason,
        **_end_entries(trace, br),
        "mobility": br.mobility,
        "range": branch_range(trace, br.id),
        "start": _named(trace, on_branch[0]),
        "end": _named(trace, on_branch[-1]),
    }


def _end_entries(trace: Trace, br: Branch) -> dict[str, Any]:
    """The branch's end, structured: ``end_kind`` (the :class:`~linkwork.kinematics.stops.StopReason` name in
    lower case), ``end_joint`` and ``end_value`` (that joint's value at the end: degrees for a revolute joint),
    ``end_point`` (the located point it ended on, or ``null``)."""
    value = br.end_value
    if value is not None and br.end_joint is not None:
        if trace.mechanism.joint_types[trace.mechanism.index(br.end_joint)] == "R":
            value = float(np.degrees(value))
    return {
        "end_kind": None if br.end_kind is None else br.end_kind.name.lower(),
        "end_joint": br.end_joint,
        "end_value": value,
        "end_point": br.end_point,
    }


def _assembly_entry(assembly: Any, names: list[str]) -> dict[str, Any]:
    """``assembly``: how a ``dh`` or ``rods`` start was closed onto its loop."""
    return {
        "residual_before": float(assembly.residual_before),
        "residual_after": float(assembly.residual_after),
        "misfit": float(getattr(assembly, "misfit", assembly.residual_after)),
        "closure_tol": float(getattr(assembly, "closure_tol", 1e-12)),
        "correction_deg": dict(zip(names, map(float, np.degrees(assembly.correction)), strict=True)),
    }


@trace_keyword
def write_report_json(
    trace: Trace,
    file: Path,
    assembly: Any | None = None,
    deployment: Deployment | None = None,
    *,
    deployment_unmet: str | None = None,
) -> None:
    """Write ``report.json`` (see :func:`report_dict`)."""
    report = report_dict(trace, assembly, deployment, deployment_unmet=deployment_unmet)
    Path(file).write_text(json_text(report), encoding="utf-8")


@trace_keyword
def write_points_csv(trace: Trace, file: Path) -> None:
    """Write ``points.csv``: ``branch,step``, then ``<name>_x,<name>_y,<name>_z`` for every joint and every named
    point (world coordinates, the mechanism's length unit), then ``transmission`` (degrees) when the mechanism
    declares a transmission angle (four-bar, slider-crank)."""
    from linkwork.kinematics.points import points_columns, positions, transmission_angles

    mech = trace.mechanism
    joints, named = positions(mech, trace.angles)
    xyz = np.concatenate([joints, named], axis=1).reshape(len(trace.angles), -1)
    stems = csv_stems(points_columns(mech))
    header = ["branch", "step", *[f"{stems[name]}_{c}" for name in points_columns(mech) for c in "xyz"]]
    mu = transmission_angles(mech, joints)
    if mu is not None:
        header.append("transmission")
        xyz = np.column_stack([xyz, np.degrees(mu)])
    require_finite(xyz, "points.csv: the positions")
    with open(file, "w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(header)
        for b, s, row in zip(trace.branch, trace.step, xyz, strict=True):
            writer.writerow([int(b), int(s), *(f"{v:.17g}" for v in row)])
