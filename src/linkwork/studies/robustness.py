"""Imperfection sensitivity by Monte Carlo along a nominal path, with its first-order prediction.

:func:`prepare` traces the nominal path once and builds everything a worker needs (:class:`RobustnessSetup`);
:func:`run_chunk` draws a chunk of imperfect samples, solves each one's misfit at every drive value (compiled
batch kernel, :mod:`linkwork.studies.misfit`) and its first-order prediction (:mod:`linkwork.studies.first_order`),
and returns per-sample rows plus mergeable per-drive histograms; :func:`robustness` runs the chunks on the Dask
engine and merges them into a :class:`RobustnessResult`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from linkwork.deprecation import trace_keyword
from linkwork.errors import SpecError
from linkwork.kinematics.ground_frame import ground_frame_arrays
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.trace_result import Trace
from linkwork.limits import MAX_PATH_POINTS
from linkwork.progress import Progress
from linkwork.studies import bands
from linkwork.studies.engine import RunStatus, default_workers, map_chunks, worker_count
from linkwork.studies.first_order import first_order_misfit, sensitivity_maps
from linkwork.studies.imperfections import (
    HingeLines,
    ImperfectionModel,
    component_scale,
    hinge_errors,
    perturbed_twists,
    sample_seeds,
)
from linkwork.studies.misfit import misfit_batch
from linkwork.studies.scale import MisfitScale, loop_weights, misfit_scale, weights_along

Array = NDArray[np.float64]

#: Gauss-Newton iterations per drive value at most.
MAX_ITER = 30
#: Closure solves (samples x path points) per task at most: about 1.3 s of one worker for the hexagon of 200
#: points, whose (S, K) arrays then take 8 MB each.
CHUNK_VALUES = 1_000_000
#: Samples per task at most, whatever the path (a sample's hinge errors, twists and their temporaries take a few
#: kB: a short path's chunks would otherwise hold hundreds of MB).
CHUNK_SAMPLES = 5000
#: Closure solves per task at least (but for the last): the tail's chunks, about 50 ms of the same hexagon.
MIN_CHUNK_VALUES = 40_000


@dataclass(frozen=True)
class RobustnessSetup:
    """What every worker needs: the mechanism (as perturbed), the nominal path and the first-order maps."""

    mech: Mechanism
    model: ImperfectionModel
    seed: int
    lines: HingeLines
    scale: MisfitScale
    u_path: Array
    drive: str
    drive_values: Array
    drive_unknown: int
    normal: Array
    weights: Array
    G: Array
    ratio_normalised: Array
    cycles: Array
    keep_tol: float

    def kernel_args(self) -> tuple[Any, ...]:
        """Arguments of :func:`linkwork.studies.misfit.misfit_batch` after the twists: ``(path, loops, weight)``,
        the loops taken from the ground (:func:`linkwork.kinematics.ground_frame.ground_frame_arrays`: the frame of
        the weights' centre, whichever loop it is)."""
        joint, sign, ptr = ground_frame_arrays(self.mech)
        rows = np.array(self.mech.rows, dtype=np.int64)
        return (
            (self.u_path, self.normal, self.cycles),
            (joint, sign, ptr, rows, self.mech.groups),
            self.weights,
        )


@dataclass
class ChunkResult:
    """Per-sample rows of one chunk and its per-drive histograms (misfit, first order) and maxima."""

    sample: NDArray[np.int64]
    seed: NDArray[np.uint64]
    misfit_max: Array
    at_step: NDArray[np.int64]
    mobility_kept: NDArray[np.bool_]
    first_order_max: Array
    hist: bands.BinCounts
    hist_first: bands.BinCounts
    drive_max: Array

    def __sizeof__(self) -> int:
        """Bytes of its arrays (what travels from a worker to the client): Dask reads the size of a result this
        way (``sys.getsizeof``), to account for worker memory and report the bytes of each task."""
        arrays = [
            getattr(self, name) for name in ("sample", "seed", "misfit_max", "at_step", "mobility_kept")
        ]
        arrays += [self.first_order_max, self.drive_max, self.hist.index, self.hist.counts]
        arrays += [self.hist_first.index, self.hist_first.counts]
        return object.__sizeof__(self) + sum(int(a.nbytes) for a in arrays)


@trace_keyword
def prepare(
    mech: Mechanism,
    trace: Trace,
    model: ImperfectionModel,
    seed: int = 0,
) -> RobustnessSetup:
    """The set-up of a study of ``mech`` along the first branch of ``trace`` (its nominal motion)."""
    if model.spatial and mech.planar:
        mech = replace(mech, planar=False)
    first = trace.branch == (trace.branches[0].id if trace.branches else 0)
    q = mech.q_from_angles(trace.angles[first])
    u_path = np.ascontiguousarray(mech.u_from_q(q))
    if u_path.shape[0] < 1:
        raise SpecError("the nominal path has no points")
    if u_path.shape[0] > MAX_PATH_POINTS:
        raise SpecError(
            f"the nominal path has {u_path.shape[0]} points; expected at most {MAX_PATH_POINTS} (memory: about "
            f"{16 * bands.N_BINS // 1000} kB per point for every chunk in flight); give fewer --steps or a "
            "shorter --until"
        )
    drive_joint = mech.index(trace.drive)
    drive_unknown = int(mech.groups[drive_joint])
    scale = misfit_scale(mech)
    lines = HingeLines.of(mech, scale.centre)
    weights = weights_along(mech, trace.angles[first], scale.length)
    cycles = loop_weights(mech)
    G, normal = sensitivity_maps(mech, u_path, lines, weights, scale.length, cycles)
    comp = component_scale(mech, model, lines)
    tol_size = float(comp[:, 2:].max(initial=0.0) + scale.length * comp[:, :2].max(initial=0.0))
    return RobustnessSetup(
        mech=mech,
        model=model,
        seed=int(seed),
        lines=lines,
        scale=scale,
        u_path=u_path,
        drive=mech.joint_names[drive_joint],
        drive_values=trace.angles[first, drive_joint],
        drive_unknown=drive_unknown,
        normal=normal,
        weights=weights,
        G=G,
        ratio_normalised=trace.condition()[first],
        cycles=cycles,
        keep_tol=1e-6 * tol_size + 1e-12 * scale.length,
    )


def run_chunk(setup: RobustnessSetup, start: int, stop: int) -> ChunkResult:
    """Samples ``start .. stop - 1``: misfits along the path by Gauss-Newton, and their first-order prediction."""
    seeds = sample_seeds(setup.seed, start, stop)
    errors = hinge_errors(seeds, setup.mech, setup.model, setup.lines)
    twists = perturbed_twists(errors, setup.lines)
    misfit = misfit_batch(twists, *setup.kernel_args(), MAX_ITER)
    predicted = first_order_misfit(setup.G, errors)
    at = np.argmax(misfit, axis=1)
    worst = misfit[np.arange(len(seeds)), at]
    return ChunkResult(
        sample=np.arange(start, stop, dtype=np.int64),
        seed=seeds,
        misfit_max=worst,
        at_step=at.astype(np.int64),
        mobility_kept=worst <= setup.keep_tol,
        first_order_max=predicted.max(axis=1),
        hist=bands.BinCounts.of_values(misfit, setup.scale.length),
        hist_first=bands.BinCounts.of_values(predicted, setup.scale.length),
        drive_max=misfit.max(axis=0),
    )


def first_order_only(setup: RobustnessSetup, start: int, stop: int) -> Array:
    """``(S,)`` the first-order prediction of the largest misfit of samples ``start .. stop - 1`` alone."""
    seeds = sample_seeds(setup.seed, start, stop)
    errors = hinge_errors(seeds, setup.mech, setup.model, setup.lines)
    return first_order_misfit(setup.G, errors).max(axis=1)


def chunk_ranges(
    samples: int, chunk: int | None = None, workers: int = 1, points: int = 1
) -> list[tuple[int, int]]:
    """``(start, stop)`` of every chunk of ``samples`` along a path of ``points`` points: ``chunk`` samples each
    when given; by default guided chunks, each half of a worker's share of the samples left, of
    :data:`MIN_CHUNK_VALUES` to :data:`CHUNK_VALUES` closure solves and at most :data:`CHUNK_SAMPLES` samples: the
    first chunks are large and the last ones small, so that the workers finish together whatever their speeds,
    while the run has few tasks (each costs a few milliseconds of the client's, the scheduler's and a worker's
    CPU: on two cores, time taken from the workers). A sample's numbers never depend on its chunk."""
    if chunk:
        size = max(1, chunk)
        return [(a, min(a + size, samples)) for a in range(0, samples, size)]
    points = max(1, points)
    largest = max(1, min(CHUNK_SAMPLES, CHUNK_VALUES // points))
    smallest = min(largest, -(-MIN_CHUNK_VALUES // points))
    out, start, share = [], 0, 2 * max(1, workers)
    while start < samples:
        size = min(largest, max(smallest, -(-(samples - start) // share)))
        out.append((start, min(start + size, samples)))
        start += size
    return out


@dataclass
class RobustnessResult:
    """A finished study: summary numbers, per-drive bands, and the per-sample columns (kept in memory)."""

    setup: RobustnessSetup
    samples: int
    misfit_max: Array
    first_order_max: Array
    mobility_kept: NDArray[np.bool_]
    hist: NDArray[np.int64]
    hist_first: NDArray[np.int64]
    drive_max: Array
    ratio_paper: Array
    samples_asked: int = 0
    stopped: str = ""

    @property
    def complete(self) -> bool:
        """Whether every sample asked for was computed (an interrupted run keeps the samples it finished)."""
        return not self.stopped

    def band(self, q: float, first_order: bool = False) -> Array:
        """``(K,)`` the ``q``-quantile of the misfit (or its first-order prediction) at every drive value."""
        counts = self.hist_first if first_order else self.hist
        return bands.percentiles(counts, q, self.setup.scale.length)


def merge_chunks(
    setup: RobustnessSetup,
    results: Iterator[ChunkResult],
    ratio_paper: Array,
    sink: Callable[[ChunkResult], None] | None = None,
) -> RobustnessResult:
    """Merge chunk results in order (``sink`` sees each one, e.g. to stream it to Parquet)."""
    K = setup.u_path.shape[0]
    hist = np.zeros((K, bands.N_BINS), dtype=np.int64)
    hist_first = np.zeros_like(hist)
    drive_max = np.zeros(K)
    worst, first, kept = [], [], []
    for res in results:
        res.hist.add_into(hist)
        res.hist_first.add_into(hist_first)
        drive_max = np.maximum(drive_max, res.drive_max)
        worst.append(res.misfit_max)
        first.append(res.first_order_max)
        kept.append(res.mobility_kept)
        if sink is not None:
            sink(res)
    misfit_max = np.concatenate(worst) if worst else np.zeros(0)
    return RobustnessResult(
        setup=setup,
        samples=len(misfit_max),
        misfit_max=misfit_max,
        first_order_max=np.concatenate(first) if first else np.zeros(0),
        mobility_kept=np.concatenate(kept) if kept else np.zeros(0, dtype=bool),
        hist=hist,
        hist_first=hist_first,
        drive_max=drive_max,
        ratio_paper=ratio_paper,
    )


def run_study(
    setup: RobustnessSetup,
    samples: int,
    ratio_paper: Array,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    client: Any = None,
    chunk: int | None = None,
    progress: Progress | None = None,
    sink: Callable[[ChunkResult], None] | None = None,
    status: RunStatus | None = None,
) -> RobustnessResult:
    """Run ``samples`` samples of a prepared study on the Dask engine and merge them.

    With ``status`` (see :func:`linkwork.studies.engine.map_chunks`) an interrupted run, or one whose cluster is
    lost, returns the samples of the chunks finished so far (the first ones, in order), with ``stopped`` set."""
    if samples < 1:
        raise SpecError(f"samples must be at least 1, got {samples}")
    if client is not None:
        n_workers = worker_count(client)
    else:
        n_workers = workers if workers is not None else default_workers()
    results = map_chunks(
        run_chunk,
        setup,
        chunk_ranges(samples, chunk, n_workers, setup.u_path.shape[0]),
        scheduler=scheduler,
        workers=workers,
        client=client,
        progress=progress,
        status=status,
    )
    merged = merge_chunks(setup, results, ratio_paper, sink)
    merged.samples_asked = samples
    merged.stopped = status.stopped if status is not None else ""
    return merged


@trace_keyword
def nominal_ratio(trace: Trace) -> Array:
    """``(K,)`` the paper's Sec. 5 ratio at the points of the path's first branch."""
    first = trace.branch == (trace.branches[0].id if trace.branches else 0)
    return trace.condition_raw()[first]  # the raw ratio, as printed in the paper (condition() is normalised)


@trace_keyword
def robustness(
    mech: Mechanism,
    trace: Trace,
    model: ImperfectionModel,
    samples: int,
    *,
    seed: int = 0,
    **engine: Any,
) -> RobustnessResult:
    """Monte Carlo of ``samples`` imperfect copies of ``mech`` along the nominal ``trace`` (from
    :func:`linkwork.trace`), on the Dask engine; ``engine`` are the keywords of :func:`run_study`
    (``scheduler``, ``workers``, ``client``, ``chunk``, ``progress``, ``sink``)."""
    if samples < 1:
        raise SpecError(f"samples must be at least 1, got {samples}")
    setup = prepare(mech, trace, model, seed)
    return run_study(setup, samples, nominal_ratio(trace), **engine)
