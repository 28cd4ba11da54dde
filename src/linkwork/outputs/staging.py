"""Safe output: files are written into a staging folder and moved into place only when all of them succeeded,
never over anything linkwork did not write (a manifest in the output folder lists what it wrote)."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import tempfile
import threading
from collections.abc import Iterable, Iterator
from pathlib import Path
from types import FrameType

from rich.console import Console, ConsoleDimensions

from linkwork.errors import SpecError
from linkwork.io.toml_reader import show

FILE_WIDTH = 10_000
"""The width (characters) of the console when standard output is a file or a pipe and ``COLUMNS`` is not set."""


class _SummaryConsole(Console):
    """A console as wide as a terminal on a terminal, and :data:`FILE_WIDTH` wide on a file or a pipe (unless
    ``COLUMNS`` says otherwise), so a table saved to a file keeps its full headers and rows ("transmission", not
    "transmiss...") instead of being squeezed into 80 columns."""

    @property
    def size(self) -> ConsoleDimensions:
        size = super().size
        if self.is_terminal or self._width is not None or "COLUMNS" in os.environ:
            return size
        return ConsoleDimensions(max(size.width, FILE_WIDTH), size.height)

    @size.setter
    def size(self, new_size: tuple[int, int]) -> None:
        self._width, self._height = new_size


console: Console = _SummaryConsole(markup=False)
"""The console every summary is printed on (standard output). Markup is off: names, files and notes a user wrote
are printed as text (``[/]`` in a joint name is two brackets and a slash); styled words are :class:`rich.text.Text`."""


MANIFEST = ".linkwork-manifest.json"
"""The file in an output folder listing the entries linkwork wrote there (the only ones it may replace)."""


def _manifest(out: Path) -> set[str]:
    """The names linkwork wrote into ``out`` before (an unreadable manifest lists nothing)."""
    try:
        names = json.loads((out / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return set()
    return {n for n in names if isinstance(n, str)} if isinstance(names, list) else set()


def check_output_folder(out: Path, names: Iterable[str] = ()) -> None:
    """Refuse, before any work, an ``--out`` that is not a folder, or ``names`` in it that linkwork did not write.

    Raises
    ------
    SpecError
        ``--out`` names an existing file, or an entry to be written exists in it without being listed in its
        :data:`MANIFEST` (a user's file is never overwritten or deleted).
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise SpecError(f"--out {show(str(out))}: is a file; expected a folder to write into")
    if not out.is_dir():
        return
    ours = _manifest(out)
    for name in names:
        if (out / name).exists() or (out / name).is_symlink():
            if name not in ours:
                raise SpecError(
                    f"--out {show(str(out))}: {show(name)} exists and was not written by linkwork; move it away "
                    "or choose another --out (linkwork never overwrites what it did not write)"
                )


@contextlib.contextmanager
def _cleanup_on_signals(stage: Path) -> Iterator[None]:
    """While staging, turn SIGTERM (and SIGHUP) into an exception, so the staging folder is removed."""

    def stop(signum: int, frame: FrameType | None) -> None:
        raise SystemExit(128 + signum)

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    wanted = [signal.SIGTERM] + ([signal.SIGHUP] if hasattr(signal, "SIGHUP") else [])
    previous = {sig: signal.signal(sig, stop) for sig in wanted}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


@contextlib.contextmanager
def staged_output(out: Path) -> Iterator[Path]:
    """Write a command's files into a temporary folder and move them into ``out`` only if all succeeded.

    A failure part way (an error, Ctrl-C, SIGTERM) removes the staging folder and leaves ``out`` as it was: no
    half-written output. Only entries linkwork wrote before (listed in ``out``'s :data:`MANIFEST`) are
    replaced; any other existing entry of the same name stops the command with a :class:`SpecError` and
    ``out`` unchanged.
    """
    out = Path(out)
    check_output_folder(out)
    try:
        parent = out.resolve().parent
        parent.mkdir(parents=True, exist_ok=True)
        stage = Path(tempfile.mkdtemp(prefix=".linkwork-", dir=parent))
    except OSError as exc:
        raise SpecError(
            f"--out {show(str(out))}: cannot write there ({exc.strerror or exc}); expected a folder linkwork may "
            "create and write into"
        ) from None
    try:
        with _cleanup_on_signals(stage):
            yield stage
            names = sorted(item.name for item in stage.iterdir() if item.name != MANIFEST)
            check_output_folder(out, names)
            out.mkdir(parents=True, exist_ok=True)
            ours = _manifest(out) | set(names)
            for name in names:
                target = out / name
                if target.is_dir() and not target.is_symlink():
                    shutil.rmtree(target)
                os.replace(stage / name, target)
            _write_manifest(out, ours)
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _write_manifest(out: Path, names: set[str]) -> None:
    """Record (atomically) the entries linkwork wrote into ``out``."""
    part = out / (MANIFEST + ".part")
    part.write_text(json.dumps(sorted(names), indent=0) + "\n", encoding="utf-8")
    os.replace(part, out / MANIFEST)


def have_matplotlib() -> bool:
    """True when the optional plotting extra (``linkwork[viz]``) is installed."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True
