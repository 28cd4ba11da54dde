"""Default output folders: a command run without ``--out`` writes into ``out/<what>-<command>/``, a folder named
after what it ran, so that runs of different linkages, problems or studies never land in one folder.

``<what>`` is the built-in's name with its ``--set`` values (``hedgepeth-rods-n=6``), a spec, problem or study
file's stem (the folder's name for the generic stems linkwork writes, ``mechanism.toml`` and ``problem.toml``), a
bundled example's name (``wing``, ``wing-mechanize`` for ``wing/mechanize.toml``) or a study's ``name``.
Characters other than letters, digits and ``. _ = + -`` become ``_``, so the folder is one plain path segment
whatever the input's name.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

DEFAULT_ROOT = Path("out")
"""The folder every default output folder is made in (relative to the working directory)."""

MAX_NAME_CHARS = 80
"""The longest ``<what>`` part of a default folder's name (a longer one is cut)."""

#: File stems linkwork itself writes, too generic to name a run: the folder holding the file names it instead.
GENERIC_STEMS = frozenset({"mechanism", "problem", "study", "spec"})

_UNSAFE = re.compile(r"[^A-Za-z0-9._=+-]+")


def safe_segment(text: str) -> str:
    """``text`` as one plain path segment: unsafe characters as ``_``, no leading dot, at most
    :data:`MAX_NAME_CHARS` characters, never empty."""
    segment = _UNSAFE.sub("_", text).lstrip(".")[:MAX_NAME_CHARS]
    return segment or "run"


def _value(value: Any) -> str:
    """A ``--set`` value as written in a folder name (``6``, ``45``, ``0.25``)."""
    return f"{value:g}" if isinstance(value, float) else str(value)


def file_label(path: Path) -> str:
    """The name a spec, problem or study file gives a run: its stem, or its folder's name for a generic stem."""
    path = Path(path)
    if path.stem.lower() in GENERIC_STEMS and path.resolve().parent.name:
        return path.resolve().parent.name
    return path.stem


def spec_label(spec: str, params: Mapping[str, Any] | None = None) -> str:
    """The name of a linkage run: a spec file's :func:`file_label`, or a built-in's name, then its ``--set``
    values in the order given (``hedgepeth-rods-n=6``)."""
    path = Path(spec)
    base = (
        file_label(path)
        if path.suffix.lower() == ".toml" or path.is_file()
        else spec.replace("_", "-").lower()
    )
    return "-".join([base, *(f"{key}={_value(value)}" for key, value in (params or {}).items())])


def problem_label(problem: str | Path) -> str:
    """The name of a synthesis run: a bundled example's name (``wing``; ``wing-mechanize`` for
    ``wing/mechanize.toml``) or the problem file's :func:`file_label`."""
    path = Path(problem)
    if path.is_file():
        return file_label(path)
    parts = [*path.parts[:-1], path.stem] if path.suffix else list(path.parts)
    if parts and parts[-1].lower() in GENERIC_STEMS and len(parts) > 1:
        parts = parts[:-1]
    return "-".join(parts) or "problem"


def run_folder(command: str, what: str) -> Path:
    """The default output folder of ``command`` run on ``what``: ``out/<what>-<command>``."""
    return DEFAULT_ROOT / f"{safe_segment(what)}-{command}"


def out_help(command: str, example: str) -> str:
    """The ``--out`` help of a command with a default folder per run."""
    return (
        f"Output folder (default: {DEFAULT_ROOT}/NAME-{command}/, named after what was run, e.g. "
        f"{DEFAULT_ROOT}/{example}-{command}/)."
    )
