"""The one writer of every output: output folders (:func:`staged_output`) and single files (:func:`write_file`).

The rules every command inherits by writing through here:

- **Ownership.** linkwork never replaces or deletes what it did not write. What it wrote into a folder is listed in
  that folder's :data:`MANIFEST` (``.linkwork-manifest.json``): the entries of each *run* (``trace``, ``synth``
  ...), and the single files written there (``export stl -o mine.stl`` records ``mine.stl`` in the manifest of
  ``mine.stl``'s folder), each with its :func:`fingerprint`. An existing entry not listed there, or listed but
  holding something else (edited since), stops the command (exit 2) naming it.
- **Folders from before fingerprints.** An entry an older manifest (format 2, or a list of names) lists is
  linkwork's only if it was not modified after that manifest was written (the old writer wrote it after every
  entry): an edited one is refused as a changed one is. A stale one is removed only when the command also writes
  anew, unchanged, entries the old manifest lists in the same part (a manifest copied into a user's folder may
  list any name); an old entry the command leaves keeps its manifest's time in the new manifest (``legacy``).
- **A run replaces its own earlier results as a whole.** The entries an earlier run wrote into the folder and this
  run does not write are removed, so no stale file (an old ``viewer.html``) stays behind. A *part* of a run (the
  mechanization a ``synth`` run adds, ``linkwork mechanize`` into a synth folder) replaces only the entries of the
  same part. Single files are never removed by a run.
- **No writing through symbolic links.** An entry to be written that is a symbolic link is refused (even if it is
  listed: linkwork never writes links); the manifest and every file are written to new files and renamed into
  place, so a link planted under a name linkwork uses is replaced, never followed.
- **All or nothing.** Files are written into a staging folder (a temporary file for a single file) beside the
  destination and moved into place only when all were written; the staging is removed on every exit path (an
  error, Ctrl-C, SIGTERM, SIGHUP).
- **Errors name the user's path.** A folder that cannot be written, a full disk or a file-size limit is one line
  naming the ``--out`` given, never a staging file: exit 2 when the place cannot be written at all, exit 3 when
  writing failed part way (nothing is left behind).
- **Finite numbers.** :func:`require_finite` is the one check that every number a writer puts in a file is finite
  (``--scale inf``, or lengths overflowing to infinity, are refused with exit 2 before anything is written).
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import os
import shutil
import signal
import tempfile
import threading
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from linkwork.errors import RequestNotMetError, SpecError
from linkwork.interrupts import Terminated, when_safe
from linkwork.io.toml_reader import show
from linkwork.messages import show_path

__all__ = [
    "MANIFEST",
    "Manifest",
    "check_output_file",
    "check_output_folder",
    "fingerprint",
    "folder_lock",
    "json_text",
    "require_finite",
    "staged_output",
    "unmodified_since",
    "write_file",
]

MANIFEST = ".linkwork-manifest.json"
"""The file in a folder listing the entries linkwork wrote there (the only ones it may replace or remove)."""

RUN = "run"
"""The part name of a whole run (see :func:`staged_output`)."""


@contextlib.contextmanager
def folder_lock(folder: Path) -> Iterator[None]:
    """Hold an exclusive lock on ``folder`` (``flock`` on the folder itself: no file is added to it) while its
    entries and :data:`MANIFEST` are checked and changed, so two commands writing into one folder at once take
    turns: each finds the other's entries recorded with their fingerprints, and no run's files are mixed with
    another's. Where ``flock`` is not available (Windows) nothing is held."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not on POSIX
        yield
        return
    handle = os.open(folder, os.O_RDONLY)
    try:
        fcntl.flock(handle, fcntl.LOCK_EX)
        yield
    finally:
        os.close(handle)  # closing releases the lock


def fingerprint(path: Path) -> str:
    """What an entry linkwork wrote holds: ``sha256:<hex>`` of a file's bytes, or of a folder's entries (their
    relative paths and bytes, in order). Recorded in the :data:`MANIFEST`, it tells linkwork's own entry from one
    with the same name that someone else wrote or changed since (a manifest copied or planted into a folder
    listing a user's ``thesis.docx``, a ``path.csv`` edited and saved by a spreadsheet): those are never replaced
    or removed. A copied folder keeps its entries' bytes, so linkwork still owns them there."""
    digest = hashlib.sha256()
    if path.is_dir() and not path.is_symlink():
        for item in sorted(path.rglob("*")):
            if item.is_file() and not item.is_symlink():
                digest.update(str(item.relative_to(path)).encode("utf-8", "surrogateescape") + b"\0")
                _hash_file(item, digest)
        return "sha256:" + digest.hexdigest()
    _hash_file(path, digest)
    return "sha256:" + digest.hexdigest()


def _hash_file(path: Path, digest: Any) -> None:
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)


class Manifest:
    """What linkwork wrote into one folder: ``parts`` (part name -> entries of that part of the last run),
    ``files`` (single files written there), ``fingerprints`` (entry -> :func:`fingerprint` when written) and
    ``legacy`` (entry -> when the manifest that listed it without a fingerprint was written, in ns since the
    epoch).

    Stored as JSON ``{"format": 3, "parts": {...}, "files": [...], "fingerprints": {...}, "legacy": {...}}``;
    format 2 (no fingerprints) and the earlier list of names are still read. An entry such a manifest lists has
    no fingerprint: it is *legacy*, its time that manifest file's modification time (the old writer wrote the
    manifest after every entry of the command), and it keeps that time in every manifest written after, until a
    command writes the entry anew (see :meth:`is_ours` and :func:`staged_output` for what a legacy entry may
    be used for)."""

    def __init__(
        self,
        parts: dict[str, set[str]] | None = None,
        files: set[str] | None = None,
        fingerprints: dict[str, str] | None = None,
        legacy: dict[str, int] | None = None,
    ) -> None:
        self.parts = parts or {}
        self.files = files or set()
        self.fingerprints = fingerprints or {}
        self.legacy = legacy or {}

    def is_ours(self, folder: Path, name: str) -> bool:
        """Whether the entry ``name`` of ``folder`` is one linkwork wrote and nobody changed since: listed, and
        holding what its fingerprint says. A legacy entry (listed by a manifest from before fingerprints) counts
        as unchanged when it was not modified after that manifest was written (:func:`unmodified_since`): a
        result a user edited since is newer than the manifest, and is refused as a changed one is."""
        if name not in self.owned():
            return False
        recorded = self.fingerprints.get(name)
        if recorded is None:
            written = self.legacy.get(name)
            return written is not None and unmodified_since(folder / name, written)
        try:
            return fingerprint(folder / name) == recorded
        except OSError:
            return False

    def changed(self, folder: Path, name: str) -> bool:
        """Whether ``name`` is listed but holds something else than linkwork wrote there."""
        return name in self.owned() and not self.is_ours(folder, name)

    @classmethod
    def read(cls, folder: Path) -> Manifest:
        """The manifest of ``folder`` (an absent, unreadable or linked manifest lists nothing)."""
        file = folder / MANIFEST
        try:
            if file.is_symlink() or not file.is_file() or file.stat().st_size > 1 << 20:
                return cls()
            written = file.stat().st_mtime_ns
            data = json.loads(file.read_text(encoding="utf-8"))
        except (OSError, ValueError, RecursionError):
            return cls()
        if isinstance(data, list):
            manifest = cls({RUN: _names(data)})
        elif isinstance(data, dict):
            parts = data.get("parts")
            parts = parts if isinstance(parts, dict) else {}
            prints = data.get("fingerprints")
            prints = prints if isinstance(prints, dict) else {}
            times = data.get("legacy")
            times = times if isinstance(times, dict) else {}
            manifest = cls(
                {str(k): _names(v) for k, v in parts.items() if isinstance(v, list)},
                _names(data.get("files")),
                {k: v for k, v in prints.items() if isinstance(k, str) and isinstance(v, str)},
                {k: v for k, v in times.items() if isinstance(k, str) and type(v) is int},
            )
        else:
            return cls()
        # Every listed entry without a fingerprint is legacy: its recorded time, else this manifest's own.
        manifest.legacy = {
            name: min(manifest.legacy.get(name, written), written)
            for name in manifest.owned() - set(manifest.fingerprints)
        }
        return manifest

    def owned(self) -> set[str]:
        """Every entry linkwork wrote into the folder."""
        return set().union(*self.parts.values(), self.files)

    def write(self, folder: Path) -> None:
        """Store the manifest (a new file renamed into place: a link in its place is replaced, not followed)."""
        owned = self.owned()
        data = {
            "format": 3,
            "parts": {k: sorted(v) for k, v in sorted(self.parts.items()) if v},
            "files": sorted(self.files),
            "fingerprints": {k: v for k, v in sorted(self.fingerprints.items()) if k in owned},
            "legacy": {
                k: v for k, v in sorted(self.legacy.items()) if k in owned and k not in self.fingerprints
            },
        }
        fd, name = tempfile.mkstemp(prefix=".linkwork-manifest-", dir=folder)
        _usual_mode(Path(name))
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as handle:
                handle.write(json.dumps(data, indent=1) + "\n")
            os.replace(name, folder / MANIFEST)
        finally:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(name)


def unmodified_since(path: Path, written: int) -> bool:
    """Whether the entry ``path`` (a file, or a folder and everything in it; never a symbolic link) was last
    modified no later than ``written`` (ns since the epoch): an entry a legacy manifest lists, unchanged since that
    manifest was written. Modification times are the file system's own, compared on one file system; an entry
    changed and then given an older time (``touch -d``, ``cp -p`` from elsewhere) is not told apart."""
    try:
        if path.is_symlink() or not _exists(path):
            return False
        latest = path.lstat().st_mtime_ns
        if path.is_dir():
            for item in path.rglob("*"):
                latest = max(latest, item.lstat().st_mtime_ns)
    except OSError:
        return False
    return latest <= written


def _usual_mode(file: Path) -> None:
    """Give a temporary file (created private) the mode a new file gets (``0o666`` less the umask)."""
    mask = os.umask(0o022)
    os.umask(mask)
    with contextlib.suppress(OSError):
        file.chmod(0o666 & ~mask)


def _names(value: Any) -> set[str]:
    return (
        {n for n in value if isinstance(n, str) and n and "/" not in n and n not in (".", "..")}
        if isinstance(value, list)
        else set()
    )


_shown = show_path


def _exists(path: Path) -> bool:
    return path.exists() or path.is_symlink()


def check_output_folder(out: Path, names: Iterable[str] = (), flag: str = "--out") -> None:
    """Refuse, before any work, an ``--out`` that is not a folder, or ``names`` in it that linkwork did not write
    or that are symbolic links.

    Raises
    ------
    SpecError
        ``--out`` names an existing file, or an entry to be written exists in it without being listed in its
        :data:`MANIFEST`, or is a symbolic link.
    """
    out = Path(out)
    with _unwritable_place(out, flag), _lock_if_folder(out):
        _check_output_folder(out, names, flag)


@contextlib.contextmanager
def _lock_if_folder(folder: Path) -> Iterator[None]:
    """:func:`folder_lock` on ``folder`` when it is an existing folder (else nothing to hold): a check reads the
    entries and the manifest while no other command is half way through changing them."""
    if folder.is_dir():
        with folder_lock(folder):
            yield
    else:
        yield


@contextlib.contextmanager
def _unwritable_place(out: Path, flag: str) -> Iterator[None]:
    """Turn an ``OSError`` met while looking at an output path (a name too long, a loop of links, a folder on
    the way that cannot be searched) into the one ``SpecError`` line naming ``flag`` and the path (exit 2)."""
    try:
        yield
    except OSError as exc:
        raise SpecError(
            f"{flag} {_shown(out)}: cannot write there ({exc.strerror or exc}); expected a place linkwork may "
            "create and write into"
        ) from None


def _check_output_folder(out: Path, names: Iterable[str], flag: str) -> None:
    if _exists(out) and not out.is_dir():
        raise SpecError(f"{flag} {_shown(out)}: is a file; expected a folder to write into")
    if not out.is_dir():
        for parent in out.absolute().parents:  # the nearest existing folder on the way must be a folder
            if _exists(parent):
                if not parent.is_dir():
                    raise SpecError(
                        f"{flag} {_shown(out)}: {_shown(parent)} on the way is a file; expected a folder to "
                        "write into"
                    )
                break
        return
    manifest = Manifest.read(out)
    for name in names:
        target = out / name
        if target.is_symlink():
            raise SpecError(
                f"{flag} {_shown(out)}: {show(name)} is a symbolic link; linkwork never writes through links, "
                "move it away or choose another folder"
            )
        if _exists(target) and manifest.changed(out, name):
            raise SpecError(
                f"{flag} {_shown(out)}: {show(name)} holds something else than linkwork wrote there (changed "
                f"since, or listed by a {MANIFEST} copied from elsewhere); move it away or choose another {flag} "
                "(linkwork never overwrites what it did not write)"
            )
        if _exists(target) and not manifest.is_ours(out, name):
            raise SpecError(
                f"{flag} {_shown(out)}: {show(name)} exists and was not written by linkwork; move it away "
                f"or choose another {flag} (linkwork never overwrites what it did not write)"
            )


@contextlib.contextmanager
def _cleanup_on_signals() -> Iterator[None]:
    """While writing, turn SIGTERM (and SIGHUP) into an exception, so the staging is removed: a
    :class:`~linkwork.interrupts.Terminated`, the ``SystemExit(128 + signum)`` the command line reports in one
    line."""

    def stop(signum: int, frame: FrameType | None) -> None:
        raise Terminated(signum)

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    wanted = [signal.SIGTERM] + ([signal.SIGHUP] if hasattr(signal, "SIGHUP") else [])
    previous = {sig: signal.signal(sig, when_safe(stop)) for sig in wanted}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


_FULL = {errno.ENOSPC, errno.EFBIG, getattr(errno, "EDQUOT", errno.ENOSPC)}


_WRITE_ERRNOS = _FULL | {errno.EACCES, errno.EPERM, errno.EROFS, errno.EIO}


def _is_write_error(exc: OSError, staging: Path) -> bool:
    """Whether ``exc`` is a failure to write into ``staging`` (by its file name, or, for a writer that names no
    file, by its kind: a full disk, a size limit, a refused permission)."""
    if exc.filename is not None:
        return str(exc.filename).startswith(str(staging))
    return exc.errno in _WRITE_ERRNOS


def _write_failed(exc: OSError, out: Path, flag: str, staging: Path) -> Exception:
    """The one line for a write that failed in the staging: it names ``out``, never the staging path."""
    reason = exc.strerror or str(exc).replace(str(staging), str(out))
    if exc.errno in _FULL:
        return RequestNotMetError(
            f"{flag} {_shown(out)}: writing failed ({reason}); nothing was written, {_shown(out)} is as it was"
        )
    return SpecError(
        f"{flag} {_shown(out)}: cannot write there ({reason}); expected a place linkwork may create and write into"
    )


def _stage_beside(out: Path, flag: str, *, folder: bool) -> Path:
    """A new staging folder (or file) in ``out``'s folder (same file system: the final move is a rename)."""
    try:
        # beside the real folder (an --out that is a link to a folder elsewhere): the final move is a rename
        parent = (out.resolve() if folder else out.absolute()).parent
        parent.mkdir(parents=True, exist_ok=True)
        if folder:
            return Path(tempfile.mkdtemp(prefix=".linkwork-", dir=parent))
        fd, name = tempfile.mkstemp(prefix=".linkwork-", suffix=out.suffix, dir=parent)
        os.close(fd)
        _usual_mode(Path(name))
        return Path(name)
    except OSError as exc:
        raise SpecError(
            f"{flag} {_shown(out)}: cannot write there ({exc.strerror or exc}); expected a place linkwork may "
            "create and write into"
        ) from None


@contextlib.contextmanager
def staged_output(out: Path, *, part: str = RUN, flag: str = "--out") -> Iterator[Path]:
    """Write a command's files into a staging folder and move them into ``out`` only if all succeeded.

    ``part`` names what is written: a whole run (the default) replaces every entry earlier runs wrote into
    ``out`` (the stale ones are removed); a named part (``"mechanize"``) replaces only the entries of that part,
    keeping the rest of the run it adds to. A failure part way (an error, Ctrl-C, SIGTERM) removes the staging
    and leaves ``out`` as it was; an entry linkwork did not write, or a symbolic link, under a name to be written
    stops the command with a :class:`SpecError` and ``out`` unchanged.
    """
    out = Path(out)
    check_output_folder(out, flag=flag)
    stage = _stage_beside(out, flag, folder=True)
    try:
        with _cleanup_on_signals():
            try:
                yield stage
            except OSError as exc:
                if not _is_write_error(exc, stage):
                    raise  # not a write into the staging (a file read on the way)
                raise _write_failed(exc, out, flag, stage) from None
            names = sorted(item.name for item in stage.iterdir() if item.name != MANIFEST)
            try:
                out.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise _write_failed(exc, out, flag, stage) from None
            with folder_lock(out):  # two runs into one --out: one after the other, never mixed
                with _unwritable_place(out, flag):
                    _check_output_folder(out, names, flag)
                try:
                    _move_into(stage, out, names, part)
                except OSError as exc:
                    raise _write_failed(exc, out, flag, stage) from None
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _move_into(stage: Path, out: Path, names: list[str], part: str) -> None:
    """Move the staged ``names`` into ``out``, remove the stale entries of the replaced parts, record them.

    A stale entry with a fingerprint is removed when it still holds what linkwork wrote. A stale legacy entry
    (listed by a manifest from before fingerprints) is removed only when its part is *vouched for*: this command
    writes anew at least one legacy entry of that part, and every such one was there, unchanged since that
    manifest (checked before any work, :func:`_check_output_folder`); and it is itself unchanged since. Otherwise
    it is only forgotten (left where it is, no longer listed): a manifest copied or planted into a user's folder
    may list any name, and nothing else tells a user's file from linkwork's."""
    out.mkdir(parents=True, exist_ok=True)
    manifest = Manifest.read(out)
    replaced = set(manifest.parts) if part == RUN else {part}
    stale = set().union(*(manifest.parts[p] for p in replaced if p in manifest.parts)) - set(names)
    vouched = {p for p in replaced if _vouched(manifest, out, p, names)}
    removable = {
        name
        for name in stale
        if not (out / name).is_symlink()
        and _exists(out / name)
        and manifest.is_ours(out, name)
        and (name in manifest.fingerprints or any(name in manifest.parts.get(p, ()) for p in vouched))
    }  # decided before any move: the entries to be written anew are compared as they were
    # first record the names about to move in (an interruption between two moves leaves only entries the
    # manifest lists, which the next run may replace), then move
    prints = {name: fingerprint(stage / name) for name in names}
    early = Manifest(
        {k: set(v) for k, v in manifest.parts.items()},
        set(manifest.files),
        {**manifest.fingerprints, **prints},
        {k: v for k, v in manifest.legacy.items() if k not in prints},
    )
    early.parts.setdefault(part, set()).update(names)
    early.write(out)
    for name in names:
        target = out / name
        if target.is_dir() and not target.is_symlink():
            shutil.rmtree(target)
        os.replace(stage / name, target)
    for name in sorted(removable):
        target = out / name
        if target.is_dir():
            shutil.rmtree(target)
        else:
            target.unlink()
    for p in replaced:
        manifest.parts.pop(p, None)
    for p in manifest.parts:
        manifest.parts[p] -= set(names)
    manifest.parts[part] = set(names)
    manifest.files -= set(names) | stale
    manifest.fingerprints.update(prints)
    for name in names:
        manifest.legacy.pop(name, None)
    manifest.write(out)


def _vouched(manifest: Manifest, out: Path, part: str, names: list[str]) -> bool:
    """Whether the legacy entries of ``part`` that this command writes anew (``names``) show the manifest's
    ``part`` to be linkwork's own: at least one, each there and unchanged since that manifest was written."""
    anew = [name for name in names if name in manifest.parts.get(part, ()) and name in manifest.legacy]
    return bool(anew) and all(manifest.is_ours(out, name) for name in anew)


def check_output_file(file: Path, flag: str = "--out") -> None:
    """Refuse, before any work, a single output ``file`` that is a folder, a symbolic link, or an existing file
    linkwork did not write (not listed in the :data:`MANIFEST` of its folder)."""
    file = Path(file)
    with _unwritable_place(file, flag), _lock_if_folder(file.absolute().parent):
        _check_output_file(file, flag)


def _check_output_file(file: Path, flag: str) -> None:
    if file.is_symlink():
        raise SpecError(
            f"{flag} {_shown(file)}: is a symbolic link; linkwork never writes through links, choose another file"
        )
    if file.is_dir():
        raise SpecError(f"{flag} {_shown(file)}: is a folder; expected a file name to write")
    if file.name == MANIFEST:
        raise SpecError(f"{flag} {_shown(file)}: is linkwork's manifest; choose another file name")
    manifest = Manifest.read(file.absolute().parent) if _exists(file) else Manifest()
    runs = sorted(part for part, names in manifest.parts.items() if file.name in names)
    if runs and file.name not in manifest.files:
        # An entry of a run's results (a trace folder's mechanism.toml, path.csv): other commands read it back
        # from the folder (export reads the very folder it writes into), so a single file written over it would
        # break that result, not replace an earlier export.
        raise SpecError(
            f"{flag} {_shown(file)}: is one of the results of a linkwork run in that folder ({runs[0]}, listed in "
            f"{MANIFEST}), which other commands read back; choose another file name"
        )
    if _exists(file) and manifest.changed(file.absolute().parent, file.name):
        raise SpecError(
            f"{flag} {_shown(file)}: holds something else than linkwork wrote there (changed since, or listed by "
            f"a {MANIFEST} copied from elsewhere); move it away or choose another file (linkwork never overwrites "
            "what it did not write)"
        )
    if _exists(file) and file.name not in manifest.owned():
        raise SpecError(
            f"{flag} {_shown(file)}: exists and was not written by linkwork; move it away or choose another "
            f"file (linkwork never overwrites what it did not write; what it wrote is listed in {MANIFEST} beside it)"
        )


def write_file(file: str | Path, write: Callable[[Path], Any], *, flag: str = "--out") -> Path:
    """Write one output file: ``write(tmp)`` writes a temporary file beside ``file``, which is then renamed to
    ``file`` and recorded in the folder's :data:`MANIFEST`. A failure part way (an error, Ctrl-C, SIGTERM) leaves
    no half-written file, and any earlier ``file`` as it was; see :func:`check_output_file` for what is refused."""
    file = Path(file)
    check_output_file(file, flag)
    tmp = _stage_beside(file, flag, folder=False)
    try:
        with _cleanup_on_signals():
            try:
                write(tmp)
            except OSError as exc:
                if not _is_write_error(exc, tmp):
                    raise
                raise _write_failed(exc, file, flag, tmp) from None
            folder = file.absolute().parent
            try:
                written = fingerprint(tmp)
                with folder_lock(folder):  # the manifest read, changed and written by one command at a time
                    with _unwritable_place(file, flag):
                        _check_output_file(file, flag)
                    os.replace(tmp, file)
                    manifest = Manifest.read(folder)
                    manifest.files.add(file.name)
                    manifest.fingerprints[file.name] = written
                    manifest.legacy.pop(file.name, None)
                    for names in manifest.parts.values():
                        names.discard(file.name)
                    manifest.write(folder)
            except OSError as exc:
                raise _write_failed(exc, file, flag, tmp) from None
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
    return file


def json_text(value: Any, indent: int | None = 2) -> str:
    """``value`` as standard JSON text (with a final newline): numpy numbers and arrays as JSON numbers and lists,
    and a computed quantity that is not finite (undefined, such as a condition number at a singular point)
    written as ``null``, never as the ``NaN`` or ``Infinity`` that strict JSON readers refuse."""

    def plain(v: Any) -> Any:
        if isinstance(v, dict):
            return {str(k): plain(x) for k, x in v.items()}
        if isinstance(v, list | tuple | np.ndarray):
            return [plain(x) for x in v]
        if isinstance(v, np.generic):
            v = v.item()
        if isinstance(v, float) and not np.isfinite(v):
            return None
        return v

    return json.dumps(plain(value), indent=indent, allow_nan=False) + "\n"


def require_finite(values: ArrayLike, what: str) -> np.ndarray:
    """``values`` as a float array, or a :class:`SpecError` (exit 2) when any is not finite: the one check every
    writer makes on the numbers it writes. ``what`` says what they are and where they came from (``"the
    solids' coordinates (--scale 1e308 times the trace's lengths)"``)."""
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise SpecError(f"{what}: expected numbers") from None
    if not np.all(np.isfinite(array)):
        bad = array[~np.isfinite(array)].ravel()[0]
        raise SpecError(f"{what}: expected finite numbers, got {bad} (nothing was written)")
    return array
