"""Linkage spec files: read a TOML description of a linkage into a :class:`Mechanism`, and write one back.

A spec file is data, never code: it is parsed with :mod:`tomllib` and every key is checked for its type,
length and range. Angles are in degrees in the file (``angles = "rad"`` switches the whole file to radians)
and in radians in the returned mechanism. A mistake is one :class:`~linkwork.errors.SpecError` line naming the
file, the key path and what was expected, for example
``bennett.toml: loop.joints[2].alpha: expected a number, got "abc"``; joints are counted from 0, so
``joints[2]`` is the third ``[[loop.joints]]`` block (joint ``C`` by default).

Two forms (see ``docs/spec-format.md`` for every key):

* ``[loop]``: one closed loop of revolute joints in loop order, in the ``dh``, ``hinge-lines`` or ``rods``
  convention (docs/spec-format.md; docs/architecture.md, "Contracts");
* ``[mechanism]``: joints between named bodies, each a revolute (``R``) or prismatic (``P``) joint on a
  line in the start configuration; the loops are a cycle basis of the body graph, ``planar = true`` keeps
  the three planar closure equations per loop.

Example
-------
.. code-block:: toml

    name = "Bennett 45/75"
    angles = "deg"

    [loop]
    convention = "dh"
    couple = [["A", "C"], ["B", "D"]]

    [[loop.joints]]
    theta = 90.0
    a = 1.0
    alpha = 45.0
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from linkwork.errors import AssemblyError, SpecError
from linkwork.io.spec_reader import (
    ANGLE_UNITS,
    CONVENTIONS,
    TOP_KEYS,
    SpecReader,
    read_loop_table,
    read_mechanism_table,
    read_points_table,
)

# The reader's key tables and limits and the writer keep their old import path, ``linkwork.io.spec``.
from linkwork.io.spec_reader import JOINT_KEYS as JOINT_KEYS
from linkwork.io.spec_reader import LOOP_KEYS as LOOP_KEYS
from linkwork.io.spec_reader import MAX_JOINTS as MAX_JOINTS
from linkwork.io.spec_reader import MECHANISM_JOINT_KEYS as MECHANISM_JOINT_KEYS
from linkwork.io.spec_reader import MECHANISM_KEYS as MECHANISM_KEYS
from linkwork.io.spec_reader import MIN_LOOP_JOINTS as MIN_LOOP_JOINTS
from linkwork.io.spec_reader import POINT_KEYS as POINT_KEYS
from linkwork.io.spec_reader import ROD_KEYS as ROD_KEYS
from linkwork.io.spec_reader import Couplings as Couplings
from linkwork.io.spec_writer import dump_spec
from linkwork.io.toml_reader import MAX_NAME_CHARS, escape_line, read_toml, show
from linkwork.kinematics.chains import Assembly
from linkwork.kinematics.mechanism import Mechanism
from linkwork.kinematics.normalization import near_mobility
from linkwork.names import name_problem

__all__ = ["CONVENTIONS", "LoadedSpec", "dump_spec", "load_spec", "resolve_spec"]


@dataclass(frozen=True)
class LoadedSpec:
    """A linkage read from a spec file or built from a built-in name.

    Attributes
    ----------
    mechanism
        The assembled mechanism, couplings and fixed joints applied.
    assembly
        For the ``dh`` and ``rods`` conventions, how the start was closed onto the loop (residual before and
        after, correction per joint in radians); ``None`` when the start is exact by construction
        (``hinge-lines``, ``[mechanism]``, built-ins).
    source
        The file read, or ``None`` for a built-in linkage.
    """

    mechanism: Mechanism
    assembly: Assembly | None
    source: Path | None

    @property
    def max_correction(self) -> float:
        """Largest correction of a joint (radians) applied to close the start; 0 when none was needed."""
        if self.assembly is None or self.assembly.correction.size == 0:
            return 0.0
        return float(np.max(np.abs(self.assembly.correction)))


# ----------------------------------------------------------------------------------------------------------
# reading
def load_spec(path: str | Path, *, closure_tol: float = 1e-12) -> LoadedSpec:
    """Read a linkage spec file (TOML) into an assembled mechanism.

    Parameters
    ----------
    path
        The spec file.
    closure_tol
        The largest least-squares closure misfit accepted when a ``dh`` or ``rods`` loop is assembled (play in
        the hinges); it is recorded in :attr:`LoadedSpec.assembly`.

    Returns
    -------
    LoadedSpec
        The mechanism (radians inside), how its start was corrected onto the loop, and the file.

    Raises
    ------
    SpecError
        One line ``file: key: what was expected`` for invalid TOML (with its line), an unknown key (with the
        closest valid one), a value of the wrong type, length or range, a zero direction, too few joints,
        duplicate joint names, an unknown joint in ``couple``/``fixed``, both or neither of ``[loop]`` and
        ``[mechanism]``, a joint connecting a body to itself, or bodies not connected to the rest.
    AssemblyError
        The start configuration of a ``dh`` or ``rods`` loop cannot be closed, or its link parameters close no
        loop within ``closure_tol`` (misfit, smallest singular value and joints named); the message starts with
        the file.
    """
    path = Path(path)
    source = str(path)
    table = _read_toml(path)
    reader = SpecReader(source)
    reader.check_keys(table, "", TOP_KEYS)
    name = reader.string(table, "name", "", default=path.stem, limit=MAX_NAME_CHARS)
    if name_problem(name, tab=True) is not None:  # a tab is fine (and valid XML)
        raise reader.error("name", f"expected {name_problem(name, tab=True)}, got {show(name)}")
    reader.string(table, "description", "", default="")  # free text for the reader
    unit = reader.choice(table, "angles", "", ANGLE_UNITS, default="deg")
    reader.degrees = unit == "deg"
    has_loop, has_mech = "loop" in table, "mechanism" in table
    if has_loop and has_mech:
        raise reader.error("mechanism", "expected exactly one of [loop] and [mechanism], got both")
    if not (has_loop or has_mech):
        raise reader.error(
            "loop",
            "missing; expected a [loop] table (one closed loop) or a [mechanism] table "
            "(joints between bodies)",
        )
    meta = {"source": source}
    try:
        if has_loop:
            mech, assembly, couplings = read_loop_table(reader, table["loop"], name, meta, closure_tol)
        else:
            mech, couplings = read_mechanism_table(reader, table["mechanism"], name, meta)
            assembly = None
    except AssemblyError as exc:
        raise AssemblyError(f"{reader.source}: {exc}", residual=exc.residual) from None
    couple, fixed = couplings
    if couple or fixed:
        mech = mech.with_couplings(couple, fixed)
    if assembly is None:
        _check_not_near_mobile(mech, reader.source, closure_tol)
    if "points" in table:
        mech = replace(mech, meta={**mech.meta, "points": read_points_table(reader, table["points"], mech)})
    return LoadedSpec(mechanism=mech, assembly=assembly, source=path)


def _check_not_near_mobile(mech: Mechanism, source: str, closure_tol: float) -> None:
    """Hinge lines a rounding away from a mobile linkage: one line with the numbers, unless within tolerance."""
    near = near_mobility(mech)
    if near is None or near.misfit <= closure_tol:
        return
    raise AssemblyError(
        f"{source}: {mech.name}: the joint lines are rigid by a hair, not mobile: smallest singular value "
        f"{near.relative:.3g} of the largest (normalised Jacobian), a closure misfit of {near.misfit:.3g} per "
        f"radian of the near-motion of joints {', '.join(near.joints)} > closure tolerance {closure_tol:.3g}; "
        "an over-constrained linkage typed with rounded coordinates? Give them to full precision, or accept the "
        "misfit as play in the hinges with a closure tolerance above it (closure_tol / --closure-tol)",
        residual=near.misfit,
    )


def resolve_spec(
    spec: str | Path, params: Mapping[str, Any] | None = None, *, closure_tol: float = 1e-12
) -> LoadedSpec:
    """A spec file or a built-in linkage by name, as the CLI's ``SPEC [--set KEY=VALUE ...]`` takes it.

    Parameters
    ----------
    spec
        A path ending in ``.toml``, containing a slash or naming an existing file is read with
        :func:`load_spec`; anything else is the name of a built-in linkage (``linkwork linkages`` lists them).
    params
        Parameters of a built-in in file units (degrees for angles); must be empty for a file.
    closure_tol
        For a file: the largest least-squares closure misfit accepted at assembly (see :func:`load_spec`).

    Returns
    -------
    LoadedSpec
        With ``assembly`` and ``source`` set to ``None`` for a built-in.

    Raises
    ------
    SpecError
        ``--set`` given with a file, an unknown built-in or parameter, or any error of :func:`load_spec`.
    """
    params = dict(params or {})
    path = Path(spec)
    looks_like_file = isinstance(spec, Path) or path.suffix.lower() == ".toml" or path.is_file()
    if looks_like_file or "/" in str(spec) or "\\" in str(spec):
        if params:
            given = ", ".join(sorted(params))
            raise SpecError(
                f"--set applies to built-in linkages only (got {given}); edit the file instead",
                source=escape_line(str(path)),
                key="--set",
            )
        return load_spec(path, closure_tol=closure_tol)
    from linkwork.linkages.registry import get

    import_builtins()
    return LoadedSpec(mechanism=get(str(spec)).make(**params), assembly=None, source=None)


def import_builtins() -> None:
    """Import every module of :mod:`linkwork.linkages` so that each registers its built-ins."""
    import linkwork.linkages as package

    for module in pkgutil.iter_modules(package.__path__):
        importlib.import_module(f"{package.__name__}.{module.name}")


def _read_toml(path: Path) -> dict[str, Any]:
    """The parsed file; a syntax error becomes a SpecError naming its line."""
    return read_toml(path, "a linkage spec file (TOML)")
