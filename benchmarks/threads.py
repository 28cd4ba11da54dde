"""One thread per process for every benchmark: numba, the BLAS pools, and the Dask workers a benchmark starts."""

from __future__ import annotations

import os
from typing import Any

VARIABLES = ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def single_threaded() -> Any:
    """Limit this process's BLAS pools to one thread (threadpoolctl, from the ``bench`` extra) and set the
    environment so that processes started from here (Dask workers) are single-threaded too. Returns the
    threadpoolctl limiter (``None`` without threadpoolctl)."""
    for name in VARIABLES:
        os.environ[name] = "1"
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        return None
    return threadpool_limits(1)
