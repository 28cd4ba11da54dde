"""Percentile bands along the path from mergeable log-histograms (so that 10^6 samples never need to be held).

Each drive value keeps a histogram of ``log10(misfit / L)`` with :data:`PER_DECADE` bins per decade from
``10^LOW`` to ``10^HIGH`` (one bin below for smaller values, including exact zeros, one above). Histograms of
chunks add up exactly (integer counts), in any order; a percentile is read off the cumulative counts and
interpolated log-linearly inside its bin (resolution ``10^(1/PER_DECADE)``, 2.3 %). The per-drive maximum is
kept exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

LOW = -16.0
HIGH = 3.0
PER_DECADE = 100
N_BINS = round((HIGH - LOW) * PER_DECADE) + 2


def bin_index(values: Array, length: float) -> NDArray[np.int64]:
    """``(S, K)`` the bin of every value of ``values (S, K)``: ``floor((log10(v / L) - LOW) PER_DECADE) + 1``,
    clipped to ``0 .. N_BINS - 1``; zeros (and anything below ``10^LOW L``) in bin 0, NaN and infinity (failed
    solves) in the last bin, as the largest. One temporary the size of ``values``, worked on in place."""
    with np.errstate(divide="ignore", invalid="ignore"):
        x = np.log10(np.maximum(values, 0.0) / length)
    x -= LOW  # in place, the same operations in the same order as (x - LOW) * PER_DECADE + 1.0
    x *= PER_DECADE
    x += 1.0
    np.nan_to_num(x, copy=False, nan=N_BINS - 1.0, posinf=N_BINS - 1.0, neginf=0.0)
    np.floor(x, out=x)
    np.clip(x, 0.0, N_BINS - 1.0, out=x)
    return x.astype(np.int64)


def histogram(values: Array, length: float) -> NDArray[np.int64]:
    """``(K, N_BINS)`` counts of ``values (S, K)`` per column."""
    K = values.shape[1]
    flat = (np.arange(K)[None, :] * N_BINS + bin_index(values, length)).ravel()
    return np.bincount(flat, minlength=K * N_BINS).reshape(K, N_BINS)


@dataclass(frozen=True)
class BinCounts:
    """A ``(K, N_BINS)`` histogram kept as its occupied bins only: flat bin indices ``index`` and their ``counts``
    (both int32).

    A chunk's histograms travel from a Dask worker to the client in this form: at most 8 bytes per sample and drive
    value (much less for a large chunk) instead of the 3 MB of the full array, most of whose bins are empty.
    """

    index: NDArray[np.int32]
    counts: NDArray[np.int32]

    @classmethod
    def of_values(cls, values: Array, length: float) -> BinCounts:
        """The occupied bins of the histogram of ``values (S, K)`` (equal to ``of(histogram(values, length))``),
        counted without the full ``(K, N_BINS)`` array: each column's bins between its lowest and highest occupied
        one are counted in one ``bincount`` (a chunk's fixed cost then grows with the bins its samples reach, not
        with ``K N_BINS``, whose allocation and scans cost milliseconds a chunk)."""
        idx = bin_index(values, length)
        if idx.size == 0:
            return cls(np.zeros(0, dtype=np.int32), np.zeros(0, dtype=np.int32))
        lo = idx.min(axis=0)
        width = idx.max(axis=0) - lo + 1
        base = np.cumsum(width) - width  # where each column's bins start in the packed counts
        idx -= lo - base
        counts = np.bincount(idx.ravel(), minlength=int(width.sum()))
        packed = np.flatnonzero(counts)
        column = np.searchsorted(base, packed, side="right") - 1
        index = column * N_BINS + (packed - base[column] + lo[column])
        return cls(index.astype(np.int32), counts[packed].astype(np.int32))

    @classmethod
    def of(cls, full: NDArray[np.int64]) -> BinCounts:
        """The occupied bins of ``full``."""
        flat = full.ravel()
        index = np.flatnonzero(flat)
        return cls(index.astype(np.int32), flat[index].astype(np.int32))

    def add_into(self, total: NDArray[np.int64]) -> None:
        """Add these counts into the full ``(K, N_BINS)`` array ``total``."""
        total.reshape(-1)[self.index] += self.counts


def percentiles(counts: NDArray[np.int64], q: float, length: float) -> Array:
    """``(K,)`` the ``q``-quantile (0..1) per row of ``counts`` (0 where it falls below ``10^LOW L``)."""
    K = counts.shape[0]
    out = np.zeros(K)
    cdf = np.cumsum(counts, axis=1)
    total = cdf[:, -1]
    for k in range(K):
        if total[k] == 0:
            out[k] = np.nan
            continue
        target = q * total[k]
        b = int(np.searchsorted(cdf[k], target, side="left"))
        b = min(b, N_BINS - 1)
        if b == 0:
            continue
        below = cdf[k, b - 1]
        frac = (target - below) / max(counts[k, b], 1)
        lo = LOW + (b - 1) / PER_DECADE
        out[k] = 10.0 ** (lo + min(max(frac, 0.0), 1.0) / PER_DECADE) * length
    return out
