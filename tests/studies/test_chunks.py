"""Chunking of a study: every sample once, in order; guided sizes that end small so workers finish together;
the misfit kernel's centred-frame weighting equal to the weighted one."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from linkwork.studies.robustness import CHUNK, MIN_CHUNK, chunk_ranges


@pytest.mark.parametrize(
    ("samples", "workers"), [(1, 1), (99, 2), (1000, 2), (20_000, 1), (20_000, 2), (123_457, 7)]
)
def test_guided_chunks_cover_every_sample_once_and_end_small(samples: int, workers: int) -> None:
    ranges = chunk_ranges(samples, None, workers)
    assert ranges[0][0] == 0 and ranges[-1][1] == samples
    assert all(a[1] == b[0] for a, b in itertools.pairwise(ranges))
    sizes = [b - a for a, b in ranges]
    assert all(0 < size <= CHUNK for size in sizes)
    assert all(size >= MIN_CHUNK for size in sizes[:-1])
    assert all(a >= b for a, b in itertools.pairwise(sizes[:-1]))  # non-increasing, but the last
    if samples >= 8 * MIN_CHUNK * workers:
        # The work a worker can be left alone with at the end is one small chunk, not a tenth of its share.
        assert sizes[-2] == MIN_CHUNK and sizes[0] >= 2 * MIN_CHUNK


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
