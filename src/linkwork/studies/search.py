"""The search for deployable structures (G&P Sec. 6-7): screen every member of a linkage family against criteria.

A search study is a sweep study (``linkage``, ``[trace]``, ``[grid]``; :mod:`linkwork.studies.study_file`) with a
``[criteria]`` table. Every grid point (a *candidate*) is assembled, its start rank taken, its motion traced and its
deployment measures computed (:mod:`linkwork.kinematics.deployment`); it then passes or fails the criteria, in the
order written in :data:`CRITERIA`, and the first one it fails is its ``reason``. Candidates are sent to the Dask
engine in batches (one task traces many), so a task's overhead is shared.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Iterator
from dataclasses import asdict, dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from linkwork.errors import LinkworkError, RigidStartError, SpecError
from linkwork.io.toml_reader import TomlReader
from linkwork.limits import plain_number
from linkwork.progress import Progress
from linkwork.studies.engine import RunStatus, default_workers, map_chunks
from linkwork.studies.study_file import Study

if TYPE_CHECKING:
    from linkwork.kinematics.deployment import Deployment
    from linkwork.kinematics.trace_result import Trace

Row = dict[str, Any]

CRITERIA = (
    "mobility",
    "max_bifurcations",
    "min_bifurcations",
    "max_membrane_stretch",
    "max_flatness",
    "max_bundle_ratio",
)
"""The criteria, in the order they are checked (a candidate's ``reason`` is the first it fails)."""

MEASURES = ("membrane_stretch", "bundle_ratio", "flatness", "bifurcations")
"""What ``rank_by`` may name: passing candidates are ranked by these, smallest first."""

CRITERIA_KEYS = (*CRITERIA, "deployed_at", "rank_by")

MEASURE_COLUMNS = (
    "rank_start",
    "mobility_start",
    "rank_min",
    "mobility_max",
    "bifurcations",
    "bifurcations_on_path",
    "membrane_stretch",
    "stretch_pair",
    "bundle_ratio",
    "flatness",
    "points",
    "end",
)
"""The columns of a candidate after its parameters (then ``passes``, ``reason``, ``shortfall``, ``error``)."""

STALLED = ("corrector failed", "no progress", "could not")
"""Ends of branch 0 that mean the tracer could not follow the motion (a start mobile to first order only)."""

MAX_BATCH = 25
"""The most candidates one Dask task traces."""


@dataclass(frozen=True)
class Criteria:
    """What a candidate must meet (``None``: not asked), where it is deployed, and how passing ones are ranked.

    ``mobility``: the mobility at the start and everywhere along the path, its located singular points included
    (a path the tracer cannot follow from the start fails it too); ``max_*``: upper limits of
    :class:`~linkwork.kinematics.deployment.Deployment`'s measures (``max_bifurcations`` counts the bifurcation
    points on the path); ``min_bifurcations``: at least that many (to find the structures that can deploy into
    the wrong shape, as the paper's search did). ``deployed_at``: ``(joint, value in degrees)`` or ``None`` (the
    last point of branch 0).
    """

    mobility: int | None = None
    max_bifurcations: int | None = None
    min_bifurcations: int | None = None
    max_membrane_stretch: float | None = None
    max_flatness: float | None = None
    max_bundle_ratio: float | None = None
    deployed_at: tuple[str, float] | None = None
    rank_by: tuple[str, ...] = ("membrane_stretch", "bundle_ratio", "flatness")


@dataclass(frozen=True)
class SearchStudy:
    """A parsed search study: the sweep study and its criteria."""

    study: Study
    criteria: Criteria = field(default_factory=Criteria)

    @property
    def total(self) -> int:
        """The number of candidates."""
        return len(self.study.points())

    def fingerprint(self) -> str:
        """A hash of everything that decides a candidate's row (not the study's name or file): a search's
        records are reused only for the same study."""
        from linkwork import __version__

        s = self.study
        settings = {
            "target": s.target,
            "grid": s.grid,
            "until": s.until,
            "steps": s.steps,
            "branches": s.branches,
            "max_steps": s.max_steps,
            "criteria": asdict(self.criteria),
            "version": __version__,
        }
        return hashlib.sha256(json.dumps(settings, sort_keys=True, default=str).encode()).hexdigest()[:16]


def parse_criteria(table: Any, source: str) -> Criteria:
    """The ``[criteria]`` table, checked (unknown keys, types and ranges name the key)."""
    reader = TomlReader(source)
    table = reader.table(table, "criteria", CRITERIA_KEYS)
    mobility = reader.integer(table, "mobility", "criteria", default=None, minimum=0, maximum=1000)
    max_bif = reader.integer(table, "max_bifurcations", "criteria", default=None, minimum=0)
    min_bif = reader.integer(table, "min_bifurcations", "criteria", default=None, minimum=0)
    limits: dict[str, float | None] = {}
    for key in ("max_membrane_stretch", "max_flatness", "max_bundle_ratio"):
        value = reader.number(table, key, "criteria", default=math.nan)
        if key in table and value < 0:
            raise reader.error(f"criteria.{key}", f"expected a number >= 0, got {value:g}")
        limits[key] = None if key not in table else value
    deployed_at = None
    if "deployed_at" in table:
        text = table["deployed_at"]
        name, sep, raw = str(text).partition("=")
        number = plain_number(raw)  # the rule of --deployed-at: 1_0 and other scripts' digits are not numbers
        value = math.nan if number is None else number
        if not isinstance(text, str) or not sep or not name.strip() or not math.isfinite(value):
            raise reader.error("criteria.deployed_at", f'expected "JOINT=VALUE" (degrees), got {text!r}')
        deployed_at = (name.strip(), value)
    rank_by = tuple(
        reader.string_list(table, "rank_by", "criteria", expected="names of measures", default=None)
        if "rank_by" in table
        else Criteria.rank_by
    )
    for i, name in enumerate(rank_by):
        if name not in MEASURES:
            raise reader.error(
                f"criteria.rank_by[{i}]", f"expected one of {', '.join(MEASURES)}, got {name!r}"
            )
    return Criteria(
        mobility=mobility,
        max_bifurcations=max_bif,
        min_bifurcations=min_bif,
        max_membrane_stretch=limits["max_membrane_stretch"],
        max_flatness=limits["max_flatness"],
        max_bundle_ratio=limits["max_bundle_ratio"],
        deployed_at=deployed_at,
        rank_by=rank_by,
    )


def load_search(path: Any) -> SearchStudy:
    """Read a search study: the sweep study file (:func:`~linkwork.studies.study_file.load_study`) with its
    ``[criteria]``; its linkage and parameter names are checked (:func:`~linkwork.studies.sweep.prepare_study`)."""
    from linkwork.studies.study_file import load_study
    from linkwork.studies.sweep import prepare_study

    study = load_study(path)
    source = str(path)
    if study.kind != "linkage":
        raise SpecError("a search screens a linkage family; expected linkage = NAME", source=source)
    if study.robustness is not None:
        raise SpecError("not used by a search; run it with linkwork sweep", source=source, key="robustness")
    if "criteria" not in study.extra:
        raise SpecError(
            "missing; expected a [criteria] table (e.g. mobility = 1)", source=source, key="criteria"
        )
    criteria = parse_criteria(study.extra["criteria"], source)
    search = SearchStudy(prepare_study(replace(study, extra={})), criteria)
    if criteria.deployed_at is not None:  # its joint must exist (checked on the first candidate)
        from linkwork.io.spec import resolve_spec

        try:
            first = resolve_spec(search.study.target, search.study.points()[0]).mechanism
        except LinkworkError:
            return search  # that candidate's own row will say why it cannot be built
        if not first.has_joint(criteria.deployed_at[0]):
            raise SpecError(
                f"no joint {criteria.deployed_at[0]!r}; joints are {', '.join(first.joint_names)}",
                source=source,
                key="criteria.deployed_at",
            )
    return search


# ------------------------------------------------------------------------------------------------ one candidate
@dataclass(frozen=True)
class Candidate:
    """One judged candidate: its row, and its trace and deployment measures (``None`` when its trace failed)."""

    row: Row
    trace: Trace | None
    deployment: Deployment | None


def evaluate(search: SearchStudy, params: dict[str, Any]) -> Candidate:
    """Trace one candidate and judge it: its row (parameters, measures, ``passes``, ``reason``, ``shortfall``,
    ``error``), trace and deployment measures."""
    from linkwork.io.spec import resolve_spec
    from linkwork.kinematics.closure import jacobian
    from linkwork.kinematics.rank import numerical_rank
    from linkwork.kinematics.tracer import trace

    study = search.study
    row: Row = dict(params)
    row.update(dict.fromkeys(MEASURE_COLUMNS))
    traced = dep = None
    error = ""
    rigid_order = 0
    try:
        mech = resolve_spec(study.target, params).mechanism
        sigma = np.linalg.svd(
            jacobian(mech, np.zeros(mech.n_joints)) @ mech.coupling_matrix(), compute_uv=False
        )
        row["rank_start"] = numerical_rank(sigma)
        row["mobility_start"] = mech.n_unknowns - row["rank_start"]
        until = _in_api_units(mech, study.until)
        traced = trace(
            mech, until=until, steps=study.steps, branches=study.branches, max_steps=study.max_steps
        )
        dep = traced.deployment(_in_api_units(mech, search.criteria.deployed_at))
        row.update(
            rank_min=mech.n_unknowns - dep.mobility_on_path,
            mobility_max=dep.mobility_on_path,
            bifurcations=len(traced.bifurcations),
            bifurcations_on_path=dep.bifurcations_on_path,
            membrane_stretch=dep.membrane_stretch,
            stretch_pair="-".join(dep.stretch_pair),
            bundle_ratio=dep.bundle_ratio,
            flatness=dep.flatness,
            points=len(traced.angles),
            end=traced.branches[0].end_reason if traced.branches else "",
        )
    except RigidStartError as exc:
        error, rigid_order = str(exc), exc.order
    except LinkworkError as exc:
        error = str(exc)
    except (np.linalg.LinAlgError, FloatingPointError) as exc:  # a numerical failure ends this candidate only
        error = f"{type(exc).__name__}: {exc}"
    passes, reason, shortfall = judge(search.criteria, row, error, rigid_order)
    row.update(passes=passes, reason=reason, shortfall=shortfall, error=error)
    return Candidate(row, traced, dep)


def _in_api_units(mech: Any, target: tuple[str, float] | None) -> tuple[str, float] | None:
    """``(joint, value)`` in file units (degrees) to the API's (radians for a revolute joint)."""
    if target is None:
        return None
    j = mech.index(target[0])
    return target[0], float(np.radians(target[1]) if mech.joint_types[j] == "R" else target[1])


def judge(criteria: Criteria, row: Row, error: str = "", rigid_order: int = 0) -> tuple[bool, str, float]:
    """``(passes, reason, shortfall)`` of a candidate's row.

    ``reason`` is the first criterion failed (in :data:`CRITERIA` order), with the value and the limit, or the
    error that stopped its trace (``rigid_order`` 2: its start was refused as rigid to second order, mobile to
    first order only, :class:`~linkwork.errors.RigidStartError`); ``shortfall`` is how far it is from passing: the sum over the failed criteria
    of the excess, relative to the limit for a measure (``(value - limit) / limit``, or ``value - limit`` for a
    limit of 0), in whole units for the mobility (``|mobility at start - wanted| + excess along the path``) and
    the bifurcations; ``inf`` when the trace failed before the measure could be taken.
    """
    failed: list[tuple[str, float]] = []
    m0, m_max = row.get("mobility_start"), row.get("mobility_max")
    if criteria.mobility is not None and m0 is not None:
        want = criteria.mobility
        if m0 != want:
            failed.append((f"mobility: {m0} at the start (wanted {want})", abs(m0 - want) + 0.0))
        elif m_max is not None and m_max > want:
            failed.append((f"mobility: rises to {m_max} on the path (wanted {want})", float(m_max - want)))
    end = str(row.get("end") or "")
    if criteria.mobility is not None and not failed and rigid_order == 2:
        failed.append(("mobility: rigid to second order (mobile to first order only)", 1.0))
    if criteria.mobility is not None and not failed and end.startswith(STALLED):
        # A rank-deficient start the tracer cannot follow: mobile to first order only, or stuck at once.
        failed.append((f"mobility: the path stops after {row['points']} points ({end.split(' (')[0]})", 1.0))
    if error:
        return False, (failed[0][0] if failed else f"error: {error}"), math.inf
    if criteria.max_bifurcations is not None and row["bifurcations_on_path"] > criteria.max_bifurcations:
        excess = float(row["bifurcations_on_path"] - criteria.max_bifurcations)
        failed.append((f"bifurcations: {row['bifurcations_on_path']} > {criteria.max_bifurcations}", excess))
    if criteria.min_bifurcations is not None and row["bifurcations_on_path"] < criteria.min_bifurcations:
        lack = float(criteria.min_bifurcations - row["bifurcations_on_path"])
        failed.append((f"bifurcations: {row['bifurcations_on_path']} < {criteria.min_bifurcations}", lack))
    for key in ("membrane_stretch", "flatness", "bundle_ratio"):
        limit = getattr(criteria, f"max_{key}")
        value = row[key]
        if limit is None:
            continue
        if not (value <= limit):  # NaN fails
            excess = (value - limit) / limit if limit > 0 else value - limit
            failed.append(
                (f"{key}: {value:.4g} > {limit:g}", float(excess) if math.isfinite(excess) else math.inf)
            )
    if not failed:
        return True, "", 0.0
    return False, failed[0][0], float(sum(e for _, e in failed))


# ------------------------------------------------------------------------------------------------ many of them
def candidate_batch(search: SearchStudy, indices: tuple[int, ...]) -> list[Row]:
    """The rows of the candidates ``indices`` (one Dask task): each row carries its grid ``index``."""
    points = search.study.points()
    rows = []
    for index in indices:
        rows.append({"index": index, **evaluate(search, points[index]).row})
    return rows


def batches(indices: list[int], workers: int) -> list[tuple[int, ...]]:
    """``indices`` in consecutive batches: about eight per worker, at most :data:`MAX_BATCH` each, so a task's
    overhead is shared and the last tasks still spread over the workers."""
    if not indices:
        return []
    size = max(1, min(MAX_BATCH, math.ceil(len(indices) / (8 * max(1, workers)))))
    return [tuple(indices[i : i + size]) for i in range(0, len(indices), size)]


def run_search(
    search: SearchStudy,
    *,
    skip: set[int] | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    client: Any = None,
    progress: Progress | None = None,
    status: RunStatus | None = None,
) -> Iterator[list[Row]]:
    """Yield the rows of every candidate not in ``skip``, batch by batch in grid order (the Dask engine,
    :func:`~linkwork.studies.engine.map_chunks`). With ``status``, SIGINT and SIGTERM (held while the run lasts)
    or a lost cluster end the run after the batches finished so far, each one whole; ``status`` says why."""
    todo = [i for i in range(search.total) if i not in (skip or set())]
    in_process = workers == 0 and client is None and scheduler is None
    # In this process a batch of one costs nothing and records every candidate as soon as it is done.
    sizes = [(i,) for i in todo] if in_process else batches(todo, workers or default_workers())
    chunks = [(batch,) for batch in sizes]
    already = search.total - len(todo)
    size = len(chunks[0][0]) if chunks else 1

    def counted(finished: int, total: int | None, /) -> None:  # chunks done -> candidates done
        if progress is not None:
            progress(already + min(finished * size, len(todo)), search.total)

    yield from map_chunks(
        candidate_batch,
        search,
        chunks,
        scheduler=scheduler,
        workers=workers,
        client=client,
        progress=counted,
        status=status,
    )


def ranked(search: SearchStudy, rows: list[Row]) -> list[Row]:
    """The passing rows, best first: by ``rank_by`` (smallest first, NaN last), then grid order."""

    def key(row: Row) -> tuple[Any, ...]:
        values = []
        for name in search.criteria.rank_by:
            value = row.get(name)
            values.append(math.inf if value is None or not math.isfinite(float(value)) else float(value))
        return (*values, row["index"])

    return sorted((r for r in rows if r["passes"]), key=key)


def closest(rows: list[Row]) -> Row | None:
    """The row nearest to passing: smallest ``shortfall`` (see :func:`judge`), then grid order; ``None`` for
    no rows."""
    if not rows:
        return None
    return min(rows, key=lambda r: (float(r["shortfall"]), r["index"]))
