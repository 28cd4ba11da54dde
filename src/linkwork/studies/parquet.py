"""Streaming per-sample rows to Parquet: one row group per chunk, written as it arrives, so memory stays flat."""

from __future__ import annotations

from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from linkwork.studies.robustness import ChunkResult

SAMPLE_COLUMNS = (
    "sample",
    "seed",
    "misfit_max",
    "step_at_max",
    "drive_at_max_deg",
    "mobility_kept",
    "first_order_max",
)


class SampleWriter:
    """Context manager writing :class:`ChunkResult` rows to ``samples.parquet``: sample index, its 64-bit seed,
    largest misfit, where along the path (step and drive value in degrees), mobility kept, first-order prediction."""

    def __init__(self, file: Path, drive_values: NDArray[np.float64], revolute_drive: bool = True) -> None:
        import pyarrow as pa

        self.file = Path(file)
        self.drive = np.degrees(drive_values) if revolute_drive else np.asarray(drive_values)
        self.schema = pa.schema(
            [
                ("sample", pa.int64()),
                ("seed", pa.uint64()),
                ("misfit_max", pa.float64()),
                ("step_at_max", pa.int64()),
                ("drive_at_max_deg" if revolute_drive else "drive_at_max", pa.float64()),
                ("mobility_kept", pa.bool_()),
                ("first_order_max", pa.float64()),
            ]
        )
        self._writer: Any = None

    def __enter__(self) -> SampleWriter:
        import pyarrow.parquet as pq

        self._writer = pq.ParquetWriter(self.file, self.schema, compression="zstd")
        return self

    def write(self, chunk: ChunkResult) -> None:
        """Append one chunk's rows."""
        import pyarrow as pa

        table = pa.Table.from_arrays(
            [
                pa.array(chunk.sample),
                pa.array(chunk.seed),
                pa.array(chunk.misfit_max),
                pa.array(chunk.at_step),
                pa.array(self.drive[chunk.at_step]),
                pa.array(chunk.mobility_kept),
                pa.array(chunk.first_order_max),
            ],
            schema=self.schema,
        )
        self._writer.write_table(table)

    def __exit__(
        self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        if self._writer is not None:
            self._writer.close()
