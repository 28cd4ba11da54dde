"""Studies benchmark: imperfect Hedgepeth hexagons by Monte Carlo on the Dask engine.

Measures, for ``hedgepeth-rods`` n = 6 traced in 200 points (199 equal steps of theta_A from the bundle to the flat
hexagon) with hinges within 1e-3 rod lengths and 0.05 deg (normal):

(a) 20,000 imperfect hexagons on two local worker processes (goal: under 60 s), the cluster's start-up timed apart;
(b) the same study on one worker: the two-worker speed-up (goal: >= 1.8x), and the cost of one closure solve
    (one drive value of one sample) in this process (goal: <= 2 us);
(c) the first-order prediction of all 10,000 largest misfits against the Monte Carlo, both as CPU time in one
    process (goal: >= 100x faster), and against the wall time of (a);
(d) memory: ``--memory-samples`` samples (10^6 by default; hexagon, 20-point path) streamed to Parquet in this
    process, peak resident memory before and after (goal: the study adds no more than about 200 MB).

The machine's load (``/proc/loadavg``) is printed with the numbers: timings on a loaded machine are noisy.
Prints a table and writes ``benchmarks/results/studies.json``.

Every process is single-threaded (``NUMBA_NUM_THREADS`` and the BLAS pools 1, here and in the workers).

Run: ``python benchmarks/bench_studies.py`` (``--samples``, ``--memory-samples`` (0 skips (d)), ``--quick``).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from threads import single_threaded

import linkwork as lw
from linkwork.linkages.hedgepeth_rods import deployed_angles
from linkwork.studies.imperfections import ImperfectionModel
from linkwork.studies.robustness import first_order_only, nominal_ratio, prepare, run_chunk, run_study

POINTS = 200  # drive values per sample: one closure solve each


def loadavg() -> str:
    try:
        return Path("/proc/loadavg").read_text().split(" ")[0:3].__str__()
    except OSError:
        return "n/a"


def hexagon_setup(points: int) -> tuple[Any, np.ndarray]:
    mech = lw.load("hedgepeth-rods", n=6)
    path = lw.trace(mech, until=("A", deployed_angles(6)[0]), steps=points - 1)
    model = ImperfectionModel(1e-3, np.radians(0.05))
    return prepare(mech, path, model, seed=0), nominal_ratio(path)


def timed_cluster_run(
    setup: Any, ratio: np.ndarray, samples: int, workers: int, chunk: int | None = None
) -> dict[str, float]:
    from dask.distributed import Client, LocalCluster

    t0 = time.perf_counter()
    with (
        LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=":0"
        ) as cluster,
        Client(cluster) as client,
    ):
        client.run(lambda: run_chunk(setup, 0, 2))  # numba cache load on every worker, timed with start-up
        cpu0 = client.run(time.process_time)
        t1 = time.perf_counter()
        res = run_study(setup, samples, ratio, client=client, chunk=chunk)
        t2 = time.perf_counter()
        cpu1 = client.run(time.process_time)
    cpu = [cpu1[w] - cpu0[w] for w in cpu0]
    return {
        "startup_s": t1 - t0,
        "study_s": t2 - t1,
        "worker_cpu_s": cpu,
        "median_misfit": float(np.median(res.misfit_max)),
    }


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def memory_run(samples: int) -> dict[str, float]:
    from linkwork.outputs.robustness import run_and_write_robustness

    setup, ratio = hexagon_setup(20)
    run_chunk(setup, 0, 2)
    before = peak_rss_mb()
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        run_and_write_robustness(setup, samples, ratio, Path(tmp) / "out", plots=False, engine={"workers": 0})
        size = (Path(tmp) / "out" / "samples.parquet").stat().st_size / 1e6
    return {
        "samples": samples,
        "peak_rss_before_mb": before,
        "peak_rss_after_mb": peak_rss_mb(),
        "added_mb": peak_rss_mb() - before,
        "parquet_mb": size,
        "seconds": time.perf_counter() - t0,
    }


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--samples", type=int, default=20_000)
    parser.add_argument("--memory-samples", type=int, default=1_000_000)
    parser.add_argument("--quick", action="store_true", help="1,000 hexagons and 100,000 for memory")
    parser.add_argument(
        "--equal-chunks",
        type=int,
        default=0,
        help="also run two workers with equal chunks of this size (2000: the chunking before guided chunks)",
    )
    parser.add_argument(
        "--out", type=Path, default=Path(__file__).resolve().parent / "results" / "studies.json"
    )
    args = parser.parse_args()
    single_threaded()
    samples = 1_000 if args.quick else args.samples
    memory_samples = 100_000 if args.quick else args.memory_samples
    report: dict[str, Any] = {"load_before": loadavg(), "cores": os.cpu_count(), "samples": samples}

    setup, ratio = hexagon_setup(POINTS)
    run_chunk(setup, 0, 2)  # compile / load the numba cache
    first_order_only(setup, 0, 10)
    t0, c0 = time.perf_counter(), time.process_time()
    first_order_only(setup, 0, samples)
    report["first_order_s"] = time.perf_counter() - t0
    report["first_order_cpu_s"] = time.process_time() - c0
    n_cpu = min(samples, 1000)
    t0 = time.process_time()
    run_chunk(setup, 0, n_cpu)
    report["mc_cpu_s_per_sample"] = (time.process_time() - t0) / n_cpu
    report["mc_us_per_closure_solve"] = report["mc_cpu_s_per_sample"] / POINTS * 1e6
    report["two_workers"] = timed_cluster_run(setup, ratio, samples, 2)
    report["one_worker"] = timed_cluster_run(setup, ratio, samples, 1)
    report["speedup_two_over_one"] = report["one_worker"]["study_s"] / report["two_workers"]["study_s"]
    if args.equal_chunks:
        report["two_workers_equal_chunks"] = timed_cluster_run(setup, ratio, samples, 2, args.equal_chunks)
        report["speedup_equal_chunks"] = (
            report["one_worker"]["study_s"] / report["two_workers_equal_chunks"]["study_s"]
        )
    # Load-independent estimate: one worker's CPU time over the busiest of two workers' (what the wall times
    # would be on idle cores).
    report["speedup_cpu_estimate"] = sum(report["one_worker"]["worker_cpu_s"]) / max(
        report["two_workers"]["worker_cpu_s"]
    )
    report["first_order_vs_mc_wall"] = report["two_workers"]["study_s"] / report["first_order_s"]
    report["first_order_vs_mc_cpu"] = report["mc_cpu_s_per_sample"] * samples / report["first_order_cpu_s"]
    report["memory"] = memory_run(memory_samples) if memory_samples > 0 else None
    report["load_after"] = loadavg()

    rows = [
        (f"(a) {samples} hexagons, 2 workers", f"{report['two_workers']['study_s']:.1f} s", "< 60 s"),
        ("    cluster start-up + cache load", f"{report['two_workers']['startup_s']:.1f} s", ""),
        (f"(b) {samples} hexagons, 1 worker", f"{report['one_worker']['study_s']:.1f} s", ""),
        ("    speed-up 2 workers / 1 (wall)", f"{report['speedup_two_over_one']:.2f}x", ">= 1.8x"),
        ("    the same from worker CPU times", f"{report['speedup_cpu_estimate']:.2f}x", "(idle cores)"),
        (
            "    one closure solve (CPU, this process)",
            f"{report['mc_us_per_closure_solve']:.2f} us",
            "<= 2 us",
        ),
        ("(c) first order, all samples", f"{report['first_order_s']:.3f} s", ""),
        ("    vs Monte Carlo wall time (a)", f"{report['first_order_vs_mc_wall']:.0f}x", ""),
        ("    CPU time, both in one process", f"{report['first_order_vs_mc_cpu']:.0f}x", ">= 100x"),
    ]
    if args.equal_chunks:
        rows.append(
            (
                f"    the same, equal chunks of {args.equal_chunks}",
                f"{report['speedup_equal_chunks']:.2f}x",
                "(A/B)",
            )
        )
    if report["memory"] is not None:
        rows.append(
            (
                f"(d) {memory_samples} samples streamed",
                f"+{report['memory']['added_mb']:.0f} MB peak RSS ({report['memory']['seconds']:.0f} s)",
                "<= ~200 MB",
            )
        )
    for name, value, goal in rows:
        print(f"{name:40s} {value:>28s}  {goal}")
    print(f"load average before {report['load_before']}, after {report['load_after']}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
