"""linkwork: kinematics of mechanisms that change shape.

* Analyse closed-loop linkages (Gan & Pellegrino 2006): :func:`load` a built-in or a spec file, :func:`trace` its
  motion, find its bifurcation points and follow every branch.
* Synthesise shape-changing planar mechanisms (Shamsudin et al. 2013): :func:`synthesize`.

Radians inside the API; degrees in files, flags and printed tables.
"""

from __future__ import annotations

import pathlib
from typing import TYPE_CHECKING, Any

from linkwork.errors import AssemblyError, ConvergenceError, LinkworkError, SpecError
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.rank import Tolerances
from linkwork.kinematics.trace_result import Bifurcation, Branch, Trace
from linkwork.kinematics.tracer import trace

if TYPE_CHECKING:
    from linkwork.synthesis.problem import Problem
    from linkwork.synthesis.result import SynthesisResult

__version__ = "0.1.0"

__all__ = [
    "AssemblyError",
    "Bifurcation",
    "Branch",
    "ConvergenceError",
    "LinkworkError",
    "Mechanism",
    "SpecError",
    "Tolerances",
    "Trace",
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
    """A mechanism from a built-in name with its parameters (angles in DEGREES, as on the command line:
    ``load("bennett", alpha1=45)``) or from a TOML spec file (``load("my.toml")``)."""
    from linkwork.io.spec import resolve_spec

    return resolve_spec(spec, params).mechanism


def synthesize(problem: Problem | str | pathlib.Path, **kwargs: Any) -> SynthesisResult:
    """Synthesise a chain of rigid links that approximates every design profile of ``problem``.

    ``problem`` is a :class:`linkwork.synthesis.problem.Problem` or the path of a problem TOML file.
    """
    from linkwork.synthesis.problem import Problem as _Problem

    if not isinstance(problem, _Problem):
        from linkwork.io.problem import load_problem

        problem = load_problem(pathlib.Path(problem))
    from linkwork.synthesis import synthesize as _synthesize

    return _synthesize(problem, **kwargs)
