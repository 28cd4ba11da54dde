"""Parameter studies: one trace (and optionally one robustness study) or one synthesis per grid point.

:func:`run_sweep` sends every grid point of a :class:`~linkwork.studies.study_file.Study` to the Dask engine as its
own task and returns one row per point, in grid order: the parameters, then for a linkage the mobility at the start,
the range of every joint (degrees), the bifurcations found, the largest Sec. 5 ratio along the path and how the
path ended (and the misfit percentiles with ``[robustness]``); for a synthesis the design found, ``e_max`` and
``e_mean``. A point that fails keeps its row, with the reason in ``error``: whatever goes wrong at one point
(a bad combination of values, a trace that does not converge, its ``time_per_point`` running out) never loses the
rows of the others. Points are sent to the engine in batches, so a grid of many quick points is not slowed down by
one task each.
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from linkwork.errors import LinkworkError, RequestNotMetError, SpecError
from linkwork.io.results import branch_range
from linkwork.io.toml_reader import TomlReader
from linkwork.messages import escape_line, show
from linkwork.names import NameMap, csv_columns
from linkwork.progress import Progress
from linkwork.studies.engine import RunStatus, map_chunks
from linkwork.studies.study_file import Study, check_work, load_study

Row = dict[str, Any]


class PointTimeout(RequestNotMetError):
    """A grid point that ran longer than its study's ``time_per_point``."""


@dataclass
class PointBudget:
    """The time budget of one grid point, checked at every progress report of its computation."""

    seconds: float
    start: float

    @classmethod
    def of(cls, study: Study) -> PointBudget:
        """A budget starting now."""
        return cls(study.time_per_point, time.monotonic())

    def __call__(self, done: int, total: int | None) -> None:
        if time.monotonic() - self.start > self.seconds:
            raise PointTimeout(f"stopped after time_per_point = {self.seconds:g} s")


def point_error(exc: BaseException) -> str:
    """The one-line reason a grid point failed, for its row's ``error`` column."""
    if isinstance(exc, LinkworkError):
        return escape_line(str(exc))
    if isinstance(exc, MemoryError):
        return "ran out of memory"
    return escape_line(f"unexpected {type(exc).__name__}: {exc}")[:500]


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

    params = study.point(index)
    row: Row = dict(params)
    budget = PointBudget.of(study)
    try:
        mech = resolve_spec(study.target, params).mechanism
        path = trace(
            mech,
            until=_until_api(mech, study.until),
            steps=study.steps,
            branches=study.branches,
            max_steps=study.max_steps,
            progress=budget,
        )
        return _linkage_row(study, mech, path, row, budget)
    except Exception as exc:  # one point's failure is its row, never the study's end
        return {**dict(params), "error": point_error(exc)}, None


def _linkage_row(study: Study, mech: Any, path: Any, row: Row, budget: PointBudget) -> tuple[Row, Any]:
    """The row of a traced grid point (and its robustness study, when the study has one)."""
    row["mobility"] = int(path.mobility[0])
    row["points"] = int(path.angles.shape[0])
    stems = joint_columns(mech.joint_names, study.grid)
    for name, (low, high) in branch_range(path, None).items():  # every branch, folds and turning points
        row[f"{stems[name]}_min"] = low
        row[f"{stems[name]}_max"] = high
    row["bifurcations"] = len(path.bifurcations)
    row["ratio_max"] = float(path.max_condition_raw)  # the paper's Sec. 5 ratio, raw
    row["end"] = path.branches[0].end_reason if path.branches else ""
    result = None
    if study.robustness is not None:
        result = _robustness_columns(study, mech, path, row, budget)
    row["error"] = ""
    return row, result if study.robustness is not None and study.robustness.figures else None


def _robustness_columns(study: Study, mech: Any, path: Any, row: Row, budget: PointBudget) -> Any:
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
    res = robustness(mech, path, model, settings.samples, seed=settings.seed, workers=0, progress=budget)
    row["misfit_p50"] = float(np.median(res.misfit_max))
    row["misfit_p95"] = float(np.percentile(res.misfit_max, 95))
    row["first_order_p50"] = float(np.median(res.first_order_max))
    row["mobility_kept"] = float(np.mean(res.mobility_kept))
    row["length_scale"] = res.setup.scale.length
    return res


def synthesis_point(study: Study, index: int) -> tuple[Row, Any]:
    """Synthesise grid point ``index`` of a synthesis study (the public :func:`linkwork.synthesis.synthesize`)."""
    params = study.point(index)
    try:
        return _synthesis_row(study, params)
    except Exception as exc:  # one point's failure is its row, never the study's end
        return {**dict(params), "error": point_error(exc)}, None


def _synthesis_row(study: Study, params: dict[str, Any]) -> tuple[Row, Any]:
    """The row of one synthesis grid point."""
    from linkwork.synthesis import synthesize

    problem = study.extra["problem"]
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
    variant = replace(problem, **changes)
    if variant.design is not None:
        variant = replace(variant, segments=None)
    result = synthesize(variant, progress=PointBudget.of(study))
    row["design"] = result.design
    row["segment_count"] = len(result.segments)
    row["e_max"] = float(result.e_max)
    row["e_mean"] = float(result.e_mean)
    row["error"] = ""
    return row, None


def prepare_study(study: Study) -> Study:
    """Load what every task needs once (a synthesis problem), check the target exists, every grid value of a
    built-in against its parameter's range, and the work asked for against the limits; before any point runs."""
    source = str(study.source) if study.source is not None else "study"
    reader = TomlReader(source)
    if study.kind == "synthesis":
        from linkwork.io.problem import load_problem

        target = study.target
        if not target.endswith(".toml") and not Path(target).exists():
            from linkwork import data

            target = str(data.example(target))
        problem = load_problem(target)
        designs = [str(v).lower() for v in study.grid.get("design", [])]
        if "each" in designs:
            if designs != ["each"]:
                raise reader.error("grid.design", 'design "each" cannot be mixed with other designs')
            if problem.segments is None and "segments" not in study.grid:
                raise reader.error("grid.segments", 'design "each" needs the number of segments')
            study = replace(study, grid={**study.grid, "design": ["each"]})
        study = replace(study, extra={"problem": problem, "segments": problem.segments})
        check_work(reader, study)  # design "each" now knows the problem's number of segments
        return study
    if study.grid:  # a built-in: its name, its parameters' names, and every value within its range
        from linkwork.io.spec import import_builtins
        from linkwork.linkages.registry import get

        import_builtins()
        entry = get(study.target)
        for key, values in study.grid.items():
            if key not in entry.params:
                raise reader.error(
                    f"grid.{key}",
                    f"{entry.name} has no parameter {show(key)}; expected {', '.join(entry.params)}",
                )
            param = entry.params[key]
            low, high = param.bounds
            for i, value in enumerate(values):
                if param.unit == "text":
                    try:
                        entry.check_value(key, value)
                    except SpecError:
                        raise reader.error(
                            f"grid.{key}[{i}]", f"expected {param.help}, got {show(value)}"
                        ) from None
                    continue
                if isinstance(value, str):
                    raise reader.error(f"grid.{key}[{i}]", f"expected a finite number, got {show(value)}")
                whole = param.unit != "int" or float(value).is_integer()
                if not (whole and low <= value <= high):
                    kind = "a whole number" if param.unit == "int" else "a number"
                    unit = " deg" if param.unit == "deg" else ""
                    raise reader.error(
                        f"grid.{key}[{i}]",
                        f"expected {kind} from {low:g} to {high:g}{unit}, got {show(value)}",
                    )
    mech = _joints_of(study)
    if mech is not None and study.until is not None and not mech.has_joint(study.until[0]):
        raise reader.error(
            "trace.until",
            f"{mech.name} has no joint {show(study.until[0])}; expected one of {', '.join(mech.joint_names)}",
        )
    return study


def _joints_of(study: Study) -> Any:
    """The study's linkage at its first grid point (a spec file as it is), for the names of its joints; ``None``
    when that point does not assemble (its own trace then says why, as any point's)."""
    from linkwork.io.spec import resolve_spec

    if not study.grid:
        return resolve_spec(study.target).mechanism  # a spec file: it must load, every point is it
    first = {key: values[0] for key, values in study.grid.items() if values}
    try:
        return resolve_spec(study.target, first).mechanism
    except LinkworkError:
        return None


def read_study(path: str | Path) -> Study:
    """Read and check a study file completely (keys, values, target, limits), ready for :func:`run_sweep`;
    every mistake is a :class:`~linkwork.errors.SpecError` naming the file and key, raised before any work."""
    return prepare_study(load_study(path))


#: Grid points per task at most: enough that a grid of many quick points is not one Dask task each.
BATCH = 64


def point_batches(total: int, workers: int) -> list[tuple[int, int]]:
    """``(start, stop)`` of the batches of grid points: about eight per worker, of 1 to :data:`BATCH` points."""
    size = max(1, min(BATCH, total // (8 * max(1, workers))))
    return [(a, min(a + size, total)) for a in range(0, total, size)]


def run_batch(study: Study, start: int, stop: int) -> list[tuple[Row, Any]]:
    """Grid points ``start .. stop - 1`` (each its own row, failed or not)."""
    func = synthesis_point if study.kind == "synthesis" else linkage_point
    return [func(study, index) for index in range(start, stop)]


def run_sweep(
    study: Study,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    client: Any = None,
    progress: Progress | None = None,
    status: RunStatus | None = None,
) -> list[tuple[Row, Any]]:
    """Every grid point's row (and robustness result when figures are asked), in grid order.

    With ``status``, an interrupt or the loss of every Dask worker or of the scheduler ends the run early: the
    rows computed so far are returned and ``status`` says what happened (see :class:`RunStatus`); without it,
    that ends in a :class:`~linkwork.errors.LinkworkError`.
    """
    from linkwork.studies.engine import default_workers

    if not (study.kind == "synthesis" and "problem" in study.extra):
        study = prepare_study(study)
    total = study.count()
    n = workers if workers else default_workers()
    batches = point_batches(total, n if client is None else 4)
    ends = [stop for _, stop in batches]

    def report(done: int, of: int | None) -> None:
        if progress is not None and done > 0:
            progress(ends[min(done, len(ends)) - 1], total)

    def failed(batch: tuple[Any, ...], reason: str) -> list[tuple[Row, Any]]:
        return [({**study.point(i), "error": reason}, None) for i in range(batch[0], batch[1])]

    rows: list[tuple[Row, Any]] = []
    for batch in map_chunks(
        run_batch,
        study,
        batches,
        scheduler=scheduler,
        workers=workers,
        client=client,
        progress=report,
        status=status,
        failed=failed,
    ):
        rows.extend(batch)
    return rows
