"""Data bundled with linkwork: the example synthesis problems (written by ``examples/make_examples.py``), reached
with :func:`example` through :mod:`importlib.resources`, so they work from an installed package."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from linkwork.errors import SpecError

EXAMPLES = ("wing", "closed", "fixed-end", "seat", "wing-six")
"""The example problems bundled with linkwork (``linkwork/data/examples/<name>/problem.toml``)."""


def example(name: str = "wing", file: str = "problem.toml") -> Path:
    """The problem file (``problem.toml``, or ``mechanize.toml`` for wing, seat and wing-six) of a bundled example (one of
    :data:`EXAMPLES`).

    Raises
    ------
    SpecError
        For an unknown name.
    """
    if name not in EXAMPLES:
        raise SpecError(f'unknown example "{name}"; expected one of {", ".join(EXAMPLES)}', key="example")
    path = Path(str(resources.files(__name__) / "examples" / name / file))
    if not path.is_file():
        raise SpecError(f"the bundled example is missing ({path}); reinstall linkwork", key="example")
    return path


def problem_file(spec: str | Path) -> Path:
    """The problem file that ``spec`` names: an existing file as it is, else a bundled example's problem file by
    name (``"wing"``), as built-in linkages are found by name; a name that is neither is a :class:`SpecError`."""
    path = Path(spec)
    if path.exists():
        return path
    if str(spec) in EXAMPLES:
        return example(str(spec))
    expected = "a problem file (TOML)"
    if not path.suffix and len(path.parts) == 1:  # a bare name: perhaps a misspelt example
        expected += f" or a bundled example ({', '.join(EXAMPLES)})"
    raise SpecError(f"{spec}: file not found; expected {expected}")
