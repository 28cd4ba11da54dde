"""The files of a search (``linkwork search``): the per-candidate records that make it resumable, and the tables,
gallery and viewers written at the end through the staging layer (:func:`linkwork.outputs.staging.staged_output`).

Records: ``OUT/.linkwork-search/records.jsonl``, a header line with the study's fingerprint, then one JSON line
per finished candidate, appended and flushed batch by batch as they come back. Re-running the same study on the
same ``OUT`` reads them and traces only the rest; a changed study starts afresh.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import tempfile
from dataclasses import asdict
from pathlib import Path
from types import TracebackType
from typing import Any

from linkwork.errors import SpecError
from linkwork.io.toml_reader import show
from linkwork.messages import show_path
from linkwork.names import csv_cell
from linkwork.outputs.staging import console, have_matplotlib, staged_output
from linkwork.studies.search import MEASURE_COLUMNS, SearchStudy, evaluate, ranked

RECORDS = Path(".linkwork-search") / "records.jsonl"
"""Where a search keeps its per-candidate records, inside its output folder."""

OUTPUT_NAMES = (
    "candidates.csv",
    "candidates.parquet",
    "ranked.csv",
    "gallery.html",
    "viewers",
    "search.json",
    "candidates.png",
)
"""What a search writes into its output folder at the end (the figure when matplotlib is installed)."""

RECORD_FORMAT = "linkwork-search-records/1"

TEXT_MEASURES = ("stretch_pair", "end")
"""The measure columns of a record that hold text (the others hold a number, or nothing)."""

VIEWER_POINTS = 150
"""Points per branch in a gallery candidate's viewer page (thinned evenly, ends and bifurcations kept): pages stay
small and quick to write; ``linkwork trace --html`` of the candidate gives every point."""


class SearchRecords:
    """The resumable record of a search in ``out``: :attr:`rows` already finished (by grid index), and
    :meth:`add` to append more (flushed and synced, so an interruption keeps every batch that came back)."""

    def __init__(self, out: Path, search: SearchStudy) -> None:
        self.file = Path(out) / RECORDS
        self.fingerprint = search.fingerprint()
        self.columns = columns(search)
        self.points = search.study.points()
        self.rows: dict[int, dict[str, Any]] = {}
        self.restarted = False
        self._fh: Any = None

    def __enter__(self) -> SearchRecords:
        self._check_place()
        if self.file.exists():
            self._read()
        if not self.rows:
            self.file.parent.mkdir(parents=True, exist_ok=True)
            header = {"format": RECORD_FORMAT, "study": self.fingerprint}
            # a new file of its own, renamed into place: a link planted under any name is never written through
            fd, part = tempfile.mkstemp(prefix=".records-", dir=self.file.parent)
            try:
                with os.fdopen(fd, "w", encoding="utf-8") as fh:
                    fh.write(json.dumps(header) + "\n")
                os.replace(part, self.file)
            finally:
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(part)
        self._fh = self.file.open("a", encoding="utf-8")
        return self

    def _check_place(self) -> None:
        """Refuse records that are not linkwork's to write: ``.linkwork-search`` or its ``records.jsonl`` a
        symbolic link (the records would be written through it, into a user's folder or file) or not what they
        should be (a user's file named ``.linkwork-search``)."""
        out = self.file.parent.parent
        for entry, kind in ((self.file.parent, "folder"), (self.file, "file")):
            if entry.is_symlink():
                raise SpecError(
                    f"--out {show_path(out)}: {show(str(entry.relative_to(out)))} is a symbolic link; linkwork "
                    "never writes through links, move it away or choose another --out"
                )
            if entry.exists() and not (entry.is_dir() if kind == "folder" else entry.is_file()):
                raise SpecError(
                    f"--out {show_path(out)}: {show(str(entry.relative_to(out)))} exists and is not the {kind} "
                    "linkwork search keeps its records in; move it away or choose another --out"
                )

    def _read(self) -> None:
        lines = self.file.read_text(encoding="utf-8").splitlines()
        try:
            header = json.loads(lines[0]) if lines else {}
        except ValueError:
            header = {}
        if not isinstance(header, dict) or header.get("format") != RECORD_FORMAT:
            raise SpecError(
                f"--out {show(str(self.file.parent.parent))}: {show(str(RECORDS))} exists and was not written by "
                "linkwork search; move it away or choose another --out"
            )
        if header.get("study") != self.fingerprint:
            self.restarted = True
            return
        for line in lines[1:]:
            try:
                row = json.loads(line)
            except ValueError:  # a line cut short by an interruption: that candidate is traced again
                continue
            if self._sound(row):  # else damaged (by hand, by a disk): that candidate is traced again
                self.rows[row["index"]] = row

    def _sound(self, row: Any) -> bool:
        """Whether ``row`` is a record as :func:`~linkwork.studies.search.evaluate` writes it, of the candidate
        its ``index`` names: every column, the index within the grid, the grid point's own parameters, and a
        number (or nothing) in every measure column but the two of text."""
        if not isinstance(row, dict) or not set(self.columns) <= set(row):
            return False
        index = row["index"]
        if type(index) is not int or not 0 <= index < len(self.points):
            return False
        if any(row[k] != v for k, v in self.points[index].items()):
            return False
        if (
            type(row["passes"]) is not bool
            or not isinstance(row["reason"], str)
            or not isinstance(row["error"], str)
        ):
            return False
        numbers = [k for k in (*MEASURE_COLUMNS, "shortfall") if k not in TEXT_MEASURES]
        if any(row[k] is not None and (type(row[k]) not in (int, float)) for k in numbers):
            return False
        return all(row[k] is None or isinstance(row[k], str) for k in TEXT_MEASURES)

    def add(self, rows: list[dict[str, Any]]) -> None:
        """Append finished candidates' rows."""
        for row in rows:
            self.rows[row["index"]] = row
            self._fh.write(json.dumps(row) + "\n")
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def __exit__(
        self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        if self._fh is not None:
            self._fh.close()


def columns(search: SearchStudy) -> list[str]:
    """``index``, the grid parameters, the measures, then ``passes``, ``reason``, ``shortfall``, ``error``."""
    return ["index", *search.study.grid, *MEASURE_COLUMNS, "passes", "reason", "shortfall", "error"]


def write_search_outputs(
    search: SearchStudy,
    rows: list[dict[str, Any]],
    out: Path,
    gallery: int = 12,
    *,
    stopped: str | None = None,
) -> dict[str, Any]:
    """Write candidates.csv / .parquet (every candidate in grid order), ranked.csv (the passing ones, best first,
    with ``rank``), search.json (the summary), and gallery.html with one viewer page per drawn candidate in
    ``viewers/`` (the best ``gallery``, or the closest when none passes), all or nothing. Returns the summary.

    A search ``stopped`` early (``"interrupted (SIGTERM)"``) writes the same files of the candidates evaluated so
    far, search.json saying ``"complete": false`` and why it ``"stopped"``, without the gallery and its viewers
    (they trace candidates again: a stop should not start more work)."""
    from linkwork.outputs.sweep import write_table
    from linkwork.studies.search import closest

    rows = sorted(rows, key=lambda r: r["index"])
    best = ranked(search, rows)
    for rank, row in enumerate(best, start=1):
        row["rank"] = rank
    cols = columns(search)
    near = closest(rows)
    summary = {
        "name": search.study.name,
        "linkage": search.study.target,
        "complete": stopped is None,
        "stopped": stopped,
        "candidates_asked": search.total,
        "candidates": len(rows),
        "passing": len(best),
        "failed_to_trace": sum(1 for r in rows if r["error"]),
        "criteria": asdict(search.criteria),
        "best": {k: best[0].get(k) for k in ["index", *search.study.grid, "membrane_stretch"]}
        if best
        else None,
        "closest": None
        if best or near is None
        else {k: near.get(k) for k in ["index", *search.study.grid, "reason", "shortfall"]},
    }
    with staged_output(out) as stage:
        write_table(rows, cols, stage / "candidates.parquet", stage / "candidates.csv")
        _write_ranked(best, ["rank", *cols], stage / "ranked.csv")
        if have_matplotlib():
            from linkwork.viz.search_plots import plot_candidates

            limits = search.criteria
            plot_candidates(
                search.study.name,
                rows,
                stage / "candidates.png",
                limits.max_membrane_stretch,
                limits.max_bundle_ratio,
            )
        (stage / "search.json").write_text(
            json.dumps(_finite(summary), indent=2, allow_nan=False) + "\n", encoding="utf-8"
        )
        if stopped is None:
            drawn = (
                best[:gallery] if best else sorted(rows, key=lambda r: (r["shortfall"], r["index"]))[:gallery]
            )
            _write_gallery(search, drawn, stage, none_pass=not best)
    return summary


def _finite(value: Any) -> Any:
    """``value`` for strict JSON: infinite and NaN numbers become ``null``, tuples lists."""
    if isinstance(value, dict):
        return {str(k): _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _write_ranked(rows: list[dict[str, Any]], cols: list[str], file: Path) -> None:
    import csv

    with file.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(cols)
        for row in rows:
            writer.writerow(["" if row.get(c) is None else csv_cell(row.get(c)) for c in cols])


def _write_gallery(search: SearchStudy, rows: list[dict[str, Any]], stage: Path, none_pass: bool) -> None:
    """gallery.html and ``viewers/candidate-NNNNN.html`` for ``rows`` (traced again here to draw them)."""
    from linkwork.viz.gallery import deployment_svg, gallery_page
    from linkwork.viz.viewer import write_trace_viewer

    points = search.study.points()
    cards = []
    (stage / "viewers").mkdir()
    for row in rows:
        again = evaluate(search, points[row["index"]])
        svg = link = ""
        if again.trace is not None and again.deployment is not None:
            svg = deployment_svg(again.trace, again.deployment)
            name = f"candidate-{row['index']:05d}.html"
            title = f"{search.study.name}: candidate {row['index']}"
            write_trace_viewer(again.trace, stage / "viewers" / name, title=title, max_points=VIEWER_POINTS)
            link = f"viewers/{name}"
        cards.append(({**again.row, "index": row["index"], "rank": row.get("rank")}, svg, link))
    what = "the closest candidates (none passes)" if none_pass else f"the best {len(rows)} passing candidates"
    summary = f"{search.study.target}: {search.total} candidates; {what}, ranked by {', '.join(search.criteria.rank_by)}."
    page = gallery_page(
        f"{search.study.name}: search gallery",
        summary,
        cards,
        list(search.study.grid),
        [
            "mobility_start",
            "mobility_max",
            "bifurcations_on_path",
            "membrane_stretch",
            "bundle_ratio",
            "flatness",
        ],
    )
    (stage / "gallery.html").write_text(page, encoding="utf-8")


def print_search_summary(search: SearchStudy, rows: list[dict[str, Any]], top: int = 15) -> None:
    """Print the best candidates (or the closest when none passes) as a table."""
    from rich.table import Table

    best = ranked(search, rows)
    show_rows = best[:top]
    title = f"{search.study.name}: {len(best)} of {len(rows)} candidate(s) pass"
    table = Table(title=title, title_justify="left")
    keys = [
        "rank",
        *search.study.grid,
        "mobility_max",
        "bifurcations_on_path",
        "membrane_stretch",
        "bundle_ratio",
        "flatness",
    ]
    heads = {"mobility_max": "mob.", "bifurcations_on_path": "bif.", "membrane_stretch": "stretch",
             "bundle_ratio": "bundle", "flatness": "flat"}  # fmt: skip
    for key in keys:
        table.add_column(heads.get(key, key), justify="right", overflow="fold")
    for row in show_rows:
        table.add_row(*[_fmt(row.get(k)) for k in keys])
    console.print(table)
    if len(best) > top:
        console.print(f"... {len(best) - top} more in ranked.csv")


def _fmt(value: Any) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)
