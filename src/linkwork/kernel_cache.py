"""Where linkwork's compiled kernels are cached, keyed to their sources, and the marker that says it is ready.

numba's own cache (``cache=True``) checks a cached function against its own source file only: a kernel that calls
(or inlines) a kernel of another file would keep running the callee's old machine code after the callee is
edited. So every linkwork kernel is declared with :func:`kernel` (``numba.njit(cache=True)`` with the cache
directory chosen here) and cached in one directory named by a **key**: a hash of linkwork's version, numba's and
Python's versions and the source of every kernel module (:data:`KERNEL_MODULES`). Editing any kernel module
changes the key, so the next process compiles into a new, empty directory: stale machine code is never loaded.

The directory is ``$LINKWORK_CACHE_DIR/kernels-<key>`` when that variable is set, else
``<linkwork>/__pycache__/kernels-<key>`` when the package folder is writable, else
``$XDG_CACHE_HOME/linkwork/kernels-<key>`` (``~/.cache``). In it, ``ready.json`` (the **marker**) lists the groups
of kernels compiled into it (``tracing``, ``synthesis``, ``studies``), written only once a group is compiled; the
tracer reads it to choose compiled kernels or their plain-Python twins (:mod:`linkwork.kinematics.jit`), without
any of numba's private attributes.

This module is on the ground floor: kernels of every layer use it, and it imports nothing of linkwork but the
version.
"""

from __future__ import annotations

import contextlib
import hashlib
import inspect
import json
import os
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterable, Iterator, Sequence
from functools import cached_property
from pathlib import Path
from typing import Any


def _set_aside_refused_environment() -> dict[str, str]:
    """Take out of the environment, before numba is imported, a ``NUMBA_NUM_THREADS`` that numba would refuse
    with a traceback as it loads (``0``, ``-1``) or with a warning quoting its own source (``x``), and return it:
    ``linkwork`` refuses it in one line (``cli.common.environment_misuse``); the library runs on numba's default
    threads instead of failing to import."""
    refused = {}
    value = os.environ.get("NUMBA_NUM_THREADS")
    if value is not None and not (value.strip().isascii() and value.strip().isdigit() and int(value) >= 1):
        refused["NUMBA_NUM_THREADS"] = os.environ.pop("NUMBA_NUM_THREADS")
    return refused


REFUSED_ENVIRONMENT: dict[str, str] = _set_aside_refused_environment()
"""Environment variables set aside before numba was imported, with the values given (see above)."""

import numba  # noqa: E402  (after the environment is made safe for it)
from numba.core import config as numba_config  # noqa: E402

from linkwork.version import __version__  # noqa: E402

KERNEL_MODULES = (
    "kinematics/bidiagonal_7x6.py",
    "kinematics/bidiagonal_rows.py",
    "kinematics/dyad_solver.py",
    "kinematics/kernels.py",
    "kinematics/march.py",
    "kinematics/planar_rows.py",
    "kinematics/small_svd.py",
    "kinematics/stops.py",
    "kinematics/trig.py",
    "studies/first_order.py",
    "studies/imperfections.py",
    "studies/misfit.py",
    "synthesis/compiled.py",
    "synthesis/compiled_search.py",
)
"""Every module that defines kernels, or whose constants kernels freeze (``stops``), relative to the package."""

GROUPS = ("tracing", "synthesis", "studies")
"""The groups of kernels the marker lists."""

MARKER = "ready.json"
LOCK = "compiling.lock"
PREFIX = "kernels-"


def _writable(folder: Path) -> bool:
    """Whether ``folder`` exists or can be made, and a file can be written in it."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError:
        return False
    return True


def default_parent(root: Path) -> Path:
    """The folder that holds the ``kernels-<key>`` directories (see the module's docstring)."""
    chosen = os.environ.get("LINKWORK_CACHE_DIR", "").strip()
    if chosen:
        return Path(chosen).expanduser()
    in_tree = root / "__pycache__"
    if _writable(in_tree):
        return in_tree
    xdg = os.environ.get("XDG_CACHE_HOME", "").strip()
    user = (Path(xdg) if xdg else Path.home() / ".cache") / "linkwork"
    if _writable(user):
        return user
    return Path(tempfile.gettempdir()) / f"linkwork-cache-{os.getuid() if hasattr(os, 'getuid') else 0}"


class KernelCache:
    """The cache of the kernels defined in ``sources`` (paths relative to ``root``), keyed to their text."""

    def __init__(self, root: Path, sources: Sequence[str], version: str, parent: Path | None = None) -> None:
        self.root = Path(root)
        self.sources = tuple(sources)
        self.version = version
        self._parent = parent

    @cached_property
    def key(self) -> str:
        """16 hex digits of the SHA-256 of the versions and every source module's path and bytes."""
        digest = hashlib.sha256()
        for part in (self.version, numba.__version__, f"{sys.version_info[0]}.{sys.version_info[1]}"):
            digest.update(part.encode() + b"\0")
        for name in self.sources:
            digest.update(name.encode() + b"\0")
            digest.update((self.root / name).read_bytes() + b"\0")
        return digest.hexdigest()[:16]

    @cached_property
    def parent(self) -> Path:
        """The folder holding the cache directories of every key."""
        return self._parent if self._parent is not None else default_parent(self.root)

    @property
    def directory(self) -> Path:
        """The cache directory of the current sources (``kernels-<key>``)."""
        return self.parent / f"{PREFIX}{self.key}"

    @property
    def marker(self) -> Path:
        """The marker file (``ready.json``) of the current sources."""
        return self.directory / MARKER

    @property
    def lock(self) -> Path:
        """The lock file a background compile holds while it fills the cache."""
        return self.directory / LOCK

    # ---- declaring kernels
    def kernel(self, **options: Any) -> Callable[[Callable[..., Any]], Any]:
        """``numba.njit(cache=True, **options)``, caching in :attr:`directory`. Refuses a function whose module is
        not among the sources (its edits would not change the key)."""

        def decorate(fn: Callable[..., Any]) -> Any:
            source = Path(inspect.getfile(fn)).resolve()
            try:
                relative = source.relative_to(self.root.resolve()).as_posix()
            except ValueError:
                relative = str(source)
            if relative not in self.sources:
                raise RuntimeError(
                    f"{fn.__qualname__} in {relative} is a kernel, but {relative} is not in KERNEL_MODULES: "
                    "add it there so that editing it invalidates the compiled cache"
                )
            with self.cache_dir_set():
                return numba.njit(cache=True, **options)(fn)

        return decorate

    @contextlib.contextmanager
    def cache_dir_set(self) -> Iterator[None]:
        """numba's cache directory set to :attr:`directory` while kernels are declared (numba chooses a cached
        function's folder when it is declared), and put back afterwards: numba functions of other packages keep
        their own cache."""
        before = numba_config.CACHE_DIR  # type: ignore[attr-defined]
        numba_config.CACHE_DIR = str(self.directory)  # type: ignore[attr-defined]  # NUMBA_CACHE_DIR
        try:
            yield
        finally:
            numba_config.CACHE_DIR = before  # type: ignore[attr-defined]

    # ---- the marker
    def ready(self, group: str) -> bool:
        """Whether the marker of the current sources lists ``group`` as compiled."""
        return group in self._marked()

    def _marked(self) -> set[str]:
        try:
            content = json.loads(self.marker.read_text())
        except (OSError, ValueError):
            return set()
        if not isinstance(content, dict) or content.get("key") != self.key:
            return set()
        return {str(g) for g in content.get("groups", [])}

    def mark_ready(self, groups: Iterable[str]) -> None:
        """Add ``groups`` to the marker (written whole, then moved into place)."""
        content = {
            "key": self.key,
            "linkwork": self.version,
            "numba": numba.__version__,
            "python": sys.version.split()[0],
            "modules": list(self.sources),
            "groups": sorted(self._marked() | set(groups)),
        }
        self.directory.mkdir(parents=True, exist_ok=True)
        staged = self.marker.with_name(f".{MARKER}.{os.getpid()}")
        staged.write_text(json.dumps(content, indent=2) + "\n")
        staged.replace(self.marker)

    def remove_stale(self) -> list[Path]:
        """Delete the cache directories of other keys (older sources) when the parent is the package's own
        ``__pycache__`` (a shared folder may hold other installs' caches); returns them."""
        removed: list[Path] = []
        if self.parent.resolve() != (self.root / "__pycache__").resolve():
            return removed
        for folder in self.parent.glob(f"{PREFIX}*"):
            if folder.is_dir() and folder.name != self.directory.name:
                shutil.rmtree(folder, ignore_errors=True)
                removed.append(folder)
        return removed


CACHE = KernelCache(Path(__file__).resolve().parent, KERNEL_MODULES, __version__)
"""linkwork's kernel cache."""

kernel = CACHE.kernel

ROWS_OPTIONS = {"error_model": "numpy", "fastmath": {"contract"}}
"""The options of the planar rows' kernels (``kinematics.planar_rows``, ``kinematics.bidiagonal_rows``) and of every
pass they call as a compiled function of its own: no division check (their divisors are guarded), fused
multiply-adds. A pass called with these options computes what it did inlined into its caller. Passes that a large
kernel calls are compiled once each (specialised on the literal sizes they are called with, inlined or called by
LLVM as it sees fit) rather than inlined by numba (``inline="always"``): numba copies an inlined function's whole
intermediate code, its own inlined callees included, at every call site, which made those kernels' cold compile
minutes long."""
"""Declare a linkwork kernel: ``@kernel()``, ``@kernel(inline="always")`` (see :meth:`KernelCache.kernel`)."""
