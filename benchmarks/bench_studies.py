"""Studies benchmark: imperfect Hedgepeth hexagons by Monte Carlo on the Dask engine.

Measures, for ``hedgepeth-rods`` n = 6 traced in 200 points (199 equal steps of theta_A from the bundle to the flat
hexagon) with hinges within 1e-3 rod lengths and 0.05 deg (normal):

(a) 20,000 imperfect hexagons on two local worker processes (goal: under 60 s), the cluster's start-up and the
    numba cache load timed apart; the cluster is the engine's own (as the command line starts it);
(b) the same study on one worker: the two-worker speed-up (goal: >= 1.8x), and the cost of one closure solve
    (one drive value of one sample) in this process, the best of five runs of 1,000 samples (goal: <= 2 us).
    Where the two-worker run loses time against 2x, from quantities a loaded machine changes little: each
    worker's CPU time (in its tasks, and in all), its tasks and samples, its idle time before the first task, between tasks and after the last (dask's task
    stream); this process's CPU time (its main thread: client and merge; the rest: the local cluster's
    scheduler and nannies, and communication), tasks and bytes sent back; and the speed-up those CPU times allow
    on two idle cores;
(c) the first-order prediction of all 10,000 largest misfits against the Monte Carlo, both as CPU time in one
    process (goal: >= 100x faster), and against the wall time of (a);
(d) memory: ``--memory-samples`` samples (10^6 by default; hexagon, 20-point path) streamed to Parquet in this
    process, peak resident memory before and after (goal: the study adds no more than about 200 MB).

The machine's load (``/proc/loadavg``) is printed with the numbers: timings on a loaded machine are noisy.
Prints a table and writes ``benchmarks/results/studies.json``.

Every process is single-threaded (``NUMBA_NUM_THREADS`` and the BLAS pools 1, here and in the workers).

Run: ``python benchmarks/bench_studies.py`` (``--samples``, ``--memory-samples`` (0 skips (d)), ``--quick``,
``--repeat N`` pairs of runs, two workers then one, the median pair reported).
"""

from __future__ import annotations

import argparse
import contextlib
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
from linkwork.studies.robustness import (
    chunk_ranges,
    first_order_only,
    nominal_ratio,
    prepare,
    run_chunk,
    run_study,
)

POINTS = 200  # drive values per sample: one closure solve each
# Runs of 1,000 samples timed for one closure solve (the best is reported, the median beside it).
CPU_REPEATS = 5


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


def client_cpu() -> dict[str, float]:
    """CPU seconds of this process so far: its main thread (the client's loop over results, the merge) and the
    rest (the event loop thread, which runs the local cluster's scheduler and nannies and the client's
    communication)."""
    total, main = time.process_time(), time.thread_time()
    return {"main": main, "loop": total - main}


def worker_cpu() -> dict[str, float]:
    """In a dask worker: CPU seconds of the process so far, and of its task threads (dask's executor), the rest
    being the worker's own event loop (messages, heartbeats, monitors)."""
    import threading

    tasks = 0.0
    for thread in threading.enumerate():
        if "Dask-Default-Threads" in thread.name and thread.ident is not None:
            with contextlib.suppress(OSError, AttributeError):
                tasks += time.clock_gettime(time.pthread_getcpuclockid(thread.ident))
    return {"process": time.process_time(), "tasks": tasks}


def worker_timeline(
    records: list[dict[str, Any]], ranges: list[tuple[int, int]], start: float, stop: float
) -> dict[str, dict[str, Any]]:
    """Per worker, from dask's task stream (each task's compute start and stop, stamped by the worker):
    tasks, samples, busy seconds, and the idle seconds before its first task (``lead``), between tasks
    (``gaps``) and after its last task until the study returned (``tail``); also each task's record. A worker
    shifts its stamps by its estimate of its clock's offset from the scheduler's, which on one machine is only
    latency noise, re-estimated at every heartbeat: these times are right to a few milliseconds (a loaded
    machine's tasks may even seem to overlap)."""
    out: dict[str, dict[str, Any]] = {}
    for rec in records:
        index = int(str(rec["key"]).rsplit("-", 1)[1])
        for ss in rec["startstops"]:
            if ss["action"] != "compute":
                continue
            w = out.setdefault(rec["worker"], {"tasks": []})
            w["tasks"].append(
                {
                    "chunk": index,
                    "samples": ranges[index][1] - ranges[index][0],
                    "start_s": ss["start"] - start,
                    "stop_s": ss["stop"] - start,
                    "bytes": int(rec.get("nbytes", 0)),
                }
            )
    for w in out.values():
        tasks = sorted(w["tasks"], key=lambda t: t["start_s"])
        busy = sum(t["stop_s"] - t["start_s"] for t in tasks)
        w.update(
            tasks=tasks,
            n_tasks=len(tasks),
            samples=sum(t["samples"] for t in tasks),
            bytes=sum(t["bytes"] for t in tasks),
            busy_s=busy,
            lead_s=tasks[0]["start_s"],
            tail_s=(stop - start) - tasks[-1]["stop_s"],
            gaps_s=tasks[-1]["stop_s"] - tasks[0]["start_s"] - busy,
        )
    return out


def timed_cluster_run(
    setup: Any, ratio: np.ndarray, samples: int, workers: int, chunk: int | None = None
) -> dict[str, Any]:
    """The study on a local cluster of ``workers`` processes started as the command line starts it (the
    engine's :func:`~linkwork.studies.engine.dask_client`), timed from the call to ``run_study`` to its return;
    the cluster's start-up and the numba cache load in every worker are timed apart. Also: each worker's CPU
    time and timeline (dask's task stream), this process's CPU time (client, scheduler, nannies), tasks and
    bytes sent back."""
    from dask.distributed import get_task_stream
    from distributed.metrics import time as dask_time

    from linkwork.studies.engine import dask_client

    t0 = time.perf_counter()
    with dask_client(None, workers) as client:
        client.run(run_chunk, setup, 0, 2)  # numba cache load on every worker, timed with start-up
        cpu0 = client.run(worker_cpu)
        with get_task_stream(client) as stream:
            c0 = client_cpu()
            t1, s1 = time.perf_counter(), dask_time()
            res = run_study(setup, samples, ratio, client=client, chunk=chunk)
            t2, s2 = time.perf_counter(), dask_time()
            c1 = client_cpu()
        cpu1 = client.run(worker_cpu)
    n_workers = len(cpu0)
    timeline = worker_timeline(
        stream.data, chunk_ranges(samples, chunk, n_workers, setup.u_path.shape[0]), s1, s2
    )
    cpu = {w: cpu1[w]["process"] - cpu0[w]["process"] for w in cpu0}
    for w, line in timeline.items():
        line["cpu_s"] = cpu.get(w, float("nan"))
        line["task_cpu_s"] = cpu1[w]["tasks"] - cpu0[w]["tasks"] if w in cpu0 else float("nan")
    return {
        "startup_s": t1 - t0,
        "study_s": t2 - t1,
        "worker_cpu_s": list(cpu.values()),
        "client_main_cpu_s": c1["main"] - c0["main"],
        "client_loop_cpu_s": c1["loop"] - c0["loop"],
        "tasks": sum(line["n_tasks"] for line in timeline.values()),
        "bytes_back": sum(line["bytes"] for line in timeline.values()),
        "workers": timeline,
        "median_misfit": float(np.median(res.misfit_max)),
    }


def losses(one: dict[str, Any], two: dict[str, Any]) -> dict[str, float]:
    """Where the two-worker run's wall time goes beyond half the one-worker run's (seconds), from quantities
    that do not depend on the machine's load: the workers' extra CPU time over one worker's, shared by two
    cores; this process's CPU time (client, scheduler, nannies), which on two cores takes from the workers;
    the busiest worker's CPU beyond the mean; and, load-dependent, the workers' idle time (before the first
    task, between tasks, after the last). ``estimate`` is the speed-up the CPU times allow on two idle cores:
    one worker's CPU over all the CPU of the two-worker run (both workers and this process) spread evenly on two
    cores (on a loaded machine the busiest worker is the one the system gave more time, so its CPU is not used
    here; ``imbalance_s`` shows it)."""
    w1 = sum(one["worker_cpu_s"])
    w2 = two["worker_cpu_s"]
    client2 = two["client_main_cpu_s"] + two["client_loop_cpu_s"]
    idle = [line["lead_s"] + line["gaps_s"] + line["tail_s"] for line in two["workers"].values()]
    return {
        "extra_worker_cpu_s": (sum(w2) - w1) / 2,
        "client_cpu_s": client2 / 2,
        "imbalance_s": max(w2) - sum(w2) / len(w2),
        "idle_s": sum(idle) / len(idle),
        "estimate": w1 / ((sum(w2) + client2) / 2),
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


def print_timelines(report: dict[str, Any]) -> None:
    """Each run's tasks, bytes, CPU times and idle times, and the two-worker run's losses against 2x."""
    for name in ("two_workers", "one_worker", "two_workers_equal_chunks"):
        run = report.get(name)
        if run is None:
            continue
        print(
            f"{name.replace('_', ' ')}: {run['tasks']} tasks, {run['bytes_back'] / 1e6:.1f} MB back; this process "
            f"{run['client_main_cpu_s']:.3f} s CPU in its main thread (client, merge) + "
            f"{run['client_loop_cpu_s']:.3f} s in the rest (scheduler, nannies, communication)"
        )
        for k, line in enumerate(run["workers"].values()):
            print(
                f"  worker {k}: {line['n_tasks']} tasks, {line['samples']} samples, CPU {line['cpu_s']:.3f} s "
                f"({line['task_cpu_s']:.3f} in tasks), "
                f"computing {line['busy_s']:.3f} s, idle {line['lead_s']:.3f} s before the first task, "
                f"{line['gaps_s']:.3f} s between tasks, {line['tail_s']:.3f} s after the last"
            )
    lost = report["losses"]
    print(
        f"two workers against half of one (s): workers' extra CPU {lost['extra_worker_cpu_s']:+.3f}, "
        f"this process's CPU {lost['client_cpu_s']:.3f}, busiest worker's CPU beyond the mean "
        f"{lost['imbalance_s']:.3f}, workers idle {lost['idle_s']:.3f} (load-dependent)"
    )


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
        "--repeat",
        type=int,
        default=1,
        help="pairs of runs (two workers, one worker); the median pair is reported",
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
    cpu = []
    for _ in range(CPU_REPEATS):  # one run of a third of a second is at the mercy of the machine
        t0 = time.process_time()
        run_chunk(setup, 0, n_cpu)
        cpu.append(time.process_time() - t0)
    report["mc_cpu_s_per_sample"] = min(cpu) / n_cpu
    report["mc_cpu_s_per_sample_median"] = float(np.median(cpu)) / n_cpu
    report["mc_us_per_closure_solve"] = report["mc_cpu_s_per_sample"] / POINTS * 1e6
    pairs = []
    for _ in range(max(1, args.repeat)):  # one worker and two, alternately, on fresh clusters
        two = timed_cluster_run(setup, ratio, samples, 2)
        one = timed_cluster_run(setup, ratio, samples, 1)
        pairs.append({"two_workers": two, "one_worker": one, "speedup": one["study_s"] / two["study_s"]})
    middle = sorted(pairs, key=lambda pair: pair["speedup"])[(len(pairs) - 1) // 2]
    report["two_workers"], report["one_worker"] = middle["two_workers"], middle["one_worker"]
    report["speedup_two_over_one"] = middle["speedup"]
    report["speedups_two_over_one"] = [pair["speedup"] for pair in pairs]
    if args.equal_chunks:
        report["two_workers_equal_chunks"] = timed_cluster_run(setup, ratio, samples, 2, args.equal_chunks)
        report["speedup_equal_chunks"] = (
            report["one_worker"]["study_s"] / report["two_workers_equal_chunks"]["study_s"]
        )
    # Load-independent estimates: one worker's CPU time over the busiest of two workers' (what the wall times
    # would be on idle cores if nothing else ran), and over all the CPU time of the two-worker run on two cores.
    report["speedup_cpu_estimate"] = sum(report["one_worker"]["worker_cpu_s"]) / max(
        report["two_workers"]["worker_cpu_s"]
    )
    report["losses"] = losses(report["one_worker"], report["two_workers"])
    report["first_order_vs_mc_wall"] = report["two_workers"]["study_s"] / report["first_order_s"]
    report["first_order_vs_mc_cpu"] = report["mc_cpu_s_per_sample"] * samples / report["first_order_cpu_s"]
    report["memory"] = memory_run(memory_samples) if memory_samples > 0 else None
    report["load_after"] = loadavg()

    rows = [
        (f"(a) {samples} hexagons, 2 workers", f"{report['two_workers']['study_s']:.1f} s", "< 60 s"),
        ("    cluster start-up + cache load", f"{report['two_workers']['startup_s']:.1f} s", ""),
        (f"(b) {samples} hexagons, 1 worker", f"{report['one_worker']['study_s']:.1f} s", ""),
        ("    speed-up 2 workers / 1 (wall)", f"{report['speedup_two_over_one']:.2f}x", ">= 1.8x"),
        ("    each pair of runs (wall)", " ".join(f"{x:.2f}x" for x in report["speedups_two_over_one"]), ""),
        ("    from worker CPU times", f"{report['speedup_cpu_estimate']:.2f}x", "(idle cores)"),
        ("    from all CPU times, on two cores", f"{report['losses']['estimate']:.2f}x", "(idle cores)"),
        (
            "    one closure solve (CPU, this process; best, median)",
            f"{report['mc_us_per_closure_solve']:.2f} us, "
            f"{report['mc_cpu_s_per_sample_median'] / POINTS * 1e6:.2f}",
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
    print_timelines(report)
    print(f"load average before {report['load_before']}, after {report['load_after']}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
