"""Reading a study file (``linkwork sweep STUDY.toml``): what to vary, over which grid, and what to compute.

A linkage study names a built-in (``linkage = "bennett"``) or a spec file (``spec = "my.toml"``, relative to the
study file; it has no parameters, so its grid is empty), trace settings in ``[trace]`` (``until = "A=120"`` in
degrees, ``steps``, ``branches``, ``max_steps``), optionally ``[robustness]`` (``samples``,
``hinge_position_tol``, ``hinge_direction_tol`` in degrees, ``distribution``, ``seed``, ``spatial_errors``,
``figures``), and a ``[grid]`` of built-in parameters in file units: each a list of values or a range
``{ from = A, to = B, count = N }`` (both ends included). A synthesis study names a problem (``problem =
"problem.toml"`` or a bundled example such as ``"seat"``) and a ``[grid]`` over ``piece_length``, ``segments``,
``design`` (``"auto"`` searches every design in one task; ``"each"``, alone, gives one row per design vector,
each its own task), ``min_pieces``, ``starts`` and ``merge_below`` (degrees).
Every grid is the full product of its lists, in the order written (the last parameter varies fastest).
``time_per_point`` (seconds, default 600) bounds the time of one grid point: a point still running then ends
with that reason in its row, and the study goes on.

Every key is checked for type, finiteness and range when the file is read (:data:`KEY_LIMITS`,
:data:`SYNTHESIS_GRID_LIMITS`), and the work it asks for against the limits of :mod:`linkwork.limits` and
:data:`MAX_GRID_POINTS`, before any grid point runs.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from linkwork import limits
from linkwork.errors import SpecError
from linkwork.io.toml_reader import MAX_NAME_CHARS, TomlReader, read_toml, show
from linkwork.limits import Limit, plain_number
from linkwork.names import name_problem
from linkwork.synthesis.problem import MAX_AUTO_SEGMENTS, MAX_PIECES, MAX_STARTS

SYNTHESIS_KEYS = ("piece_length", "segments", "design", "min_pieces", "starts", "merge_below")
TOP_KEYS = (
    "name",
    "description",
    "linkage",
    "spec",
    "problem",
    "time_per_point",
    "trace",
    "grid",
    "robustness",
    "criteria",
)
TRACE_KEYS = ("until", "steps", "branches", "max_steps")
ROBUSTNESS_KEYS = (
    "samples",
    "hinge_position_tol",
    "hinge_direction_tol",
    "distribution",
    "seed",
    "spatial_errors",
    "figures",
)


@dataclass(frozen=True)
class RobustnessSettings:
    """The robustness study run at every grid point (tolerances in length units and degrees, as in the file)."""

    samples: int
    position_tol: float
    direction_tol_deg: float
    distribution: str = "normal"
    seed: int = 0
    spatial_errors: bool = False
    figures: bool = False


@dataclass(frozen=True)
class Study:
    """A parsed study file: its kind (``"linkage"`` or ``"synthesis"``), target, settings and grid."""

    kind: str
    name: str
    target: str
    grid: dict[str, list[Any]]
    until: tuple[str, float] | None = None
    steps: int | None = None
    branches: bool = False
    max_steps: int = 5000
    robustness: RobustnessSettings | None = None
    source: Path | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    time_per_point: float = 600.0
    _cache: dict[Any, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    @property
    def each_design(self) -> bool:
        """Whether the grid lists every design vector (``design = "each"``), one point each."""
        return self.kind == "synthesis" and self.grid.get("design") == ["each"]

    def _base(self) -> list[str]:
        """The grid's parameters that are not expanded into design vectors."""
        return [k for k in self.grid if not (self.each_design and k == "design")]

    def _designs_of(self, point: dict[str, Any]) -> int:
        """The design vectors of one base point with ``design = "each"`` (``2**segments``)."""
        return 2 ** int(point.get("segments", self.extra.get("segments") or 0))

    def count(self) -> int:
        """The number of grid points, computed without listing them."""
        base = self._base()
        total = 1
        for key in base:
            total *= len(self.grid[key])
        if not self.each_design:
            return total
        if "segments" in self.grid:
            others = total // len(self.grid["segments"])
            return others * sum(2 ** int(q) for q in self.grid["segments"])
        return total * self._designs_of({})

    def point(self, index: int) -> dict[str, Any]:
        """Grid point ``index`` as ``{parameter: value}``, found without listing the others (the last
        parameter varies fastest; with ``design = "each"`` the design vector varies fastest of all)."""
        base = self._base()
        if not self.each_design:
            return self._base_point(base, index)
        if not 0 <= index < self.count():
            raise IndexError(index)
        ends = self._design_ends(base)
        combo = int(np.searchsorted(ends, index, side="right"))
        point = self._base_point(base, combo)
        index -= int(ends[combo - 1]) if combo else 0
        q = int(point.get("segments", self.extra.get("segments") or 0))
        letters = "".join("C" if index >> (q - 1 - i) & 1 else "M" for i in range(q))
        return {**point, "design": letters}

    def _design_ends(self, base: list[str]) -> np.ndarray:
        """The cumulative number of design vectors after each base point (computed once per study)."""
        key = ("design_ends", id(self.grid), self.extra.get("segments"))
        if key not in self._cache:
            counts = [self._designs_of(self._base_point(base, i)) for i in range(self._base_count(base))]
            self._cache.clear()
            self._cache[key] = np.cumsum(np.asarray(counts, dtype=np.int64))
        return self._cache[key]

    def _base_count(self, base: list[str]) -> int:
        total = 1
        for key in base:
            total *= len(self.grid[key])
        return total

    def _base_point(self, base: list[str], index: int) -> dict[str, Any]:
        point: dict[str, Any] = {}
        for key in reversed(base):
            values = self.grid[key]
            index, at = divmod(index, len(values))
            point[key] = values[at]
        return {key: point[key] for key in base}

    def points(self) -> list[dict[str, Any]]:
        """Every grid point as ``{parameter: value}`` (one empty point for an empty grid).

        A synthesis grid with ``design = "each"`` has one point per design vector of each point's number of
        segments (the design search of ``design = "auto"``, one task per design)."""
        return [self.point(i) for i in range(self.count())]


MAX_GRID_POINTS = 100_000
"""The most grid points a study may have (the product of every parameter's number of values, with
``design = "each"`` every design vector of every number of segments)."""

TIME_PER_POINT = Limit("a number of seconds", 0.0, 7 * 24 * 3600.0, open_low=True)
"""The bounds of ``time_per_point``."""

KEY_LIMITS: dict[str, Limit] = {
    "trace.steps": limits.STEPS,
    "trace.max_steps": limits.STEPS,
    "robustness.samples": limits.SAMPLES,
    "robustness.hinge_position_tol": limits.POSITION_TOL,
    "robustness.hinge_direction_tol": limits.DIRECTION_TOL,
    "robustness.seed": limits.SEED,
    "time_per_point": TIME_PER_POINT,
}
"""The bounds of every numeric key of a study file, by key path."""

SYNTHESIS_GRID_LIMITS: dict[str, Limit] = {
    "piece_length": Limit("a positive length", 0.0, limits.MAX_MAGNITUDE, open_low=True),
    "segments": Limit(
        'a whole number of segments (searched by design "auto" or listed by "each")',
        1,
        MAX_AUTO_SEGMENTS,
        whole=True,
    ),
    "min_pieces": Limit("a whole number of pieces", 2, MAX_PIECES, whole=True),
    "starts": Limit("a whole number of starts", 1, MAX_STARTS, whole=True),
    "merge_below": Limit("an angle in degrees", 0.0, 180.0, open_high=True),
}
"""The bounds of every value of a synthesis grid's numeric parameters (``design`` is checked on its own)."""


def checked_number(reader: TomlReader, table: dict[str, Any], key: str, path: str, limit: Limit) -> Any:
    """``table[key]`` checked against ``limit`` (a :class:`SpecError` naming the key path and the bounds)."""
    full = f"{path}.{key}" if path else key
    value = table[key]
    if limit.broken(value):
        raise reader.error(full, f"expected {limit.expected(key)}, got {show(value)}")
    return value


def _grid_values(reader: TomlReader, value: Any, key: str) -> list[Any]:
    where = f"grid.{key}"
    if isinstance(value, list):
        if not value:
            raise reader.error(where, "expected a non-empty list of values")
        if len(value) > MAX_GRID_POINTS:
            raise reader.error(where, f"lists {len(value)} values; expected at most {MAX_GRID_POINTS}")
        return list(value)
    if isinstance(value, dict):
        reader.check_keys(value, where, ("from", "to", "count"))
        if not all(k in value for k in ("from", "to", "count")):
            raise reader.error(where, "expected { from = A, to = B, count = N } with numbers")
        lo = reader.scalar(value["from"], f"{where}.from")
        hi = reader.scalar(value["to"], f"{where}.to")
        count = value["count"]
        span = Limit("a whole number of values", 1, MAX_GRID_POINTS, whole=True)
        if span.broken(count):
            raise reader.error(f"{where}.count", f"expected {span.expected('count')}, got {show(count)}")
        return [float(x) for x in np.linspace(lo, hi, count)]
    return [value]


def _check_linkage_grid(reader: TomlReader, grid: dict[str, list[Any]]) -> None:
    """Every value of a built-in's parameter a finite number, or a one-line text for a text parameter (its range
    or pattern is the built-in's own, checked by :func:`linkwork.studies.sweep.prepare_study`)."""
    for key, values in grid.items():
        for i, value in enumerate(values):
            if isinstance(value, str) and 0 < len(value) <= MAX_NAME_CHARS and value.isprintable():
                continue
            if isinstance(value, bool) or not isinstance(value, int | float) or not np.isfinite(float(value)):
                raise reader.error(
                    f"grid.{key}[{i}]",
                    f"expected a finite number (or a text parameter's value), got {show(value)}",
                )


def _check_synthesis_grid(reader: TomlReader, grid: dict[str, list[Any]]) -> None:
    """Every value of a synthesis grid of the right type and within its bounds; ``design`` is ``"auto"``,
    ``"each"`` (alone) or a design vector of M and C letters."""
    reader.check_keys(grid, "grid", SYNTHESIS_KEYS)
    for key, values in grid.items():
        for i, value in enumerate(values):
            where = f"grid.{key}[{i}]"
            if key == "design":
                _check_design(reader, value, where, values)
                continue
            limit = SYNTHESIS_GRID_LIMITS[key]
            if limit.broken(value):
                raise reader.error(where, f"expected {limit.expected(key)}, got {show(value)}")


def _check_design(reader: TomlReader, value: Any, where: str, values: list[Any]) -> None:
    expected = 'a design vector of M and C letters such as "MCMC", "auto", or "each" alone'
    if not isinstance(value, str) or not value.strip():
        raise reader.error(where, f"expected {expected}, got {show(value)}")
    word = value.strip().lower()
    if word == "each" and len(values) > 1:
        raise reader.error(where, 'design "each" cannot be mixed with other designs')
    if word in ("auto", "each"):
        return
    if not set(value.strip().upper()) <= set("MC") or len(value.strip()) > MAX_PIECES:
        raise reader.error(where, f"expected {expected}, got {show(value)}")


def _parse_until(reader: TomlReader, text: Any) -> tuple[str, float]:
    name, sep, raw = str(text).partition("=")
    number = plain_number(raw)  # the rule of --until: 1_0 and other scripts' digits are not numbers
    value = float("nan") if number is None else number
    if not isinstance(text, str) or not sep or not name.strip() or not np.isfinite(value):
        raise reader.error("trace.until", f'expected "JOINT=VALUE" (degrees), got {show(text)}')
    return name.strip(), value


def _robustness(reader: TomlReader, raw: Any) -> RobustnessSettings:
    table = reader.table(raw, "robustness", ROBUSTNESS_KEYS)
    numbers = {}
    for key in ("samples", "hinge_position_tol", "hinge_direction_tol", "seed"):
        if key in table:
            numbers[key] = checked_number(reader, table, key, "robustness", KEY_LIMITS[f"robustness.{key}"])
        elif key != "seed":
            raise reader.error(
                f"robustness.{key}", f"missing; expected {KEY_LIMITS[f'robustness.{key}'].what}"
            )
    return RobustnessSettings(
        samples=int(numbers["samples"]),
        position_tol=float(numbers["hinge_position_tol"]),
        direction_tol_deg=float(numbers["hinge_direction_tol"]),
        distribution=reader.choice(
            table, "distribution", "robustness", ("normal", "uniform"), default="normal"
        ),
        seed=int(numbers.get("seed", 0)),
        spatial_errors=reader.boolean(table, "spatial_errors", "robustness", default=False),
        figures=reader.boolean(table, "figures", "robustness", default=False),
    )


def check_work(reader: TomlReader, study: Study) -> None:
    """Refuse a study whose work exceeds the stated limits (grid points, Monte Carlo samples)."""
    total = study.count()
    if total > MAX_GRID_POINTS:
        why = ' (design "each" lists 2**segments design vectors per point)' if study.each_design else ""
        raise reader.error("grid", f"has {total} grid points{why}; expected at most {MAX_GRID_POINTS}")
    if study.robustness is not None and total * study.robustness.samples > limits.MAX_STUDY_SAMPLES:
        raise reader.error(
            "robustness.samples",
            f"{study.robustness.samples} samples at each of {total} grid points is "
            f"{total * study.robustness.samples} samples; expected at most {limits.MAX_STUDY_SAMPLES:g}",
        )


def load_study(path: str | Path) -> Study:
    """Read a study file and check every key (type, finite, range) and the work it asks for, before any grid
    point runs; paths in it are relative to it. A mistake is a :class:`SpecError` naming the file and key."""
    path = Path(path)
    source = str(path)
    reader = TomlReader(source)
    table = read_toml(path, "a study file (TOML)")
    reader.check_keys(table, "", TOP_KEYS)
    given = [k for k in ("linkage", "spec", "problem") if k in table]
    if len(given) != 1:
        raise SpecError("give exactly one of linkage, spec or problem", source=reader.source)
    target = reader.string(table, given[0], "", default=None, limit=4096)
    name = reader.string(table, "name", "", default=path.stem, limit=MAX_NAME_CHARS)
    if name_problem(name, tab=True) is not None:
        raise reader.error("name", f"expected {name_problem(name, tab=True)}, got {show(name)}")
    if "description" in table and not isinstance(table["description"], str):
        raise reader.error("description", f"expected a string, got {show(table['description'])}")
    budget = (
        float(checked_number(reader, table, "time_per_point", "", TIME_PER_POINT))
        if ("time_per_point" in table)
        else 600.0
    )
    grid_table = table.get("grid", {})
    if not isinstance(grid_table, dict):
        raise reader.error("grid", f"expected a table of parameters, got {show(grid_table)}")
    grid = {key: _grid_values(reader, value, key) for key, value in grid_table.items()}
    if given[0] == "problem":
        if "trace" in table or "robustness" in table:
            extra = "trace" if "trace" in table else "robustness"
            raise reader.error(extra, "applies to a linkage study, not to a synthesis problem")
        _check_synthesis_grid(reader, grid)
        if target.endswith(".toml") or "/" in target:
            target = str((path.parent / target).resolve())
        study = Study(
            kind="synthesis", name=name, target=target, grid=grid, source=path, time_per_point=budget
        )
        check_work(reader, study)
        return study
    trace_table = reader.table(table.get("trace", {}), "trace", TRACE_KEYS)
    until = _parse_until(reader, trace_table["until"]) if "until" in trace_table else None
    steps = (
        checked_number(reader, trace_table, "steps", "trace", KEY_LIMITS["trace.steps"])
        if ("steps" in trace_table)
        else None
    )
    if steps is not None and until is None:
        raise reader.error(
            "trace.steps", "needs trace.until (the steps are equal steps of the drive up to it)"
        )
    max_steps = (
        checked_number(reader, trace_table, "max_steps", "trace", KEY_LIMITS["trace.max_steps"])
        if ("max_steps" in trace_table)
        else 5000
    )
    _check_linkage_grid(reader, grid)
    if given[0] == "spec":
        target = str((path.parent / target).resolve())
        if grid:
            raise reader.error("grid", "a spec file has no parameters to vary; use a built-in linkage")
    robustness = _robustness(reader, table["robustness"]) if "robustness" in table else None
    if robustness is not None and steps is not None and steps + 1 > limits.MAX_PATH_POINTS:
        raise reader.error(
            "trace.steps",
            f"expected at most {limits.MAX_PATH_POINTS - 1} with [robustness] (the nominal path's points each keep "
            f"per-point histograms in memory), got {steps}",
        )
    study = Study(
        kind="linkage",
        name=name,
        target=target,
        grid=grid,
        until=until,
        steps=steps,
        branches=reader.boolean(trace_table, "branches", "trace", default=False),
        max_steps=int(max_steps),
        robustness=robustness,
        source=path,
        time_per_point=budget,
        extra={"criteria": table["criteria"]} if "criteria" in table else {},  # linkwork search's table
    )
    check_work(reader, study)
    return study
