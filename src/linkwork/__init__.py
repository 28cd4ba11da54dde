"""linkwork: kinematics of mechanisms that change shape.

* Analyse closed-loop linkages (Gan & Pellegrino 2006): :func:`load` a built-in or a spec file, :func:`trace` its
  motion, find its bifurcation points and follow every branch.
* Synthesise shape-changing planar mechanisms (Shamsudin et al. 2013): :func:`synthesize`.

Radians everywhere in the Python API (built-in parameters of :func:`load` too); degrees in files, flags and
printed tables.
"""

from __future__ import annotations

import pathlib
from typing import TYPE_CHECKING, Any

from linkwork.errors import AssemblyError, ConvergenceError, LinkworkError, SpecError
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import Tolerances
from linkwork.kinematics.stops import StopReason
from linkwork.kinematics.trace_result import Bifurcation, Branch, Trace
from linkwork.kinematics.trace_stats import TraceStats
from linkwork.kinematics.tracer import trace
from linkwork.version import __version__ as __version__

if TYPE_CHECKING:
    from linkwork.synthesis.problem import Problem
    from linkwork.synthesis.result import SynthesisResult


__all__ = [
    "AssemblyError",
    "Bifurcation",
    "Branch",
    "ConvergenceError",
    "LinkworkError",
    "Mechanism",
    "SpecError",
    "StopReason",
    "Tolerances",
    "Trace",
    "TraceStats",
    "load",
    "synthesize",
    "trace",
]


def __getattr__(name: str) -> Any:
    """``lw.Path``: the traced result's former name, kept for one release as a deprecated alias of :class:`Trace`."""
    if name == "Path":
        import warnings

        warnings.warn(
            "linkwork.Path is renamed linkwork.Trace; the alias goes in the next release",
            DeprecationWarning,
            stacklevel=2,
        )
        return Trace
    raise AttributeError(f"module 'linkwork' has no attribute {name!r}")


def load(spec: str | pathlib.Path, **params: Any) -> Mechanism:
    """A mechanism from a built-in name with its parameters, or from a TOML spec file (``load("my.toml")``).

    Parameters are in API units like everything in the Python API: angles in RADIANS
    (``load("bennett", alpha1=np.radians(45))``); only files, ``--set`` flags and printed tables use degrees.
    ``linkwork linkages`` lists every built-in's parameters.
    """
    from linkwork.io.spec import resolve_spec

    _check_source("spec", spec, "a built-in name or the path of a spec file (TOML)")
    params = {key: _plain(value) for key, value in params.items()}
    return resolve_spec(spec, _file_units(spec, params)).mechanism


def _check_source(argument: str, value: Any, expected: str) -> None:
    """Refuse, as one :class:`SpecError` naming the argument, a ``value`` that is neither a string nor a path
    (``lw.load(3)``, ``lw.load(None)``, bytes: Python's ``TypeError`` from inside ``pathlib``)."""
    if not isinstance(value, str | pathlib.PurePath):
        raise SpecError(f"{argument}={value!r:.80}: expected {expected}")


def _plain(value: Any) -> Any:
    """A numpy scalar (``np.float32(0.5)``, ``np.int64(6)``, a 0-d array) as the plain Python number it holds,
    so that the API takes numpy's numbers wherever it takes Python's (as ``lw.trace`` does); anything else as it
    is (the parameter's check says what it expected)."""
    import numbers

    if hasattr(value, "ndim") and getattr(value, "ndim", None) == 0 and hasattr(value, "item"):
        value = value.item()
    if isinstance(value, bool):
        return value
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        return float(value)
    return value


def _file_units(spec: str | pathlib.Path, params: dict[str, Any]) -> dict[str, Any]:
    """Built-in parameters converted from API units (radians) to the file units ``resolve_spec`` reads."""
    if not params or isinstance(spec, pathlib.Path) or pathlib.Path(spec).suffix.lower() == ".toml":
        return params
    import math

    from linkwork.io.spec import import_builtins
    from linkwork.linkages.registry import REGISTRY, get

    import_builtins()
    if str(spec).replace("_", "-").lower() not in REGISTRY:
        return params  # a file name without .toml, or an unknown name: resolve_spec says which
    entry = get(str(spec))
    out = dict(params)
    for key, value in params.items():
        param = entry.params.get(key)
        if (
            param is not None
            and param.unit == "deg"
            and isinstance(value, int | float)
            and not isinstance(value, bool)
        ):
            out[key] = math.degrees(value)
    return out


def synthesize(problem: Problem | str | pathlib.Path, **kwargs: Any) -> SynthesisResult:
    """Synthesise a chain of rigid links that approximates every design profile of ``problem``.

    ``problem`` is a :class:`linkwork.synthesis.problem.Problem`, the path of a problem TOML file, or the name of
    a bundled example (``"wing"``, see :data:`linkwork.data.EXAMPLES`).
    """
    from linkwork.synthesis.problem import Problem as _Problem

    if not isinstance(problem, _Problem):
        _check_source(
            "problem", problem, "a Problem, the path of a problem file (TOML) or a bundled example's name"
        )
        from linkwork.data import problem_file
        from linkwork.io.problem import load_problem

        problem = load_problem(problem_file(problem))
    from linkwork.synthesis import synthesize as _synthesize

    return _synthesize(problem, **kwargs)
