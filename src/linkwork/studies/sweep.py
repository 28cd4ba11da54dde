"""Parameter studies: one trace (and optionally one robustness study) or one synthesis per grid point.

:func:`run_sweep` sends every grid point of a :class:`~linkwork.studies.study_file.Study` to the Dask engine as its
own task and returns one row per point, in grid order: the parameters, then for a linkage the mobility at the start,
the range of every joint (degrees), the bifurcations found, the largest Sec. 5 ratio along the path and how the
path ended (and the misfit percentiles with ``[robustness]``); for a synthesis the design found, ``e_max`` and
``e_mean``. A point that fails keeps its row, with the reason in ``error``.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from linkwork.errors import LinkworkError, SpecError
from linkwork.names import NameMap, csv_columns
from linkwork.progress import Progress
from linkwork.studies.engine import map_chunks
from linkwork.studies.study_file import Study

Row = dict[str, Any]


def _until_api(mech: Any, until: tuple[str, float] | None) -> tuple[str, float] | None:
    if until is None:
        return None
    j = mech.index(until[0])
    return until[0], float(np.radians(until[1]) if mech.joint_types[j] == "R" else until[1])


SWEEP_FIXED = (
    "mobility",
    "points",
    "bifurcations",
    "ratio_max",
    "end",
    "error",
    "misfit_p50",
    "misfit_p95",
    "first_order_p50",
    "mobility_kept",
    "length_scale",
    "design",
    "segment_count",
    "e_max",
    "e_mean",
)
"""The fixed columns of ``sweep.csv`` (besides the grid parameters and ``<joint>_min``, ``<joint>_max``)."""


def joint_columns(joints: Sequence[str], grid: Iterable[str] = ()) -> NameMap:
    """The column stem of every joint in ``sweep.csv`` (``<stem>_min``, ``<stem>_max``): the joint's name, or
    ``joint:<name>`` when a column would clash with a fixed one or a grid parameter (``ratio`` gives
    ``joint:ratio_max``; :func:`linkwork.names.csv_columns`)."""
    return csv_columns("sweep.csv", joints, {*SWEEP_FIXED, *grid}, suffixes=("_min", "_max"))


def linkage_point(study: Study, index: int) -> tuple[Row, Any]:
    """Trace grid point ``index`` of a linkage study; returns its row and, if robustness figures are asked, the
    robustness result (else ``None``)."""
    from linkwork.io.spec import resolve_spec
    from linkwork.kinematics.tracer import trace

    params = study.points()[index]
    row: Row = dict(params)
    try:
        mech = resolve_spec(study.target, params).mechanism
        path = trace(
            mech,
            until=_until_api(mech, study.until),
            steps=study.steps,
            branches=study.branches,
            max_steps=study.max_steps,
        )
    except LinkworkError as exc:
        row["error"] = str(exc)
        return row, None
    row["mobility"] = int(path.mobility[0])
    row["points"] = int(path.angles.shape[0])
    stems = joint_columns(mech.joint_names, study.grid)
    for j, name in enumerate(mech.joint_names):
        deg = np.degrees(path.angles[:, j]) if mech.joint_types[j] == "R" else path.angles[:, j]
        row[f"{stems[name]}_min"] = float(deg.min())
        row[f"{stems[name]}_max"] = float(deg.max())
    row["bifurcations"] = len(path.bifurcations)
    row["ratio_max"] = float(path.max_condition_raw)  # the paper's Sec. 5 ratio, raw
    row["end"] = path.branches[0].end_reason if path.branches else ""
    result = None
    if study.robustness is not None:
        result = _robustness_columns(study, mech, path, row)
    row["error"] = ""
    return row, result if study.robustness is not None and study.robustness.figures else None


def _robustness_columns(study: Study, mech: Any, path: Any, row: Row) -> Any:
    from linkwork.studies.imperfections import ImperfectionModel
    from linkwork.studies.robustness import robustness

    settings = study.robustness
    assert settings is not None
    model = ImperfectionModel(
        settings.position_tol,
        float(np.radians(settings.direction_tol_deg)),
        settings.distribution,
        spatial=settings.spatial_errors or not mech.moves_in_plane,
    )
    res = robustness(mech, path, model, settings.samples, seed=settings.seed, workers=0)
    row["misfit_p50"] = float(np.median(res.misfit_max))
    row["misfit_p95"] = float(np.percentile(res.misfit_max, 95))
    row["first_order_p50"] = float(np.median(res.first_order_max))
    row["mobility_kept"] = float(np.mean(res.mobility_kept))
    row["length_scale"] = res.setup.scale.length
    return res


def synthesis_point(study: Study, index: int) -> tuple[Row, Any]:
    """Synthesise grid point ``index`` of a synthesis study (the public :func:`linkwork.synthesis.synthesize`)."""
    from linkwork.synthesis import synthesize

    problem = study.extra["problem"]
    params = study.points()[index]
    row: Row = dict(params)
    changes: dict[str, Any] = {}
    for key, value in params.items():
        if key == "design":
            changes["design"] = None if str(value).lower() == "auto" else str(value)
        elif key == "merge_below":
            changes[key] = float(np.radians(float(value)))
        elif key == "piece_length":
            changes[key] = float(value)
        else:
            changes[key] = int(value)
    if "segments" in changes and "design" not in changes:
        changes["design"] = None  # varying the number of segments means searching the designs of each
    try:
        variant = replace(problem, **changes)
        if variant.design is not None:
            variant = replace(variant, segments=None)
        result = synthesize(variant)
    except LinkworkError as exc:
        row["error"] = str(exc)
        return row, None
    row["design"] = result.design
    row["segment_count"] = len(result.segments)
    row["e_max"] = float(result.e_max)
    row["e_mean"] = float(result.e_mean)
    row["error"] = ""
    return row, None


def prepare_study(study: Study) -> Study:
    """Load what every task needs once (a synthesis problem) and check the target exists."""
    if study.kind == "synthesis":
        from pathlib import Path

        from linkwork.io.problem import load_problem

        target = study.target
        if not target.endswith(".toml") and not Path(target).exists():
            from linkwork import data

            target = str(data.example(target))
        problem = load_problem(target)
        if "each" in [str(v).lower() for v in study.grid.get("design", [])]:
            if [str(v).lower() for v in study.grid["design"]] != ["each"]:
                raise SpecError('design "each" cannot be mixed with other designs', key="grid.design")
            if problem.segments is None and "segments" not in study.grid:
                raise SpecError('design "each" needs the number of segments', key="grid.segments")
            study = replace(study, grid={**study.grid, "design": ["each"]})
        return replace(study, extra={"problem": problem, "segments": problem.segments})
    from linkwork.io.spec import resolve_spec

    if study.grid:  # a built-in: its name and parameter names must be right (values are checked per point)
        from linkwork.io.spec import import_builtins
        from linkwork.linkages.registry import get

        import_builtins()
        entry = get(study.target)
        unknown = [k for k in study.grid if k not in entry.params]
        if unknown:
            raise SpecError(
                f"{entry.name} has no parameter {unknown[0]!r}; expected {', '.join(entry.params)}",
                source=str(study.source),
                key=f"grid.{unknown[0]}",
            )
    else:
        resolve_spec(study.target)
    return study


def run_sweep(
    study: Study,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    client: Any = None,
    progress: Progress | None = None,
) -> list[tuple[Row, Any]]:
    """Every grid point's row (and robustness result when figures are asked), in grid order."""
    if not (study.kind == "synthesis" and "problem" in study.extra):
        study = prepare_study(study)
    func = synthesis_point if study.kind == "synthesis" else linkage_point
    chunks = [(i,) for i in range(len(study.points()))]
    return list(
        map_chunks(
            func, study, chunks, scheduler=scheduler, workers=workers, client=client, progress=progress
        )
    )
