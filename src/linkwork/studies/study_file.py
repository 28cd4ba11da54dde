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
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from linkwork.errors import SpecError
from linkwork.io.toml_reader import TomlReader, read_toml, show

SYNTHESIS_KEYS = ("piece_length", "segments", "design", "min_pieces", "starts", "merge_below")
TOP_KEYS = ("name", "description", "linkage", "spec", "problem", "trace", "grid", "robustness", "criteria")
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

    def points(self) -> list[dict[str, Any]]:
        """Every grid point as ``{parameter: value}`` (one empty point for an empty grid).

        A synthesis grid with ``design = "each"`` has one point per design vector of each point's number of
        segments (the design search of ``design = "auto"``, one task per design)."""
        keys = list(self.grid)
        if self.kind != "synthesis" or self.grid.get("design") != ["each"]:
            return [dict(zip(keys, combo, strict=True)) for combo in itertools.product(*self.grid.values())]
        base = [k for k in keys if k != "design"]
        out = []
        for combo in itertools.product(*(self.grid[k] for k in base)):
            point = dict(zip(base, combo, strict=True))
            q = int(point.get("segments", self.extra.get("segments") or 0))
            for letters in itertools.product("MC", repeat=q):
                out.append({**point, "design": "".join(letters)})
        return out


MAX_GRID_POINTS = 100_000
"""The most grid points a study may have (the product of every parameter's number of values)."""


def _check_keys(table: dict[str, Any], allowed: tuple[str, ...], where: str, source: str) -> None:
    """Refuse an unknown key, with a did-you-mean hint (the one TOML reader's rule)."""
    TomlReader(source).check_keys(table, where.rstrip("."), allowed)


def _grid_values(value: Any, key: str, source: str) -> list[Any]:
    if isinstance(value, list):
        if not value:
            raise SpecError("expected a non-empty list of values", source=source, key=f"grid.{key}")
        return list(value)
    if isinstance(value, dict):
        _check_keys(value, ("from", "to", "count"), f"grid.{key}.", source)
        try:
            lo, hi, count = float(value["from"]), float(value["to"]), value["count"]
        except (KeyError, TypeError, ValueError):
            raise SpecError(
                "expected { from = A, to = B, count = N } with numbers", source=source, key=f"grid.{key}"
            ) from None
        if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= MAX_GRID_POINTS:
            raise SpecError(
                f"count must be a whole number from 1 to {MAX_GRID_POINTS}, got {show(count)}",
                source=source,
                key=f"grid.{key}",
            )
        if not (np.isfinite(lo) and np.isfinite(hi)):
            raise SpecError(
                f"expected finite from and to, got {lo} and {hi}", source=source, key=f"grid.{key}"
            )
        return [float(x) for x in np.linspace(lo, hi, count)]
    return [value]


def _parse_until(text: Any, source: str) -> tuple[str, float]:
    name, sep, raw = str(text).partition("=")
    try:
        value = float(raw)
    except ValueError:
        value = float("nan")
    if not isinstance(text, str) or not sep or not name.strip() or not np.isfinite(value):
        raise SpecError(f'expected "JOINT=VALUE" (degrees), got {text!r}', source=source, key="trace.until")
    return name.strip(), value


def _robustness(table: Any, source: str) -> RobustnessSettings:
    if not isinstance(table, dict):
        raise SpecError("expected a table", source=source, key="robustness")
    _check_keys(table, ROBUSTNESS_KEYS, "robustness.", source)
    try:
        return RobustnessSettings(
            samples=int(table["samples"]),
            position_tol=float(table["hinge_position_tol"]),
            direction_tol_deg=float(table["hinge_direction_tol"]),
            distribution=str(table.get("distribution", "normal")),
            seed=int(table.get("seed", 0)),
            spatial_errors=bool(table.get("spatial_errors", False)),
            figures=bool(table.get("figures", False)),
        )
    except KeyError as exc:
        raise SpecError("missing key", source=source, key=f"robustness.{exc.args[0]}") from None
    except (TypeError, ValueError) as exc:
        raise SpecError(f"expected numbers: {exc}", source=source, key="robustness") from None


def load_study(path: str | Path) -> Study:
    """Read and check a study file; paths in it are relative to it."""
    path = Path(path)
    source = str(path)
    table = read_toml(path, "a study file (TOML)")
    _check_keys(table, TOP_KEYS, "", source)
    given = [k for k in ("linkage", "spec", "problem") if k in table]
    if len(given) != 1:
        raise SpecError("give exactly one of linkage, spec or problem", source=source)
    grid_table = table.get("grid", {})
    if not isinstance(grid_table, dict):
        raise SpecError("expected a table of parameters", source=source, key="grid")
    grid = {key: _grid_values(value, key, source) for key, value in grid_table.items()}
    total = int(np.prod([len(values) for values in grid.values()], dtype=float)) if grid else 1
    if total > MAX_GRID_POINTS:
        raise SpecError(
            f"has {total} grid points; expected at most {MAX_GRID_POINTS}", source=source, key="grid"
        )
    name = str(table.get("name", path.stem))
    if given[0] == "problem":
        _check_keys(grid, SYNTHESIS_KEYS, "grid.", source)
        target = str(table["problem"])
        if target.endswith(".toml") or "/" in target:
            target = str((path.parent / target).resolve())
        return Study(kind="synthesis", name=name, target=target, grid=grid, source=path)
    trace_table = table.get("trace", {})
    if not isinstance(trace_table, dict):
        raise SpecError("expected a table", source=source, key="trace")
    _check_keys(trace_table, TRACE_KEYS, "trace.", source)
    until = _parse_until(trace_table["until"], source) if "until" in trace_table else None
    steps = trace_table.get("steps")
    if steps is not None and (
        isinstance(steps, bool) or not isinstance(steps, int) or steps < 1 or until is None
    ):
        raise SpecError("expected a whole number >= 1, with trace.until", source=source, key="trace.steps")
    target = str(table.get("linkage") or table.get("spec"))
    if "spec" in table:
        target = str((path.parent / target).resolve())
        if grid:
            raise SpecError(
                "a spec file has no parameters to vary; use a built-in linkage", source=source, key="grid"
            )
    robustness = _robustness(table["robustness"], source) if "robustness" in table else None
    return Study(
        kind="linkage",
        name=name,
        target=target,
        grid=grid,
        until=until,
        steps=steps,
        branches=bool(trace_table.get("branches", False)),
        max_steps=int(trace_table.get("max_steps", 5000)),
        robustness=robustness,
        source=path,
        extra={"criteria": table["criteria"]} if "criteria" in table else {},  # linkwork search's table
    )
