"""Safe output: files are written into a staging folder and moved into place only when all of them succeeded."""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from rich.console import Console

console = Console(markup=False)
"""The console every summary is printed on (standard output). Markup is off: names, files and notes a user wrote
are printed as text (``[/]`` in a joint name is two brackets and a slash); styled words are :class:`rich.text.Text`."""


@contextlib.contextmanager
def staged_output(out: Path) -> Iterator[Path]:
    """Write a command's files into a temporary folder and move them into ``out`` only if all succeeded.

    A failure part way leaves ``out`` as it was: no half-written output.
    """
    out = Path(out)
    parent = out.resolve().parent
    parent.mkdir(parents=True, exist_ok=True)
    stage = Path(tempfile.mkdtemp(prefix=".linkwork-", dir=parent))
    try:
        yield stage
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
    out.mkdir(parents=True, exist_ok=True)
    for item in stage.iterdir():
        target = out / item.name
        if target.is_dir() and not target.is_symlink():
            shutil.rmtree(target)
        os.replace(item, target)
    shutil.rmtree(stage, ignore_errors=True)


def have_matplotlib() -> bool:
    """True when the optional plotting extra (``linkwork[viz]``) is installed."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True
