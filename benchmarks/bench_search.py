"""Search benchmark: 1,024 Guest-type rectangular frames screened by ``linkwork search`` on two local workers.

The study (written to a temporary folder): ``rect-frame`` with Guest's cuts (``EW``), every one of the 64 choices
of hinge faces, 4 widths and 4 sections: 64 x 4 x 4 = 1,024 candidates, each traced (at most 5,000 steps: the
mobile ones close their path in about 500) and judged on mobility, bifurcations and membrane stretch.

Measures, as a user running ``linkwork search STUDY -o OUT --workers 2`` sees it:

(a) the whole search on two local worker processes, the cluster's start-up included (goal: under 120 s), and
    apart: the time to the last candidate's row, and the gallery (12 candidates traced again, 12 viewer pages);
(b) the same search in one process (``--workers 0``): the two-worker speed-up (goal: >= 1.7x);
(c) the tables of (a) and (b) are the same: texts, whole numbers and pass/fail equal, measures to 1e-9 relative
    (a worker may run the compiled kernels and this process their plain-Python twins).

The machine's load (``/proc/loadavg``) is printed with the numbers: timings on a loaded machine are noisy.
Prints a table and writes ``benchmarks/results/search.json``.

Run: ``python benchmarks/bench_search.py`` (``--quick``: 128 candidates; ``--workers N``; ``--skip-serial``).
"""

from __future__ import annotations

import argparse
import itertools
import json
import tempfile
import time
from pathlib import Path
from typing import Any

GOAL_SECONDS = 120.0


def loadavg() -> str:
    try:
        return str(Path("/proc/loadavg").read_text().split(" ")[0:3])
    except OSError:
        return "n/a"


def study_text(quick: bool) -> str:
    """The benchmark's study file: 64 face choices x widths x sections (1,024 candidates, 128 with quick)."""
    faces = ["".join(f) for f in itertools.product("io", repeat=6)]
    widths = "[0.5, 1.0]" if quick else "[0.4, 0.6, 0.8, 1.0]"
    sections = "[0.1]" if quick else "[0.05, 0.1, 0.15, 0.2]"
    return "\n".join(
        [
            'name = "rect-frame benchmark"',
            'linkage = "rect-frame"',
            "[trace]",
            "max_steps = 5000",
            "[grid]",
            f"width = {widths}",
            f"section = {sections}",
            'cuts = ["EW"]',
            f"faces = {json.dumps(faces)}",
            "[criteria]",
            "mobility = 1",
            "max_bifurcations = 0",
            "max_membrane_stretch = 1.0",
            'deployed_at = "A=0"',
            "",
        ]
    )


def run(study: Path, out: Path, workers: int) -> dict[str, Any]:
    """One search as ``linkwork search`` runs it; times the candidates and the outputs apart."""
    from linkwork.outputs.search import SearchRecords, write_search_outputs
    from linkwork.studies.search import load_search, run_search

    t0 = time.perf_counter()
    search = load_search(study)
    with SearchRecords(out, search) as records:
        for rows in run_search(search, skip=set(records.rows), workers=workers):
            records.add(rows)
        rows = list(records.rows.values())
    t1 = time.perf_counter()
    summary = write_search_outputs(search, rows, out, gallery=12)
    t2 = time.perf_counter()
    return {
        "candidates": len(rows),
        "passing": summary["passing"],
        "seconds_total": t2 - t0,
        "seconds_candidates": t1 - t0,
        "seconds_outputs": t2 - t1,
        "per_candidate_ms": 1e3 * (t1 - t0) / max(1, len(rows)),
    }


def compare(one: Path, two: Path) -> tuple[bool, float]:
    """Whether two candidates.csv hold the same rows (texts, whole numbers and pass/fail equal, measures to 1e-9
    relative: compiled and plain-Python kernels agree to round-off), and the largest relative difference."""
    import csv
    import math

    with one.open() as f1, two.open() as f2:
        a, b = list(csv.reader(f1)), list(csv.reader(f2))
    if len(a) != len(b) or a[0] != b[0]:
        return False, math.inf
    same, worst = True, 0.0
    for ra, rb in zip(a[1:], b[1:], strict=True):
        for x, y in zip(ra, rb, strict=True):
            try:
                fx, fy = float(x), float(y)
            except ValueError:
                same &= x == y
                continue
            if x.lstrip("-").isdigit() or not (math.isfinite(fx) and math.isfinite(fy)):
                same &= x == y
            else:
                diff = abs(fx - fy) / max(abs(fy), 1e-12)
                worst = max(worst, diff)
                same &= diff <= 1e-9
    return same, worst


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--quick", action="store_true", help="128 candidates instead of 1,024")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--skip-serial", action="store_true", help="skip (b), the one-process run")
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "search.json")
    args = parser.parse_args()

    print(f"load average before: {loadavg()}")
    results: dict[str, Any] = {"load_before": loadavg()}
    with tempfile.TemporaryDirectory() as tmp:
        study = Path(tmp) / "study.toml"
        study.write_text(study_text(args.quick), encoding="utf-8")
        parallel = run(study, Path(tmp) / "parallel", args.workers)
        results["parallel"] = parallel
        print(
            f"(a) {parallel['candidates']} candidates on {args.workers} workers: {parallel['seconds_total']:.1f} s "
            f"(candidates {parallel['seconds_candidates']:.1f} s, {parallel['per_candidate_ms']:.1f} ms each; "
            f"outputs and gallery {parallel['seconds_outputs']:.1f} s); {parallel['passing']} pass; goal under "
            f"{GOAL_SECONDS:.0f} s for 1,024: {'met' if parallel['seconds_total'] < GOAL_SECONDS else 'NOT met'}"
        )
        if not args.skip_serial:
            serial = run(study, Path(tmp) / "serial", 0)
            results["serial"] = serial
            speedup = serial["seconds_candidates"] / parallel["seconds_candidates"]
            results["speedup"] = speedup
            print(
                f"(b) one process: {serial['seconds_candidates']:.1f} s for the candidates: speed-up {speedup:.2f}x"
            )
            same, worst = compare(
                Path(tmp) / "parallel" / "candidates.csv", Path(tmp) / "serial" / "candidates.csv"
            )
            results["same_table"], results["largest_relative_difference"] = same, worst
            print(
                f"(c) the same candidates.csv: {same} (texts and counts equal; measures differ by {worst:.1e} at most)"
            )
    results["load_after"] = loadavg()
    print(f"load average after: {loadavg()}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(results, indent=2) + "\n", encoding="utf-8")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
