"""Chunking of a study: every sample once, in order; guided sizes that end small so workers finish together;
the misfit kernel's centred-frame weighting equal to the weighted one."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from linkwork.studies.robustness import CHUNK_VALUES, MIN_CHUNK_VALUES, chunk_ranges


@pytest.mark.parametrize(
    ("samples", "workers", "points"),
    [(1, 1, 200), (99, 2, 200), (1000, 2, 200), (20_000, 1, 200), (20_000, 2, 200), (123_457, 7, 41),
     (5000, 2, 10_000), (300, 3, 1)],
)  # fmt: skip
def test_guided_chunks_cover_every_sample_once_and_end_small(samples: int, workers: int, points: int) -> None:
    ranges = chunk_ranges(samples, None, workers, points)
    assert ranges[0][0] == 0 and ranges[-1][1] == samples
    assert all(a[1] == b[0] for a, b in itertools.pairwise(ranges))
    sizes = [b - a for a, b in ranges]
    largest = CHUNK_VALUES // points
    smallest = min(largest, -(-MIN_CHUNK_VALUES // points))
    assert all(0 < size <= largest for size in sizes)  # a task's arrays stay bounded however long the path
    assert all(size >= smallest for size in sizes[:-1])
    assert all(a >= b for a, b in itertools.pairwise(sizes[:-1]))  # non-increasing, but the last
    for (start, _), size in zip(ranges, sizes, strict=True):
        # At most half a worker's share of what is left: the rest still spreads over every worker.
        assert size <= max(smallest, -(-(samples - start) // (2 * workers)))
    if samples >= 8 * smallest * workers:
        # The work a worker can be left alone with at the end is one small chunk.
        assert sizes[-2] == smallest and sizes[0] >= 2 * smallest


def test_a_given_chunk_size_is_kept() -> None:
    assert chunk_ranges(10, 3) == [(0, 3), (3, 6), (6, 9), (9, 10)]


def test_bin_counts_add_up_to_the_full_histogram() -> None:
    from linkwork.studies import bands

    rng = np.random.default_rng(3)
    values = 10.0 ** rng.uniform(-9, -2, size=(300, 40))
    values[:, 0] = 0.0  # exact zeros (the start of a path) and a failed solve
    values[5, 7] = np.nan
    full = bands.histogram(values, 0.5)
    total = np.zeros_like(full)
    for part in np.array_split(values, 3):
        bands.BinCounts.of(bands.histogram(part, 0.5)).add_into(total)
    assert np.array_equal(total, full)
    assert total.sum() == values.size


def _dense_by_definition(values: np.ndarray, length: float) -> np.ndarray:
    """The histogram as the bands module defines it, written out case by case (zeros and negatives in bin 0,
    NaN and infinity in the last bin, else floor((log10(v / L) - LOW) PER_DECADE) + 1 clipped)."""
    from linkwork.studies import bands

    K = values.shape[1]
    with np.errstate(divide="ignore", invalid="ignore"):
        x = np.log10(np.maximum(values, 0.0) / length)
    pos = np.where(np.isfinite(x), (x - bands.LOW) * bands.PER_DECADE + 1.0, 0.0)
    pos = np.where(np.isnan(x) | (x == np.inf), bands.N_BINS - 1.0, pos)
    idx = np.clip(np.floor(pos), 0, bands.N_BINS - 1).astype(np.int64)
    out = np.zeros((K, bands.N_BINS), dtype=np.int64)
    np.add.at(out, (np.broadcast_to(np.arange(K), idx.shape), idx), 1)
    return out


@pytest.mark.parametrize("seed", range(6))
def test_occupied_bins_counted_directly_equal_the_full_histogram(seed: int) -> None:
    """A chunk's bins are counted without the full (K, N_BINS) array: the same bins and counts, in the same order,
    for values spread over every decade, exactly on bin edges, zeros, negatives, NaN, infinities, tiny subnormals,
    and a single sample."""
    from linkwork.studies import bands

    rng = np.random.default_rng(seed)
    S, K = (1, 37) if seed == 0 else (int(rng.integers(2, 700)), int(rng.integers(1, 60)))
    length = float(rng.choice([1.0, 0.37, 1e-3, 250.0]))
    values = 10.0 ** rng.uniform(-20, 5, size=(S, K)) * length
    edges = (
        10.0 ** (bands.LOW + rng.integers(-50, bands.N_BINS + 50, size=(S, K)) / bands.PER_DECADE) * length
    )
    values = np.where(rng.random((S, K)) < 0.3, edges, values)
    for bad in (0.0, -1.0, np.nan, np.inf, -np.inf, 5e-324):
        values[rng.random((S, K)) < 0.02] = bad
    dense = _dense_by_definition(values, length)
    assert np.array_equal(bands.histogram(values, length), dense)
    direct = bands.BinCounts.of_values(values, length)
    via_dense = bands.BinCounts.of(dense)
    assert direct.index.dtype == np.int32 and direct.counts.dtype == np.int32
    assert np.array_equal(direct.index, via_dense.index)
    assert np.array_equal(direct.counts, via_dense.counts)
    total = np.zeros_like(dense)
    direct.add_into(total)
    assert np.array_equal(total, dense) and total.sum() == values.size


def test_a_chunk_reports_the_bytes_it_sends_back(bennett) -> None:
    """Dask reads a result's size with sys.getsizeof (worker memory, the benchmark's bytes per task): a chunk's
    is the size of its arrays, what pickling it for the client takes, to within pickle's headers."""
    import pickle
    import sys

    from linkwork.studies.imperfections import ImperfectionModel
    from linkwork.studies.robustness import prepare, run_chunk

    mech, path = bennett
    setup = prepare(mech, path, ImperfectionModel(1e-4, np.radians(0.01)), seed=1)
    for stop in (1, 300):
        chunk = run_chunk(setup, 0, stop)
        sent = len(pickle.dumps(chunk, protocol=5))
        assert abs(sys.getsizeof(chunk) - sent) <= 3000, (stop, sys.getsizeof(chunk), sent)
