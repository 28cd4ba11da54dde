"""Benchmark of the first run on a fresh install: ``linkwork trace`` with an empty numba cache against a warm run.

What it measures, each command in a fresh process with ``LINKWORK_CACHE_DIR`` pointing to a new empty folder:

1. **cold, default** (``LINKWORK_JIT=auto``): the first run traces with the plain-Python kernels and starts the
   background compile; wall time, the trace time it reports, and its stderr note;
2. the background compile: wall time until the cache is filled (lock file gone, marker ``ready.json`` lists the
   tracing kernels);
3. **warm**: the same command again, median of ``--repeats`` runs; the goal is cold <= 2 x warm;
4. **cold, compile first** (``LINKWORK_JIT=compiled``, a second empty cache): the old behaviour, compile in the
   process, announced and excluded from the reported trace time.

Prints a table and writes ``benchmarks/results/bench_first_run.json``. The machine's load is printed with the
numbers: on a shared machine wall times vary run to run.

Run: ``python benchmarks/bench_first_run.py [--repeats 3] [--plots]``
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

COMMAND = ["trace", "hedgepeth-rods", "--set", "n=6", "--until", "A=128.6822"]
GOAL = 2.0


def run(cache: Path, out: Path, mode: str, plots: bool) -> dict[str, object]:
    """One ``linkwork trace`` in a fresh process: wall time, reported trace seconds, stderr notes."""
    env = dict(os.environ, LINKWORK_CACHE_DIR=str(cache), LINKWORK_JIT=mode)
    cmd = [
        sys.executable,
        "-c",
        "from linkwork.cli import main; main()",
        *COMMAND,
        "-o",
        str(out),
        *([] if plots else ["--no-plots"]),
    ]
    begin = time.perf_counter()
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - begin
    found = re.search(r"(\d+) points in ([0-9.]+) s", " ".join(done.stdout.split()))
    report = json.loads((out / "report.json").read_text())
    return {
        "wall": wall,
        "reported": float(found.group(2)) if found else float("nan"),
        "points": int(found.group(1)) if found else 0,
        "end": report["branches"][0]["end_reason"],
        "notes": [line for line in done.stderr.splitlines() if line.startswith("note:")],
    }


def wait_for_background(cache: Path, timeout: float = 600.0) -> float:
    """Seconds until the background compile has written the cache and removed its lock file."""
    begin = time.perf_counter()
    while time.perf_counter() - begin < timeout:
        locked = list(cache.rglob("compiling.lock"))
        marked = [m for m in cache.rglob("ready.json") if "tracing" in json.loads(m.read_text())["groups"]]
        if marked and not locked:
            return time.perf_counter() - begin
        time.sleep(0.25)
    raise RuntimeError(f"the background compile did not finish in {timeout} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--plots", action="store_true", help="draw the figures too (the command's default)")
    parser.add_argument(
        "--out", type=Path, default=Path(__file__).parent / "results" / "bench_first_run.json"
    )
    args = parser.parse_args()
    load_before = Path("/proc/loadavg").read_text().split()[:3] if Path("/proc/loadavg").exists() else []
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        cache = root / "cache-auto"
        cold = run(cache, root / "cold", "auto", args.plots)
        cold["background_compile_wall"] = cold["wall"] + wait_for_background(cache)
        warm_runs = [run(cache, root / f"warm{i}", "auto", args.plots) for i in range(args.repeats)]
        compiled = run(root / "cache-compiled", root / "compiled", "compiled", args.plots)
    warm_wall = statistics.median(float(r["wall"]) for r in warm_runs)  # type: ignore[arg-type]
    warm_reported = statistics.median(float(r["reported"]) for r in warm_runs)  # type: ignore[arg-type]
    ratio = float(cold["wall"]) / warm_wall  # type: ignore[arg-type]
    load_after = Path("/proc/loadavg").read_text().split()[:3] if Path("/proc/loadavg").exists() else []
    rows = [
        ("command", "linkwork " + " ".join(COMMAND) + ("" if args.plots else " --no-plots")),
        ("cold (empty cache), wall", f"{cold['wall']:.2f} s"),
        ("cold, reported trace time", f"{cold['reported']:.3f} s ({cold['points']} points, {cold['end']})"),
        ("cold, note on stderr", " / ".join(cold["notes"]) or "(none)"),  # type: ignore[arg-type]
        (
            "background compile done after",
            f"{cold['background_compile_wall']:.1f} s (wall, from the cold start)",
        ),
        (f"warm, wall (median of {args.repeats})", f"{warm_wall:.2f} s"),
        ("warm, reported trace time", f"{warm_reported:.3f} s"),
        ("cold / warm", f"{ratio:.2f}x (goal <= {GOAL}x: {'met' if ratio <= GOAL else 'NOT met'})"),
        ("compile first (LINKWORK_JIT=compiled), wall", f"{compiled['wall']:.2f} s"),
        ("compile first, reported trace time", f"{compiled['reported']:.3f} s (compile excluded)"),
        ("load average before / after", f"{' '.join(load_before)} / {' '.join(load_after)}"),
    ]
    width = max(len(k) for k, _ in rows)
    for key, value in rows:
        print(f"{key:<{width}}  {value}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(
        json.dumps(
            {
                "command": COMMAND,
                "plots": args.plots,
                "cold": cold,
                "warm": warm_runs,
                "warm_wall_median": warm_wall,
                "ratio": ratio,
                "goal": GOAL,
                "compile_first": compiled,
                "load_before": load_before,
                "load_after": load_after,
                "python": platform.python_version(),
                "machine": platform.machine(),
            },
            indent=2,
        )
    )
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
