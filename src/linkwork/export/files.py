"""Writing one export file safely, through the one writer (:func:`linkwork.io.writer.write_file`): into a
temporary file beside it, moved into place only when complete, never over a file linkwork did not write, never
through a symbolic link."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from linkwork.io.writer import write_file


def write_whole(file: str | Path, write: Callable[[Path], Any]) -> Path:
    """Call ``write(tmp)`` on a temporary path in ``file``'s folder, then move it to ``file`` (see
    :func:`linkwork.io.writer.write_file`)."""
    return write_file(file, write)
